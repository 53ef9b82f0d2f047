//! `nanohaptics replay FILE --serve` (issue 42, item 5): it re-simulates the recording, says
//! where its page is, serves it (GET only, its own origin) and ends on Ctrl-C; its flags are
//! refused where they make no sense.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `GET path` on `addr` with `extra` header lines; the status line and the body.
fn get(addr: &str, path: &str, extra: &str) -> (String, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\n{extra}Connection: close\r\n\r\n"
    )
    .unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    let (head, body) = text.split_once("\r\n\r\n").unwrap();
    (head.lines().next().unwrap().to_string(), body.to_string())
}

#[test]
fn replay_serve_serves_the_page_and_ends_on_ctrl_c() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["replay", "recordings/wall.mcap", "--serve", "--port", "0"])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    // "recordings/wall.mcap: 4000 ticks in 251 frames (0.1 s); open http://127.0.0.1:PORT/ …"
    assert!(
        line.starts_with("recordings/wall.mcap: 4000 ticks in 251 frames ("),
        "{line}"
    );
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|r| r.split('/').next())
        .unwrap()
        .to_string();
    let (status, body) = get(&addr, "/replay/index.json", "");
    assert_eq!(status, "HTTP/1.1 200 OK");
    let index: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(index["ticks"], 4000);
    assert_eq!(index["rate_hz"], 1000);
    assert_eq!(index["frame_ticks"].as_array().unwrap().len(), 251);
    let (status, page) = get(&addr, "/", "");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(page.contains("<script type=\"module\" src=\"/replay.js\">"));
    // Another site's page gets nothing; nothing but GET is taken; ranges are bounded.
    let (status, _) = get(
        &addr,
        "/replay/hello.json",
        "Origin: http://evil.example\r\n",
    );
    assert_eq!(status, "HTTP/1.1 403 Forbidden");
    let (status, body) = get(&addr, "/replay/frames.json?from=0&count=501", "");
    assert_eq!(status, "HTTP/1.1 400 Bad Request");
    assert_eq!(
        body,
        "`count` = 501 is out of range: allowed 0 ≤ count ≤ 500\n"
    );
    let k = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "recordings/wall.mcap: re-simulating the session for the page ..."
    );
}

#[test]
fn replay_serve_refuses_flags_it_does_not_take_and_a_damaged_file() {
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
            .args(args)
            .current_dir(root())
            .output()
            .unwrap()
    };
    let o = run(&["replay", "recordings/wall.mcap", "--serve", "--verify"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .starts_with("error: the argument '--serve' cannot be used with '--verify'"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = run(&["replay", "recordings/wall.mcap", "--port", "9"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains("the following required arguments were not provided:\n  --serve"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let cut = Path::new(env!("CARGO_TARGET_TMPDIR")).join("replay_serve_cut.mcap");
    let bytes = std::fs::read(root().join("recordings/wall.mcap")).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let reader = recording::read_recording_file(&cut, false)
        .err()
        .unwrap()
        .to_string();
    let o = run(&["replay", cut.to_str().unwrap(), "--serve", "--port", "0"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err.lines().last().unwrap(),
        format!("error: {}: {reader}", cut.display())
    );
}
