//! Command clipping and the steering controller.

mod common;
use common::*;
use nalgebra::Vector2;
use ot_envelope::geometry::{contains, nearest_on_boundary};
use ot_envelope::inverse::Choice;
use ot_envelope::steer::{Controller, ParticleState, SteerParams};
use ot_envelope::{ClipMode, EnvelopeError, clip_command, working_envelope};
use proptest::prelude::*;
use std::sync::OnceLock;

fn paper_we() -> &'static ot_envelope::Envelope {
    static WE: OnceLock<ot_envelope::Envelope> = OnceLock::new();
    WE.get_or_init(|| working_envelope(&paper(), &v(0.1, 0.1), None).expect("envelope"))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn clipping_splits_the_command_and_lands_on_the_envelope(x in -2000.0f64..2000.0, y in -2000.0f64..2000.0) {
        let we = paper_we();
        let c = v(x, y) * NM;
        let r = clip_command(we, &c, ClipMode::Radial).expect("clip");
        let n = clip_command(we, &c, ClipMode::Nearest).expect("clip");
        for k in [&r, &n] {
            prop_assert!(((k.allowed + k.excess) - c).norm() <= 1e-20);
        }
        if we.contains(&c) {
            prop_assert_eq!(r.excess, Vector2::zeros());
            prop_assert_eq!(n.excess, Vector2::zeros());
        } else {
            // both on the boundary
            prop_assert!(nearest_on_boundary(&we.polygon, &r.allowed).1 < 1e-15);
            prop_assert!(nearest_on_boundary(&we.polygon, &n.allowed).1 < 1e-15);
            // radial: on the segment from zero displacement to the command
            let cr = r.allowed.x * c.y - r.allowed.y * c.x;
            prop_assert!(cr.abs() <= 1e-9 * c.norm_squared());
            prop_assert!(r.allowed.dot(&c) > 0.0);
            // nearest never exceeds radial
            prop_assert!(n.excess.norm() <= r.excess.norm() + 1e-18);
        }
    }
}

#[test]
fn radial_clip_of_a_fast_particle_starts_from_its_free_drift() {
    let p = paper();
    let we = working_envelope(&p, &v(3.0, 1.0), None).expect("envelope");
    assert!(!we.contains(&Vector2::zeros()));
    // "stay put" is impossible: radial clipping runs from the drift towards zero
    let k = clip_command(&we, &Vector2::zeros(), ClipMode::Radial).expect("clip");
    let d = we.free_displacement;
    let cr = (k.allowed - d).x * (-d).y - (k.allowed - d).y * (-d).x;
    assert!(cr.abs() < 1e-6 * d.norm_squared());
    assert!(k.excess.norm() > 2e-6);
}

#[test]
fn bad_clip_input_is_a_typed_error() {
    let e = clip_command(paper_we(), &v(f64::NAN, 0.0), ClipMode::Radial)
        .expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "command [m] = NaN is out of range: allowed finite"
    );
    assert!(matches!(
        ClipMode::from_name("sideways"),
        Err(EnvelopeError::Value(_))
    ));
    assert_eq!(
        ClipMode::from_name("nearest").expect("mode"),
        ClipMode::Nearest
    );
}

fn params() -> SteerParams {
    SteerParams {
        stiffness: 0.5,
        mode: ClipMode::Radial,
        tol: 0.5e-9,
        margin_waists: 3.0,
    }
}

#[test]
fn command_inside_moves_the_particle_exactly_to_the_cursor() {
    let p = paper();
    let mut c = Controller::new(params()).expect("controller");
    let state = ParticleState {
        position: v(2e-6, -1e-6),
        velocity: v(0.05, -0.02),
    };
    let cursor = state.position + v(150.0 * NM, -220.0 * NM);
    let out = c.step(&p, &state, &cursor).expect("step");
    assert_eq!(out.excess, Vector2::zeros());
    assert_eq!(out.force, Vector2::zeros());
    // apply the trap for one tick: the particle lands on the cursor
    let (d, _, _) = p
        .flow(&(out.trap - state.position), &state.velocity)
        .expect("flow");
    assert!((state.position + d - cursor).norm() < 1e-12);
}

#[test]
fn command_outside_feels_a_spring_on_the_excess_and_moves_to_the_wall() {
    let p = paper();
    let mut c = Controller::new(params()).expect("controller");
    let state = ParticleState {
        position: v(0.0, 0.0),
        velocity: v(0.0, 0.0),
    };
    let cursor = v(2000.0 * NM, 500.0 * NM);
    let out = c.step(&p, &state, &cursor).expect("step");
    // reaction opposes the command, magnitude k·|excess|
    assert!(out.force.dot(&cursor) < 0.0);
    assert!((out.force + out.excess * 0.5).norm() < 1e-20);
    // the particle really reaches the clipped displacement, at the wall
    let (d, _, _) = p
        .flow(&(out.trap - state.position), &state.velocity)
        .expect("flow");
    assert!((d - out.allowed).norm() < 1e-12);
    assert!(nearest_on_boundary(&out.envelope.polygon, &d).1 < 3.0 * params().tol);
    assert!(!contains(&out.envelope.polygon, &cursor));
}

#[test]
fn controller_tracks_a_cursor_path_continuously_and_deterministically() {
    let p = paper();
    let run = || {
        let mut c = Controller::new(params()).expect("controller");
        let mut s = ParticleState {
            position: v(0.0, 0.0),
            velocity: v(0.0, 0.0),
        };
        let mut log = Vec::new();
        for k in 0..40 {
            let t = k as f64 * 0.1;
            let cursor = v(1.5e-6 * t.sin(), 0.8e-6 * (1.0 - t.cos()));
            let out = c.step(&p, &s, &cursor).expect("step");
            let (d, vel, _) = p.flow(&(out.trap - s.position), &s.velocity).expect("flow");
            s = ParticleState {
                position: s.position + d,
                velocity: vel,
            };
            log.push((out.trap, out.force, out.choice, s.position));
        }
        log
    };
    let a = run();
    assert_eq!(a, run());
    // after the first tick the branch is continued
    assert!(
        a.iter()
            .skip(1)
            .filter(|x| x.2 == Choice::Continued)
            .count()
            >= 35
    );
    // the particle follows the cursor path closely
    let last = a.last().expect("ticks").3;
    let t = 3.9f64;
    assert!((last - v(1.5e-6 * t.sin(), 0.8e-6 * (1.0 - t.cos()))).norm() < 0.3e-6);
}

#[test]
fn steer_params_from_toml_are_validated() {
    let ok: SteerParams = toml::from_str("stiffness = 0.2\nmode = \"nearest\"").expect("toml");
    assert_eq!(ok.mode, ClipMode::Nearest);
    assert!(toml::from_str::<SteerParams>("stiffness = 0.2\nstiffnes = 1").is_err());
    let bad = SteerParams {
        stiffness: -1.0,
        ..params()
    };
    let e = Controller::new(bad).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "stiffness [N/m] = -1 is out of range: allowed finite and > 0"
    );
}
