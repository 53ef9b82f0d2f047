//! Every step of the built-in module can be done: its scene, with the step's switches, driven
//! headlessly by a script that does the task, meets the step's condition on the tick the world
//! reports it; a script that does not do the task does not meet it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::source::OperatorChoice;
use haptic_loop::session::{SessionArrays, SessionOptions, run_session};
use haptic_types::Event;
use lesson::scripts::{self, ScriptText};
use teaching::{Condition, Evaluator, Lesson, Step};

fn module() -> Lesson {
    teaching::builtin::module().unwrap_or_else(|e| panic!("{e}"))
}

fn step<'a>(m: &'a Lesson, id: &str) -> &'a Step {
    m.steps.iter().find(|s| s.id == id).expect(id)
}

/// `text` with the step's switches set at the start (as the page sets them before the first
/// tick).
fn with_switches(mut text: String, s: &Step) -> String {
    for (name, value) in s.switch_pairs() {
        text.push_str(&format!(
            "\n[[switch]]\nt_s = 0.0\nname = \"{name}\"\nvalue = {value:?}\n"
        ));
    }
    text
}

/// Runs the step's scene with `script` (`None`: the scene's own house script) through a rigid
/// stylus, for `seconds` (`None`: the script's length).
fn run(s: &Step, script: Option<String>, seconds: Option<f64>) -> SessionArrays {
    let mut o = SessionOptions::new(s.source.clone());
    o.script = script.map(|t| with_switches(t, s));
    o.script_origin = Some(format!("test script of step {}", s.id));
    o.operator = OperatorChoice::Rigid;
    o.start_time_ns = Some(0);
    o.seconds = seconds;
    run_session(&o, &mut |_, _| {})
        .unwrap_or_else(|e| panic!("{e}"))
        .arrays
}

/// Feeds the first `ticks` ticks of a run to the step's evaluator; the tick it was met on.
fn evaluate(s: &Step, a: &SessionArrays, ticks: usize) -> Option<u64> {
    evaluate_as(s.done, s, a, ticks)
}

/// [`evaluate`] with another condition of the vocabulary, in the step's scene.
fn evaluate_as(c: Condition, s: &Step, a: &SessionArrays, ticks: usize) -> Option<u64> {
    assert_eq!(a.state_fields, s.state_fields);
    let mut e = Evaluator::new(c, s.kind, &s.state_fields, s.rate_hz).unwrap();
    let n = a.state_fields.len();
    let mut k = 0;
    for (i, row) in a.state.chunks(n).take(ticks).enumerate() {
        let tick = a.tick[i];
        let mut events = Vec::new();
        while k < a.events.len() && a.events[k].0 == tick {
            events.push(Event::new(a.events[k].1.clone(), a.events[k].2.clone()));
            k += 1;
        }
        e.feed(&events, row);
    }
    e.met_at()
}

fn all(s: &Step, a: &SessionArrays) -> Option<u64> {
    evaluate(s, a, a.tick.len())
}

/// The first tick with event `name`.
fn first(a: &SessionArrays, name: &str) -> Option<u64> {
    a.events.iter().find(|e| e.1 == name).map(|e| e.0)
}

fn column(a: &SessionArrays, name: &str) -> Vec<f64> {
    a.state_column(name).expect(name)
}

#[test]
fn the_brick_steps_are_met_on_the_tick_the_world_reports_them() {
    let m = module();
    // The brick house, by the scene's own house script: met on the first tick complete_s ≥ 0.
    let s = step(&m, "brick-house");
    let house = run(s, None, None);
    let complete = column(&house, "complete_s");
    let done = complete.iter().position(|c| *c >= 0.0).unwrap() as u64;
    assert_eq!(all(s, &house), Some(done));
    assert_eq!(column(&house, "slots_filled")[done as usize], 4.0);
    assert_eq!(column(&house, "slots_filled")[done as usize - 1], 3.0);
    let (lift, _) = scripts::brick_lift(&[]);
    let lifted = run(s, Some(lift.clone()), None);
    assert_eq!(all(s, &lifted), None);
    // `brick_placed`, the vocabulary's other brick condition: the house's first filled slot;
    // a brick lifted and carried fills none.
    let placed = first(&house, "brick.slot_filled").unwrap();
    assert!(placed < done);
    let n = house.tick.len();
    assert_eq!(
        evaluate_as(Condition::BrickPlaced, s, &house, n),
        Some(placed)
    );
    let n = lifted.tick.len();
    assert_eq!(evaluate_as(Condition::BrickPlaced, s, &lifted, n), None);

    // Lifting: met on the first tick the held brick is 0.1 m above where it was grabbed.
    let s = step(&m, "lift");
    let a = run(s, Some(lift), None);
    let grab = first(&a, "brick.grabbed").unwrap() as usize;
    let z = column(&a, "proxy_z_m");
    let held = column(&a, "holding");
    let risen = (grab..z.len())
        .find(|&i| held[i] == 1.0 && z[i] - z[grab] >= 0.1)
        .unwrap();
    assert_eq!(all(s, &a), Some(risen as u64));
    assert!(z[risen - 1] - z[grab] < 0.1);
    // The same motion without the grip: no brick comes up.
    let no_grip = ScriptText::new("lift without the grip")
        .at(0.0, [-22.5, 2.5, 7.5])
        .at(0.6, [-22.5, 2.5, -6.8])
        .at(1.3, [-22.5, 2.5, 7.5])
        .text();
    let b = run(s, Some(no_grip.clone()), None);
    assert_eq!(first(&b, "brick.grabbed"), None);
    assert_eq!(all(s, &b), None);

    // Throwing, with gravity and (the step's switch) without it: met on `brick.thrown`.
    for id in ["throw", "gravity-off", "compare-brick"] {
        let s = step(&m, id);
        let (throw, release) = scripts::brick_throw(if id == "compare-brick" { 0.2 } else { 0.3 });
        let a = run(s, Some(throw), None);
        let thrown = first(&a, "brick.thrown").unwrap();
        assert_eq!(all(s, &a), Some(thrown), "{id}");
        assert_eq!(thrown, (release * 1000.0).ceil() as u64, "{id}");
        // What the gravity-off step asks the student to predict: with gravity the thrown brick
        // lands (an impact with the ground) within the 2 s the script goes on; without it, it
        // flies on and never meets the ground.
        let landed = a
            .events
            .iter()
            .any(|e| e.0 > thrown && e.1 == "brick.impact" && e.2.contains("\"ground\""));
        assert_eq!(landed, id != "gravity-off", "{id}");
        // Carried and never let go: not thrown.
        let (carry, _) = scripts::brick_lift(&[]);
        assert_eq!(all(s, &run(s, Some(carry), None)), None, "{id}");
    }
    let s = step(&m, "gravity-off");
    assert_eq!(
        s.switch_pairs().collect::<Vec<_>>(),
        [("gravity_m_per_s2", 0.0)]
    );

    // Inertia off: the lift is met as with inertia on; without the grip it is not.
    let s = step(&m, "inertia-off");
    let (lift, _) = scripts::brick_lift(&[]);
    let a = run(s, Some(lift), None);
    let grab = first(&a, "brick.grabbed").unwrap() as usize;
    let z = column(&a, "proxy_z_m");
    let risen = (grab..z.len()).find(|&i| z[i] - z[grab] >= 0.1).unwrap();
    assert_eq!(all(s, &a), Some(risen as u64));
    assert_eq!(all(s, &run(s, Some(no_grip), None)), None);
}

/// World z of the tip centre (nm) → device mm in the built-in nano scene.
fn dev_z(z_nm: f64) -> f64 {
    (z_nm - 3.5) / 0.15
}

#[test]
fn the_atom_steps_are_met_on_the_tick_the_world_reports_them() {
    let m = module();
    // Snap and pull-off: the approach–retract cycle over a substrate atom.
    let cycle = scripts::approach_retract(&[]);
    let s = step(&m, "snap");
    let a = run(s, Some(cycle.clone()), None);
    let snap = first(&a, "nano.snap").unwrap();
    assert_eq!(all(s, &a), Some(snap));
    // Hovering 1.5 nm above the atom's top: no snap.
    let hover = ScriptText::new("hover")
        .at(0.0, [-1.0, -1.0, dev_z(0.45 + 1.5)])
        .at(2.0, [-1.0, -1.0, dev_z(0.45 + 1.5)])
        .text();
    let hovered = run(s, Some(hover), None);
    assert_eq!(first(&hovered, "nano.snap"), None);
    assert_eq!(all(s, &hovered), None);

    // The content question's "about ten times harder": the game's release at ten times the
    // snap force.
    match nanoworld::Params::game_default().interaction {
        nanoworld::Interaction::Game(g) => assert_eq!(g.pull_off_ratio, 10.0),
        nanoworld::Interaction::Physical(_) => panic!("the game's laws"),
    }
    let s = step(&m, "pull-off");
    let pull = first(&a, "nano.pull_off").unwrap();
    assert!(pull > snap);
    assert_eq!(all(s, &a), Some(pull));
    // Down into contact and held there: snapped, never pulled off.
    let press = ScriptText::new("press and hold")
        .at(0.0, [-1.0, -1.0, dev_z(0.45 + 1.5)])
        .at(2.0, [-1.0, -1.0, dev_z(0.45 - 0.25)])
        .at(4.2, [-1.0, -1.0, dev_z(0.45 - 0.25)])
        .text();
    let b = run(s, Some(press), None);
    assert!(first(&b, "nano.snap").is_some());
    assert_eq!(all(s, &b), None);

    // Putting an atom back: pick it up, carry it 30 mm (4.5 nm) away, bring it back down to
    // where it was taken.
    let s = step(&m, "put-back");
    let [x, y] = scripts::NANO_PICK_XY_MM;
    let (up, down) = (scripts::NANO_CARRY_Z_MM, scripts::NANO_PICK_Z_MM);
    let back = ScriptText::new("put an atom back")
        .at(0.0, [x, y, up])
        .at(0.557, [x, y, down])
        .at(1.113, [x, y, up])
        .at(2.0, [x + 30.0, y, up])
        .at(3.0, [x, y, up])
        .at(3.557, [x, y, down])
        .at(4.0, [x, y, down])
        .text();
    let a = run(s, Some(back), None);
    let met = all(s, &a).unwrap() as usize;
    let taken = a
        .events
        .iter()
        .find(|e| e.1 == "nano.atom_attached" || e.1 == "nano.atom_picked_up")
        .unwrap()
        .0 as usize;
    let tip = |i: usize| ["tip_x_m", "tip_y_m", "tip_z_m"].map(|f| column(&a, f)[i]);
    let dist = |i: usize| {
        let (p, o) = (tip(i), tip(taken));
        ((p[0] - o[0]).powi(2) + (p[1] - o[1]).powi(2) + (p[2] - o[2]).powi(2)).sqrt()
    };
    // Met on the first tick of the return within 0.5 nm, in the final descent (after 3 s).
    assert!(met > 3000, "{met}");
    assert!(
        dist(met) <= 0.5e-9 && dist(met - 1) > 0.5e-9,
        "{}",
        dist(met)
    );
    assert!((taken..met).any(|i| dist(i) >= 2e-9));
    // `atom_picked_up`, the vocabulary's other atom condition: met on the tick the atom came
    // onto the tip; hovering above the surface picks up nothing.
    let n = a.tick.len();
    assert_eq!(
        evaluate_as(Condition::AtomPickedUp, s, &a, n),
        Some(taken as u64)
    );
    let n = hovered.tick.len();
    assert_eq!(evaluate_as(Condition::AtomPickedUp, s, &hovered, n), None);
    // The irreversibility the step shows: the atom is still on the tip at the end.
    assert_eq!(*column(&a, "carried_atoms").last().unwrap(), 1.0);
    // Carried away and never brought back: not met.
    let b = run(s, Some(scripts::atom_throw(0.3, &[])), None);
    assert!(
        first(&b, "nano.atom_attached").is_some() || first(&b, "nano.atom_picked_up").is_some()
    );
    assert_eq!(all(s, &b), None);

    // The atom house, by the scene's house script: met on `nano.house_complete`.
    let s = step(&m, "atom-house");
    let house = run(s, None, None);
    let done = first(&house, "nano.house_complete").unwrap();
    assert_eq!(all(s, &house), Some(done));
    assert_eq!(all(s, &b), None);

    // Trying to throw an atom for 15 s: met on tick 14 999 at 1 kHz, not a tick before.
    let s = step(&m, "compare-atom");
    let a = run(s, Some(scripts::atom_throw(0.3, &[])), Some(15.0));
    assert_eq!(a.tick.len(), 15_000);
    assert_eq!(all(s, &a), Some(14_999));
    assert_eq!(evaluate(s, &a, 14_999), None);
}
