//! The game in a real browser: Debian's headless `chromium`, driven through the DevTools
//! Protocol. A pointer session and a keyboard-only session each fill a blueprint slot of the
//! brick world; their recordings replay bit for bit; the page received every sound event at its
//! tick and the sound samples of `render --audio --proximity`; page errors fail the tests;
//! screenshots go to docs/figures/play/.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::{Browser, fnv1a};
use haptic_loop::session::{SceneSource, read_arrays};
use play::{PlayConfig, PlayError, PlaySummary};
use recording::read_recording_file;
use serde_json::Value;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::{JoinHandle, sleep};
use std::time::Duration;

const W: u32 = 1280;
const H: u32 = 760;
/// Falcon workspace radius × the page's fill, m.
const R_M: f64 = 0.04 * play::input::WORKSPACE_FILL;

/// One browser session at a time: the tests share two cores with the real-time loop.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

struct Session {
    url: String,
    stop: Arc<AtomicBool>,
    handle: JoinHandle<Result<PlaySummary, PlayError>>,
    out: PathBuf,
}

fn start(scene: &str, name: &str) -> Session {
    let out = std::env::temp_dir().join(format!("nh-play-{}-{name}.mcap", std::process::id()));
    let mut c = PlayConfig::new(SceneSource::resolve(scene.as_ref()).unwrap(), out.clone());
    c.port = 0;
    c.seconds = Some(60.0);
    let stop = Arc::new(AtomicBool::new(false));
    let play::Running { url, handle } = play::start(c, stop.clone()).expect("the server started");
    Session {
        url,
        stop,
        handle,
        out,
    }
}

fn figures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/figures/play")
}

fn browser() -> Browser {
    match Browser::launch(W, H) {
        Ok(b) => b,
        Err(e) => panic!("{e}"),
    }
}

/// The canvas's centre and the pixels per unit-ball radius of the pointer mapping.
fn canvas_geometry(b: &mut Browser) -> (f64, f64, f64) {
    let r = b
        .eval("(() => { const r = document.getElementById('view').getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()")
        .unwrap();
    let v: Vec<f64> = r
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    (v[0] + v[2] / 2.0, v[1] + v[3] / 2.0, 0.46 * v[2].min(v[3]))
}

fn hand(b: &mut Browser) -> [f64; 3] {
    let v = b.eval("window.__play.hand.n").unwrap();
    let a: Vec<f64> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    [a[0], a[1], a[2]]
}

fn open_and_start(b: &mut Browser, url: &str, keyboard: bool) {
    b.open(url).unwrap();
    b.wait_for(
        "window.__play.hello !== null && !document.getElementById('go').disabled",
        10.0,
    )
    .unwrap();
    if keyboard {
        // Start is focused when the scene is known: Enter presses it.
        b.key("Enter", true, false).unwrap();
        b.key("Enter", false, false).unwrap();
    } else {
        let r = b
            .eval("(() => { const r = document.getElementById('go').getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; })()")
            .unwrap();
        let (x, y) = (r[0].as_f64().unwrap(), r[1].as_f64().unwrap());
        b.mouse("mousePressed", x, y, true, 0.0).unwrap();
        b.mouse("mouseReleased", x, y, false, 0.0).unwrap();
    }
    b.wait_for("window.__play.role === 'hand'", 10.0).unwrap();
    b.wait_for("window.__play.frames > 5", 10.0).unwrap();
}

/// Moves the pointer's height (wheel) to `z_m` in `steps` steps over `secs` s at (px, py).
fn wheel_to(b: &mut Browser, px: f64, py: f64, z_m: f64, steps: u32, secs: f64, down: bool) {
    let target = z_m / R_M;
    for i in 1..=steps {
        let now = hand(b)[2];
        let goal = now + (target - now) / f64::from(steps - i + 1);
        b.mouse("mouseWheel", px, py, down, -(goal - now) / 0.0015)
            .unwrap();
        sleep(Duration::from_secs_f64(secs / f64::from(steps)));
    }
}

fn end_session(b: &mut Browser, s: Session, shot: &str) -> (PlaySummary, Value) {
    b.key("e", true, false).unwrap();
    b.key("e", false, false).unwrap();
    b.wait_for("window.__play.ended !== null", 10.0).unwrap();
    // The end screen's link serves the recording.
    let bytes = b
        .eval("fetch(document.getElementById('download').href).then(r => r.arrayBuffer()).then(a => a.byteLength)")
        .unwrap();
    sleep(Duration::from_millis(300));
    b.screenshot(&figures().join(shot)).unwrap();
    let page = b.eval("JSON.parse(JSON.stringify(window.__play, (k, v) => k === 'lastFrame' ? undefined : v))").unwrap();
    b.check().unwrap();
    s.stop.store(true, Ordering::Relaxed);
    let summary = s.handle.join().unwrap().unwrap();
    assert_eq!(
        bytes.as_u64(),
        Some(std::fs::metadata(&s.out).unwrap().len()),
        "the download link serves the recording"
    );
    assert_eq!(summary.end, "stopped");
    (summary, page)
}

/// Replays the recording bit for bit and checks the sounds the page got against it.
fn check_recording(out: &std::path::Path, summary: &PlaySummary, page: &Value) {
    let rec = read_recording_file(out, false).unwrap();
    let report = haptic_loop::replay::verify(&rec).unwrap();
    assert!(report.ok(), "replay diverged: {:?}", report.divergence);
    assert_eq!(report.ticks, summary.stats.ticks);
    assert!(report.messages_compared > report.ticks);

    // The sound events at their ticks, as `render --audio` finds them in the recording.
    let arrays = read_arrays(out, false).unwrap();
    let offline = haptic_loop::sound::sound_events(&arrays).unwrap();
    let got: Vec<(u64, String)> = page["sounds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s[0].as_u64().unwrap(), s[1].as_str().unwrap().to_string()))
        .collect();
    let want: Vec<(u64, String)> = offline
        .iter()
        .map(|e| {
            (
                (e.t_s * f64::from(arrays.rate_hz)).round() as u64,
                play::publish::sound_name(&e.sound).0.to_string(),
            )
        })
        .collect();
    assert!(
        !want.is_empty(),
        "a session that places a brick makes sounds"
    );
    assert_eq!(got, want);
    // And the samples: the page hashed every sample it received.
    let track = haptic_loop::sound::session_sound(&arrays, "brickworld", true, 44_100).unwrap();
    assert_eq!(summary.published.sound_samples_limited, 0);
    assert_eq!(page["pcm"]["first"], 0);
    assert_eq!(
        page["pcm"]["samples"].as_u64(),
        Some(track.samples.len() as u64)
    );
    let h = fnv1a(track.samples.iter().flat_map(|s| s.to_le_bytes()));
    assert_eq!(
        page["pcm"]["hash"].as_u64(),
        Some(u64::from(h)),
        "the page's sound equals render --audio"
    );
}

#[test]
fn a_pointer_grabs_a_brick_and_places_it_in_a_slot() {
    let _one = serial();
    let s = start("brickworld", "pointer");
    let mut b = browser();
    open_and_start(&mut b, &s.url, false);
    b.screenshot(&figures().join("start.png")).unwrap();
    let (cx, cy, k) = canvas_geometry(&mut b);
    let px = |x_m: f64, y_m: f64| (cx + x_m / R_M * k, cy - y_m / R_M * k);
    // The built-in script's path: above the spawned brick, down, grip, up, over slot 1, down,
    // let go, up.
    let (ax, ay) = px(-0.0225, 0.0025);
    b.mouse("mouseMoved", ax, ay, false, 0.0).unwrap();
    wheel_to(&mut b, ax, ay, 0.0075, 4, 0.5, false);
    wheel_to(&mut b, ax, ay, -0.0068, 15, 0.6, false);
    sleep(Duration::from_millis(150));
    b.mouse("mousePressed", ax, ay, true, 0.0).unwrap();
    sleep(Duration::from_millis(200));
    wheel_to(&mut b, ax, ay, 0.0075, 15, 0.6, true);
    let (bx, by) = px(0.0, 0.0025);
    for i in 1..=20 {
        let f = f64::from(i) / 20.0;
        b.mouse(
            "mouseMoved",
            ax + (bx - ax) * f,
            ay + (by - ay) * f,
            true,
            0.0,
        )
        .unwrap();
        sleep(Duration::from_millis(45));
    }
    b.screenshot(&figures().join("carry.png")).unwrap();
    wheel_to(&mut b, bx, by, -0.0067, 15, 0.6, true);
    sleep(Duration::from_millis(300));
    b.mouse("mouseReleased", bx, by, false, 0.0).unwrap();
    sleep(Duration::from_millis(200));
    wheel_to(&mut b, bx, by, 0.0075, 10, 0.4, false);
    b.wait_for("window.__play.lastFrame.state.slots_filled >= 1", 3.0)
        .unwrap();
    // The menu: gravity to 5 m/s², recorded as a switch on the tick it applied to.
    b.eval("document.getElementById('sw-gravity_m_per_s2').value = '5'; document.querySelector('#menu button').click(); 0").unwrap();
    b.wait_for("window.__play.switched.length === 1", 3.0)
        .unwrap();
    // A value out of range is refused with the switch's range, and the session goes on.
    b.eval("document.getElementById('sw-gravity_m_per_s2').value = '1000'; document.querySelector('#menu button').click(); 0").unwrap();
    b.wait_for("window.__play.errors.length === 1", 3.0)
        .unwrap();
    let err = b.eval("window.__play.errors[0].message").unwrap();
    assert_eq!(
        err,
        "switch `gravity_m_per_s2` = 1000 is out of range: allowed 0 ≤ value ≤ 100"
    );
    sleep(Duration::from_millis(300));
    b.screenshot(&figures().join("placed.png")).unwrap();
    let out = s.out.clone();
    let (summary, page) = end_session(&mut b, s, "end.png");
    assert!(
        summary.state("slots_filled").unwrap() >= 1.0,
        "{:?}",
        summary.state
    );
    assert!(summary.state("score").unwrap() >= 25.0 - 1e-9);
    assert_eq!(
        page["ended"]["state"]["score"].as_f64(),
        summary.state("score")
    );
    assert!(summary.input_latency_ms.is_some());
    assert_eq!(summary.page_messages_refused, 1);
    let sw = &page["switched"][0];
    let rec = read_recording_file(&out, false).unwrap();
    let sched = recording::switch_schedule(&rec, 1_000_000).unwrap();
    assert_eq!(sched.len(), 1);
    assert_eq!(Some(sched[0].0), sw["tick"].as_u64());
    assert_eq!(
        (sched[0].1.name.as_str(), sched[0].1.value),
        ("gravity_m_per_s2", 5.0)
    );
    check_recording(&out, &summary, &page);
}

/// Holds arrow keys (coarse, then with Shift) until the hand's axis `axis` reaches `target_m`.
fn key_to(b: &mut Browser, axis: usize, target_m: f64) {
    let target = target_m / R_M;
    let keys = [
        ("ArrowRight", "ArrowLeft"),
        ("ArrowUp", "ArrowDown"),
        ("PageUp", "PageDown"),
    ][axis];
    for (tol, fine) in [(0.04, false), (0.003, true)] {
        let err = target - hand(b)[axis];
        if err.abs() <= tol {
            continue;
        }
        let key = if err > 0.0 { keys.0 } else { keys.1 };
        b.key(key, true, fine).unwrap();
        for _ in 0..2000 {
            let e = target - hand(b)[axis];
            if e.abs() <= tol * 0.5 || (e > 0.0) != (err > 0.0) {
                break;
            }
            sleep(Duration::from_millis(5));
        }
        b.key(key, false, fine).unwrap();
    }
}

#[test]
fn a_keyboard_only_session_fills_a_slot() {
    let _one = serial();
    let s = start("brickworld", "keys");
    let mut b = browser();
    open_and_start(&mut b, &s.url, true);
    key_to(&mut b, 2, 0.0075);
    key_to(&mut b, 0, -0.0225);
    key_to(&mut b, 1, 0.0025);
    sleep(Duration::from_millis(300));
    key_to(&mut b, 2, -0.0068);
    sleep(Duration::from_millis(150));
    b.key(" ", true, false).unwrap();
    b.key(" ", false, false).unwrap();
    sleep(Duration::from_millis(200));
    key_to(&mut b, 2, 0.0075);
    key_to(&mut b, 0, 0.0);
    key_to(&mut b, 1, 0.0025);
    key_to(&mut b, 2, -0.0067);
    sleep(Duration::from_millis(300));
    b.key(" ", true, false).unwrap();
    b.key(" ", false, false).unwrap();
    sleep(Duration::from_millis(200));
    key_to(&mut b, 2, 0.0075);
    b.wait_for("window.__play.lastFrame.state.slots_filled >= 1", 3.0)
        .unwrap();
    let out = s.out.clone();
    let (summary, page) = end_session(&mut b, s, "end-keyboard.png");
    assert!(summary.state("slots_filled").unwrap() >= 1.0);
    // The log (the ARIA live region) announced the grab and the slot.
    let said: Vec<String> = page["said"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect();
    for want in [
        "you are the hand",
        "grip on",
        "grip off",
        "brick grabbed",
        "slot filled",
        "score 25",
    ] {
        assert!(
            said.iter().any(|s| s.contains(want)),
            "`{want}` not announced: {said:?}"
        );
    }
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
    assert!(page["inputsSent"].as_u64().unwrap() > 10);
}

#[test]
fn the_nano_world_plays_in_the_page() {
    let _one = serial();
    let s = start("nanoworld", "nano");
    let mut b = browser();
    open_and_start(&mut b, &s.url, false);
    let (cx, cy, k) = canvas_geometry(&mut b);
    // Down towards the substrate and across it.
    b.mouse("mouseMoved", cx, cy, false, 0.0).unwrap();
    wheel_to(&mut b, cx, cy, -0.012, 20, 1.0, false);
    for i in 0..=30 {
        let f = f64::from(i) / 30.0;
        b.mouse("mouseMoved", cx + 0.3 * k * f, cy - 0.2 * k * f, false, 0.0)
            .unwrap();
        sleep(Duration::from_millis(30));
    }
    sleep(Duration::from_millis(300));
    b.screenshot(&figures().join("nano.png")).unwrap();
    let drawn = b.eval("window.__play.draws").unwrap().as_u64().unwrap();
    assert!(drawn > 30, "{drawn} draws");
    let out = s.out.clone();
    let (summary, page) = end_session(&mut b, s, "end-nano.png");
    assert!(summary.stats.ticks > 1500);
    assert_eq!(page["hello"]["kind"], "nanoworld");
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
}

#[test]
fn page_errors_and_failed_loads_fail_the_harness() {
    let _one = serial();
    let s = start("brickworld", "errors");
    let mut b = browser();
    // A path the server does not have: the load reports HTTP 404.
    b.open(&format!("{}nope.js", s.url)).unwrap();
    let e = b.check().unwrap_err();
    assert!(e.contains("HTTP 404"), "{e}");
    b.errors.clear();
    // The page itself loads clean; a thrown exception is caught.
    b.open(&s.url).unwrap();
    b.wait_for("window.__play.hello !== null", 10.0).unwrap();
    b.check().unwrap();
    b.eval("setTimeout(() => { throw new Error('boom'); }, 0); 0")
        .unwrap();
    sleep(Duration::from_millis(200));
    let e = b.check().unwrap_err();
    assert!(e.contains("boom"), "{e}");
    // A page that cannot be reached fails to open.
    let dead = "http://127.0.0.1:9/";
    assert!(b.open(dead).is_err() || b.check().is_err());
    s.stop.store(true, Ordering::Relaxed);
    assert!(matches!(
        s.handle.join().unwrap(),
        Err(PlayError::NotStarted)
    ));
}
