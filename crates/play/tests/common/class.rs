//! A class served by the test and reached as its pages would: HTTP requests, the join form,
//! the students' and the teacher's WebSocket links.
#![allow(dead_code)]

use haptic_loop::session::SceneSource;
use play::classroom::{ClassAddresses, ClassConfig, ClassSummary, run};
use serde_json::{Value, json};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

pub type Ws = WebSocket<MaybeTlsStream<TcpStream>>;

/// A class served on a thread of the test.
pub struct Running {
    pub addr: ClassAddresses,
    pub host: String,
    pub stop: Arc<AtomicBool>,
    pub handle: JoinHandle<Result<ClassSummary, play::PlayError>>,
    pub dir: PathBuf,
}

/// A class of at most `max` on brickworld (the teacher's code TEACH123), its recordings in
/// the target folder's `nh-class-PID-NAME`.
pub fn start(name: &str, max: usize) -> Running {
    start_config(name, |c| c.max_students = max)
}

/// [`start`] with a lesson.
pub fn start_with(name: &str, max: usize, lesson: Option<teaching::Lesson>) -> Running {
    start_config(name, |c| {
        c.max_students = max;
        c.lesson = lesson;
    })
}

/// A class on brickworld, any free port, the teacher's code TEACH123, its recordings in the
/// target folder's `nh-class-PID-NAME`, with what `configure` changes; served on a thread once
/// its addresses are known.
pub fn start_config(name: &str, configure: impl FnOnce(&mut ClassConfig)) -> Running {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-class-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut c = ClassConfig::new(
        SceneSource::resolve("brickworld".as_ref()).unwrap(),
        dir.clone(),
    );
    c.port = 0;
    c.teacher_code = Some("TEACH123".into());
    configure(&mut c);
    let stop = Arc::new(AtomicBool::new(false));
    let s2 = stop.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    let handle = std::thread::spawn(move || {
        run(&c, &s2, &mut |a| {
            let _ = tx.send(a.clone());
        })
    });
    let addr = rx.recv_timeout(Duration::from_secs(20)).unwrap();
    let host = addr
        .student_url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    Running {
        addr,
        host,
        stop,
        handle,
        dir,
    }
}

pub fn http(host: &str, request: &str) -> String {
    let mut s = TcpStream::connect(host).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut out = Vec::new();
    s.read_to_end(&mut out).unwrap();
    String::from_utf8_lossy(&out).to_string()
}

/// `GET path`: the whole response's bytes.
pub fn get_bytes(host: &str, path: &str) -> Vec<u8> {
    let mut s = TcpStream::connect(host).unwrap();
    s.write_all(format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n").as_bytes())
        .unwrap();
    let mut out = Vec::new();
    s.read_to_end(&mut out).unwrap();
    out
}

pub fn get(host: &str, path: &str) -> String {
    http(
        host,
        &format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n"),
    )
}

/// A form `POST` to `/join` from the join page (`name` URL-encoded), with `headers` (each
/// ending in `\r\n`) in place of the page's own `Origin` and `Sec-Fetch-Site`.
pub fn post_join(host: &str, name: &str, headers: Option<&str>) -> String {
    let body = format!("name={name}");
    let own = format!("Origin: http://{host}\r\nSec-Fetch-Site: same-origin\r\n");
    http(
        host,
        &format!(
            "POST /join HTTP/1.1\r\nHost: {host}\r\n{}Content-Type: \
             application/x-www-form-urlencoded\r\nContent-Length: {}\r\n\r\n{body}",
            headers.unwrap_or(&own),
            body.len()
        ),
    )
}

/// Joins as `name` through the join page's form; the session token from the redirect.
pub fn join(host: &str, name: &str) -> String {
    let r = post_join(host, name, None);
    assert!(r.starts_with("HTTP/1.1 303 See Other"), "{r}");
    let loc = r
        .lines()
        .find_map(|l| l.strip_prefix("Location: /play?s="))
        .unwrap();
    loc.trim().to_string()
}

pub fn ws(host: &str, path: &str) -> Ws {
    let (ws, _) = tungstenite::connect(format!("ws://{host}{path}").as_str()).unwrap();
    if let MaybeTlsStream::Plain(s) = ws.get_ref() {
        s.set_read_timeout(Some(Duration::from_millis(5))).unwrap();
    }
    ws
}

pub fn read_for(ws: &mut Ws, secs: f64) -> Vec<Value> {
    let t0 = Instant::now();
    let mut out = Vec::new();
    while t0.elapsed().as_secs_f64() < secs {
        if let Ok(Message::Text(t)) = ws.read() {
            out.push(serde_json::from_str(t.as_str()).unwrap());
        }
    }
    out
}

pub fn send(ws: &mut Ws, v: Value) {
    ws.send(Message::text(v.to_string())).unwrap();
}

/// A lesson of two short steps: a pre-test question; 0.3 s of bricks with gravity off, then
/// "what did the bricks do?"; 0.2 s of atoms, locked for the teacher.
pub const TWO_STEP_LESSON: &str = r#"
[lesson]
title = "Two worlds"

[[test]]
prompt = "Which force holds a few atoms to a surface?"
answer = "choice"
choices = ["Their weight", "Surface attraction"]
correct = "Surface attraction"

[[step]]
id = "float"
title = "No gravity"
scene = "brickworld"
switches = { gravity_m_per_s2 = 0.0 }
task = "Watch the bricks."
done = { when = "time", seconds = 0.3 }
after = { prompt = "What did the bricks do?", answer = "text" }

[[step]]
id = "atoms"
title = "Atoms"
scene = "nanoworld"
locked = true
task = "Watch the atoms."
done = { when = "time", seconds = 0.2 }
"#;

/// The latest `lesson` message a page was sent among `got` (or `None`).
pub fn last_lesson(got: &[Value]) -> Option<Value> {
    got.iter().rev().find(|m| m["type"] == "lesson").cloned()
}

/// A student's page link and what it was sent but not yet looked at.
pub struct Page {
    pub ws: Ws,
    pub unread: Vec<Value>,
}

impl Page {
    pub fn new(ws: Ws) -> Page {
        Page {
            ws,
            unread: Vec::new(),
        }
    }

    /// Reads until the lesson reaches `place` (within 10 s): the messages up to that one
    /// (the rest stay unread).
    pub fn until_place(&mut self, place: &str) -> Vec<Value> {
        let t0 = Instant::now();
        loop {
            if let Some(i) = self
                .unread
                .iter()
                .position(|m| m["type"] == "lesson" && m["place"] == place)
            {
                return self.unread.drain(..=i).collect();
            }
            assert!(
                t0.elapsed() < Duration::from_secs(10),
                "the lesson never reached `{place}`; the last: {:?}",
                last_lesson(&self.unread)
            );
            self.unread.extend(read_for(&mut self.ws, 0.05));
        }
    }

    /// Reads until the page is sent a `hello` (a step's world opened): its scene's kind.
    pub fn hello_kind(&mut self) -> String {
        let t0 = Instant::now();
        loop {
            if let Some(i) = self.unread.iter().position(|m| m["type"] == "hello") {
                let h: Vec<Value> = self.unread.drain(..=i).collect();
                return h[i]["kind"].as_str().unwrap().to_string();
            }
            assert!(t0.elapsed() < Duration::from_secs(10), "no hello");
            self.unread.extend(read_for(&mut self.ws, 0.05));
        }
    }
}

/// The page starts the hand and keeps it still at the middle of the workspace.
pub fn hand(page: &mut Page, seq: &mut u64) {
    *seq += 1;
    send(
        &mut page.ws,
        json!({"type": "input", "seq": *seq, "pos": [0.0, 0.0, 0.3], "buttons": 0, "t_ms": *seq as f64}),
    );
}
