//! The lesson driver on a play server's link, its worlds stepped under a batch clock with a
//! scripted hand.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::*;
use crate::input::WORKSPACE_FILL;
use crate::protocol::LessonAsk;
use crate::server::Page;
use crate::session::Step;
use haptic_engine::clock::Batch;
use std::sync::mpsc::{Receiver, sync_channel};
use teaching::evaluate::ticks_in;
use teaching::progress::describe;
use tungstenite::Message;

/// A pre-test question, a `time` step with gravity off and a question before, and a locked
/// nano step met by the world (snap-to-contact) with a short text after.
pub(crate) const TWO_STEPS: &str = r#"
[lesson]
title = "Two steps"

[[test]]
prompt = "Which force holds a few atoms together?"
answer = "choice"
choices = ["Their weight", "Surface attraction"]
correct = "Surface attraction"

[[step]]
id = "float"
title = "No gravity"
scene = "brickworld"
switches = { gravity_m_per_s2 = 0.0 }
task = "Gravity is off: watch the bricks."
done = { when = "time", seconds = 0.05 }
before = { prompt = "What will a brick do?", answer = "choice", choices = ["Fall", "Float"] }

[[step]]
id = "snap"
title = "Snap to contact"
scene = "nanoworld"
locked = true
task = "Come down slowly towards the surface."
done = { when = "atom_snapped" }
after = { prompt = "What did you feel?", answer = "text" }
"#;

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../target/test-lesson")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A driver of [`TWO_STEPS`] with one page (id 1) whose messages come out of the receiver.
fn driver(name: &str) -> (LessonDriver, Arc<Shared>, Receiver<Message>) {
    let lesson = teaching::parse_lesson(TWO_STEPS, "two.lesson.toml", None).unwrap();
    let shared = Arc::new(Shared::default());
    let (tx, rx) = sync_channel(4096);
    shared.pages.lock().unwrap().push(Page {
        id: 1,
        tx,
        wake: None,
    });
    let d = LessonDriver::new(lesson, shared.clone(), dir(name));
    (d, shared, rx)
}

/// The JSON messages the page was sent, in order.
fn sent(rx: &Receiver<Message>) -> Vec<serde_json::Value> {
    let mut out = Vec::new();
    while let Ok(m) = rx.try_recv() {
        if let Message::Text(t) = m {
            out.push(serde_json::from_str(t.as_str()).unwrap());
        }
    }
    out
}

/// Runs the open world with `hand(tick)` (a point of the page's unit ball) as the page's hand
/// until it ends; at most `limit` ticks.
fn run_world(
    d: &mut LessonDriver,
    shared: &Shared,
    hand: impl Fn(u64) -> [f64; 3],
    limit: u64,
) -> (Option<u64>, u64, PathBuf) {
    let mut w = d.open_world().unwrap().unwrap();
    let r = shared
        .scene
        .lock()
        .unwrap()
        .clone()
        .unwrap()
        .workspace_radius_m;
    let mut clock = Batch;
    for t in 0..=limit {
        let p = hand(t).map(|x| x * WORKSPACE_FILL * r);
        shared.input.set(p, 0, 0.0);
        if w.session.step(&mut clock) == Step::Ended {
            break;
        }
        assert!(t < limit, "the step was not met in {limit} ticks");
    }
    let run = d.close_world(w);
    assert!(run.session.error.is_none(), "{:?}", run.session.error);
    (
        run.met_at,
        run.session.stats.ticks,
        run.session.recording.clone(),
    )
}

fn verify(rec: &Path) -> recording::Recording {
    let r = recording::read_recording_file(rec, false).unwrap();
    assert!(
        haptic_loop::replay::verify(&r).unwrap().ok(),
        "{}",
        rec.display()
    );
    r
}

#[test]
fn a_steps_scene_and_switches_are_set_before_its_first_tick_and_a_time_completes_it() {
    let (mut d, shared, rx) = driver("time");
    let first = sent(&rx);
    assert_eq!(first.len(), 1);
    assert_eq!(first[0]["type"], "lesson");
    assert_eq!(first[0]["place"], "pre_test");
    assert_eq!(
        first[0]["words"],
        "Before the lesson, question 1 of 1: Which force holds a few atoms together?"
    );
    // No world before the pre-test and the prediction are answered.
    assert!(d.open_world().is_none());
    assert_eq!(d.answer(PageAnswer::Choice(0)).unwrap(), Place::Before(0));
    assert!(d.open_world().is_none());
    assert_eq!(d.answer(PageAnswer::Choice(1)).unwrap(), Place::Doing(0));
    // The world the pages are told is the step's, its menu showing gravity off from the
    // start.
    let mut w = d.open_world().unwrap().unwrap();
    let hello: serde_json::Value =
        serde_json::from_str(&shared.hello.lock().unwrap().clone().unwrap()).unwrap();
    assert_eq!(hello["kind"], "brickworld");
    let g = hello["switches"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == "gravity_m_per_s2")
        .unwrap();
    assert_eq!(g["value"], 0.0);
    w.session.request_end();
    assert_eq!(w.session.step(&mut Batch), Step::Ended);
    // Ended before its first tick: not met, still at the task.
    let run = d.close_world(w);
    assert_eq!((run.met_at, run.session.stats.ticks), (None, 0));
    assert_eq!(d.progress().place(), Place::Doing(0));
    shared.end_requested.store(false, Ordering::Relaxed);

    let (met, ticks, rec) = run_world(&mut d, &shared, |_| [0.0, 0.0, 0.0], 10_000);
    let rate = d.lesson().steps[0].rate_hz;
    let n = ticks_in(0.05, rate);
    assert_eq!((met, ticks), (Some(n - 1), n));
    assert_eq!(rec, d.recording_of("float"));
    assert!(rec.ends_with("time/float.mcap"));
    // The switch is the recording's first tick's, and the recording replays bit for bit.
    let r = verify(&rec);
    let period_ns = 1_000_000_000 / u64::from(rate);
    let sched = recording::switch_schedule(&r, period_ns).unwrap();
    assert_eq!(sched.len(), 1);
    assert_eq!(
        (sched[0].0, sched[0].1.name.as_str(), sched[0].1.value),
        (0, "gravity_m_per_s2", 0.0)
    );
    let s = &d.progress().steps()[0];
    assert_eq!((s.ticks, s.met_at), (n, Some(n - 1)));
    assert_eq!(s.before, Some(Answer::Choice(1)));
    // The next step is locked: a lone student has it opened on reaching it.
    assert_eq!(d.progress().place(), Place::Waiting(1));
    assert!(d.open_for_lone_student());
    assert_eq!(d.progress().place(), Place::Doing(1));
    assert!(!d.open_for_lone_student());
}

#[test]
fn a_world_condition_completes_its_step_on_the_tick_the_world_reports_it() {
    let (mut d, shared, _rx) = driver("world");
    d.answer(PageAnswer::Choice(1)).unwrap();
    d.answer(PageAnswer::Choice(0)).unwrap();
    run_world(&mut d, &shared, |_| [0.0; 3], 10_000);
    assert!(d.open_for_lone_student());
    // The tip comes down from 1.95 nm to 0.2 nm above the atom's top over 2 s (the lesson's
    // approach): device mm (z_nm − 3.5) / 0.15 on a 40 mm workspace.
    let mm = |z_nm: f64| (z_nm - 3.5) / 0.15;
    let (top, low) = (mm(1.95), mm(0.2));
    let hand = move |t: u64| {
        let f = (t as f64 / 2000.0).min(1.0);
        [-1.0 / 40.0, -1.0 / 40.0, (top + (low - top) * f) / 40.0]
    };
    let (met, ticks, rec) = run_world(&mut d, &shared, hand, 3000);
    let r = verify(&rec);
    // The world's first snap is on the tick the step was met (the last recorded).
    let met = met.unwrap();
    assert_eq!(ticks, met + 1);
    drop(r);
    let a = haptic_loop::session::read_arrays(&rec, false).unwrap();
    let snaps: Vec<u64> = a
        .events
        .iter()
        .filter(|(_, n, _)| n == "nano.snap")
        .map(|(t, _, _)| *t)
        .collect();
    assert_eq!(snaps, vec![met]);
    // Part way down: the tip had not reached the surface's pull at once.
    assert!((500..2000).contains(&met), "met at {met}");
    assert_eq!(d.progress().place(), Place::After(1));
    assert_eq!(d.progress().steps()[1].met_at, Some(met));
}

#[test]
fn answers_reach_the_progress_and_bad_ones_are_refused_with_their_reason() {
    let (mut d, shared, rx) = driver("answers");
    let ask = |a: LessonAsk| {
        shared
            .lesson_asks
            .lock()
            .unwrap()
            .as_mut()
            .unwrap()
            .push((1, a))
    };
    sent(&rx);
    ask(LessonAsk::Answer(PageAnswer::Choice(2)));
    ask(LessonAsk::Answer(PageAnswer::Text("weight".into())));
    ask(LessonAsk::Answer(PageAnswer::Choice(1)));
    d.take_asks();
    let msgs = sent(&rx);
    assert_eq!(msgs[0]["type"], "error");
    assert_eq!(msgs[0]["field"], "answer");
    assert_eq!(
        msgs[0]["message"],
        "answer: choice 2 is out of range: allowed 0 ≤ choice < 2"
    );
    assert_eq!(
        msgs[1]["message"],
        "answer: a text where one of the choices is asked"
    );
    assert_eq!(msgs[2]["type"], "lesson");
    assert_eq!(msgs[2]["place"], "before");
    assert_eq!(msgs[2]["question"]["choices"][1], "Float");
    assert_eq!(
        msgs[2]["words"],
        "Step 1 of 2, No gravity. Gravity is off: watch the bricks. Before you start: What will a brick do?"
    );
    assert_eq!(d.progress().pre_test(), &[Some(Answer::Choice(1))]);
    d.answer(PageAnswer::Choice(0)).unwrap();
    // No answer while the world runs.
    assert_eq!(
        d.answer(PageAnswer::Choice(0)).unwrap_err().to_string(),
        "an answer now: the student is at step 1, doing the task"
    );
    run_world(&mut d, &shared, |_| [0.0; 3], 10_000);
    d.open_for_lone_student();
    let hand = |t: u64| {
        [
            -0.025,
            -0.025,
            (-10.333 + (-21.667 + 10.333) * (t as f64 / 2000.0).min(1.0)) / 40.0,
        ]
    };
    run_world(&mut d, &shared, hand, 3000);
    let long = "x".repeat(2001);
    assert_eq!(
        d.answer(PageAnswer::Text(long)).unwrap_err().to_string(),
        "answer: a text of 2001 characters: allowed 1 to 2000"
    );
    assert_eq!(
        d.answer(PageAnswer::Text("   ".into()))
            .unwrap_err()
            .to_string(),
        "answer: a text of 0 characters: allowed 1 to 2000"
    );
    assert_eq!(
        d.answer(PageAnswer::Choice(0)).unwrap_err().to_string(),
        "answer: a choice where a short text is asked"
    );
    assert_eq!(
        d.answer(PageAnswer::Text("  It pulled down. ".into()))
            .unwrap(),
        Place::PostTest(0)
    );
    assert_eq!(
        d.progress().steps()[1].after,
        Some(Answer::Text("It pulled down.".into()))
    );
    assert_eq!(d.answer(PageAnswer::Choice(1)).unwrap(), Place::Finished);
    let v = d.view();
    assert_eq!(v.place, "finished");
    assert_eq!(
        v.score,
        Some(crate::protocol::Scores {
            pre: (1, 1),
            post: (1, 1)
        })
    );
    assert_eq!(
        v.words,
        "The lesson is finished. Before: 1 of 1 right. After: 1 of 1 right."
    );
    // A page that connects now is told where the student is.
    let late: serde_json::Value =
        serde_json::from_str(&shared.lesson.lock().unwrap().clone().unwrap()).unwrap();
    assert_eq!(late["place"], "finished");
}

#[test]
fn a_step_opened_by_its_url_is_a_demonstration_and_an_unknown_one_is_refused() {
    let (mut d, shared, rx) = driver("url");
    sent(&rx);
    shared
        .lesson_asks
        .lock()
        .unwrap()
        .as_mut()
        .unwrap()
        .push((1, LessonAsk::Step("lift".into())));
    d.take_asks();
    let msgs = sent(&rx);
    assert_eq!(msgs[0]["field"], "step.id");
    assert_eq!(
        msgs[0]["message"],
        "step `lift` is not in the lesson (its steps: float, snap)"
    );
    // The locked step, opened for a demonstration: no tests, no wait, straight to its task.
    d.open_step("snap").unwrap();
    assert_eq!(d.lesson().steps.len(), 1);
    assert_eq!(d.progress().place(), Place::Doing(0));
    assert_eq!(d.view().title, "Two steps: step snap (demonstration)");
    assert_eq!(d.view().step_id, "snap");
    let (mut d, _, _) = driver("url-late");
    d.answer(PageAnswer::Choice(0)).unwrap();
    assert_eq!(
        d.open_step("float").unwrap_err().to_string(),
        format!(
            "a step is opened by its URL only before the lesson begins: the student is at {}",
            describe(Place::Before(0))
        )
    );
    // Without a lesson, a page's answer is refused.
    let plain = Shared::default();
    let (tx, rx) = sync_channel(16);
    plain.pages.lock().unwrap().push(Page {
        id: 3,
        tx,
        wake: None,
    });
    crate::server::on_page_message(&plain, 3, r#"{"type":"answer","choice":1}"#);
    let m = sent(&rx);
    assert_eq!(
        m[0]["message"],
        "this session runs no lesson (a lesson is played with nanohaptics play --lesson)"
    );
}

#[test]
fn every_step_of_the_builtin_module_opens_its_world_with_its_switches() {
    let module = teaching::builtin::module().unwrap();
    for step in &module.steps {
        let shared = Arc::new(Shared::default());
        let mut d = LessonDriver::new(module.clone(), shared.clone(), dir("builtin"));
        d.open_step(&step.id).unwrap();
        if let Some(before) = &step.before {
            assert_eq!(d.progress().place(), Place::Before(0), "{}", step.id);
            let a = match &before.kind {
                teaching::QuestionKind::Choice { .. } => PageAnswer::Choice(0),
                teaching::QuestionKind::Text => PageAnswer::Text("a guess".into()),
            };
            d.answer(a).unwrap();
        }
        let mut w = d.open_world().unwrap().unwrap();
        let hello: serde_json::Value =
            serde_json::from_str(&shared.hello.lock().unwrap().clone().unwrap()).unwrap();
        assert_eq!(hello["kind"], step.kind, "{}", step.id);
        for (name, value) in step.switch_pairs() {
            let s = hello["switches"]
                .as_array()
                .unwrap()
                .iter()
                .find(|s| s["name"] == name)
                .unwrap();
            assert_eq!(s["value"].as_f64(), Some(value), "{} {name}", step.id);
        }
        w.session.request_end();
        assert_eq!(w.session.step(&mut Batch), Step::Ended);
        assert_eq!(d.close_world(w).met_at, None);
    }
}
