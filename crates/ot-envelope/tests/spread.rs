//! The spread envelope build: finished, it is the one-shot build bit for
//! bit; each slice spends at most its budget plus one work item; while it
//! runs, the controller serves the last envelope translated, within 0.1 nm
//! of converged dynamics; and a session with spread builds replays bit for
//! bit.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::Vector2;
use ot_envelope::geometry::hausdorff;
use ot_envelope::spread::{EnvelopeBuild, max_item_evals};
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickParams};
use ot_envelope::world::{Input, Params, World};
use ot_envelope::{ClipMode, EnvelopeOptions, OffsetRegion, working_envelope_with};
use ot_physics::Propagator;
use ot_physics::budget::{choose_tick_map, converged};
use world_form::Limits;

type V2 = Vector2<f64>;

/// The scene's tick map (RK4×2 at 0.2 µs, chosen by the 0.01 nm budget)
/// and its budget grid (3.75 waists, 0.6 waist per cell).
fn scene_tick() -> Propagator<2> {
    choose_tick_map(paper_model([600e-9, 300e-9]), 0.2e-6, 1e-11, 0.1)
        .unwrap()
        .0
}
const MARGIN: f64 = 3.75;
const CELL: f64 = 0.6;
const TOL: f64 = 0.5e-9;

fn bits(p: &[V2]) -> Vec<(u64, u64)> {
    p.iter().map(|v| (v.x.to_bits(), v.y.to_bits())).collect()
}

#[test]
fn a_spread_build_finished_is_the_one_shot_build_bit_for_bit() {
    let prop = scene_tick();
    for v0 in [v(0.0, 0.0), v(0.025, 0.0), v(-0.01, 0.04), v(0.07, -0.05)] {
        let mut one = EnvelopeBuild::new(&prop, &v0, MARGIN, Some(CELL), TOL).unwrap();
        let r = one.advance(&prop, None).unwrap();
        assert!(r.done && r.geometry);
        let one = one.take().unwrap();
        // the public one-shot path over the same region and grid
        let public = working_envelope_with(
            &prop,
            &v0,
            &EnvelopeOptions {
                tol: TOL,
                cell_waists: Some(CELL),
                region: Some(OffsetRegion::around_drift(&prop, &v0, MARGIN).unwrap()),
                coarse_grid: true,
            },
        )
        .unwrap();
        assert_eq!(bits(&one.envelope.polygon), bits(&public.polygon));
        assert_eq!(one.envelope.evals, public.evals);
        for budget in [1, 7, 64, 256, 5000] {
            let mut b = EnvelopeBuild::new(&prop, &v0, MARGIN, Some(CELL), TOL).unwrap();
            let mut slices = 1;
            while !b.advance(&prop, Some(budget)).unwrap().done {
                slices += 1;
            }
            let s = b.take().unwrap();
            assert_eq!(bits(&s.envelope.polygon), bits(&one.envelope.polygon));
            assert_eq!(bits(&s.map.disp), bits(&one.map.disp));
            let jb = |m: &ot_envelope::SampledMap| -> Vec<u64> {
                m.jac
                    .iter()
                    .flat_map(|j| j.iter().map(|x| x.to_bits()))
                    .collect()
            };
            assert_eq!(jb(&s.map), jb(&one.map));
            let fo: Vec<V2> = s.folds.iter().flat_map(|f| [f.0, f.1]).collect();
            let fone: Vec<V2> = one.folds.iter().flat_map(|f| [f.0, f.1]).collect();
            assert_eq!(bits(&fo), bits(&fone));
            assert_eq!(s.envelope.evals, one.envelope.evals);
            assert_eq!(s.envelope.fold_curves, one.envelope.fold_curves);
            // small budgets really spread the work; the geometry always has a slice of its own
            if budget <= 256 {
                assert!(
                    slices as u64 > one.envelope.evals / (budget + 40),
                    "{slices}"
                );
            } else {
                assert_eq!(slices, 2, "budget {budget}");
            }
        }
    }
}

#[test]
fn every_slice_spends_at_most_its_budget_plus_one_work_item() {
    let prop = scene_tick();
    let per_flow = prop
        .flow_offset_jacobian(&v(0.0, 0.0), &v(0.0, 0.0))
        .unwrap()
        .evals;
    assert_eq!(per_flow, 8, "RK4×2: 4 stages × 2 substeps");
    for budget in [1, 50, 256] {
        for v0 in [v(0.0, 0.0), v(0.03, 0.01)] {
            let mut b = EnvelopeBuild::new(&prop, &v0, MARGIN, Some(CELL), TOL).unwrap();
            let (mut total, mut geometry, mut largest) = (0, 0, 0);
            loop {
                let r = b.advance(&prop, Some(budget)).unwrap();
                assert!(
                    r.evals < budget + max_item_evals(per_flow),
                    "budget {budget}: slice of {} evaluations",
                    r.evals
                );
                if r.geometry {
                    assert_eq!(r.evals, 0, "the geometry stage runs alone");
                    geometry += 1;
                }
                total += r.evals;
                largest = largest.max(r.evals);
                if r.done {
                    break;
                }
            }
            assert_eq!(geometry, 1);
            assert!(largest >= budget.min(per_flow));
            let built = b.take().unwrap();
            // every evaluation of the build is counted in some slice
            assert_eq!(total, built.envelope.evals);
            assert!(b.take().is_none(), "taken once");
        }
    }
    let mut b = EnvelopeBuild::new(&prop, &v(0.0, 0.0), MARGIN, Some(CELL), TOL).unwrap();
    assert_eq!(
        b.advance(&prop, Some(0)).unwrap_err().to_string(),
        "budget [force evaluations] = 0 is out of range: allowed ≥ 1"
    );
}

fn params(budget: Option<u64>) -> TickParams {
    let mut p = TickParams::new(SteerParams {
        stiffness: 0.8,
        mode: ClipMode::Radial,
        tol: TOL,
        margin_waists: MARGIN,
    });
    p.cell_waists = Some(CELL);
    p.build_evals_per_tick = budget;
    p
}

/// A session of `ticks` ticks: the particle at rest is grabbed, then
/// dragged right at 40 nm per tick (the command clipped, the velocity
/// jumps to ~25 nm/µs), then the cursor stops. Returns (trap bits, slice
/// evaluations, rebuilt) per tick and calls `each` with every tick.
fn fast_drag(
    prop: &Propagator<2>,
    c: &mut TickController,
    ticks: usize,
    mut each: impl FnMut(&TickController, &ParticleState),
) -> Vec<((u64, u64), u64, bool)> {
    let mut s = ParticleState {
        position: V2::zeros(),
        velocity: V2::zeros(),
    };
    c.prebuild(prop, &V2::zeros()).unwrap();
    c.continue_from(&V2::zeros());
    let mut out = Vec::new();
    for k in 0..ticks {
        let cursor = V2::new(40e-9 * (k.min(ticks / 2)) as f64, 0.0);
        let o = c.step(prop, &s, &cursor).unwrap();
        each(c, &s);
        out.push((
            (o.trap.x.to_bits(), o.trap.y.to_bits()),
            o.slice_evals,
            o.rebuilt,
        ));
        let (d, vel, _) = prop.flow(&(o.trap - s.position), &s.velocity).unwrap();
        s.position += d;
        s.velocity = vel * 0.1;
    }
    out
}

#[test]
fn the_envelope_served_during_a_spread_rebuild_stays_within_a_tenth_of_a_nanometre() {
    let prop = scene_tick();
    let truth = converged(*prop.model(), prop.dt()).unwrap();
    let mut c = TickController::new(params(Some(256))).unwrap();
    let (mut worst, mut checked) = (0.0f64, 0);
    let ticks = fast_drag(&prop, &mut c, 80, |c, s| {
        if c.building() {
            let reference = working_envelope_with(
                &truth,
                &s.velocity,
                &EnvelopeOptions {
                    tol: 0.02e-9,
                    coarse_grid: false,
                    region: Some(OffsetRegion::around_drift(&truth, &s.velocity, 4.5).unwrap()),
                    ..Default::default()
                },
            )
            .unwrap();
            worst = worst.max(hausdorff(c.envelope(), &reference.polygon, 0.05e-9));
            checked += 1;
        }
    });
    let st = c.stats();
    eprintln!(
        "worst {:.4} nm over {checked} ticks served during spread builds; {st:?}",
        worst * 1e9
    );
    // the velocity jump and the stop each start a spread build, served meanwhile
    assert!(st.spread_builds >= 2, "{st:?}");
    assert!(checked >= 10, "{checked}");
    assert!(worst <= 0.1e-9, "{:e} m", worst);
    // docs/ot-envelope.md: "a fast drag (velocity jump to 25 nm/µs, then a stop) served by 3
    // spread builds with no whole build, every tick served during a spread build within 0.1 nm
    // (Hausdorff) of converged dynamics (worst 0.059 nm)" (measured 0.0592 nm over 27 ticks)
    assert_eq!((st.spread_builds, checked), (3, 27), "{st:?}");
    assert!((0.0585e-9..0.0595e-9).contains(&worst), "{:e} m", worst);
    // no tick built a whole envelope: the prebuild is the only one
    assert!(ticks.iter().all(|t| !t.2));
    assert_eq!(st.rebuilds, 1 + st.spread_builds);
    assert_eq!((st.dropped_builds, st.full_solves), (0, 0));
    let per_flow = 8;
    assert!(
        st.max_slice_evals < 256 + max_item_evals(per_flow),
        "{st:?}"
    );
    assert!(ticks.iter().all(|t| t.1 < 256 + max_item_evals(per_flow)));
}

#[test]
fn a_session_with_spread_builds_replays_bit_for_bit() {
    let prop = scene_tick();
    let run = |budget| {
        let mut c = TickController::new(params(budget)).unwrap();
        let t = fast_drag(&prop, &mut c, 120, |_, _| {});
        (t, c.stats())
    };
    let (a, sa) = run(Some(256));
    let (b, sb) = run(Some(256));
    assert_eq!(a, b);
    assert_eq!(sa, sb);
    // without spread builds the velocity jump (~25 nm/µs, below the 30 nm/µs
    // of `warm_dv`) is served by the prebuild translated all along: fewer
    // builds, other envelopes, so other clipped targets
    let (w, sw) = run(None);
    assert_eq!((sw.rebuilds, sw.spread_builds, sw.build_slices), (1, 0, 0));
    assert!(w.iter().all(|t| !t.2 && t.1 == 0));
    assert!(sa.spread_builds >= 2);
    assert_ne!(a, w);
}

#[test]
fn the_world_builds_the_first_envelope_before_the_grab() {
    let limits = Limits::FALCON.in_world(1e6, 1e-3);
    let mut w = World::new(&Params::paper(), &limits).unwrap();
    // built at load, for the particle at rest
    assert_eq!(w.tick_stats().rebuilds, 1);
    let at = |x: f64, grab: bool| Input {
        cursor_m: [x, 0.0],
        grab,
    };
    w.step(&at(0.0, false));
    w.step(&at(0.0, true));
    assert!(w.grabbed());
    let st = w.tick_stats();
    // the first grabbed step was warm: no build, no grid solve, continued
    // from the trap the particle sat in
    assert_eq!(
        (st.ticks, st.rebuilds, st.full_solves, st.continued),
        (1, 1, 0, 1)
    );
    assert!(!w.envelope().is_empty());
    // a bad budget names its field and range
    let bad = Params {
        envelope_build_evals_per_tick: Some(0),
        ..Params::paper()
    };
    assert_eq!(
        World::new(&bad, &limits).err().unwrap().to_string(),
        "`envelope_build_evals_per_tick` = 0 is out of range: allowed 1 ≤ \
         envelope_build_evals_per_tick ≤ 1e6"
    );
}

#[test]
fn bad_spread_settings_are_typed_errors() {
    let mut p = params(Some(0));
    assert_eq!(
        TickController::new(p).unwrap_err().to_string(),
        "build_evals_per_tick = 0 is out of range: allowed ≥ 1 (or none: no spread build)"
    );
    p = params(Some(256));
    p.spread_dv = 0.05;
    assert_eq!(
        TickController::new(p).unwrap_err().to_string(),
        "spread_dv [m/s] = 0.05 is out of range: allowed ≤ warm_dv"
    );
}
