//! A lesson in a real browser (`play --lesson`), by keyboard alone: Debian's headless
//! `chromium`, driven through the DevTools Protocol. A student answers the pre-test, predicts,
//! does a `time` step (gravity off) and a locked nano step that the keyboard meets (coming down
//! until the tip snaps to the surface), says what they noticed in a text area, answers the
//! post-test and sees the completion with the scores. Every answer reaches the progress; each
//! step's recording replays bit for bit, its switches on its first tick; the questions are
//! labelled form controls and the live region says each place. A step opens alone by its
//! address (`?step=ID`), an unknown one is said, and E stops the lesson. The screenshot of a question
//! goes to the target folder's `tmp/figures/play/` (`scripts/figures.sh` writes it to
//! docs/figures/play/).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::figures;
use haptic_loop::session::{SceneSource, read_arrays};
use play::PlayConfig;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::sleep;
use std::time::Duration;
use teaching::Answer;

/// One browser at a time: the tests share two cores with the real-time loop.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

const W: u32 = 1280;
const H: u32 = 760;

const LESSON: &str = r#"
[lesson]
title = "Two steps"

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
task = "Gravity is off: watch the bricks for half a second."
done = { when = "time", seconds = 0.5 }
before = { prompt = "What will a brick do?", answer = "choice", choices = ["Fall", "Float"] }

[[step]]
id = "snap"
title = "Snap to contact"
scene = "nanoworld"
locked = true
task = "Come down slowly towards the surface (Page Down)."
done = { when = "atom_snapped" }
after = { prompt = "What did you feel?", answer = "text" }
"#;

fn place_is(b: &mut Browser, place: &str) {
    b.wait_for(
        &format!("window.__play.lesson !== null && window.__play.lesson.place === '{place}'"),
        20.0,
    )
    .unwrap();
}

/// The focused element's tag and, for a radio, its label's text.
fn focused(b: &mut Browser) -> Value {
    b.eval("(() => { const e = document.activeElement; return [e.tagName, e.type || '', e.parentElement && e.parentElement.tagName === 'LABEL' ? e.parentElement.textContent.trim() : '']; })()")
        .unwrap()
}

/// Chooses the `i`-th choice of the radio group in focus by keyboard (the first is focused:
/// Space checks it, each ArrowDown moves to and checks the next) and submits with Enter.
fn choose(b: &mut Browser, i: usize, label: &str) {
    assert_eq!(focused(b)[1], "radio");
    if i == 0 {
        b.press(" ");
    }
    for _ in 0..i {
        b.press("ArrowDown");
    }
    assert_eq!(focused(b)[2], label);
    b.press("Enter");
}

#[test]
fn a_student_completes_a_lesson_by_keyboard_and_each_step_replays() {
    let _one = serial();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-lesson-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two.lesson.toml");
    std::fs::write(&file, LESSON).unwrap();
    let lesson = teaching::load_lesson(&file).unwrap();
    let mut c = PlayConfig::new(
        SceneSource::resolve("brickworld".as_ref()).unwrap(),
        dir.join("lesson.mcap"),
    );
    c.port = 0;
    c.lesson = Some(lesson);
    let stop = Arc::new(AtomicBool::new(false));
    let play::Running { url, handle } = play::start(c, stop.clone()).unwrap();
    let mut b = Browser::launch(W, H).unwrap_or_else(|e| panic!("{e}"));
    b.open(&url).unwrap();

    // The pre-test: a radio group in a fieldset whose legend is the prompt; the live region
    // says it.
    place_is(&mut b, "pre_test");
    let form = b
        .eval("[document.querySelector('#lesson-form legend').textContent, [...document.querySelectorAll('#lesson-form label')].map(l => l.textContent.trim()), document.getElementById('lesson-words').getAttribute('aria-live'), document.getElementById('lesson-words').textContent, document.getElementById('lesson').classList.contains('hidden'), document.getElementById('start').classList.contains('hidden')]")
        .unwrap();
    assert_eq!(
        form,
        json!([
            "Which force holds a few atoms to a surface?",
            ["Their weight", "Surface attraction"],
            "polite",
            "Before the lesson, question 1 of 1: Which force holds a few atoms to a surface?",
            false,
            true
        ])
    );
    choose(&mut b, 1, "Surface attraction");

    // The prediction, asked before the step's world runs (no world yet: no hello).
    place_is(&mut b, "before");
    assert_eq!(b.eval("window.__play.hello").unwrap(), Value::Null);
    sleep(Duration::from_millis(200));
    b.screenshot(&figures().join("lesson-question.png"))
        .unwrap();
    choose(&mut b, 1, "Float");

    // The step's world: its scene, gravity off in the menu from the start; Start by Enter.
    place_is(&mut b, "doing");
    b.wait_for("window.__play.hello !== null && !document.getElementById('go').disabled && document.activeElement === document.getElementById('go')", 10.0).unwrap();
    assert_eq!(b.eval("[window.__play.hello.kind, window.__play.menu.gravity_m_per_s2, document.getElementById('lesson-now').textContent]").unwrap(),
        json!(["brickworld", 0, "No gravity: Gravity is off: watch the bricks for half a second."]));
    b.press("Enter");
    b.wait_for("window.__play.role === 'hand'", 10.0).unwrap();

    // The time step completes by itself; the locked step opens for the lone student and its
    // world (the nano world) starts at once, the canvas focused.
    b.wait_for("window.__play.hello.kind === 'nanoworld' && window.__play.lesson.place === 'doing' && document.activeElement.id === 'view'", 20.0).unwrap();
    assert!(
        b.eval("window.__play.lessons.some(l => l.place === 'waiting' && l.step === 1)")
            .unwrap()
            .as_bool()
            .unwrap()
    );
    // Down towards the surface until the tip snaps.
    b.key("PageDown", true, false).unwrap();
    let r = b.wait_for("window.__play.lesson.place === 'after'", 20.0);
    b.key("PageDown", false, false).unwrap();
    r.unwrap();

    // The snap sounded: the second world's sound stream started again at its tick 0 and the
    // synthesis played the snap's onset.
    b.wait_for("(() => { const e = window.__play.events.find(e => e[1] === 'nano.snap'); return !!e && window.__play.sound.played.some(p => p[0] === e[0]); })()", 10.0).unwrap();
    assert_eq!(b.eval("window.__play.sound.restarts").unwrap(), 1);

    // What they noticed: a labelled text area, typed, Tab to Answer, Enter.
    assert_eq!(focused(&mut b)[0], "TEXTAREA");
    assert_eq!(
        b.eval("document.querySelector('label[for=answer-text]').textContent")
            .unwrap(),
        "Your answer (up to 2000 characters)"
    );
    for k in ["i", "t", " ", "p", "u", "l", "l", "e", "d"] {
        b.press(k);
    }
    b.press("Tab");
    assert_eq!(b.eval("document.activeElement.id").unwrap(), "answer-go");
    b.press("Enter");

    place_is(&mut b, "post_test");
    choose(&mut b, 1, "Surface attraction");
    place_is(&mut b, "finished");
    let done = b
        .eval("[document.getElementById('lesson-h').textContent, document.getElementById('lesson-score').textContent, document.activeElement.id, document.getElementById('lesson-words').textContent, window.__play.errors.length]")
        .unwrap();
    assert_eq!(
        done,
        json!([
            "The lesson is finished",
            "Before the lesson: 1 of 1 right. After: 1 of 1 right.",
            "lesson-h",
            "The lesson is finished. Before: 1 of 1 right. After: 1 of 1 right.",
            0
        ])
    );
    // The second world completed: the worklet played its stream to the end and reported it;
    // the first world's stream it reported when the restart came.
    b.wait_for("window.__play.sound.live !== null", 10.0)
        .unwrap();
    let sound = b.eval("window.__play.sound").unwrap();
    b.check().unwrap();
    stop.store(true, Ordering::Relaxed);
    let summary = handle.join().unwrap().unwrap();
    let l = summary.lesson.unwrap();
    // Each world's sound, bit for bit against `render --audio` of its recording from its tick
    // 0: the restart reached the worklet after the first world's ticks and its finish and
    // before the second's first ticks (the link sends all three on one port, in order). The
    // first stream may be cut short by the restart (its last samples not yet played).
    let streams = sound["streams"].as_array().unwrap();
    assert_eq!(streams.len(), 1, "one restart: {streams:?}");
    let (first, second) = (&streams[0], &sound["live"]);
    assert_eq!(
        (first["kind"].as_str(), second["kind"].as_str()),
        (Some("stream"), Some("done"))
    );
    for (r, run, kind, complete) in [
        (first, &l.runs[0], "brickworld", first["complete"] == true),
        (second, &l.runs[1], "nanoworld", true),
    ] {
        let a = read_arrays(&run.session.recording, false).unwrap();
        let (sr, track, _, played) = common::live::check_samples(&a, kind, r, complete);
        println!(
            "{}: {played} of {} samples at {sr} Hz played (complete {complete})",
            run.id,
            track.len()
        );
    }
    assert_eq!(second["restarts"], 1);

    // Every answer reached the progress.
    let p = &l.progress;
    assert_eq!(p.pre_test(), &[Some(Answer::Choice(1))]);
    assert_eq!(p.post_test(), &[Some(Answer::Choice(1))]);
    assert_eq!(p.steps()[0].before, Some(Answer::Choice(1)));
    assert_eq!(p.steps()[1].after, Some(Answer::Text("it pulled".into())));
    assert_eq!((p.test_score(true), p.test_score(false)), ((1, 1), (1, 1)));

    // Each step its own recording, met on its condition's tick, replaying bit for bit.
    assert_eq!(l.dir, dir.join("lesson"));
    assert_eq!(l.runs.len(), 2);
    let float = &l.runs[0];
    assert_eq!((float.id.as_str(), float.met_at), ("float", Some(499)));
    assert_eq!(float.session.recording, dir.join("lesson/float.mcap"));
    let snap = &l.runs[1];
    assert_eq!(snap.session.recording, dir.join("lesson/snap.mcap"));
    for r in &l.runs {
        let rec = recording::read_recording_file(&r.session.recording, false).unwrap();
        assert!(haptic_loop::replay::verify(&rec).unwrap().ok(), "{}", r.id);
        assert_eq!(p.steps()[r.step].met_at, r.met_at);
        assert_eq!(p.steps()[r.step].ticks, r.session.stats.ticks);
    }
    let rec = recording::read_recording_file(&float.session.recording, false).unwrap();
    let sched = recording::switch_schedule(&rec, 1_000_000).unwrap();
    assert_eq!(sched.len(), 1);
    assert_eq!(
        (sched[0].0, sched[0].1.name.as_str(), sched[0].1.value),
        (0, "gravity_m_per_s2", 0.0)
    );
    // The lesson's report beside the recordings: each step's row from the progress and its
    // world, the largest force felt read back from the step's recording.
    let names: Vec<String> = l
        .report
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "class-steps.csv",
            "class-tests.csv",
            "class-report.md",
            "class-time-per-step.png",
            "class-pre-post.png"
        ]
    );
    assert!(l.report.iter().all(|p| p.parent() == Some(l.dir.as_path())));
    for r in &l.runs {
        let a = read_arrays(&r.session.recording, false).unwrap();
        let peak = a
            .columns
            .device_force_n
            .iter()
            .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
            .fold(0.0, f64::max);
        assert_eq!(r.peak_force_n, peak, "{}", r.id);
    }
    assert!(snap.peak_force_n > 0.0);
    let steps = std::fs::read_to_string(&l.report[0]).unwrap();
    let rows: Vec<&str> = steps.lines().collect();
    assert_eq!(rows.len(), 3, "{steps}");
    let num = |v: Option<f64>| v.map_or(String::new(), world_form::fmt_num);
    assert_eq!(
        rows[1],
        format!(
            "student,1,float,No gravity,done,0.5,0.499,{},{},Float,",
            num(Some(float.peak_force_n)),
            num(float.session.state("score"))
        )
    );
    let nano_hz = f64::from(read_arrays(&snap.session.recording, false).unwrap().rate_hz);
    let snap_ticks = snap.session.stats.ticks;
    assert_eq!(
        rows[2],
        format!(
            "student,2,snap,Snap to contact,done,{},{},{},{},,it pulled",
            num(Some(snap_ticks as f64 / nano_hz)),
            num(snap.met_at.map(|t| t as f64 / nano_hz)),
            num(Some(snap.peak_force_n)),
            num(snap.session.state("score"))
        )
    );
    let md = std::fs::read_to_string(&l.report[2]).unwrap();
    assert!(
        md.contains("| student | the end of the lesson | 2 of 2 |"),
        "{md}"
    );
    // The snap step ended on the tick of the world's one snap.
    let a = read_arrays(&snap.session.recording, false).unwrap();
    let snaps: Vec<u64> = a
        .events
        .iter()
        .filter(|(_, n, _)| n == "nano.snap")
        .map(|(t, _, _)| *t)
        .collect();
    assert_eq!(snaps, vec![snap.met_at.unwrap()]);
}

/// Serves `LESSON` with `play --lesson`; (url, stop, handle).
fn serve(
    name: &str,
) -> (
    String,
    Arc<AtomicBool>,
    std::thread::JoinHandle<Result<play::PlaySummary, play::PlayError>>,
) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-lesson-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let lesson = teaching::parse_lesson(LESSON, "two.lesson.toml", None).unwrap();
    let mut c = PlayConfig::new(
        SceneSource::resolve("brickworld".as_ref()).unwrap(),
        dir.join("lesson.mcap"),
    );
    c.port = 0;
    c.lesson = Some(lesson);
    let stop = Arc::new(AtomicBool::new(false));
    let play::Running { url, handle } = play::start(c, stop.clone()).unwrap();
    (url, stop, handle)
}

#[test]
fn a_step_opens_by_its_address_for_a_demonstration_and_an_unknown_one_is_said() {
    let _one = serial();
    let (url, stop, handle) = serve("url");
    let mut b = Browser::launch(W, H).unwrap_or_else(|e| panic!("{e}"));
    // An unknown step: the page says why, and the lesson stays at its start.
    b.open(&format!("{url}?step=lift")).unwrap();
    b.wait_for("window.__play.errors.length > 0", 10.0).unwrap();
    assert_eq!(
        b.eval("[window.__play.errors[0].field, window.__play.errors[0].message, document.getElementById('announce').textContent, window.__play.lesson.place]").unwrap(),
        json!(["step.id", "step `lift` is not in the lesson (its steps: float, snap)", "step `lift` is not in the lesson (its steps: float, snap)", "pre_test"])
    );
    // The locked nano step by its address: no tests, no wait, its world at once.
    b.open(&format!("{url}?step=snap")).unwrap();
    b.wait_for("window.__play.lesson !== null && window.__play.lesson.step_id === 'snap' && window.__play.hello !== null", 10.0).unwrap();
    assert_eq!(
        b.eval("[window.__play.lesson.title, window.__play.lesson.place, window.__play.lesson.steps, window.__play.hello.kind, document.activeElement.id]").unwrap(),
        json!(["Two steps: step snap (demonstration)", "doing", 1, "nanoworld", "go"])
    );
    // Start, then E before the tip snaps: the lesson stops there, with the end screen.
    b.press("Enter");
    b.wait_for(
        "window.__play.role === 'hand' && window.__play.frames > 5",
        10.0,
    )
    .unwrap();
    b.press("e");
    b.wait_for("window.__play.ended !== null", 10.0).unwrap();
    assert_eq!(
        b.eval("[window.__play.ended.end, document.getElementById('end').classList.contains('hidden'), window.__play.lesson.place]").unwrap(),
        json!(["stopped", false, "doing"])
    );
    b.check().unwrap();
    stop.store(true, Ordering::Relaxed);
    let s = handle.join().unwrap().unwrap();
    let l = s.lesson.unwrap();
    assert_eq!(
        (l.runs.len(), l.runs[0].id.as_str(), l.runs[0].met_at),
        (1, "snap", None)
    );
    assert_eq!(s.session.end, "stopped");
    assert!(s.session.stats.ticks > 0);
    assert_eq!(l.progress.steps()[0].ticks, s.session.stats.ticks);
    let rec = recording::read_recording_file(&s.session.recording, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
}
