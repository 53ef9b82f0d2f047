//! The built-in module (`play --lesson` without a file) in a real browser, by keyboard alone:
//! Debian's headless `chromium`, driven through the DevTools Protocol by a keyboard pilot
//! (`common/pilot.rs`) that reads what the page shows and acts only through key events. A
//! student answers the pre-test, builds the brick house, lifts, throws (gravity on, gravity
//! off), lifts with inertia off, snaps the tip, pulls it off, tries to put an atom back, builds
//! the atom house, throws a brick and tries to throw an atom, answering each question before
//! and after, and the post-test. Every step's condition is met; every answer reaches the
//! progress; each step's recording verifies and replays bit for bit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::pilot::Pilot;
use haptic_loop::session::{SceneSource, read_arrays};
use play::PlayConfig;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use teaching::condition::Condition;
use teaching::{Answer, Question, QuestionKind};

/// One browser at a time: the tests share two cores with the real-time loop.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

const W: u32 = 1280;
const H: u32 = 760;

/// The page's expression that the lesson has moved past step `i`'s world.
fn past(i: usize) -> String {
    format!("window.__play.lesson.step !== {i} || window.__play.lesson.place !== 'doing'")
}

/// Answers the question the page shows by keyboard and waits for the page's next place:
/// a choice (the first radio is focused: Space checks it, each ArrowDown checks the next;
/// Enter submits), or a text typed into the text area (Tab to Answer, Enter).
fn answer(p: &mut Pilot, q: &Question, choice: usize, text: &str) -> Answer {
    let before = p.eval("window.__play.lessons.length");
    let focused = p.eval("[document.activeElement.tagName, document.activeElement.type || '']");
    let a = match &q.kind {
        QuestionKind::Choice { choices, .. } => {
            assert_eq!(focused, json!(["INPUT", "radio"]), "{}", q.prompt);
            if choice == 0 {
                p.press(" ");
            }
            for _ in 0..choice {
                p.press("ArrowDown");
            }
            let label = p.eval("document.activeElement.parentElement.textContent.trim()");
            assert_eq!(label, json!(choices[choice]));
            Answer::Choice(choice)
        }
        QuestionKind::Text => {
            assert_eq!(focused[0], "TEXTAREA", "{}", q.prompt);
            for c in text.chars() {
                p.press(&c.to_string());
            }
            p.press("Tab");
            assert_eq!(p.eval("document.activeElement.id"), "answer-go");
            Answer::Text(text.to_string())
        }
    };
    p.press("Enter");
    p.b.wait_for(&format!("window.__play.lessons.length > {before}"), 10.0)
        .unwrap();
    a
}

/// The place the page shows and its step.
fn place(p: &mut Pilot) -> (String, Value) {
    let v = p.eval("[window.__play.lesson.place, window.__play.lesson.step]");
    (v[0].as_str().unwrap_or("").to_string(), v[1].clone())
}

/// A point over the substrate's middle (the slab the page draws first), 1.5 nm or more from
/// every orange atom and outside the loading zone, `z` above the surface.
fn clear_spot(p: &mut Pilot, z: f64) -> [f64; 3] {
    let c = p.eval("window.__play.lastFrame.prims[0].c");
    let mid = [c[0].as_f64().unwrap(), c[1].as_f64().unwrap()];
    let atoms = p.atoms();
    let (lo, hi) = p.loading_zone();
    for r in 0..8 {
        for k in 0..8 {
            let a = f64::from(k) * std::f64::consts::FRAC_PI_4;
            let d = f64::from(r) * 0.5e-9;
            let q = [mid[0] + d * a.cos(), mid[1] + d * a.sin()];
            let in_zone = q[0] >= lo[0] && q[0] <= hi[0] && q[1] >= lo[1] && q[1] <= hi[1];
            let clear = atoms
                .iter()
                .all(|b| ((b.c[0] - q[0]).powi(2) + (b.c[1] - q[1]).powi(2)).sqrt() > 1.5e-9);
            if clear && !in_zone {
                return [q[0], q[1], z];
            }
        }
    }
    panic!("no clear spot over the substrate");
}

/// Does step `i` of the module by keyboard until the page moves past it.
fn do_step(p: &mut Pilot, i: usize, kind: &str, done: Condition) {
    let past = past(i);
    match (done, kind) {
        (Condition::HouseComplete, "brickworld") => {
            let (worst, tries) = p.build_brick_house(&past);
            println!(
                "  brick house: {tries} bricks put, the largest miss {:.1} mm",
                worst * 1e3
            );
        }
        (Condition::HouseComplete, _) => {
            let (worst, n) = p.build_atom_house(&past);
            println!(
                "  atom house: {n} atoms put, the largest miss {:.3} nm",
                worst * 1e9
            );
        }
        (Condition::BrickLifted { height_m }, _) => p.lift_brick(height_m, &past),
        (Condition::BrickThrown, _) => {
            let speeds = p.throw_brick(&past, 20);
            println!("  release speeds (m/s): {speeds:.3?}");
        }
        (Condition::AtomSnapped, _) => {
            let s = clear_spot(p, 2.0e-9);
            p.go_to(s, 0.05e-9);
            p.come_down_until(&past);
        }
        (Condition::AtomPulledOff, _) => {
            let s = clear_spot(p, 2.0e-9);
            p.go_to(s, 0.05e-9);
            p.come_down_until("window.__play.lastFrame.state.anchored === 1");
            assert!(
                p.hold_until("PageUp", false, &past, 10.0),
                "pulled up, yet the tip did not come off"
            );
        }
        (Condition::AtomPutBack { within_m, away_m }, _) => {
            let took = p.fetch_atom();
            let t = p.tip();
            // Away (up, past `away_m` from where it was taken), then back over that spot.
            let up = [t[0], t[1], took[2] + away_m + 0.5e-9];
            p.go_to(up, 0.1e-9);
            let back = p.hand_of([took[0], took[1], took[2] + 0.4 * within_m]);
            assert!(
                p.steer(back, 0.002, Some(&past), 10.0),
                "the atom came back to where it was taken, yet the step is not done"
            );
        }
        (Condition::Time { seconds }, _) => {
            // Try to throw an atom: take one and shake it from side to side.
            p.fetch_atom();
            let t0 = Instant::now();
            let mut k = 0;
            while !p.hold_until(
                if k % 2 == 0 {
                    "ArrowRight"
                } else {
                    "ArrowLeft"
                },
                false,
                &past,
                0.3,
            ) {
                k += 1;
                assert!(
                    t0.elapsed().as_secs_f64() < seconds + 20.0,
                    "the time step never ended"
                );
            }
        }
        (c, k) => panic!("no keyboard plan for `{}` in {k}", c.name()),
    }
}

/// Words a student might write after step `id`.
fn words_after(id: &str) -> &'static str {
    match id {
        "brick-house" => "its weight",
        "lift" => "it pulled back",
        "gravity-off" => "it flew on",
        "inertia-off" => "no push back",
        "put-back" => "it stayed on the tip",
        "atom-house" => "atoms stick",
        _ => "i felt it",
    }
}

#[test]
fn a_student_completes_the_built_in_module_by_keyboard_and_each_step_replays() {
    let _one = serial();
    let module = teaching::builtin::module().unwrap();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-module-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut c = PlayConfig::new(
        SceneSource::resolve("brickworld".as_ref()).unwrap(),
        dir.join("module.mcap"),
    );
    c.port = 0;
    c.lesson = Some(module.clone());
    let stop = Arc::new(AtomicBool::new(false));
    let play::Running { url, handle } = play::start(c, stop.clone()).unwrap();
    let mut b = Browser::launch(W, H).unwrap_or_else(|e| panic!("{e}"));
    b.open(&url).unwrap();
    let mut p = Pilot::new(&mut b);
    let t_all = Instant::now();

    // The pre-test: each content question answered right.
    let correct = |q: &Question| match &q.kind {
        QuestionKind::Choice { correct, .. } => correct.unwrap(),
        QuestionKind::Text => panic!("a test question is a choice"),
    };
    let mut pre = Vec::new();
    p.b.wait_for(
        "window.__play.lesson !== null && window.__play.lesson.place === 'pre_test'",
        20.0,
    )
    .unwrap();
    for q in &module.test {
        assert_eq!(place(&mut p).0, "pre_test");
        pre.push(Some(answer(&mut p, q, correct(q), "")));
    }

    // The steps.
    let mut befores = Vec::new();
    let mut afters = Vec::new();
    let mut walls = Vec::new();
    for (i, step) in module.steps.iter().enumerate() {
        p.b.wait_for(
            &format!("window.__play.lesson.step === {i} && ['before', 'doing'].includes(window.__play.lesson.place)"),
            20.0,
        )
        .unwrap();
        befores.push(step.before.as_ref().map(|q| {
            assert_eq!(place(&mut p).0, "before");
            answer(&mut p, q, 1, "")
        }));
        p.b.wait_for(
            &format!("window.__play.lesson.step === {i} && window.__play.lesson.place === 'doing'"),
            20.0,
        )
        .unwrap();
        // The step's own world: a new hello, then its frames.
        p.b.wait_for(
            &format!("window.__play.hello !== null && window.__play.hello !== window.__pilotHello && window.__play.hello.kind === '{}'", step.kind),
            20.0,
        )
        .unwrap();
        p.eval("window.__pilotHello = window.__play.hello, window.__pilotFrames = window.__play.frames, 0");
        if i == 0 {
            p.b.wait_for("!document.getElementById('go').disabled && document.activeElement === document.getElementById('go')", 10.0).unwrap();
            p.press("Enter");
            p.b.wait_for("window.__play.role === 'hand'", 10.0).unwrap();
        }
        p.b.wait_for("window.__play.frames > window.__pilotFrames + 3 && document.activeElement.id === 'view'", 10.0)
            .unwrap();
        p.read_mapping();
        if i == 0 {
            p.learn_arrows();
        }
        println!("step {} `{}` ({})", i + 1, step.id, step.done.name());
        let t0 = Instant::now();
        do_step(&mut p, i, step.kind, step.done);
        p.let_go();
        p.b.wait_for(&past(i), 20.0).unwrap();
        let wall = t0.elapsed();
        println!("  done in {:.1} s of wall time", wall.as_secs_f64());
        walls.push(wall);
        afters.push(step.after.as_ref().map(|q| {
            p.b.wait_for("window.__play.lesson.place === 'after'", 10.0)
                .unwrap();
            answer(&mut p, q, 1, words_after(&step.id))
        }));
    }

    // The post-test, then the end with the scores.
    let mut post = Vec::new();
    for q in &module.test {
        p.b.wait_for("window.__play.lesson.place === 'post_test'", 10.0)
            .unwrap();
        post.push(Some(answer(&mut p, q, correct(q), "")));
    }
    p.b.wait_for("window.__play.lesson.place === 'finished'", 10.0)
        .unwrap();
    let n = module.test.len();
    assert_eq!(
        p.eval("document.getElementById('lesson-score').textContent"),
        json!(format!(
            "Before the lesson: {n} of {n} right. After: {n} of {n} right."
        ))
    );
    p.b.check().unwrap();
    println!(
        "the whole module: {:.1} s of wall time",
        t_all.elapsed().as_secs_f64()
    );
    stop.store(true, Ordering::Relaxed);
    let summary = handle.join().unwrap().unwrap();
    let l = summary.lesson.unwrap();

    // Every answer reached the progress.
    let pr = &l.progress;
    assert_eq!(pr.place(), teaching::Place::Finished);
    assert_eq!(pr.pre_test(), pre.as_slice());
    assert_eq!(pr.post_test(), post.as_slice());
    assert_eq!(
        (pr.test_score(true), pr.test_score(false)),
        ((n, n), (n, n))
    );
    for (i, s) in pr.steps().iter().enumerate() {
        assert_eq!(s.before, befores[i], "{}", module.steps[i].id);
        assert_eq!(s.after, afters[i], "{}", module.steps[i].id);
    }

    // Each step its own world, met on a tick of it, recorded as STEP-ID.mcap, replaying bit
    // for bit.
    assert_eq!(l.runs.len(), module.steps.len());
    for (i, r) in l.runs.iter().enumerate() {
        let step = &module.steps[i];
        assert_eq!((r.step, r.id.as_str()), (i, step.id.as_str()));
        assert_eq!(r.session.recording, l.dir.join(format!("{}.mcap", step.id)));
        let met = r
            .met_at
            .unwrap_or_else(|| panic!("step {} not met", step.id));
        assert_eq!(pr.steps()[i].met_at, Some(met));
        assert_eq!(pr.steps()[i].ticks, r.session.stats.ticks);
        let rec = recording::read_recording_file(&r.session.recording, false).unwrap();
        assert!(
            haptic_loop::replay::verify(&rec).unwrap().ok(),
            "{} does not replay bit for bit",
            step.id
        );
        let a = read_arrays(&r.session.recording, false).unwrap();
        let hz = f64::from(a.rate_hz);
        // The condition's event is in the recording on the tick the step was met.
        let names: &[&str] = match step.done {
            Condition::BrickThrown => &["brick.thrown"],
            Condition::AtomSnapped => &["nano.snap"],
            Condition::AtomPulledOff => &["nano.pull_off"],
            Condition::HouseComplete if step.kind == "nanoworld" => &["nano.house_complete"],
            _ => &[],
        };
        if !names.is_empty() {
            assert!(
                a.events
                    .iter()
                    .any(|(t, n, _)| *t == met && names.contains(&n.as_str())),
                "{}: no {names:?} on tick {met}",
                step.id
            );
        }
        if let Condition::Time { seconds } = step.done {
            assert_eq!(met + 1, (seconds * hz).round() as u64, "{}", step.id);
        }
        println!(
            "{:>14}: met at {:7.3} s of sim time ({} ticks), {:5.1} s of wall time",
            step.id,
            (met + 1) as f64 / hz,
            r.session.stats.ticks,
            walls[i].as_secs_f64()
        );
    }
}
