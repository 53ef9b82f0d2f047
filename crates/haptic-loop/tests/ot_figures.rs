//! The optical-tweezers tick's figures in `docs/ot-envelope.md` ("Measured") and BENCHMARKS.md
//! ("Work per tick", "Accuracy reached"), held: a batch session of each scene on its default
//! script (6 s, as `examples/ot_tick.rs` runs it), the world's steering replayed from the
//! recorded particle states (bit for bit against the recorded trap), its `TickStats` exactly,
//! and the served envelope's Hausdorff distance from converged dynamics at the ticks served
//! while a spread build was under way (every one of them) and at every `every`-th grabbed tick.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

use haptic_loop::scene::SceneFile;
use haptic_loop::scene::optical::OtParams;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use nalgebra::Vector2;
use ot_envelope::geometry::hausdorff;
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickParams, TickStats};
use ot_envelope::{EnvelopeOptions, OffsetRegion, working_envelope_with};
use ot_physics::TrapModel;
use ot_physics::budget::{choose_tick_map, converged};
use std::path::Path;

type V2 = Vector2<f64>;

/// What one scene's session gave.
struct Figures {
    stats: TickStats,
    grabbed: u64,
    /// Ticks whose envelope was checked, and of which served during a spread build.
    checked: u64,
    checked_spread: u64,
    /// Worst Hausdorff distance (nm) of the served envelope over the checked ticks.
    worst_nm: f64,
    /// Worst Hausdorff distance (nm) of a whole build at the same ticks.
    worst_cold_nm: f64,
    /// Ticks whose replayed trap differs from the recorded one.
    mismatches: u64,
    /// The most force evaluations one slice spent in a grabbed tick.
    max_slice: u64,
}

fn figures(scene: &str, every: u64) -> Figures {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("scenes").join(scene)).unwrap();
    let mut src = SceneSource::from_text(&text, scene);
    src.dir = Some(root.join("scenes"));
    let mut o = SessionOptions::new(src);
    o.seconds = Some(6.0);
    let r = run_session(&o, &mut |_, _| {}).unwrap();

    let p: OtParams = SceneFile::parse(&text).unwrap().world().unwrap().unwrap();
    assert!(p.warm_start && p.spread_build && p.rk4_substeps.is_none());
    let model = TrapModel::builder(
        p.depth_nj * 1e-9,
        [p.waist_x_nm * 1e-9, p.waist_y_nm * 1e-9],
    )
    .mass(p.mass_g * 1e-3)
    .build()
    .unwrap();
    let dt = p.dt_us * 1e-6;
    let prop = choose_tick_map(model, dt, p.tick_map_tol_nm.unwrap_or(0.01) * 1e-9, 0.1)
        .unwrap()
        .0;
    let truth = converged(model, dt).unwrap();
    let tol = p
        .envelope_tol_nm
        .map_or(ot_envelope::DEFAULT_TOL, |t| t * 1e-9);
    let g = ot_envelope::grid::choose_grid(&prop, tol, 0.1).unwrap();
    let margin = p.envelope_margin_waists.unwrap_or(g.margin_waists);
    let cell = p.envelope_cell_waists.unwrap_or(g.cell_waists);
    let mut tp = TickParams::new(SteerParams {
        stiffness: p.stiffness_n_per_m,
        mode: p.clip,
        tol,
        margin_waists: margin,
    });
    tp.cell_waists = Some(cell);
    tp.build_evals_per_tick = Some(
        p.envelope_build_evals_per_tick
            .unwrap_or(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK),
    );
    let mut c = TickController::new(tp).unwrap();
    c.prebuild(&prop, &V2::zeros()).unwrap();

    let a = &r.arrays;
    let col = |n: &str| a.state_column(n).unwrap();
    let (px, py, vx, vy) = (
        col("particle_x_m"),
        col("particle_y_m"),
        col("particle_vx_m_per_s"),
        col("particle_vy_m_per_s"),
    );
    let (tx, ty, gr) = (col("trap_x_m"), col("trap_y_m"), col("grabbed"));
    let start = V2::new(p.start_um[0] * 1e-6, p.start_um[1] * 1e-6);
    let mut f = Figures {
        stats: TickStats::default(),
        grabbed: 0,
        checked: 0,
        checked_spread: 0,
        worst_nm: 0.0,
        worst_cold_nm: 0.0,
        mismatches: 0,
        max_slice: 0,
    };
    for i in 0..a.tick.len() {
        let v_before = if i == 0 {
            V2::zeros()
        } else {
            V2::new(vx[i - 1], vy[i - 1])
        };
        if gr[i] != 1.0 {
            c.prepare(&prop, &v_before).unwrap();
            continue;
        }
        if i == 0 || gr[i - 1] != 1.0 {
            let trap = if i == 0 {
                start
            } else {
                V2::new(tx[i - 1], ty[i - 1])
            };
            c.continue_from(&trap);
        }
        let s = if i == 0 {
            ParticleState {
                position: start,
                velocity: V2::zeros(),
            }
        } else {
            ParticleState {
                position: V2::new(px[i - 1], py[i - 1]),
                velocity: V2::new(vx[i - 1], vy[i - 1]),
            }
        };
        let cur = a.cursor_m[i];
        let out = c.step(&prop, &s, &V2::new(cur[0], cur[1])).unwrap();
        if out.trap.x.to_bits() != tx[i].to_bits() || out.trap.y.to_bits() != ty[i].to_bits() {
            f.mismatches += 1;
        }
        f.grabbed += 1;
        f.max_slice = f.max_slice.max(out.slice_evals);
        let spreading = c.building() || out.slice_evals > 0;
        if f.grabbed % every == 0 || spreading {
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
            let cold = working_envelope_with(
                &prop,
                &s.velocity,
                &EnvelopeOptions {
                    tol,
                    cell_waists: Some(cell),
                    region: Some(OffsetRegion::around_drift(&prop, &s.velocity, margin).unwrap()),
                    ..Default::default()
                },
            )
            .unwrap();
            let h = hausdorff(c.envelope(), &reference.polygon, 0.05e-9) * 1e9;
            let hc = hausdorff(&cold.polygon, &reference.polygon, 0.05e-9) * 1e9;
            f.worst_nm = f.worst_nm.max(h);
            f.worst_cold_nm = f.worst_cold_nm.max(hc);
            f.checked += 1;
            f.checked_spread += u64::from(spreading);
        }
    }
    f.stats = c.stats();
    eprintln!(
        "{scene}: {} grabbed, {} checked ({} during a spread build), worst {:.4} nm \
         (a whole build {:.4} nm), max slice {}, {:?}",
        f.grabbed, f.checked, f.checked_spread, f.worst_nm, f.worst_cold_nm, f.max_slice, f.stats
    );
    f
}

/// `x` rounds to `printed` at `decimals` decimals (two-sided).
fn assert_printed(what: &str, x: f64, printed: f64, decimals: i32) {
    let half = 0.5 * 10f64.powi(-decimals);
    assert!(
        (x - printed).abs() <= half + 1e-12,
        "{what}: {x} does not print as {printed:.*}",
        decimals as usize
    );
}

/// The counters every session of both scenes shares: no whole build, no dropped build, no
/// failed fold check, no grid solve, every grabbed tick a continued Newton step (the first one
/// included), the largest slice 256 + one work item.
fn expected(ticks: u64, spread_builds: u64, build_slices: u64) -> TickStats {
    TickStats {
        ticks,
        // the prebuild (particle at rest, before the grab) and the spread builds
        rebuilds: 1 + spread_builds,
        spread_builds,
        build_slices,
        max_slice_evals: 280,
        dropped_builds: 0,
        verify_failures: 0,
        continued: ticks,
        fold_seeded: 0,
        full_solves: 0,
        parked: 0,
    }
}

/// docs/ot-envelope.md "Measured"; BENCHMARKS.md "Work per tick" and "Accuracy reached",
/// 1 kHz row: 5,000 grabbed ticks, 14 spread builds in 126 slices, the largest 280
/// evaluations; every 10th grabbed tick and all 126 served during a spread build checked (612):
/// served envelope 0.062 nm, a whole build at the same ticks 0.060 nm.
#[test]
fn scene_1khz_default_script() {
    let f = figures("optical_tweezers.toml", 10);
    assert_eq!(f.mismatches, 0);
    assert_eq!(f.stats, expected(5000, 14, 126));
    assert_eq!(f.max_slice, 280);
    assert_eq!((f.grabbed, f.checked, f.checked_spread), (5000, 612, 126));
    assert_printed("served envelope (nm)", f.worst_nm, 0.062, 3);
    assert_printed("whole build (nm)", f.worst_cold_nm, 0.060, 3);
}

/// BENCHMARKS.md "Work per tick" and "Accuracy reached", 10 kHz row: 50,000 grabbed ticks,
/// 7 spread builds in 63 slices, the largest 280 evaluations; every 50th grabbed tick and all 63
/// served during a spread build checked (1,062): served envelope 0.061 nm, a whole build at the
/// same ticks 0.060 nm.
#[test]
fn scene_10khz_default_script() {
    let f = figures("optical_tweezers_10khz.toml", 50);
    assert_eq!(f.mismatches, 0);
    assert_eq!(f.stats, expected(50_000, 7, 63));
    assert_eq!(f.max_slice, 280);
    assert_eq!((f.grabbed, f.checked, f.checked_spread), (50_000, 1062, 63));
    assert_printed("served envelope (nm)", f.worst_nm, 0.061, 3);
    assert_printed("whole build (nm)", f.worst_cold_nm, 0.060, 3);
}
