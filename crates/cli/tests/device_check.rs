//! `nanohaptics device-check` from the command line: a fake device with a fault fails the rule
//! it breaks (exit 2, the report's line and count); bad arguments are refused naming the flag.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::{Command, Output, Stdio};

fn nh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn a_device_numbering_from_1_fails_sample_seq_and_the_check_exits_2() {
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let addr = format!("udp:127.0.0.1:{port}");
    let check = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["device-check", &addr, "--wait-s", "20"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let dev = nh(&[
        "fake-device",
        &addr,
        "--grip",
        "loose",
        "--check-hand",
        "--fault",
        "numbers-from-1",
    ]);
    assert!(
        dev.status.success(),
        "{}",
        String::from_utf8_lossy(&dev.stderr)
    );
    let out = check.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{text}\n{err}");
    assert!(
        text.starts_with(&format!(
            "device-check of `falcon` on {addr}: session version 2"
        )),
        "{text}"
    );
    assert!(text.contains("\nFAIL  sample.seq       6"), "{text}");
    assert!(
        text.ends_with("14 rules: 13 passed, 1 failed, 0 not applicable (failed: sample.seq)\n"),
        "{text}"
    );
    // The progress lines name every stage and what the hand is asked to do.
    for stage in [
        "wall: push",
        "brick: keep pushing",
        "loss:",
        "silence:",
        "resume:",
        "bye:",
    ] {
        assert!(err.contains(&format!("device-check: {stage}")), "{err}");
    }
}

#[test]
fn bad_arguments_are_refused_naming_the_flag_and_the_range() {
    let o = nh(&["device-check", "udp:127.0.0.1:9", "--rate", "50"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: --rate = 50 is out of range: allowed 100–10000 Hz\n"
    );
    let o = nh(&["device-check", "udp:127.0.0.1:9", "--wait-s", "0"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: --wait-s = 0 is out of range: allowed 0 < s ≤ 86400\n"
    );
    let o = nh(&["device-check", "tcp:1"]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: address `tcp:1`: expected udp:HOST:PORT, e.g. udp:127.0.0.1:9870\n"
    );
    let o = nh(&["fake-device", "udp:127.0.0.1:9", "--fault", "nope"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: --fault `nope` is not a fault (allowed: numbers-from-1, ignores-planes, \
         backs-off-in-silence, half-rate)\n"
    );
    let o = nh(&[
        "fake-device",
        "udp:127.0.0.1:9",
        "--fault",
        "ignores-planes",
    ]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "error: --fault ignores-planes needs a modelled device speaking protocol 2 or 3 \
         (--grip, --protocol 2): only such a device renders planes\n"
    );
}
