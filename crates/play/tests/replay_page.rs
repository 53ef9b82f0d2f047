//! Any recording replayed in the browser (issue 42, item 5): `nanohaptics replay FILE --serve`'s
//! page in Debian's headless Chromium, driven by keyboard. It plays, says the events it passes,
//! pauses, changes speed, and scrubbed to a tick it draws the primitives the scene draws at
//! that tick when the recording is re-simulated (as `nanohaptics render` draws them: compared
//! as data, not pixels); its sound buffer holds `render --audio --proximity`'s samples bit for
//! bit; a damaged file is refused with the recording reader's error.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::figures;
use common::live::hash;
use haptic_engine::sink::{Sink, SinkError, TickView};
use haptic_loop::replay::Resimulation;
use haptic_loop::session::SessionArrays;
use haptic_types::Primitive;
use play::replay::{ReplayBook, ReplayServer, SAMPLE_RATE_HZ};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn golden(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../recordings")
        .join(name)
}

/// The primitives the scene draws after tick `at`, re-simulated from the recording apart from
/// the replay book (the path `render` draws its frames from).
struct DrawAt {
    at: u64,
    prims: Vec<Primitive>,
}

impl Sink for DrawAt {
    fn name(&self) -> &'static str {
        "draw-at"
    }
    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        if t.result.tick == self.at {
            t.lp.scene().draw(&mut self.prims);
        }
        Ok(())
    }
}

fn drawn_at(rec: &Path, at: u64) -> Vec<Primitive> {
    let r = recording::read_recording_file(rec, false).unwrap();
    let mut sink = DrawAt {
        at,
        prims: Vec::new(),
    };
    Resimulation::prepare(&r)
        .unwrap()
        .run(vec![&mut sink])
        .unwrap();
    assert!(!sink.prims.is_empty(), "tick {at} drawn");
    sink.prims
}

/// `v` with every number as an f64 (JavaScript writes 1.0 as `1`): compared, the values are
/// then equal exactly when their doubles are.
fn as_f64s(v: Value) -> Value {
    match v {
        Value::Number(n) => serde_json::json!(n.as_f64().unwrap()),
        Value::Array(a) => Value::Array(a.into_iter().map(as_f64s).collect()),
        Value::Object(o) => Value::Object(o.into_iter().map(|(k, v)| (k, as_f64s(v))).collect()),
        other => other,
    }
}

fn wait_until(b: &mut Browser, expr: &str) {
    b.wait_for(expr, 30.0)
        .unwrap_or_else(|e| panic!("{expr}: {e}"));
}

fn num(b: &mut Browser, expr: &str) -> f64 {
    b.eval(expr).unwrap().as_f64().unwrap()
}

#[test]
fn a_recording_replays_in_the_page_by_keyboard_and_draws_and_sounds_as_render() {
    let rec = golden("brickworld.mcap");
    let book = ReplayBook::from_file(&rec).unwrap();
    let (ticks, frames) = (book.ticks, book.frames.len());
    // Every 16th tick is a frame, and a last one without drawing.
    assert_eq!(frames as u64, ticks.div_ceil(16) + 1);
    let mut server = ReplayServer::start(book, rec.clone(), 0).unwrap();
    let url = server.url();
    let mut b = Browser::launch(1280, 760).unwrap();
    b.open(&url).unwrap();
    wait_until(&mut b, "window.__replay && window.__replay.ready");
    assert_eq!(num(&mut b, "__replay.index.ticks"), ticks as f64);
    assert_eq!(num(&mut b, "__replay.drawn.tick"), 0.0);
    // The sound is render --audio --proximity's track.
    let arrays =
        SessionArrays::from_recording(&recording::read_recording_file(&rec, false).unwrap())
            .unwrap();
    let track = haptic_loop::sound::session_sound(&arrays, "brickworld", true, SAMPLE_RATE_HZ)
        .unwrap()
        .samples;
    assert_eq!(num(&mut b, "__replay.sound.samples"), track.len() as f64);

    // Play by keyboard (Space), watch the events go by, pause (K).
    b.key(" ", true, false).unwrap();
    b.key(" ", false, false).unwrap();
    wait_until(&mut b, "__replay.playing && __replay.tick > 2500");
    b.key("k", true, false).unwrap();
    b.key("k", false, false).unwrap();
    wait_until(&mut b, "!__replay.playing");
    let paused = num(&mut b, "__replay.tick");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(num(&mut b, "__replay.tick"), paused, "paused");
    // The buffer it played: the track, bit for bit.
    assert_eq!(
        num(&mut b, "__replay.sound.hash"),
        f64::from(hash(&track)),
        "the page's sound buffer is render --audio's track"
    );
    assert!(num(&mut b, "__replay.sound.starts") >= 1.0);
    // The events it said were the recording's game events up to where it paused, in order.
    let said = b.eval("__replay.said").unwrap();
    let said = said.as_array().unwrap();
    assert!(!said.is_empty(), "no event said in {paused} ticks");
    let recorded: Vec<u64> = arrays.events.iter().map(|e| e.0).collect();
    let mut last = 0;
    for s in said {
        let t = s[0].as_u64().unwrap();
        assert!(
            t >= last && t <= paused as u64 && recorded.contains(&t),
            "{s}"
        );
        last = t;
    }
    assert!(
        said.iter()
            .any(|s| s[1].as_str().unwrap().contains("brick")),
        "{said:?}"
    );

    // Faster (]) and slower ([): the speed the sound restarts at.
    b.key("]", true, false).unwrap();
    b.key("]", false, false).unwrap();
    assert_eq!(num(&mut b, "__replay.speed"), 2.0);
    b.key("[", true, false).unwrap();
    b.key("[", false, false).unwrap();
    b.key("[", true, false).unwrap();
    b.key("[", false, false).unwrap();
    assert_eq!(num(&mut b, "__replay.speed"), 0.5);

    // The timeline by keyboard: End, then Home.
    b.eval("document.getElementById('timeline').focus()")
        .unwrap();
    b.key("End", true, false).unwrap();
    b.key("End", false, false).unwrap();
    wait_until(&mut b, &format!("__replay.tick === {}", ticks - 1));
    b.key("Home", true, false).unwrap();
    b.key("Home", false, false).unwrap();
    wait_until(&mut b, "__replay.tick === 0 && __replay.drawn.tick === 0");

    // Scrubbed to a tick (as a drag does: the input's value and its event), the page draws
    // what the scene draws there; between two frames, the frame before.
    for (to, frame) in [(8000u64, 8000u64), (13_337, 13_328)] {
        b.eval(&format!(
            "(() => {{ const t = document.getElementById('timeline'); t.value = '{to}'; \
             t.dispatchEvent(new Event('input')); }})()"
        ))
        .unwrap();
        wait_until(&mut b, &format!("__replay.drawn.tick === {frame}"));
        let page = as_f64s(b.eval("__replay.drawn.prims").unwrap());
        let want = as_f64s(serde_json::to_value(drawn_at(&rec, frame)).unwrap());
        assert_eq!(page, want, "tick {frame}");
        assert_eq!(
            b.eval("document.getElementById('time').textContent")
                .unwrap(),
            format!("{:.3} s", to as f64 / 1000.0)
        );
    }
    b.screenshot(&figures().join("replay.png")).unwrap();
    b.check().unwrap();
    drop(b);
    server.stop();
}

#[test]
fn a_damaged_or_foreign_file_is_refused_with_the_readers_error() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cut = dir.join("replay_page_cut.mcap");
    let bytes = std::fs::read(golden("wall.mcap")).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let foreign = dir.join("replay_page_foreign.mcap");
    std::fs::write(&foreign, b"not a recording at all").unwrap();
    for p in [cut, foreign] {
        let want = recording::read_recording_file(&p, false)
            .err()
            .unwrap()
            .to_string();
        let got = ReplayBook::from_file(&p).err().unwrap().to_string();
        assert_eq!(got, want);
    }
}
