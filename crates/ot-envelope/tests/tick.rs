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

/// docs/ot-envelope.md, "Spread rebuilds": the defaults the text names, 5 nm/µs for
/// `spread_dv`, 256 for `build_evals_per_tick`, 30 nm/µs for `warm_dv`.
#[test]
fn the_documented_defaults() {
    let p = params(true);
    assert_eq!(p.spread_dv, 5e-3); // 5 nm/µs
    assert_eq!(p.build_evals_per_tick, Some(256));
    assert_eq!(p.warm_dv, 30e-3); // 30 nm/µs
    assert_eq!(ot_envelope::tick::DEFAULT_SPREAD_DV, 5e-3);
    assert_eq!(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK, 256);
    assert_eq!(ot_envelope::tick::DEFAULT_WARM_DV, 30e-3);
}

/// docs/ot-envelope.md, "Spread rebuilds", the guarantee: how far the translated envelope is
/// from converged dynamics at the scene's tick and grid (`scenes/optical_tweezers.toml`: the
/// budget map at Δt = 0.2 µs, the grid `choose_grid` sizes for the default tolerance). A
/// build for a base velocity (0, or 20 nm/µs along x) is put in service by `prebuild`, and
/// the next tick, for the base plus a change of 10, 30 or 40 nm/µs along x, y or the
/// diagonal, serves it translated (`warm_dv` raised past 40 nm/µs so the tick translates
/// rather than rebuilds; the fold check passes in every case). Hausdorff distance from a
/// converged-dynamics envelope (DOP853 rtol 1e-12 map, tolerance 0.02 nm, 4.5-waist region,
/// as `ot_tick` checks), as ranges over the six cases; and the builds themselves at the bases.
/// (The doc's earlier figures, 0.058–0.066, 0.059–0.076 and 0.075–0.084 nm, came from an
/// unrecorded choice of directions; the upper ends agree with these to 0.001 nm.)
#[test]
fn translation_error_at_the_scene_tick_and_grid() {
    let prop = scene_tick();
    let truth = converged(*prop.model(), prop.dt()).unwrap();
    let tol = ot_envelope::DEFAULT_TOL;
    let g = ot_envelope::grid::choose_grid(&prop, tol, 0.1).unwrap();
    let mut p = TickParams::new(SteerParams {
        stiffness: 0.8,
        mode: ClipMode::Radial,
        tol,
        margin_waists: g.margin_waists,
    });
    p.cell_waists = Some(g.cell_waists);
    p.build_evals_per_tick = None;
    p.warm_dv = 0.05;
    let reference = |v: &V2| {
        let r = working_envelope_with(
            &truth,
            v,
            &EnvelopeOptions {
                tol: 0.02e-9,
                coarse_grid: false,
                region: Some(ot_envelope::OffsetRegion::around_drift(&truth, v, 4.5).unwrap()),
                ..Default::default()
            },
        )
        .unwrap();
        r.polygon
    };
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let dirs = [V2::new(1.0, 0.0), V2::new(0.0, 1.0), V2::new(r, r)];
    let bases = [V2::zeros(), V2::new(0.02, 0.0)];
    let mut built = (f64::INFINITY, 0.0f64);
    let mut ranges = [(f64::INFINITY, 0.0f64); 3];
    for base in bases {
        let mut c = TickController::new(p).unwrap();
        c.prebuild(&prop, &base).unwrap();
        let h = hausdorff(c.envelope(), &reference(&base), 0.05e-9) * 1e9;
        built = (built.0.min(h), built.1.max(h));
        for d in dirs {
            for (k, dv) in [0.01, 0.03, 0.04].into_iter().enumerate() {
                let mut c = TickController::new(p).unwrap();
                c.prebuild(&prop, &base).unwrap();
                let v = base + d * dv;
                let s = ParticleState {
                    position: V2::zeros(),
                    velocity: v,
                };
                // the command: where the particle goes with the trap left on it (Newton
                // continued from there), so the tick solves without a build or a grid solve
                c.continue_from(&V2::zeros());
                let cursor = prop.flow(&V2::zeros(), &v).unwrap().0;
                let out = c.step(&prop, &s, &cursor).unwrap();
                let st = c.stats();
                assert!(
                    !out.rebuilt && st.rebuilds == 1 && st.verify_failures == 0,
                    "base {base:?} dir {d:?} dv {dv}: {st:?}"
                );
                let h = hausdorff(c.envelope(), &reference(&v), 0.05e-9) * 1e9;
                eprintln!("base {base:?} dir {d:?} dv {dv}: {h:.4} nm");
                ranges[k] = (ranges[k].0.min(h), ranges[k].1.max(h));
            }
        }
    }
    eprintln!("builds {built:?}; translated {ranges:?}");
    // the builds themselves: 0.035 nm (base 0) and 0.058 nm (base 20 nm/µs)
    assert_printed("build, least", built.0, 0.035, 3);
    assert_printed("build, most", built.1, 0.058, 3);
    // 0.038–0.065 nm at 10 nm/µs, 0.047–0.076 nm at 30, 0.052–0.083 nm at 40
    for ((lo, hi), (want_lo, want_hi)) in
        ranges
            .into_iter()
            .zip([(0.038, 0.065), (0.047, 0.076), (0.052, 0.083)])
    {
        assert_printed("translated, least", lo, want_lo, 3);
        assert_printed("translated, most", hi, want_hi, 3);
    }
}

/// docs/ot-envelope.md: "at the scene's Δt = 0.2 µs and 0.01 nm the cheapest map is RK4 × 2 (8
/// force evaluations per flow, against 32 for the old RK4 × 8)".
#[test]
fn the_scene_tick_map_and_its_evaluations() {
    let prop = scene_tick();
    assert_eq!(prop.method(), ot_physics::Method::Rk4 { substeps: 2 });
    let per_flow = |p: &Propagator<2>| p.flow(&V2::new(100e-9, 50e-9), &V2::zeros()).unwrap().2;
    assert_eq!(per_flow(&prop), 8);
    let old = Propagator::new(
        *prop.model(),
        ot_physics::Method::Rk4 { substeps: 8 },
        prop.dt(),
    )
    .unwrap();
    assert_eq!(per_flow(&old), 32);
}
