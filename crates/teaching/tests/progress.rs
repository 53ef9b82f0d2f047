//! The progress state machine: whatever a student and a teacher do, in any order, the student
//! never moves back and never enters a step that is locked.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use proptest::prelude::*;
use teaching::progress::ProgressError;
use teaching::{Answer, Lesson, Place, Progress};

fn module() -> Lesson {
    teaching::builtin::module().unwrap_or_else(|e| panic!("{e}"))
}

/// What a student or the teacher does.
#[derive(Clone, Debug)]
enum Op {
    Choice(usize),
    Text(String),
    Tick(bool),
    Open(usize),
    Lock(usize),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => (0usize..6).prop_map(Op::Choice),
        2 => "[ a-z]{0,4}".prop_map(Op::Text),
        4 => any::<bool>().prop_map(Op::Tick),
        1 => (0usize..13).prop_map(Op::Open),
        1 => (0usize..13).prop_map(Op::Lock),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn never_backwards_never_into_a_locked_step(
        locked in proptest::collection::vec(proptest::bool::weighted(0.3), 11),
        ops in proptest::collection::vec(op(), 0..400),
    ) {
        // The built-in module with any steps locked at the start.
        let mut m = module();
        for (s, l) in m.steps.iter_mut().zip(&locked) {
            s.locked = *l;
        }
        let mut p = Progress::new(&m);
        // The test's own record of which steps are open.
        let mut open: Vec<bool> = m.steps.iter().map(|s| !s.locked).collect();
        for o in ops {
            let before = p.position();
            let place = p.place();
            let student = !matches!(o, Op::Open(_) | Op::Lock(_));
            let r = match o {
                Op::Choice(i) => p.answer(Answer::Choice(i)),
                Op::Text(t) => p.answer(Answer::Text(t)),
                Op::Tick(met) => p.tick(met),
                Op::Open(s) => {
                    let r = p.open(s);
                    if s < open.len() { open[s] = true; }
                    r
                }
                Op::Lock(s) => {
                    let r = p.lock(s);
                    if s < open.len() { open[s] = false; }
                    r
                }
            };
            let after = p.position();
            prop_assert!(after >= before, "moved back: {before} -> {after}");
            prop_assert!(after <= before + 1, "skipped: {before} -> {after}");
            if r.is_err() {
                prop_assert_eq!(after, before);
            }
            // Leaving the first place of a step needs the step open.
            for (s, is_open) in open.iter().enumerate() {
                if p.step_start(s) == Some(before) && after > before {
                    prop_assert!(*is_open, "left the start of locked step {s}");
                }
            }
            // A student waiting at a locked step can neither answer nor tick.
            if matches!(place, Place::Waiting(_)) && student {
                let not_now = matches!(r, Err(ProgressError::NotNow { .. }));
                prop_assert!(not_now);
                prop_assert_eq!(after, before);
            }
            // Waiting at a step is being at its start while it is locked.
            for (s, is_open) in open.iter().enumerate() {
                let at_start = p.step_start(s) == Some(p.position());
                prop_assert_eq!(p.place() == Place::Waiting(s), at_start && !is_open);
            }
        }
    }
}

/// The whole module, answered and done: the answers, the ticks and the tests' scores are kept.
#[test]
fn a_student_goes_through_the_module() {
    let m = module();
    let mut p = Progress::new(&m);
    // Pre-test: questions 1 and 3 right (choices 1, 2 are correct for them).
    for c in [1, 0, 2, 0, 1] {
        assert!(matches!(p.place(), Place::PreTest(_)));
        p.answer(Answer::Choice(c)).unwrap();
    }
    assert_eq!(p.test_score(true), (2, 5));
    // Step 1: no question before; three ticks, met on the third.
    assert_eq!(p.place(), Place::Doing(0));
    assert_eq!(
        p.answer(Answer::Choice(0)).unwrap_err().to_string(),
        "an answer now: the student is at step 1, doing the task"
    );
    p.tick(false).unwrap();
    p.tick(false).unwrap();
    assert_eq!(p.tick(true).unwrap(), Place::After(0));
    assert_eq!(
        p.answer(Answer::Choice(0)).unwrap_err().to_string(),
        "answer: a choice where a short text is asked"
    );
    assert_eq!(
        p.answer(Answer::Text("  ".into())).unwrap_err().to_string(),
        "answer: a text of 0 characters: allowed 1 to 2000"
    );
    p.answer(Answer::Text(" heavy ".into())).unwrap();
    assert_eq!(p.steps()[0].ticks, 3);
    assert_eq!(p.steps()[0].met_at, Some(2));
    assert_eq!(p.steps()[0].after, Some(Answer::Text("heavy".into())));
    // Steps 2 to 5, each met on its first tick, every question answered with its first choice.
    while p.place().step().is_some_and(|s| s < 5) {
        match p.place() {
            Place::Doing(_) => p.tick(true).map(drop),
            Place::Before(s) | Place::After(s) => {
                let q = if matches!(p.place(), Place::Before(_)) {
                    m.steps[s].before.as_ref()
                } else {
                    m.steps[s].after.as_ref()
                };
                match q.unwrap().kind {
                    teaching::QuestionKind::Text => p.answer(Answer::Text("ok".into())),
                    _ => p.answer(Answer::Choice(0)),
                }
                .map(drop)
            }
            other => panic!("{other:?}"),
        }
        .unwrap();
    }
    // Step 6 (the atom world) is locked: the student waits, ticks count nothing.
    assert_eq!(p.place(), Place::Waiting(5));
    assert_eq!(
        p.tick(true).unwrap_err().to_string(),
        "a tick now: the student is at step 6, locked (waiting for the teacher)"
    );
    assert_eq!(
        p.open(11).unwrap_err().to_string(),
        "step 11 is out of range: allowed 0 ≤ step < 11"
    );
    assert_eq!(p.open(5).unwrap(), Place::Before(5));
    assert_eq!(p.steps()[5].ticks, 0);
}
