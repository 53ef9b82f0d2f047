//! The built-in module by keyboard: what a student at the keyboard does at each step of
//! `crates/teaching/modules/nanoscale.toml`, through the keyboard pilot ([`super::pilot`]), and
//! the whole way through a lesson's places (the questions, each step's world) on one page.
#![allow(dead_code)]

use super::pilot::Pilot;
use serde_json::{Value, json};
use std::time::{Duration, Instant};
use teaching::condition::Condition;
use teaching::{Answer, Lesson, Question, QuestionKind};

/// The page's expression that the lesson has moved past step `i`'s world.
pub fn past(i: usize) -> String {
    format!("window.__play.lesson.step !== {i} || window.__play.lesson.place !== 'doing'")
}

/// Answers the question the page shows by keyboard and waits for the page's next place:
/// a choice (the first radio is focused: Space checks it, each ArrowDown checks the next;
/// Enter submits), or a text typed into the text area (Tab to Answer, Enter).
pub fn answer(p: &mut Pilot, q: &Question, choice: usize, text: &str) -> Answer {
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
pub fn place(p: &mut Pilot) -> (String, Value) {
    let v = p.eval("[window.__play.lesson.place, window.__play.lesson.step]");
    (v[0].as_str().unwrap_or("").to_string(), v[1].clone())
}

/// A point over the substrate's middle (the slab the page draws first), 1.5 nm or more from
/// every orange atom and outside the loading zone, `z` above the surface.
pub fn clear_spot(p: &mut Pilot, z: f64) -> [f64; 3] {
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
pub fn do_step(p: &mut Pilot, i: usize, kind: &str, done: Condition) {
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
pub fn words_after(id: &str) -> &'static str {
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

/// What a student answered and how long each step's world took them.
#[derive(Debug, Default)]
pub struct Taken {
    /// The pre-test's answers.
    pub pre: Vec<Option<Answer>>,
    /// Each step's answer before and after (`None`: no question).
    pub befores: Vec<Option<Answer>>,
    pub afters: Vec<Option<Answer>>,
    /// The post-test's answers.
    pub post: Vec<Option<Answer>>,
    /// Each step's wall time, from its world's first frames to the page moving on.
    pub walls: Vec<Duration>,
}

/// The index of test question `q`'s correct choice.
pub fn correct(q: &Question) -> usize {
    match &q.kind {
        QuestionKind::Choice { correct, .. } => correct.unwrap(),
        QuestionKind::Text => panic!("a test question is a choice"),
    }
}

/// Takes `lesson` on the page `p` drives, by keyboard alone: the pre-test (`right`: each
/// answered right, else each answered with the first choice), then steps `0..steps` (each
/// question before and after answered, each world's condition met), then, when every step was
/// taken, the post-test (right). A locked step the student reaches calls `at_locked(step)`,
/// which must open it. Stops at step `steps`'s task when `steps` is short of the lesson.
pub fn take_lesson(
    p: &mut Pilot,
    lesson: &Lesson,
    steps: usize,
    right: bool,
    at_locked: &mut dyn FnMut(usize),
) -> Taken {
    let mut t = Taken::default();
    p.b.wait_for(
        "!!window.__play && window.__play.lesson !== null && window.__play.lesson.place === 'pre_test'",
        20.0,
    )
    .unwrap();
    for q in &lesson.test {
        assert_eq!(place(p).0, "pre_test");
        let c = if right { correct(q) } else { 0 };
        t.pre.push(Some(answer(p, q, c, "")));
    }
    for (i, step) in lesson.steps.iter().enumerate().take(steps) {
        if step.locked {
            p.b.wait_for(
                &format!(
                    "window.__play.lesson.step === {i} && window.__play.lesson.place === 'waiting'"
                ),
                20.0,
            )
            .unwrap();
            at_locked(i);
        }
        p.b.wait_for(
            &format!("window.__play.lesson.step === {i} && ['before', 'doing'].includes(window.__play.lesson.place)"),
            20.0,
        )
        .unwrap();
        t.befores.push(step.before.as_ref().map(|q| {
            assert_eq!(place(p).0, "before");
            answer(p, q, 1, "")
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
        do_step(p, i, step.kind, step.done);
        p.let_go();
        p.b.wait_for(&past(i), 20.0).unwrap();
        let wall = t0.elapsed();
        println!("  done in {:.1} s of wall time", wall.as_secs_f64());
        t.walls.push(wall);
        t.afters.push(step.after.as_ref().map(|q| {
            p.b.wait_for("window.__play.lesson.place === 'after'", 10.0)
                .unwrap();
            answer(p, q, 1, words_after(&step.id))
        }));
    }
    if steps < lesson.steps.len() {
        let i = steps;
        p.b.wait_for(
            &format!("window.__play.lesson.step === {i} && ['before', 'doing'].includes(window.__play.lesson.place)"),
            20.0,
        )
        .unwrap();
        return t;
    }
    for q in &lesson.test {
        p.b.wait_for("window.__play.lesson.place === 'post_test'", 10.0)
            .unwrap();
        t.post.push(Some(answer(p, q, correct(q), "")));
    }
    p.b.wait_for("window.__play.lesson.place === 'finished'", 10.0)
        .unwrap();
    t
}
