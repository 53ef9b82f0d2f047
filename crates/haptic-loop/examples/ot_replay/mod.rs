//! The optical-tweezers world's steering replayed from a session's recorded particle states,
//! shared by `ot_tick.rs` (its Hausdorff check) and the test that holds its figures
//! (`tests/ot_figures.rs`): the envelope built at load, kept fresh between grabs (not with the
//! old settings, `warm_start = false`), spread rebuilds, the replayed trap checked bit for bit
//! against the recorded one, and the served envelope's Hausdorff distance from converged
//! dynamics at every `every`-th grabbed tick and at every tick served while a spread build is
//! under way.
#![allow(dead_code)]

use haptic_loop::scene::SceneFile;
use haptic_loop::scene::optical::OtParams;
use haptic_loop::session::SessionReport;
use nalgebra::Vector2;
use ot_envelope::geometry::hausdorff;
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickParams, TickStats};
use ot_envelope::{EnvelopeOptions, OffsetRegion, working_envelope_with};
use ot_physics::budget::{choose_tick_map, converged};
use ot_physics::{Propagator, TrapModel};

type BoxError = Box<dyn std::error::Error>;
type V2 = Vector2<f64>;

/// What a replayed session gave.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// The replaying controller's counters at the end.
    pub stats: TickStats,
    /// Grabbed ticks.
    pub grabbed: u64,
    /// Ticks whose envelope was checked, and of which served during a spread build.
    pub checked: u64,
    pub checked_spread: u64,
    /// Worst Hausdorff distance (nm) of the served envelope over the checked ticks.
    pub worst_nm: f64,
    /// Worst Hausdorff distance (nm) of a whole build at the same ticks.
    pub worst_cold_nm: f64,
    /// Worst Hausdorff distance (nm) of the served envelope over the ticks served during a
    /// spread build.
    pub worst_spread_nm: f64,
    /// Ticks whose replayed trap differs from the recorded one.
    pub mismatches: u64,
    /// The most force evaluations one slice spent in a grabbed tick.
    pub max_slice: u64,
}

/// The scene's world as the replay needs it: its tick map, converged dynamics, tolerance,
/// region and grid, and a controller set up as the world's (the first envelope prebuilt).
struct World {
    prop: Propagator<2>,
    truth: Propagator<2>,
    tol: f64,
    margin: f64,
    cell: f64,
    /// Old settings (`warm_start = false`): no envelope kept fresh between grabs.
    old: bool,
    start: V2,
    c: TickController,
}

fn world(text: &str) -> Result<World, BoxError> {
    let file = SceneFile::parse(text)?;
    let p: OtParams = file.world()?.ok_or("not an optical scene")?;
    let old = !p.warm_start;
    let model = TrapModel::builder(
        p.depth_nj * 1e-9,
        [p.waist_x_nm * 1e-9, p.waist_y_nm * 1e-9],
    )
    .mass(p.mass_g * 1e-3)
    .build()?;
    let dt = p.dt_us * 1e-6;
    let prop = match p.rk4_substeps {
        Some(n) => Propagator::new(model, ot_physics::Method::Rk4 { substeps: n }, dt)?,
        None => choose_tick_map(model, dt, p.tick_map_tol_nm.unwrap_or(0.01) * 1e-9, 0.1)?.0,
    };
    let truth = converged(model, dt)?;
    let tol = p
        .envelope_tol_nm
        .map_or(ot_envelope::DEFAULT_TOL, |t| t * 1e-9);
    // the scene's region and grid: fixed by hand, or chosen from the tolerance
    let (margin, cell) = match (p.envelope_margin_waists, p.envelope_cell_waists) {
        (Some(m), Some(c)) => (m, c),
        (m, c) => {
            let g = ot_envelope::grid::choose_grid(&prop, tol, 0.1)?;
            (m.unwrap_or(g.margin_waists), c.unwrap_or(g.cell_waists))
        }
    };
    let mut tp = TickParams::new(SteerParams {
        stiffness: p.stiffness_n_per_m,
        mode: p.clip,
        tol,
        margin_waists: margin,
    });
    tp.warm_start = !old;
    tp.cell_waists = Some(cell);
    tp.build_evals_per_tick = match (p.spread_build, p.envelope_build_evals_per_tick) {
        (false, _) => None,
        (true, b) => Some(b.unwrap_or(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK)),
    };
    let mut c = TickController::new(tp)?;
    // as the world: the first envelope for the particle at rest, before the first grab
    c.prebuild(&prop, &V2::zeros())?;
    Ok(World {
        prop,
        truth,
        tol,
        margin,
        cell,
        old,
        start: V2::new(p.start_um[0] * 1e-6, p.start_um[1] * 1e-6),
        c,
    })
}

/// Replays the steering of the session `r` of the scene `text` from its recorded states and
/// measures the envelope's Hausdorff distance from converged dynamics every `every` grabbed
/// ticks (and at every tick served during a spread build).
pub fn replay(text: &str, r: &SessionReport, every: u64) -> Result<Replay, BoxError> {
    let mut w = world(text)?;
    let a = &r.arrays;
    let col = |n: &str| a.state_column(n).ok_or(format!("no column {n}"));
    let (px, py, vx, vy) = (
        col("particle_x_m")?,
        col("particle_y_m")?,
        col("particle_vx_m_per_s")?,
        col("particle_vy_m_per_s")?,
    );
    let (tx, ty, g) = (col("trap_x_m")?, col("trap_y_m")?, col("grabbed")?);
    let mut f = Replay {
        stats: TickStats::default(),
        grabbed: 0,
        checked: 0,
        checked_spread: 0,
        worst_nm: 0.0,
        worst_cold_nm: 0.0,
        worst_spread_nm: 0.0,
        mismatches: 0,
        max_slice: 0,
    };
    for i in 0..a.tick.len() {
        let v_before = if i == 0 {
            V2::zeros()
        } else {
            V2::new(vx[i - 1], vy[i - 1])
        };
        if g[i] != 1.0 {
            // as the world between grabs: keep the envelope fresh
            if !w.old {
                w.c.prepare(&w.prop, &v_before)?;
            }
            continue;
        }
        if i == 0 || g[i - 1] != 1.0 {
            // as the world on grab: continue from the trap the particle sits in
            let trap = if i == 0 {
                w.start
            } else {
                V2::new(tx[i - 1], ty[i - 1])
            };
            w.c.continue_from(&trap);
        }
        let s = if i == 0 {
            ParticleState {
                position: w.start,
                velocity: V2::zeros(),
            }
        } else {
            ParticleState {
                position: V2::new(px[i - 1], py[i - 1]),
                velocity: V2::new(vx[i - 1], vy[i - 1]),
            }
        };
        let cur = a.cursor_m[i];
        let out = w.c.step(&w.prop, &s, &V2::new(cur[0], cur[1]))?;
        if out.trap.x.to_bits() != tx[i].to_bits() || out.trap.y.to_bits() != ty[i].to_bits() {
            f.mismatches += 1;
        }
        f.grabbed += 1;
        f.max_slice = f.max_slice.max(out.slice_evals);
        // every tick served while a spread build is under way is checked
        let spreading = w.c.building() || out.slice_evals > 0;
        if f.grabbed % every == 0 || spreading {
            check(&w, &s.velocity, spreading, &mut f)?;
        }
    }
    f.stats = w.c.stats();
    Ok(f)
}

/// The served envelope and a whole build at drift `v` against converged dynamics, into `f`.
fn check(w: &World, v: &V2, spreading: bool, f: &mut Replay) -> Result<(), BoxError> {
    // converged dynamics over a wider region than the scene's
    let reference = working_envelope_with(
        &w.truth,
        v,
        &EnvelopeOptions {
            tol: 0.02e-9,
            coarse_grid: false,
            region: Some(OffsetRegion::around_drift(&w.truth, v, 4.5)?),
            ..Default::default()
        },
    )?;
    let cold = working_envelope_with(
        &w.prop,
        v,
        &EnvelopeOptions {
            tol: w.tol,
            cell_waists: Some(w.cell),
            region: Some(OffsetRegion::around_drift(&w.prop, v, w.margin)?),
            ..Default::default()
        },
    )?;
    let h = hausdorff(w.c.envelope(), &reference.polygon, 0.05e-9) * 1e9;
    let hc = hausdorff(&cold.polygon, &reference.polygon, 0.05e-9) * 1e9;
    f.worst_nm = f.worst_nm.max(h);
    f.worst_cold_nm = f.worst_cold_nm.max(hc);
    f.checked += 1;
    if spreading {
        f.worst_spread_nm = f.worst_spread_nm.max(h);
        f.checked_spread += 1;
    }
    Ok(())
}
