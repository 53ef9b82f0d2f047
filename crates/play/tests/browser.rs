//! The game in a real browser: Debian's headless `chromium`, driven through the DevTools
//! Protocol. A pointer session and a keyboard-only session each fill a blueprint slot of the
//! brick world; their recordings replay bit for bit; the page received every sound event at its
//! tick and every tick's input of its sound synthesis, and played the samples of `render
//! --audio --proximity` for the recording bit for bit (its drops aside), each sound it was sent
//! played once or lost in a listed drop (common/live.rs); the Events list (the live
//! region) speaks of the game only; the menu shows each switch's value as it changes; a
//! scripted gamepad (injected through the DevTools Protocol: headless Chromium has none) moves
//! the hand, grips and rumbles with the force; page errors fail the tests; screenshots go to
//! the target folder's `tmp/figures/play/` (`scripts/figures.sh` writes them to docs/figures/play/).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::figures;
use common::live;
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
    let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-play-{}-{name}.mcap", std::process::id()));
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

fn end_session(b: &mut Browser, s: Session, shot: Option<&str>) -> (PlaySummary, Value) {
    b.key("e", true, false).unwrap();
    b.key("e", false, false).unwrap();
    b.wait_for("window.__play.ended !== null", 10.0).unwrap();
    // The worklet played the stream's last samples and reported what it heard.
    b.wait_for("window.__play.sound.live !== null", 10.0)
        .unwrap();
    // The end screen's link serves the recording.
    let bytes = b
        .eval("fetch(document.getElementById('download').href).then(r => r.arrayBuffer()).then(a => a.byteLength)")
        .unwrap();
    if let Some(shot) = shot {
        sleep(Duration::from_millis(300));
        b.screenshot(&figures().join(shot)).unwrap();
    }
    let page = b.eval("JSON.parse(JSON.stringify(window.__play, (k, v) => k === 'lastFrame' ? undefined : v))").unwrap();
    // The link is the one the `end` message names.
    let href = b
        .eval("document.getElementById('download').getAttribute('href')")
        .unwrap();
    assert_eq!(href, page["ended"]["recording"], "the download link");
    b.check().unwrap();
    s.stop.store(true, Ordering::Relaxed);
    let summary = s.handle.join().unwrap().unwrap();
    assert_eq!(
        bytes.as_u64(),
        Some(std::fs::metadata(&s.out).unwrap().len()),
        "the download link serves the recording"
    );
    assert_eq!(summary.session.end, "stopped");
    (summary, page)
}

/// What the page wrote to its Events list (the live region) and announced.
fn said(page: &Value) -> Vec<String> {
    page["said"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

/// The Events list and the announcer spoke of the game only: short sentences, never the
/// loop's timing, safety or device reports (which the page did receive: the first tick's
/// `safety.config` is in its events, and stays in the recording).
fn assert_only_the_game_said(page: &Value) {
    let names: Vec<&str> = page["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e[1].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&"safety.config"),
        "the page got the loop's reports: {names:?}"
    );
    for s in said(page) {
        for word in [
            "deadline",
            "safety",
            "watchdog",
            "clamped",
            "device",
            "config",
            "passivity",
            "sample",
            "{",
            "}",
            "\"",
            "impact",
        ] {
            assert!(!s.contains(word), "`{word}` said: {s}");
        }
    }
}

/// Replays the recording bit for bit and checks the sounds the page got against it.
fn check_recording(out: &std::path::Path, summary: &PlaySummary, page: &Value) {
    let rec = read_recording_file(out, false).unwrap();
    let report = haptic_loop::replay::verify(&rec).unwrap();
    assert!(report.ok(), "replay diverged: {:?}", report.divergence);
    assert_eq!(report.ticks, summary.session.stats.ticks);
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
    // And the synthesis's input: every tick once, in order, each sound with it (the page
    // synthesises the samples; tests/browser_sound.rs compares them with `render --audio`).
    assert_eq!(
        summary.session.published.sound_ticks,
        summary.session.stats.ticks
    );
    assert_eq!(page["sound"]["firstTick"], 0);
    assert_eq!(page["sound"]["gaps"], 0);
    // The page is cross-origin isolated (the server's headers), so the ticks went to the
    // synthesis through its shared ring, every one (none waited past the ring's room).
    assert_eq!(page["sound"]["ring"], true);
    assert_eq!(page["sound"]["overflow"], 0);
    assert_eq!(
        page["sound"]["ticks"].as_u64(),
        Some(summary.session.stats.ticks)
    );
    assert_eq!(page["sound"]["sounds"].as_u64(), Some(want.len() as u64));
    assert_eq!(
        page["sound"]["messages"].as_u64(),
        Some(summary.session.published.sound_messages)
    );
    // The page's audio ran at its context's rate, and played the session's samples.
    assert!(page["sound"]["sampleRate"].as_f64().unwrap() >= 8000.0);
    check_live_sound(out, page);
}

/// The page's live sound: the samples its worklet played are `render --audio --proximity`'s
/// of the recording, bit for bit, and the sounds it played are those it was sent
/// (common/live.rs).
fn check_live_sound(out: &std::path::Path, page: &Value) -> live::Heard {
    let arrays = read_arrays(out, false).unwrap();
    let kind = page["hello"]["kind"].as_str().unwrap();
    let h = live::check(&arrays, kind, &page["sound"]["live"], &page["sound"]);
    // Each sound played had its tick → output latency measured (once: common/live.rs), a
    // positive time under the session's length.
    for ms in page["sound"]["latencyMs"].as_array().unwrap() {
        let ms = ms.as_f64().unwrap();
        assert!(ms > 0.0 && ms < 60_000.0, "{ms} ms");
    }
    println!(
        "live sound ({kind}, {} Hz): {} of {} samples played, as render --audio's; \
         {} underruns, {} samples dropped, {} silent ones skipped, {} waited, {} late messages \
         guessed over, {} samples concealed; sounds sent {}, played {}, lost in a drop {}",
        h.sample_rate_hz,
        h.played_samples,
        h.track_samples,
        h.underruns,
        h.dropped,
        h.skipped,
        h.waited,
        h.guesses,
        h.concealed,
        h.sent,
        h.played,
        h.lost
    );
    h
}

/// The gravity switch's line in the menu (its value now and its range) and its input's value.
fn menu_value(b: &mut Browser) -> (String, String) {
    let v = b
        .eval("[document.getElementById('now-gravity_m_per_s2').textContent, document.getElementById('sw-gravity_m_per_s2').value]")
        .unwrap();
    (
        v[0].as_str().unwrap().to_string(),
        v[1].as_str().unwrap().to_string(),
    )
}

/// Another page of the session: a WebSocket client of the page's origin (as a second
/// browser tab would open).
fn other_page(
    url: &str,
) -> tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<std::net::TcpStream>> {
    use tungstenite::client::IntoClientRequest;
    let host = url.trim_start_matches("http://").trim_end_matches('/');
    let mut req = format!("ws://{host}/ws").into_client_request().unwrap();
    req.headers_mut()
        .insert("Origin", format!("http://{host}").parse().unwrap());
    tungstenite::connect(req).unwrap().0
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
    // The menu shows each switch's value now beside its range: the hello's value first.
    let g0 = b
        .eval("window.__play.hello.switches.find(s => s.name === 'gravity_m_per_s2').value")
        .unwrap();
    assert_eq!(g0.as_f64(), Some(9.81));
    assert_eq!(
        menu_value(&mut b),
        ("now 9.81 · allowed 0 to 100".into(), "9.81".into())
    );
    // Gravity to 5 m/s², recorded as a switch on the tick it applied to; the menu follows.
    b.eval("document.getElementById('sw-gravity_m_per_s2').value = '5'; document.querySelector('#menu button').click(); 0").unwrap();
    b.wait_for("window.__play.switched.length === 1", 3.0)
        .unwrap();
    assert_eq!(
        menu_value(&mut b),
        ("now 5 · allowed 0 to 100".into(), "5".into())
    );
    // A value out of range is refused with the switch's range, and the session goes on.
    b.eval("document.getElementById('sw-gravity_m_per_s2').value = '1000'; document.querySelector('#menu button').click(); 0").unwrap();
    b.wait_for("window.__play.errors.length === 1", 3.0)
        .unwrap();
    let err = b.eval("window.__play.errors[0].message").unwrap();
    assert_eq!(
        err,
        "switch `gravity_m_per_s2` = 1000 is out of range: allowed 0 ≤ value ≤ 100"
    );
    // The refused value stays in the input to be corrected; the value now is still 5.
    assert_eq!(
        menu_value(&mut b),
        ("now 5 · allowed 0 to 100".into(), "1000".into())
    );
    // Another page sets gravity to 3 m/s²: this page's menu shows it.
    let mut other = other_page(&s.url);
    other
        .send(tungstenite::Message::text(
            r#"{"type":"switch","name":"gravity_m_per_s2","value":3}"#,
        ))
        .unwrap();
    b.wait_for("window.__play.switched.length === 2", 3.0)
        .unwrap();
    assert_eq!(
        menu_value(&mut b),
        ("now 3 · allowed 0 to 100".into(), "3".into())
    );
    drop(other);
    sleep(Duration::from_millis(300));
    b.screenshot(&figures().join("placed.png")).unwrap();
    let out = s.out.clone();
    let (summary, page) = end_session(&mut b, s, Some("end.png"));
    assert!(
        summary.session.state("slots_filled").unwrap() >= 1.0,
        "{:?}",
        summary.session.state
    );
    assert!(summary.session.state("score").unwrap() >= 25.0 - 1e-9);
    assert_eq!(
        page["ended"]["state"]["score"].as_f64(),
        summary.session.state("score")
    );
    assert!(summary.session.input_latency_ms.is_some());
    assert_eq!(summary.page_messages_refused, 1);
    let rec = read_recording_file(&out, false).unwrap();
    let sched = recording::switch_schedule(&rec, 1_000_000).unwrap();
    assert_eq!(sched.len(), 2);
    for (k, want) in [5.0, 3.0].into_iter().enumerate() {
        let sw = &page["switched"][k];
        assert_eq!(Some(sched[k].0), sw["tick"].as_u64());
        assert_eq!(
            (sched[k].1.name.as_str(), sched[k].1.value),
            ("gravity_m_per_s2", want)
        );
    }
    assert_eq!(page["menu"]["gravity_m_per_s2"].as_f64(), Some(3.0));
    let said = said(&page);
    for want in [
        "grip on",
        "grabbed brick 1",
        "let go of brick 1",
        "slot 1 filled with brick 1",
        "gravity_m_per_s2 set to 5",
        "gravity_m_per_s2 set to 3",
    ] {
        assert!(
            said.iter().any(|s| s.contains(want)),
            "`{want}` not said: {said:?}"
        );
    }
    assert_only_the_game_said(&page);
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
    // The page served at another path than `/`, with a query (as a classroom serves it):
    // its modules load by absolute path and its link is `/ws` with the page's query.
    open_and_start(&mut b, &format!("{}index.html?s=tok-3", s.url), true);
    assert_eq!(
        b.websockets,
        [format!(
            "ws://{}/ws?s=tok-3",
            s.url.trim_start_matches("http://").trim_end_matches('/')
        )]
    );
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
    let (summary, page) = end_session(&mut b, s, Some("end-keyboard.png"));
    assert!(summary.session.state("slots_filled").unwrap() >= 1.0);
    // The log (the ARIA live region) announced the grab and the slot, in words.
    let said = said(&page);
    for want in [
        "you are the hand",
        "grip on",
        "grip off",
        "grabbed brick 1",
        "slot 1 filled with brick 1",
        "score 25",
    ] {
        assert!(
            said.iter().any(|s| s.contains(want)),
            "`{want}` not announced: {said:?}"
        );
    }
    assert_only_the_game_said(&page);
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
    assert!(page["inputsSent"].as_u64().unwrap() > 10);
    check_live_sound(&out, &page);
}

#[test]
fn the_nano_world_plays_in_the_page() {
    let _one = serial();
    let s = start("nanoworld", "nano");
    let mut b = browser();
    open_and_start(&mut b, &s.url, false);
    let (cx, cy, k) = canvas_geometry(&mut b);
    // Down onto the substrate (the tip snaps to it) and across it.
    b.mouse("mouseMoved", cx, cy, false, 0.0).unwrap();
    wheel_to(&mut b, cx, cy, -0.021, 20, 1.0, false);
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
    let (summary, page) = end_session(&mut b, s, Some("end-nano.png"));
    assert!(summary.session.stats.ticks > 1500);
    assert_eq!(page["hello"]["kind"], "nanoworld");
    assert_only_the_game_said(&page);
    // The tip snapped to the substrate (and, pulled across it, maybe came off): said in words.
    let names: Vec<&str> = page["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e[1].as_str().unwrap())
        .collect();
    assert!(names.contains(&"nano.snap"), "{names:?}");
    let said = said(&page);
    assert!(
        said.iter().any(|s| s.contains("snap: tip to the surface")),
        "{said:?}"
    );
    if names.contains(&"nano.pull_off") {
        assert!(said.iter().any(|s| s.contains("pull-off: ")), "{said:?}");
    }
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
    check_live_sound(&out, &page);
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

/// A scripted standard-mapping gamepad, injected before the page's scripts (headless Chromium
/// has no gamepad): `navigator.getGamepads()` returns it; the test sets its axes and buttons
/// over time (`window.__pad.axis(i, v)`, `window.__pad.button(i, v)`); its
/// `vibrationActuator.playEffect` records each request with the tick of the frame the page
/// shows (`rumbles`: [tick, strong, weak, duration ms, type]); and each poll records the
/// frame's time (the animation timeline's, the time the page's frame loop steps with), the
/// page's last input (`seq`, `n`) and what the pad returned (`polls`: [t ms, seq, n, axes,
/// button values]).
const GAMEPAD: &str = r#"(() => {
  const buttons = Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 }));
  const S = { polls: [], rumbles: [] };
  const pad = {
    id: 'nanohaptics scripted gamepad (STANDARD GAMEPAD)', index: 0, connected: true,
    mapping: 'standard', timestamp: 0, axes: [0, 0, 0, 0], buttons,
    vibrationActuator: {
      type: 'dual-rumble', effects: ['dual-rumble'],
      playEffect(type, p) {
        const P = window.__play;
        S.rumbles.push([P && P.lastFrame ? P.lastFrame.tick : -1, p.strongMagnitude, p.weakMagnitude, p.duration, type]);
        return Promise.resolve('complete');
      },
      reset() { S.rumbles.push([-1, 0, 0, 0, 'reset']); return Promise.resolve('complete'); },
    },
  };
  S.axis = (i, v) => { pad.axes[i] = v; };
  S.button = (i, v) => { buttons[i] = { pressed: v > 0.5, touched: v > 0, value: v }; };
  window.__pad = S;
  Object.defineProperty(Navigator.prototype, 'getGamepads', { configurable: true, value() {
    const P = window.__play;
    if (P && P.hand && S.polls.length < 100000) {
      S.polls.push([document.timeline.currentTime, P.hand.seq, P.hand.n.slice(), pad.axes.slice(), buttons.map((b) => b.value)]);
    }
    pad.timestamp = performance.now();
    return [pad, null, null, null];
  } });
})();"#;

/// One poll of the scripted gamepad.
struct Poll {
    t_ms: f64,
    seq: u64,
    n: [f64; 3],
    axes: [f64; 4],
    buttons: Vec<f64>,
}

fn f3(v: &Value) -> [f64; 3] {
    [
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    ]
}

/// input.js's gamepad mapping, stated again: the left stick moves the hand in the view's plane
/// (right; up is away), the right stick's y moves it up (stick up: hand up), at 0.5 unit-ball
/// radii per second at full tilt, with a dead zone of 0.12; the camera's yaw turns "right".
fn stick_velocity(axes: [f64; 4], yaw: f64) -> [f64; 3] {
    let dz = |v: f64| if v.abs() < 0.12 { 0.0 } else { v };
    let (u, v) = (dz(axes[0]), -dz(axes[1]));
    let (cy, sy) = (yaw.cos(), yaw.sin());
    [
        0.5 * (u * -sy + v * -cy),
        0.5 * (u * cy + v * -sy),
        0.5 * -dz(axes[3]),
    ]
}

#[test]
fn a_gamepad_moves_the_hand_grips_and_rumbles_with_the_force() {
    let _one = serial();
    let s = start("brickworld", "gamepad");
    let mut b = browser();
    b.inject(GAMEPAD).unwrap();
    open_and_start(&mut b, &s.url, false);
    let hello = b.eval("window.__play.hello").unwrap();
    let radius_m = hello["workspace_radius_m"].as_f64().unwrap();
    let max_force_n = hello["max_force_n"].as_f64().unwrap();
    let set = |b: &mut Browser, what: &str| {
        b.eval(&format!("window.__pad.{what}; 0")).unwrap();
    };
    // The sticks, one at a time, each held a while and let go: right at full tilt, up (away)
    // at half tilt, right inside the dead zone, and the right stick up (the hand rises).
    sleep(Duration::from_millis(300));
    let strokes: [(usize, f64, u64); 4] =
        [(0, 1.0, 400), (1, -0.5, 400), (0, 0.1, 300), (3, -1.0, 300)];
    for (axis, v, ms) in strokes {
        set(&mut b, &format!("axis({axis}, {v})"));
        sleep(Duration::from_millis(ms));
        set(&mut b, &format!("axis({axis}, 0)"));
        sleep(Duration::from_millis(250));
    }
    // The right trigger grips (button 0 of the device); LB turns (button 1).
    set(&mut b, "button(7, 1)");
    sleep(Duration::from_millis(300));
    set(&mut b, "button(7, 0)");
    sleep(Duration::from_millis(250));
    set(&mut b, "button(4, 1)");
    sleep(Duration::from_millis(200));
    set(&mut b, "button(4, 0)");
    sleep(Duration::from_millis(250));
    // So far the hand was free: no force, no rumble.
    let before = b.eval("window.__pad.rumbles.length").unwrap();
    assert_eq!(before.as_u64(), Some(0), "a rumble while the hand was free");
    let strokes_end = b
        .eval("window.__pad.polls.length")
        .unwrap()
        .as_u64()
        .unwrap() as usize;
    // Down into the floor until the force is a third of the device's largest, held, then up
    // to the height it started from, free again (a frame's force alone cannot tell: a tick
    // that misses its deadline sends zero force).
    let z0 = b.eval("window.__play.hand.n[2]").unwrap().as_f64().unwrap();
    set(&mut b, "axis(3, 1)");
    b.wait_for(
        "(() => { const f = window.__play.lastFrame.device_force_n; return Math.hypot(...f) > window.__play.hello.max_force_n / 3; })()",
        10.0,
    )
    .unwrap();
    set(&mut b, "axis(3, 0)");
    sleep(Duration::from_millis(300));
    set(&mut b, "axis(3, -1)");
    b.wait_for(&format!("window.__play.hand.n[2] >= {z0}"), 10.0)
        .unwrap();
    set(&mut b, "axis(3, 0)");
    b.wait_for(
        "Math.hypot(...window.__play.lastFrame.device_force_n) === 0",
        10.0,
    )
    .unwrap();
    sleep(Duration::from_millis(300));
    let pad = b
        .eval("({ polls: window.__pad.polls, rumbles: window.__pad.rumbles })")
        .unwrap();
    let out = s.out.clone();
    let (summary, page) = end_session(&mut b, s, None);
    assert!(summary.session.stats.ticks > 1000);

    let polls: Vec<Poll> = pad["polls"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| Poll {
            t_ms: p[0].as_f64().unwrap(),
            seq: p[1].as_u64().unwrap(),
            n: f3(&p[2]),
            axes: [0, 1, 2, 3].map(|i| p[3][i].as_f64().unwrap()),
            buttons: p[4]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect(),
        })
        .collect();
    assert!(polls.len() > 60, "{} polls", polls.len());
    let a = read_arrays(&out, false).unwrap();
    let ticks = a.tick.len();
    assert!(a.tick.iter().enumerate().all(|(i, t)| *t == i as u64));
    // Every tick's recorded input is the page's hand at the input the tick read: the page's
    // point of the unit ball on the device workspace, bit for bit.
    let mut checked = 0;
    for p in polls.iter().filter(|p| p.seq > 0) {
        for i in (0..ticks).filter(|&i| a.device_seq[i] == p.seq) {
            assert_eq!(
                a.device_position_m[i],
                play::input::page_to_device(p.n, radius_m),
                "tick {i}, input {}",
                p.seq
            );
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} ticks checked");
    // The position at the last tick that read input `seq` or an earlier one, and at the first
    // that read `seq` or a later one.
    let at_or_before = |seq: u64| {
        let i = (0..ticks).rev().find(|&i| a.device_seq[i] <= seq).unwrap();
        a.device_position_m[i]
    };
    let at_or_after = |seq: u64| {
        let i = (0..ticks).find(|&i| a.device_seq[i] >= seq).unwrap();
        a.device_position_m[i]
    };
    // Each stroke: the recorded hand moved as input.js's mapping says over the frames the
    // stick was held (each frame steps by the time since the last, at most 0.1 s).
    let yaw = -std::f64::consts::FRAC_PI_2; // the camera's yaw (the test does not orbit)
    for (axis, v, _) in strokes {
        let held: Vec<usize> = (1..strokes_end)
            .filter(|&k| polls[k].axes[axis] == v)
            .collect();
        assert!(held.len() > 3, "stroke {axis} = {v}: {} frames", held.len());
        let (k0, k1) = (held[0], *held.last().unwrap());
        assert_eq!(k1 - k0 + 1, held.len(), "one stroke of axis {axis}");
        let secs: f64 = (k0..=k1)
            .map(|k| ((polls[k].t_ms - polls[k - 1].t_ms) / 1000.0).min(0.1))
            .sum();
        let vel = stick_velocity(polls[k0].axes, yaw);
        let want = play::input::page_to_device(vel.map(|x| x * secs), radius_m);
        let p0 = at_or_before(polls[k0].seq);
        let p1 = at_or_after(polls[k1 + 1].seq);
        assert_eq!(p0, play::input::page_to_device(polls[k0].n, radius_m));
        assert_eq!(p1, play::input::page_to_device(polls[k1 + 1].n, radius_m));
        let got = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
        eprintln!("stroke axis {axis} = {v}: {secs:.3} s held, moved {got:?} m, want {want:?} m");
        for c in 0..3 {
            assert!(
                (got[c] - want[c]).abs() <= 1e-12,
                "stroke axis {axis} = {v}: moved {got:?} m, the mapping says {want:?} m"
            );
        }
        // In words: full right moves right only; half up moves away at half the speed; the
        // dead zone does not move; the right stick up raises the hand.
        let speed =
            [got[0].abs(), got[1].abs(), got[2].abs()].map(|d| d / secs / (0.999 * radius_m));
        let (dir, sign, want_speed) = match (axis, v) {
            (0, 1.0) => (0, 1.0, 0.5),
            (1, -0.5) => (1, 1.0, 0.25),
            (0, 0.1) => (0, 0.0, 0.0),
            _ => (2, 1.0, 0.5),
        };
        assert!((speed[dir] - want_speed).abs() < 1e-9, "{speed:?}");
        assert!(got[dir] * sign >= 0.0 && (0..3).all(|c| c == dir || speed[c] < 1e-12));
        eprintln!("  {speed:?} unit-ball radii per second");
    }
    // The right trigger is the grip (button 0 of the recorded input), LB button 1: on from the
    // input the page sent at the first frame it was held, off from the first after.
    for (pad_button, bit) in [(7usize, 0u32), (4, 1)] {
        let held: Vec<usize> = (0..polls.len())
            .filter(|&k| polls[k].buttons[pad_button] > 0.5)
            .collect();
        assert!(held.len() > 3, "button {pad_button}: {} frames", held.len());
        let (k0, k1) = (held[0], *held.last().unwrap());
        let (on, off) = (polls[k0].seq + 1, polls[k1 + 1].seq + 1);
        let mut on_ticks = 0;
        for i in 0..ticks {
            let pressed = a.device_buttons[i] & (1 << bit) != 0;
            assert_eq!(
                pressed,
                (on..off).contains(&a.device_seq[i]),
                "tick {i} (input {}): pad button {pad_button} → device button {bit}",
                a.device_seq[i]
            );
            on_ticks += u32::from(pressed);
        }
        assert!(on_ticks > 100, "button {bit} held {on_ticks} ticks");
    }
    let grip = &page["hello"]["buttons"][0];
    assert!(
        a.events
            .iter()
            .any(|(_, n, d)| n == "button.down" && Some(d.as_str()) == grip.as_str())
    );
    let said = said(&page);
    for want in ["grip on", "grip off", "grab missed: no brick in reach"] {
        assert!(
            said.iter().any(|s| s.contains(want)),
            "`{want}` not said: {said:?}"
        );
    }
    assert_only_the_game_said(&page);

    // The rumble follows the force: each request's magnitude is the force of the frame the
    // page showed, as a share of the device's largest (the weak motor half of it); none while
    // the hand was free; it rose as the hand pressed into the floor, and the last request,
    // once the hand was free, is zero.
    let rumbles: Vec<(usize, f64, f64)> = pad["rumbles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            assert_eq!(r[4], "dual-rumble");
            (
                r[0].as_u64().unwrap() as usize,
                r[1].as_f64().unwrap(),
                r[2].as_f64().unwrap(),
            )
        })
        .collect();
    assert!(rumbles.len() > 3, "{rumbles:?}");
    eprintln!(
        "{} rumble requests: {:?}",
        rumbles.len(),
        rumbles
            .iter()
            .map(|r| (r.0, (r.1 * 1000.0).round() / 1000.0))
            .collect::<Vec<_>>()
    );
    let share = |i: usize| {
        let f = a.device_force_n[i];
        ((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() / max_force_n).min(1.0)
    };
    for &(tick, strong, weak) in &rumbles {
        let m = share(tick);
        if strong > 0.0 {
            assert!(
                (strong - m).abs() <= 1e-9 && m > 0.02,
                "tick {tick}: rumble {strong}, force share {m}"
            );
            assert_eq!(weak, strong * 0.5);
        } else {
            assert!(m <= 0.02, "tick {tick}: rumble stopped at force share {m}");
            assert_eq!(weak, 0.0);
        }
    }
    let (imax, &(_, peak, _)) = rumbles
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.1.total_cmp(&y.1.1))
        .unwrap();
    assert!(peak > 0.3, "peak rumble {peak}");
    assert!(rumbles[0].1 < peak, "the rumble rose: {rumbles:?}");
    assert!(imax < rumbles.len() - 1);
    assert_eq!(rumbles.last().unwrap().1, 0.0, "the rumble fell to zero");
    // Free again at the end: no force over the session's last 100 ticks.
    assert!((ticks - 100..ticks).all(|i| share(i) == 0.0));
    let rec = read_recording_file(&out, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
}

/// The page's words for every game event of the golden recordings (recordings/*.mcap: the
/// brick world under both solver settings, the nano world, the wall, the optical tweezers): a
/// short sentence, never JSON, and nothing for the loop's reports and the events the player
/// hears or feels.
#[test]
fn every_game_event_of_the_golden_recordings_reads_as_a_short_sentence() {
    let _one = serial();
    let s = start("brickworld", "words");
    let mut b = browser();
    b.open(&s.url).unwrap();
    b.wait_for("window.__play.hello !== null", 10.0).unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../recordings");
    let mut said_names = std::collections::BTreeSet::new();
    for file in [
        "brickworld.mcap",
        "brickworld_shipped.mcap",
        "nanoworld.mcap",
        "wall.mcap",
        "optical_tweezers.mcap",
    ] {
        let rec = read_recording_file(&root.join(file), false).unwrap();
        let a = haptic_loop::SessionArrays::from_recording(&rec).unwrap();
        // Each distinct event, at most 30 of a name.
        let mut count = std::collections::BTreeMap::<&str, usize>::new();
        let mut distinct = std::collections::BTreeSet::new();
        for (_, n, d) in &a.events {
            let c = count.entry(n.as_str()).or_default();
            if *c < 30 && distinct.insert((n.as_str(), d.as_str())) {
                *c += 1;
            }
        }
        let events: Vec<(&str, &str)> = distinct.into_iter().collect();
        let hello = serde_json::json!({ "buttons": rec.description.device_buttons });
        let words = b
            .eval(&format!(
                "import('/events.js').then((m) => {}.map(([n, d]) => [m.eventClass(n), m.sentence(n, d, {hello})]))",
                serde_json::to_string(&events).unwrap()
            ))
            .unwrap();
        for ((name, detail), w) in events.iter().zip(words.as_array().unwrap()) {
            let class = w[0].as_str().unwrap();
            let grip_button = rec.description.device_buttons.first().map(String::as_str);
            match (class, w[1].as_str()) {
                ("game", Some(text)) | ("now", Some(text)) => {
                    assert!(
                        !text.is_empty() && text.chars().count() <= 60,
                        "{file}: {name} {detail} → `{text}`"
                    );
                    for bad in [
                        "{",
                        "}",
                        "\"",
                        "_",
                        "?",
                        "undefined",
                        "NaN",
                        "null",
                        "object",
                    ] {
                        assert!(
                            !text.contains(bad),
                            "{file}: {name} {detail} → `{text}` ({bad})"
                        );
                    }
                    said_names.insert(name.to_string());
                }
                ("now", None) => assert!(
                    name.starts_with("button.") && Some(*detail) != grip_button,
                    "{file}: {name} {detail} said nothing"
                ),
                ("quiet", None) | ("loop", None) => {}
                (c, t) => panic!("{file}: {name} {detail}: class {c}, said {t:?}"),
            }
        }
    }
    eprintln!("game events said in the golden recordings: {said_names:?}");
    for n in [
        "brick.grabbed",
        "brick.released",
        "brick.slot_filled",
        "nano.snap",
        "nano.pull_off",
        "wall.contact_begin",
        "ot.grab",
        "button.down",
    ] {
        assert!(
            said_names.contains(n),
            "{n} not in the golden recordings' words"
        );
    }
    b.check().unwrap();
    s.stop.store(true, Ordering::Relaxed);
    assert!(matches!(
        s.handle.join().unwrap(),
        Err(PlayError::NotStarted)
    ));
}
