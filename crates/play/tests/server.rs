//! The server without a browser: its HTTP paths, the watchdog when the page goes quiet, and a
//! bridged device as the hand with a page that watches (served before the device's hello).

#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::bridge::BridgeConfig;
use haptic_devices::bridge::fake::{FakeConfig, run_fake};
use haptic_devices::script::Script;
use haptic_loop::session::{SceneSource, read_arrays};
use haptic_types::DeviceModel;
use haptic_types::device::FALCON;
use play::protocol::ServerMsg;
use play::{PlayConfig, PlayError, PlaySummary, run};
use recording::read_recording_file;
use serde_json::Value;
use std::io::{Read, Write};
use std::net::{TcpStream, UdpSocket};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

type Ws = WebSocket<MaybeTlsStream<TcpStream>>;

fn start(
    scene: &str,
    name: &str,
    device: Option<BridgeConfig>,
) -> (
    String,
    Arc<AtomicBool>,
    JoinHandle<Result<PlaySummary, PlayError>>,
    PathBuf,
) {
    start_with(scene, name, device, webguard::gate::Limits::default())
}

fn start_with(
    scene: &str,
    name: &str,
    device: Option<BridgeConfig>,
    limits: webguard::gate::Limits,
) -> (
    String,
    Arc<AtomicBool>,
    JoinHandle<Result<PlaySummary, PlayError>>,
    PathBuf,
) {
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-play-srv-{}-{name}.mcap", std::process::id()));
    let mut c = PlayConfig::new(SceneSource::resolve(scene.as_ref()).unwrap(), out.clone());
    c.port = 0;
    c.device = device;
    c.keep_serving_s = Some(0.0);
    c.limits = limits;
    let stop = Arc::new(AtomicBool::new(false));
    let s2 = stop.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    let h = std::thread::spawn(move || {
        run(&c, &s2, &mut |u| {
            let _ = tx.send(u.to_string());
        })
    });
    let url = rx.recv_timeout(Duration::from_secs(10)).unwrap();
    (url, stop, h, out)
}

fn http(url: &str, request: &str) -> String {
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = TcpStream::connect(addr).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

fn page(url: &str) -> Ws {
    let ws_url = format!("{}ws", url.replace("http://", "ws://"));
    let (ws, _) = tungstenite::connect(ws_url.as_str()).unwrap();
    if let MaybeTlsStream::Plain(s) = ws.get_ref() {
        s.set_read_timeout(Some(Duration::from_millis(5))).unwrap();
    }
    ws
}

/// Waits for the session's hello (within 10 s), then presses Start, as the page does (its
/// Start button is enabled by the hello).
fn start_when_open(ws: &mut Ws) {
    let t0 = Instant::now();
    while !read_for(ws, 0.05).iter().any(|m| m["type"] == "hello") {
        assert!(t0.elapsed() < Duration::from_secs(10), "no hello in 10 s");
    }
    send(ws, serde_json::json!({"type": "start"}));
}

/// The text messages that arrive within `secs` (each one also read as a typed
/// [`ServerMsg`]: what the server sends is what the protocol's type says).
fn read_for(ws: &mut Ws, secs: f64) -> Vec<Value> {
    let t0 = Instant::now();
    let mut out = Vec::new();
    while t0.elapsed().as_secs_f64() < secs {
        if let Ok(Message::Text(t)) = ws.read() {
            let typed: ServerMsg = serde_json::from_str(t.as_str())
                .unwrap_or_else(|e| panic!("not a ServerMsg ({e}): {t}"));
            let v: Value = serde_json::from_str(t.as_str()).unwrap();
            assert_eq!(v["type"], typed.type_name());
            out.push(v);
        }
    }
    out
}

fn send(ws: &mut Ws, v: Value) {
    ws.send(Message::text(v.to_string())).unwrap();
}

#[test]
fn the_page_is_served_on_its_paths_only() {
    let (url, stop, h, _) = start("brickworld", "http", None);
    let host = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let get = |path: &str| {
        http(
            &url,
            &format!("GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n"),
        )
    };
    let index = get("/");
    assert!(
        index.starts_with("HTTP/1.1 200 OK\r\nContent-Type: text/html"),
        "{index}"
    );
    assert!(index.contains("<canvas id=\"view\""));
    assert!(index.contains(r#"<script type="module" src="/main.js">"#));
    // The page's modules, as JavaScript (a browser runs a module of no other type).
    for m in play::server::PAGE_FILES
        .iter()
        .filter(|f| f.path.ends_with(".js"))
    {
        let r = get(m.path);
        assert!(
            r.starts_with("HTTP/1.1 200 OK\r\nContent-Type: text/javascript; charset=utf-8\r\n"),
            "{}: {r}",
            m.path
        );
        assert!(r.ends_with(m.body), "{}", m.path);
    }
    for m in [
        "/main.js",
        "/camera.js",
        "/draw.js",
        "/input.js",
        "/sound.js",
        "/messages.js",
    ] {
        assert!(get(m).starts_with("HTTP/1.1 200 OK"), "{m}");
    }
    // Only the whitelist: the old single script, other files of the crate, paths out.
    for p in [
        "/play.js",
        "/lib.rs",
        "/page/main.js",
        "/../Cargo.toml",
        "/main.js/",
    ] {
        assert!(get(p).starts_with("HTTP/1.1 404"), "{p}");
    }
    assert!(get("/play.css").starts_with("HTTP/1.1 200 OK\r\nContent-Type: text/css"));
    assert!(get("/favicon.ico").starts_with("HTTP/1.1 204"));
    let rec = get("/recording.mcap");
    assert!(rec.starts_with("HTTP/1.1 404"));
    assert!(rec.ends_with("the recording is served once the session has ended\n"));
    assert!(get("/etc/passwd").starts_with("HTTP/1.1 404"));
    assert!(get("/ws").starts_with("HTTP/1.1 400"));
    let post = http(
        &url,
        &format!("POST / HTTP/1.1\r\nHost: {host}\r\nContent-Length: 0\r\n\r\n"),
    );
    assert!(post.starts_with("HTTP/1.1 405"));
    // Loopback only.
    assert!(url.starts_with("http://127.0.0.1:"));
    stop.store(true, Ordering::Relaxed);
    assert!(matches!(h.join().unwrap(), Err(PlayError::NotStarted)));
}

#[test]
fn the_watchdog_takes_the_force_down_when_the_page_goes_quiet() {
    let (url, _stop, h, out) = start("wall", "watchdog", None);
    let mut ws = page(&url);
    let hello = read_for(&mut ws, 0.3);
    assert_eq!(hello[0]["type"], "hello");
    assert_eq!(hello[0]["page_is_hand"], true);
    send(&mut ws, serde_json::json!({"type": "start"}));
    let press = |ws: &mut Ws, seq: u64| {
        let t_ms = haptic_loop::session::now_unix_ns() as f64 * 1e-6;
        send(
            ws,
            serde_json::json!({"type": "input", "seq": seq, "pos": [0.0, 0.0, -0.25], "buttons": 0, "t_ms": t_ms}),
        );
    };
    let mut seq = 0;
    // Pressing into the wall for 0.8 s, silent for 0.6 s, pressing again for 0.6 s.
    for (secs, talk) in [(0.8, true), (0.6, false), (0.6, true)] {
        let t0 = Instant::now();
        while t0.elapsed().as_secs_f64() < secs {
            if talk {
                seq += 1;
                press(&mut ws, seq);
            }
            let _ = read_for(&mut ws, 0.02);
        }
    }
    send(&mut ws, serde_json::json!({"type": "end"}));
    let msgs = read_for(&mut ws, 0.5);
    assert!(msgs.iter().any(|m| m["type"] == "end"));
    let s = h.join().unwrap().unwrap();
    assert_eq!(s.session.end, "stopped");
    let a = read_arrays(&out, false).unwrap();
    let first = |name: &str| a.events.iter().find(|e| e.1 == name).map(|e| e.0);
    let (late, lost, back) = (
        first("device.sample_late").unwrap(),
        first("device.lost").unwrap(),
        first("device.resumed").unwrap(),
    );
    assert!(late < lost && lost < back, "{late} {lost} {back}");
    // Zero force from the loss to the return; the watchdog's ramp takes at most 10 ticks.
    assert!(lost - late <= 10, "{late} {lost}");
    let fz = |t: u64| a.device_force_n[t as usize][2];
    assert!(
        fz(late - 1) > 1.0,
        "pressed into the wall: {}",
        fz(late - 1)
    );
    assert!((lost..back).all(|t| fz(t) == 0.0));
    assert!(a.state.len() > 1500);
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
}

#[test]
fn a_bridged_device_is_the_hand_and_the_page_watches() {
    let port = UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let mut b = BridgeConfig::parse(&format!("udp:127.0.0.1:{port}")).unwrap();
    b.wait_s = 30.0;
    let (url, _stop, h, out) = start("wall", "bridged", Some(b));
    // The page is served before the device's hello: it is told what the session waits for.
    let mut ws = page(&url);
    let first = read_for(&mut ws, 0.3);
    assert_eq!(first[0]["type"], "waiting");
    assert_eq!(first[0]["for"], "the device's hello");
    let text = SceneSource::builtin("wall").unwrap().scripts[0].1.clone();
    let fake = FakeConfig {
        target: format!("127.0.0.1:{port}").parse().unwrap(),
        model: DeviceModel::Falcon,
        script: Script::from_toml(&text, &FALCON).unwrap(),
        hand: None,
        physical: None,
        loss: 0.0,
        jitter_s: 0.0,
        latency_s: 0.0,
        seed: 1,
        seconds: Some(2.0),
        outage: None,
        wait_s: 20.0,
        bye: true,
        protocol: haptic_devices::local::Protocol::V2,
        fault: None,
    };
    let dev = std::thread::spawn(move || run_fake(&fake, None));
    let msgs = read_for(&mut ws, 0.6);
    let hello = msgs.iter().find(|m| m["type"] == "hello").unwrap();
    assert_eq!(hello["page_is_hand"], false);
    send(&mut ws, serde_json::json!({"type": "start"}));
    send(
        &mut ws,
        serde_json::json!({"type": "input", "seq": 1, "pos": [0, 0, 0], "buttons": 0, "t_ms": 1}),
    );
    let mut msgs = read_for(&mut ws, 2.5);
    dev.join().unwrap().unwrap();
    let s = h.join().unwrap().unwrap();
    msgs.extend(read_for(&mut ws, 0.2));
    assert_eq!(s.session.end, "device_ended");
    assert!(
        msgs.iter()
            .any(|m| m["type"] == "role" && m["role"] == "view")
    );
    assert!(msgs.iter().any(|m| m["type"] == "error"
        && m["message"] == "a device is the hand in this session: the page only watches"));
    let frames = msgs.iter().filter(|m| m["type"] == "frame").count();
    assert!(
        frames as u64 * 16 >= s.session.stats.ticks / 2,
        "{frames} frames for {} ticks",
        s.session.stats.ticks
    );
    assert!(s.session.input_latency_ms.is_none());
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
}

#[test]
fn a_busy_port_and_a_bad_length_are_named() {
    let busy = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = busy.local_addr().unwrap().port();
    let mut c = PlayConfig::new(
        SceneSource::resolve("brickworld".as_ref()).unwrap(),
        std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nh-play-busy.mcap"),
    );
    c.port = port;
    let stop = AtomicBool::new(false);
    let e = run(&c, &stop, &mut |_| {}).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("cannot serve the page on 127.0.0.1:{port}: ")),
        "{e}"
    );
    assert!(e.ends_with("(choose another with --port, or --port 0 for any free port)"));
    // On its own thread (`start`), the same error comes back instead of a URL.
    let threaded = match play::start(c.clone(), std::sync::Arc::new(AtomicBool::new(false))) {
        Err(e) => e.to_string(),
        Ok(r) => panic!("served {} on a busy port", r.url),
    };
    assert_eq!(threaded, e);
    c.port = 0;
    c.seconds = Some(-1.0);
    assert_eq!(
        run(&c, &stop, &mut |_| {}).unwrap_err().to_string(),
        "session length [s] = -1 is out of range: allowed 0 < length ≤ 3600 s"
    );
}

/// A WebSocket upgrade to `url`'s `/ws` with `host` and `origin` as sent by a browser: the
/// answer's head, and its body when refused.
fn upgrade(url: &str, host: &str, origin: &str) -> String {
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(
        format!(
            "GET /ws HTTP/1.1\r\nHost: {host}\r\nOrigin: {origin}\r\nUpgrade: websocket\r\n\
             Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
        )
        .as_bytes(),
    )
    .unwrap();
    let mut out = Vec::new();
    let mut b = [0u8; 1];
    while let Ok(1) = s.read(&mut b) {
        out.push(b[0]);
        // A switched connection stays open: its head is the answer.
        if out.ends_with(b"\r\n\r\n") && out.starts_with(b"HTTP/1.1 101") {
            break;
        }
    }
    String::from_utf8(out).unwrap()
}

#[test]
fn forged_origin_and_host_are_refused_counted_and_change_nothing() {
    let (url, stop, h, _) = start("brickworld", "forged", None);
    let host = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let port = host.rsplit(':').next().unwrap().to_string();
    // Cross-site WebSocket hijacking: a page of another site opens our /ws.
    let r = upgrade(&url, &host, "https://evil.example");
    assert!(r.starts_with("HTTP/1.1 403 Forbidden"), "{r}");
    assert!(r.ends_with(&format!(
        "Origin `https://evil.example` is not this page's own origin `http://{host}`: a page \
         from another site may not use this server\n"
    )));
    // DNS rebinding: the attacker's host name resolving to 127.0.0.1.
    for path in ["/", "/ws", "/recording.mcap"] {
        let r = http(
            &url,
            &format!("GET {path} HTTP/1.1\r\nHost: rebind.evil.example:{port}\r\n\r\n"),
        );
        assert!(r.starts_with("HTTP/1.1 403 Forbidden"), "{path}: {r}");
        assert!(r.contains("Host `rebind.evil.example:"), "{r}");
    }
    let r = upgrade(
        &url,
        &format!("rebind.evil.example:{port}"),
        &format!("http://rebind.evil.example:{port}"),
    );
    assert!(r.starts_with("HTTP/1.1 403 Forbidden"), "{r}");
    // No Host at all, and a malformed head.
    assert!(http(&url, "GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 403"));
    assert!(http(&url, "GET / HTTP/1.1 x\r\n\r\n").starts_with("HTTP/1.1 400"));
    // The page's own origin is served, by loopback name or address.
    let r = upgrade(&url, &host, &format!("http://{host}"));
    assert!(r.starts_with("HTTP/1.1 101 Switching Protocols"), "{r}");
    let lh = format!("localhost:{port}");
    assert!(upgrade(&url, &lh, &format!("http://{lh}")).starts_with("HTTP/1.1 101"));
    // A real page plays; too big a message closes only its own link.
    let mut p = page(&url);
    start_when_open(&mut p);
    send(
        &mut p,
        serde_json::json!({"type": "input", "seq": 1, "pos": [0, 0, 0], "buttons": 0, "t_ms": 1}),
    );
    let _ = read_for(&mut p, 0.3);
    let mut big = page(&url);
    let _ = big.send(Message::text("x".repeat(5000)));
    let t0 = Instant::now();
    let closed = loop {
        match big.read() {
            Err(tungstenite::Error::Io(e))
                if e.kind() == std::io::ErrorKind::WouldBlock
                    || e.kind() == std::io::ErrorKind::TimedOut =>
            {
                if t0.elapsed() > Duration::from_secs(10) {
                    break false;
                }
            }
            Err(_) | Ok(Message::Close(_)) => break true,
            Ok(_) => {}
        }
    };
    assert!(closed, "a 5000-byte message closes its link");
    // A page flooding messages is refused beyond its rate, and told so.
    let mut flood = page(&url);
    for _ in 0..1500 {
        let _ = flood.send(Message::text(r#"{"type":"start"}"#));
    }
    let msgs = read_for(&mut flood, 1.0);
    assert!(
        msgs.iter()
            .any(|m| m["message"]
                == "too many messages: at most 500 per second (this one was dropped)"),
        "{msgs:?}"
    );
    send(&mut p, serde_json::json!({"type": "end"}));
    let _ = read_for(&mut p, 0.5);
    stop.store(true, Ordering::Relaxed);
    let s = h.join().unwrap().unwrap();
    assert_eq!(s.refused.origin, 1, "{:?}", s.refused);
    assert_eq!(s.refused.host, 5, "{:?}", s.refused);
    assert_eq!(s.refused.head, 1, "{:?}", s.refused);
    assert_eq!(s.refused.size, 1, "{:?}", s.refused);
    assert!(s.refused.rate >= 400, "{:?}", s.refused);
    // Only the real page and the two good upgrades connected (and the flooder, the big one).
    assert_eq!(s.pages_served, 5);
}

#[test]
#[allow(unsafe_code)] // one setsockopt on a socket this test owns
fn a_page_that_stops_reading_loses_frames_never_the_loop() {
    use std::os::fd::AsRawFd;
    // Small buffers (8 KiB in the kernel, 32 KiB in the link) so a stalled page fills them in
    // a second instead of the system's few MiB.
    let limits = webguard::gate::Limits {
        send_buffer_bytes: Some(8192),
        max_write_buffer_bytes: 32 * 1024,
        ..webguard::gate::Limits::default()
    };
    let (url, stop, h, _) = start_with("brickworld", "stalled", None, limits);
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    // The player's page.
    let mut p = page(&url);
    start_when_open(&mut p);
    // A page that opens its link and then never reads, with a small receive buffer so its
    // socket fills within a second.
    let raw = TcpStream::connect(addr).unwrap();
    let small: libc::c_int = 4096;
    // SAFETY: a valid socket and a c_int option value of the right size.
    unsafe {
        libc::setsockopt(
            raw.as_raw_fd(),
            libc::SOL_SOCKET,
            libc::SO_RCVBUF,
            (&small as *const libc::c_int).cast(),
            std::mem::size_of::<libc::c_int>() as libc::socklen_t,
        );
    }
    let (_stalled, _) = tungstenite::client(format!("ws://{addr}/ws").as_str(), raw).unwrap();
    // The player keeps playing for 4 s; it keeps getting frames all along.
    let mut frames_late = 0;
    let t0 = Instant::now();
    let mut k = 0u64;
    while t0.elapsed() < Duration::from_secs(4) {
        k += 1;
        send(
            &mut p,
            serde_json::json!({"type": "input", "seq": k, "pos": [0, 0, 0], "buttons": 0, "t_ms": k as f64}),
        );
        let got = read_for(&mut p, 0.05);
        if t0.elapsed() > Duration::from_secs(3) {
            frames_late += got.iter().filter(|m| m["type"] == "frame").count();
        }
    }
    send(&mut p, serde_json::json!({"type": "end"}));
    let _ = read_for(&mut p, 0.3);
    stop.store(true, Ordering::Relaxed);
    let tj = Instant::now();
    let s = h.join().unwrap().unwrap();
    // The end did not wait for the stalled page: no write waited out its socket's timeout (its
    // link gets CLOSE_WAIT at the close; the 5 s timeout, twice a turn, held it 21.7 s).
    let ended_in = tj.elapsed();
    assert!(
        ended_in < Duration::from_secs(play::server::WRITE_TIMEOUT_S),
        "the end took {ended_in:?}"
    );
    // The stalled page's queue overflowed: its frames were dropped, counted…
    assert!(s.messages_dropped > 0, "{s:?}");
    // …while the player's page kept receiving them in the last second,
    assert!(frames_late > 10, "{frames_late} frames in the last second");
    // and the loop ran every tick of the session (none waited for the stalled page).
    assert!(s.session.stats.ticks > 3000, "{}", s.line());
}
