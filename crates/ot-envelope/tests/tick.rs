//! The warm-started steering tick: agrees with a full rebuild, rebuilds
//! rarely in a steady drag, is deterministic, and its inverse answers
//! reproduce the target under converged dynamics.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::Vector2;
use ot_envelope::geometry::hausdorff;
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickOutput, TickParams};
use ot_envelope::{ClipMode, EnvelopeOptions, working_envelope_with};
use ot_physics::Propagator;
use ot_physics::budget::{choose_tick_map, converged};

type V2 = Vector2<f64>;

fn scene_tick() -> Propagator<2> {
    choose_tick_map(paper_model([600e-9, 300e-9]), 0.2e-6, 1e-11, 0.1)
        .unwrap()
        .0
}

fn params(warm: bool) -> TickParams {
    let mut p = TickParams::new(SteerParams {
        stiffness: 0.8,
        mode: ClipMode::Radial,
        tol: 0.5e-9,
        margin_waists: 3.0,
    });
    p.warm_start = warm;
    p
}

/// A drag along a circle of `radius` (m) at `speed` (m per tick), the
/// particle following through the trap (velocity kept at 10 % per tick, as
/// the scene). Returns every tick's output and envelope.
fn drag(
    prop: &Propagator<2>,
    c: &mut TickController,
    ticks: usize,
    radius: f64,
    step: f64,
    mut each: impl FnMut(usize, &TickOutput, &[V2], &ParticleState),
) {
    let mut s = ParticleState {
        position: V2::zeros(),
        velocity: V2::zeros(),
    };
    for k in 0..ticks {
        let a = k as f64 * step / radius;
        let cursor = V2::new(radius * (a.cos() - 1.0), radius * a.sin());
        let out = c.step(prop, &s, &cursor).unwrap();
        each(k, &out, c.envelope(), &s);
        let (d, v, _) = prop.flow(&(out.trap - s.position), &s.velocity).unwrap();
        s.position += d;
        s.velocity = v * 0.1;
    }
}

#[test]
fn warm_envelope_stays_within_a_tenth_of_a_nanometre_of_converged_dynamics() {
    let prop = scene_tick();
    let truth = converged(*prop.model(), prop.dt()).unwrap();
    let mut c = TickController::new(params(true)).unwrap();
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    // a fast drag (the command often outside the envelope) and a slow one
    for (ticks, step) in [(400, 30e-9), (400, 2e-9)] {
        drag(&prop, &mut c, ticks, 2e-6, step, |k, out, poly, s| {
            if k % 40 == 7 && !out.rebuilt {
                let reference = working_envelope_with(
                    &truth,
                    &s.velocity,
                    &EnvelopeOptions {
                        tol: 0.02e-9,
                        coarse_grid: false,
                        ..Default::default()
                    },
                )
                .unwrap();
                worst = worst.max(hausdorff(poly, &reference.polygon, 0.05e-9));
                checked += 1;
            }
        });
    }
    let st = c.stats();
    eprintln!(
        "worst Hausdorff {:.3e} m over {checked} warm ticks; {st:?}",
        worst
    );
    assert!(checked >= 10);
    // issue 13's target: ≤ 0.1 nm from converged dynamics at every tick
    assert!(worst <= 0.1e-9, "{worst:e} m");
    // BENCHMARKS.md (docs/bench/ot-tick.md): "Tests: warm envelopes within 0.081 nm of
    // converged dynamics over two drags (`ot-envelope/tests/tick.rs`)" (measured 0.0808 nm at
    // 20 ticks)
    assert_eq!(checked, 20);
    assert!((0.0805e-9..0.0815e-9).contains(&worst), "{worst:e} m");
    assert!(st.rebuilds * 4 < st.ticks, "{st:?}");
}

#[test]
fn warm_and_cold_ticks_reach_the_same_targets_and_replay_bit_exactly() {
    let prop = scene_tick();
    let run = |warm: bool| {
        let mut c = TickController::new(params(warm)).unwrap();
        let mut outs = Vec::new();
        drag(&prop, &mut c, 600, 2e-6, 20e-9, |_, o, poly, s| {
            outs.push((*o, poly.len(), *s));
        });
        (outs, c.stats())
    };
    let (w1, s1) = run(true);
    let (w2, s2) = run(true);
    assert_eq!(s1, s2);
    for (a, b) in w1.iter().zip(&w2) {
        assert_eq!(a.0.trap.x.to_bits(), b.0.trap.x.to_bits());
        assert_eq!(a.0.trap.y.to_bits(), b.0.trap.y.to_bits());
        assert_eq!(a.1, b.1);
    }
    let (cold, sc) = run(false);
    assert_eq!(sc.rebuilds, sc.ticks);
    assert!(s1.rebuilds * 4 < s1.ticks, "{s1:?}");
    // every tick's allowed displacement is reached by the tick map to the
    // solver's residual, warm or cold
    for (o, _, s) in w1.iter().chain(&cold) {
        let (d, _, _) = prop.flow(&(o.trap - s.position), &s.velocity).unwrap();
        assert!(
            (d - o.allowed).norm() < 1e-11,
            "{:e}",
            (d - o.allowed).norm()
        );
    }
    eprintln!("warm {s1:?}\ncold {sc:?}");
}

#[test]
fn bad_tick_settings_are_typed_errors() {
    let mut p = params(true);
    p.warm_dv = -1.0;
    assert_eq!(
        TickController::new(p).unwrap_err().to_string(),
        "warm_dv [m/s] = -1 is out of range: allowed finite and > 0"
    );
    let mut p = params(true);
    p.verify_points = 0;
    assert_eq!(
        TickController::new(p).unwrap_err().to_string(),
        "verify_points = 0 is out of range: allowed 1 ..= 64"
    );
}

#[test]
fn without_a_previous_trap_a_clipped_target_is_solved_from_the_fold_points() {
    // After a drag, the hand lets go and grabs again (no previous trap):
    // the clipped command is solved by Newton from the nearest fold points,
    // with no grid solve, and the tick map reaches it.
    let prop = scene_tick();
    let mut c = TickController::new(params(true)).unwrap();
    let mut last = ParticleState {
        position: V2::zeros(),
        velocity: V2::zeros(),
    };
    drag(&prop, &mut c, 300, 2e-6, 2e-9, |_, o, _, s| {
        let (d, v, _) = prop.flow(&(o.trap - s.position), &s.velocity).unwrap();
        last = ParticleState {
            position: s.position + d,
            velocity: v * 0.1,
        };
    });
    let before = c.stats();
    c.reset();
    let far = last.position + V2::new(0.0, 3e-6);
    let out = c.step(&prop, &last, &far).unwrap();
    let after = c.stats();
    assert_eq!(
        out.choice,
        ot_envelope::inverse::Choice::FoldSeeded,
        "{after:?}"
    );
    assert!(!out.rebuilt && after.full_solves == before.full_solves);
    assert!(out.excess.norm() > 1e-6, "the command was clipped");
    let (d, _, _) = prop
        .flow(&(out.trap - last.position), &last.velocity)
        .unwrap();
    assert!((d - out.allowed).norm() < 1e-11);
}

#[test]
fn a_velocity_jump_fails_the_fold_check_and_rebuilds() {
    // With the velocity threshold out of the way, only the fold check guards
    // the translation: changes of 10 and 30 nm/µs pass it and the translated
    // envelope is within 0.1 nm of converged dynamics; jumps of 100 and
    // 300 nm/µs fail it and rebuild.
    let prop = scene_tick();
    let truth = converged(*prop.model(), prop.dt()).unwrap();
    let mut p = params(true);
    p.warm_dv = 10.0;
    let at = |v: V2| ParticleState {
        position: V2::zeros(),
        velocity: v,
    };
    let cursor = V2::new(10e-9, 0.0);
    for (dv, warm) in [(0.01, true), (0.03, true), (0.1, false), (0.3, false)] {
        let mut c = TickController::new(p).unwrap();
        assert!(c.step(&prop, &at(V2::zeros()), &cursor).unwrap().rebuilt);
        let out = c.step(&prop, &at(V2::new(0.0, dv)), &cursor).unwrap();
        let st = c.stats();
        assert_eq!(out.rebuilt, !warm, "dv {dv}: {st:?}");
        assert_eq!(st.verify_failures, u64::from(!warm));
        let reference = working_envelope_with(
            &truth,
            &V2::new(0.0, dv),
            &EnvelopeOptions {
                tol: 0.02e-9,
                coarse_grid: false,
                ..Default::default()
            },
        )
        .unwrap();
        let h = hausdorff(c.envelope(), &reference.polygon, 0.05e-9);
        eprintln!("dv {dv} m/s: {:.4} nm", h * 1e9);
        assert!(h <= 0.1e-9, "dv {dv}: {h:e} m");
    }
}
