//! The envelope's offset region and grid spacing sized from its error budget
//! (the polygon tolerance `tol`, m) and the tick `Δt`, chosen once per
//! (tick map, tolerance) and reported.
//!
//! * **Region margin** (waists beyond the drift path): an offset outside the
//!   region is at least `M` waists (on one axis) from the particle during the
//!   whole tick, where the Gaussian's force is at most
//!   `F(M) = 2 P0 √(k_max q) e^{−q}`, `q = ln2 M²`; such a trap moves the
//!   particle by at most `δ(M) = F(M) Δt²/(2m)` from its free drift
//!   (`F(M) Δt/γ` overdamped). Every displacement the region leaves out lies
//!   within `δ` of the free drift, which is within `δ` of the region edge's
//!   image, so the region costs at most `2δ` of Hausdorff distance. The
//!   margin is the smallest on a quarter-waist ladder (2 … 8 waists) with
//!   `2δ ≤ tol/4`.
//! * **Grid spacing** (waists per cell): measured, not estimated. For a spread
//!   of start velocities (0 and `v_max` along x, y and the diagonal) the
//!   envelope is built on each spacing of a ladder (1 … 0.1 waists) and
//!   compared with the envelope of the same map on a 0.05-waist grid at
//!   `tol/10`; the spacing chosen is the coarsest whose envelope, and that of
//!   the next finer spacing of the ladder, is within `tol/2` of it at every
//!   velocity (the finest when none is). The choice is remembered per
//!   (model, map, Δt, tol, v_max) in the process, so a scene built twice
//!   (replay, render) measures once.
//!
//! Together with the polygon's own tolerance these shares keep the envelope
//! within its budget of the tick map's true reachable set; the tick map's own
//! distance from converged dynamics is budgeted apart (`ot_physics::budget`).

use crate::envelope::{EnvelopeOptions, working_envelope_with};
use crate::error::{EnvelopeError, Result, ValueError, positive};
use crate::geometry::hausdorff;
use crate::region::OffsetRegion;
use nalgebra::Vector2;
use ot_physics::{Propagator, TrapModel};

type V2 = Vector2<f64>;

/// Spacings tried, coarsest first (waists per cell).
pub const CELL_LADDER: [f64; 10] = [1.0, 0.8, 0.6, 0.5, 0.4, 0.3, 0.25, 0.2, 0.15, 0.1];

/// Spacing of the reference grid the ladder is measured against (waists).
pub const REFERENCE_CELL_WAISTS: f64 = 0.05;

/// Smallest and largest region margins tried (waists).
const MARGIN_RANGE: (f64, f64) = (2.0, 8.0);

/// What [`choose_grid`] chose, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridChoice {
    /// Region half-width beyond the drift path (waists).
    pub margin_waists: f64,
    /// Bound on the Hausdorff distance the region's cut costs, `2δ` (m).
    pub region_bound_m: f64,
    /// Grid spacing (waists per cell).
    pub cell_waists: f64,
    /// Largest Hausdorff distance measured between the chosen grid's
    /// envelope and the reference grid's (m).
    pub grid_error_m: f64,
    /// The envelope tolerance the choice was made for (m).
    pub tol_m: f64,
    /// Grid vertices of a build at rest (the most of the velocities probed
    /// is within a few percent for the scene's speeds).
    pub vertices: usize,
    /// Start velocities probed.
    pub velocities: usize,
    /// Largest start speed probed (m/s).
    pub v_max: f64,
}

/// The choice in words, its numbers by [`fmt_num`](world_form::fmt_num) (measured ones to
/// three significant digits). Only printed: the scenes record the choice as a typed event (its
/// fields), not this text.
impl std::fmt::Display for GridChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let num = |x: f64| world_form::fmt_sig(x, 3);
        write!(
            f,
            "envelope grid: region {} waists beyond the drift path (cut ≤ {} m), cell {} \
             waists ({} m from a {} waist grid at {} speeds ≤ {} m/s; budget {} m of tol {} m), \
             {} vertices at rest",
            world_form::fmt_num(self.margin_waists),
            num(self.region_bound_m),
            world_form::fmt_num(self.cell_waists),
            num(self.grid_error_m),
            world_form::fmt_num(REFERENCE_CELL_WAISTS),
            self.velocities,
            num(self.v_max),
            num(self.tol_m / 2.0),
            num(self.tol_m),
            self.vertices
        )
    }
}

/// Largest distance (m) a trap farther than `margin` waists (on one axis)
/// from the particle's path can move it from its free drift over `dt` (s).
pub fn cut_bound(model: &TrapModel<2>, dt: f64, margin: f64) -> f64 {
    let kmax = std::f64::consts::LN_2 / model.length_scale().powi(2);
    let q = std::f64::consts::LN_2 * margin * margin;
    // √q e^{−q} falls for q ≥ 1/2; below, bound by its peak
    let q = q.max(0.5);
    let force = 2.0 * model.well.depth() * (kmax * q).sqrt() * (-q).exp();
    match (model.mass, model.drag) {
        (Some(m), _) => force * dt * dt / (2.0 * m),
        (None, Some(g)) => force * dt / g,
        (None, None) => 0.0,
    }
}

/// The region margin (waists) for tolerance `tol` (m) and its cut bound `2δ` (m).
pub fn region_margin(model: &TrapModel<2>, dt: f64, tol: f64) -> Result<(f64, f64)> {
    let tol = positive("tol [m]", tol)?;
    let mut m = MARGIN_RANGE.0;
    while m <= MARGIN_RANGE.1 {
        let b = 2.0 * cut_bound(model, dt, m);
        if b <= tol / 4.0 {
            return Ok((m, b));
        }
        m += 0.25;
    }
    Ok((MARGIN_RANGE.1, 2.0 * cut_bound(model, dt, MARGIN_RANGE.1)))
}

/// The start velocities probed: 0 and `v_max` along x, y and the diagonal.
fn velocities(v_max: f64) -> Vec<V2> {
    let s = std::f64::consts::FRAC_1_SQRT_2 * v_max;
    if v_max == 0.0 {
        return vec![V2::zeros()];
    }
    vec![
        V2::zeros(),
        V2::new(v_max, 0.0),
        V2::new(0.0, v_max),
        V2::new(s, s),
    ]
}

/// Envelope of `prop` at `v0` on `region` with `cell` waists, to `tol` (m).
fn build(
    prop: &Propagator<2>,
    v0: &V2,
    region: &OffsetRegion,
    cell: f64,
    tol: f64,
) -> Result<Vec<V2>> {
    Ok(working_envelope_with(
        prop,
        v0,
        &EnvelopeOptions {
            tol,
            cell_waists: Some(cell),
            region: Some(*region),
            coarse_grid: true,
        },
    )?
    .polygon)
}

/// Most boundary points one comparison of two envelopes samples (both boundaries together).
pub const MAX_BOUNDARY_SAMPLES: f64 = 1e6;

fn perimeter(p: &[V2]) -> f64 {
    (0..p.len())
        .map(|i| (p[(i + 1) % p.len()] - p[i]).norm())
        .sum()
}

/// Refuses a comparison of `a` and `b` sampled every `step` m that would take more than
/// [`MAX_BOUNDARY_SAMPLES`] points: a tolerance far finer than the boundary's length (1 pm on a
/// micrometre envelope is 10⁸ points, minutes of work for an envelope no display resolves).
fn check_samples(a: &[V2], b: &[V2], step: f64) -> Result<()> {
    let length = perimeter(a) + perimeter(b);
    let samples = (length / step).ceil();
    if samples > MAX_BOUNDARY_SAMPLES {
        return Err(EnvelopeError::Value(ValueError::out_of_range(
            "envelope grid choice: boundary samples",
            samples,
            format!(
                "≤ 1e6 (the boundaries are compared every tol/8 = {} m along {} m of \
                 boundary: choose a tolerance ≥ {} m for this envelope)",
                world_form::fmt_num(step),
                world_form::fmt_sig(length, 3),
                world_form::fmt_sig(8.0 * length / MAX_BOUNDARY_SAMPLES, 3),
            ),
        )));
    }
    Ok(())
}

/// The Hausdorff distance (m) of the envelope on the spacings of
/// [`CELL_LADDER`] from the reference grid's, worst over the velocities
/// probed, for `prop` at tolerance `tol` (m) with region margin `margin`,
/// coarsest first, stopping after the first two consecutive spacings within
/// `tol/2` (the rest are `None`). Boundaries are compared every `tol/8`.
pub fn ladder_errors(
    prop: &Propagator<2>,
    tol: f64,
    margin: f64,
    v_max: f64,
) -> Result<Vec<Option<f64>>> {
    let mut cases = Vec::new();
    for v0 in velocities(v_max) {
        let region = OffsetRegion::around_drift(prop, &v0, margin)?;
        let reference = build(prop, &v0, &region, REFERENCE_CELL_WAISTS, tol / 10.0)?;
        cases.push((v0, region, reference));
    }
    let mut out = vec![None; CELL_LADDER.len()];
    let mut passed = 0;
    for (k, &cell) in CELL_LADDER.iter().enumerate() {
        let mut worst: f64 = 0.0;
        for (v0, region, reference) in &cases {
            let poly = build(prop, v0, region, cell, tol)?;
            check_samples(&poly, reference, tol / 8.0)?;
            worst = worst.max(hausdorff(&poly, reference, tol / 8.0));
        }
        out[k] = Some(worst);
        passed = if worst <= tol / 2.0 { passed + 1 } else { 0 };
        if passed == 2 {
            break;
        }
    }
    Ok(out)
}

/// Choose the region margin and the grid spacing of `prop`'s envelopes for
/// tolerance `tol` (m) and start speeds up to `v_max` (m/s).
pub fn choose_grid(prop: &Propagator<2>, tol: f64, v_max: f64) -> Result<GridChoice> {
    let tol = positive("tol [m]", tol)?;
    if !(v_max.is_finite() && v_max >= 0.0) {
        return Err(EnvelopeError::Value(ValueError::out_of_range(
            "v_max [m/s]",
            v_max,
            "finite and ≥ 0",
        )));
    }
    let key = cache_key(prop, tol, v_max);
    if let Some(g) = CHOICES
        .lock()
        .ok()
        .and_then(|c| c.iter().find(|(k, _)| *k == key).map(|(_, g)| *g))
    {
        return Ok(g);
    }
    let g = measure_choice(prop, tol, v_max)?;
    if let Ok(mut c) = CHOICES.lock() {
        c.push((key, g));
    }
    Ok(g)
}

/// Choices made so far in this process, by [`cache_key`].
static CHOICES: std::sync::Mutex<Vec<(String, GridChoice)>> = std::sync::Mutex::new(Vec::new());

/// Everything a choice depends on, exactly (bit patterns).
fn cache_key(prop: &Propagator<2>, tol: f64, v_max: f64) -> String {
    let m = prop.model();
    let w = m.well.waists();
    let bits = [
        m.well.depth(),
        w[0],
        w[1],
        m.mass.unwrap_or(f64::NAN),
        m.drag.unwrap_or(f64::NAN),
        m.kt.unwrap_or(f64::NAN),
        m.external_force[0],
        m.external_force[1],
        prop.dt(),
        tol,
        v_max,
    ]
    .map(f64::to_bits);
    format!("{:?} {bits:?}", prop.method())
}

fn measure_choice(prop: &Propagator<2>, tol: f64, v_max: f64) -> Result<GridChoice> {
    let (margin, region_bound) = region_margin(prop.model(), prop.dt(), tol)?;
    let errors = ladder_errors(prop, tol, margin, v_max)?;
    // the coarsest spacing that, with the next finer one, is within the
    // share; else the finest
    let share = tol / 2.0;
    let within = |k: usize| errors[k].is_some_and(|e| e <= share);
    let k = (0..CELL_LADDER.len() - 1)
        .find(|&k| within(k) && within(k + 1))
        .unwrap_or(CELL_LADDER.len() - 1);
    let region = OffsetRegion::around_drift(prop, &V2::zeros(), margin)?;
    let w = prop.model().well.waists();
    let ext = region.hi - region.lo;
    let vertices = (0..2)
        .map(|i| (ext[i] / (CELL_LADDER[k] * w[i])).ceil() as usize + 1)
        .product();
    Ok(GridChoice {
        margin_waists: margin,
        region_bound_m: region_bound,
        cell_waists: CELL_LADDER[k],
        grid_error_m: errors[k].unwrap_or(f64::INFINITY),
        tol_m: tol,
        vertices,
        velocities: velocities(v_max).len(),
        v_max,
    })
}
