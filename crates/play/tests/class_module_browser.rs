//! The built-in module taken by a class, in real browsers and by keyboard alone (Debian's
//! headless `chromium`, driven through the DevTools Protocol by a keyboard pilot,
//! `common/pilot.rs`, that reads what the page shows and acts only through key events).
//!
//! - **Bo** joins by keyboard, answers the pre-test, builds the brick house, and stops at step 2.
//! - **Ada** joins and takes the whole module. She answers the pre-test, then builds the brick
//!   house, lifts, throws (gravity on, gravity off) and lifts with inertia off. She waits at the
//!   locked *Snap to contact* until the teacher opens it. Then she snaps the tip, pulls it
//!   off, tries to put an atom back, builds the atom house, throws a brick and tries to throw an
//!   atom, answering every question before and after, and the post-test.
//! - **The teacher page** (Bo's tab once he stops) shows both students' steps. Its *Open the
//!   next step* reaches both, and its answers table holds every answer, in order.
//! - **The result:** each step's recording replays bit for bit with its condition's event on
//!   the tick it was met, and the class report has every row.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::class::start_with;
use common::module::{correct, take_lesson, words_after};
use common::pilot::Pilot;
use haptic_loop::session::read_arrays;
use serde_json::{Value, json};
use std::sync::atomic::Ordering;
use std::time::Instant;
use teaching::condition::Condition;
use teaching::{Lesson, QuestionKind};

const W: u32 = 1280;
const H: u32 = 760;

/// Joins the class at `url` by keyboard: the name typed into the focused field, Enter.
fn join_by_keyboard(b: &mut Browser, url: &str, name: &str) {
    b.open(url).unwrap();
    b.wait_for(
        "document.activeElement === document.querySelector('input[name=name]')",
        10.0,
    )
    .unwrap();
    for c in name.chars() {
        b.press(&c.to_string());
    }
    b.press("Enter");
}

/// Once `until` holds on the teacher page, its rows (each student's name and step) are `rows`.
fn rows_when(t: &mut Browser, until: &str, rows: Value) {
    t.wait_for(until, 20.0).unwrap();
    let shown = t.eval("[...document.querySelectorAll('#students tbody tr')].map(r => [r.children[0].textContent, r.children[2].textContent])").unwrap();
    assert_eq!(shown, rows);
}

/// Where each answer of a student who took steps `0..steps` of `lesson` (and both tests when
/// `post`) is said on the teacher page, in order.
fn answer_places(lesson: &Lesson, steps: usize, post: bool) -> Vec<String> {
    let mut at: Vec<String> = (1..=lesson.test.len())
        .map(|q| format!("pre-test {q}"))
        .collect();
    for s in lesson.steps.iter().take(steps) {
        if s.before.is_some() {
            at.push(format!("{}, before", s.id));
        }
        if s.after.is_some() {
            at.push(format!("{}, after", s.id));
        }
    }
    if post {
        at.extend((1..=lesson.test.len()).map(|q| format!("post-test {q}")));
    }
    at
}

#[test]
fn a_class_takes_the_built_in_module_by_keyboard_and_the_teacher_follows() {
    let module = teaching::builtin::module().unwrap();
    let n = module.steps.len();
    let locked: Vec<usize> = (0..n).filter(|&i| module.steps[i].locked).collect();
    assert_eq!(locked, [5], "the module locks its first atom step");
    let c = start_with("module", 4, Some(module.clone()));
    let t_all = Instant::now();

    // Bo: the pre-test (each first choice), the brick house, then he stops at step 2.
    let mut t = Browser::launch(W, H).unwrap_or_else(|e| panic!("{e}"));
    join_by_keyboard(&mut t, &c.addr.student_url, "Bo");
    let bo = take_lesson(&mut Pilot::new(&mut t), &module, 1, false, &mut |i| {
        panic!("Bo met a locked step {i}")
    });
    // His tab becomes the teacher's: his lesson stays at step 2 with no page.
    t.open(&c.addr.teacher_url).unwrap();

    // Ada takes the whole module; at the locked step the teacher page shows both students
    // where they are and opens it.
    let mut a = Browser::launch(W, H).unwrap_or_else(|e| panic!("{e}"));
    join_by_keyboard(&mut a, &c.addr.student_url, "Ada");
    let mut opened = false;
    let ada = take_lesson(&mut Pilot::new(&mut a), &module, n, true, &mut |i| {
        assert_eq!(i, 5);
        rows_when(
            &mut t,
            "[...document.querySelectorAll('#students tbody tr')].some(r => r.children[2].textContent.includes('waiting for you'))",
            json!([
                ["Bo", "2 of 11 · Lift a brick · predicting"],
                ["Ada", "6 of 11 · Snap to contact · waiting for you"]
            ]),
        );
        assert_eq!(
            t.eval("document.getElementById('open-next').textContent")
                .unwrap(),
            "Open the next step (Snap to contact)"
        );
        t.eval("document.getElementById('open-next').click()")
            .unwrap();
        t.wait_for(
            "document.getElementById('said').textContent === 'step 6 (snap) is open for everyone: 2 students told'",
            10.0,
        )
        .unwrap();
        opened = true;
    });
    assert!(opened);
    assert_eq!(
        a.eval("document.getElementById('lesson-score').textContent")
            .unwrap(),
        json!(format!(
            "Before the lesson: {0} of {0} right. After: {0} of {0} right.",
            module.test.len()
        ))
    );
    a.check().unwrap();
    println!(
        "Bo's part and Ada's whole module: {:.1} s of wall time",
        t_all.elapsed().as_secs_f64()
    );

    // The teacher page: Ada at the end, Bo still at step 2; every answer, in order, as said;
    // a Watch link for each step whose world closed.
    rows_when(
        &mut t,
        "[...document.querySelectorAll('#students tbody tr')].some(r => r.children[2].textContent === 'the end of the lesson') && document.querySelectorAll('a.watch-step').length === 12 && document.getElementById('open-next').disabled",
        json!([
            ["Bo", "2 of 11 · Lift a brick · predicting"],
            ["Ada", "the end of the lesson"]
        ]),
    );
    let rows = t
        .eval("[...document.querySelectorAll('#answers tbody tr')].map(r => [...r.children].map(c => c.textContent))")
        .unwrap();
    let rows = rows.as_array().unwrap();
    let of = |name: &str, col: usize| -> Vec<String> {
        rows.iter()
            .filter(|r| r[0] == name)
            .map(|r| r[col].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(of("Ada", 1), answer_places(&module, n, true));
    assert_eq!(of("Bo", 1), answer_places(&module, 1, false));
    let ada_words = of("Ada", 3);
    for s in &module.steps {
        if matches!(s.after.as_ref().map(|q| &q.kind), Some(QuestionKind::Text)) {
            assert!(
                ada_words.contains(&words_after(&s.id).to_string()),
                "{}",
                s.id
            );
        }
    }
    t.check().unwrap();

    c.stop.store(true, Ordering::Relaxed);
    let summary = c.handle.join().unwrap().unwrap();

    // Each step's world: Ada's eleven and Bo's brick house, each met on its last tick, its
    // condition's event on that tick, replaying bit for bit.
    let mut runs: Vec<(String, String)> = summary
        .students
        .iter()
        .map(|s| (s.name.clone(), s.step.clone().unwrap()))
        .collect();
    runs.sort();
    let mut want: Vec<(String, String)> = module
        .steps
        .iter()
        .map(|s| ("Ada".to_string(), s.id.clone()))
        .chain([("Bo".to_string(), "brick-house".to_string())])
        .collect();
    want.sort();
    assert_eq!(runs, want);
    for r in &summary.students {
        let id = r.step.as_deref().unwrap();
        let step = module.steps.iter().find(|s| s.id == id).unwrap();
        assert_eq!(r.session.end, "completed", "{}", r.line());
        let rec = recording::read_recording_file(&r.session.recording, false).unwrap();
        assert!(
            haptic_loop::replay::verify(&rec).unwrap().ok(),
            "{} does not replay bit for bit",
            r.line()
        );
        let arrays = read_arrays(&r.session.recording, false).unwrap();
        let hz = f64::from(arrays.rate_hz);
        let met = r.session.stats.ticks - 1;
        let names: &[&str] = match step.done {
            Condition::BrickThrown => &["brick.thrown"],
            Condition::AtomSnapped => &["nano.snap"],
            Condition::AtomPulledOff => &["nano.pull_off"],
            Condition::HouseComplete if step.kind == "nanoworld" => &["nano.house_complete"],
            _ => &[],
        };
        if !names.is_empty() {
            assert!(
                arrays
                    .events
                    .iter()
                    .any(|(t, n, _)| *t == met && names.contains(&n.as_str())),
                "{}: no {names:?} on tick {met}",
                r.line()
            );
        }
        if let Condition::Time { seconds } = step.done {
            assert_eq!(met + 1, (seconds * hz).round() as u64, "{id}");
        }
        println!(
            "{:>4} {:>14}: met at {:7.3} s of sim time",
            r.name,
            id,
            (met + 1) as f64 / hz
        );
    }
    for (name, taken) in [("Ada", &ada), ("Bo", &bo)] {
        for (i, w) in taken.walls.iter().enumerate() {
            println!(
                "{name} {:>14}: {:5.1} s of wall time",
                module.steps[i].id,
                w.as_secs_f64()
            );
        }
    }

    // The class report: every step of each, where they are on it, and the tests.
    let steps = std::fs::read_to_string(c.dir.join("class-steps.csv")).unwrap();
    let states: Vec<(String, String)> = steps
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[4].to_string())
        })
        .collect();
    let mut want_states: Vec<(String, String)> = Vec::new();
    for i in 0..n {
        want_states.push((
            "Bo".into(),
            ["done", "before"]
                .get(i)
                .unwrap_or(&"not reached")
                .to_string(),
        ));
    }
    want_states.extend((0..n).map(|_| ("Ada".to_string(), "done".to_string())));
    assert_eq!(states, want_states);
    let tests = std::fs::read_to_string(c.dir.join("class-tests.csv")).unwrap();
    for (q, question) in module.test.iter().enumerate() {
        let bo_right = if correct(question) == 0 { "yes" } else { "no" };
        for (who, test, right) in [
            ("Ada", "pre", "yes"),
            ("Ada", "post", "yes"),
            ("Bo", "pre", bo_right),
        ] {
            let line = tests
                .lines()
                .find(|l| l.starts_with(&format!("{who},{test},{},", q + 1)))
                .unwrap();
            assert!(line.ends_with(&format!(",{right}")), "{line}");
        }
    }
    let _ = std::fs::remove_dir_all(&c.dir);
}
