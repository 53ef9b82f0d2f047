//! The working envelope (WE) in 2D: the boundary of the set of displacements
//! reachable in one tick, as a counter-clockwise polygon.
//!
//! Method (see `docs/ot-envelope.md`): the boundary of the image of a smooth
//! map of the plane lies on the image of its critical set `det J = 0` (the
//! folds) and of the region's edge. So:
//! 1. sample `det J` on a grid of offsets ([`SampledMap`]);
//! 2. trace the zero set with marching squares, place each crossing on its
//!    grid edge by regula falsi, map it, and take the image tangent from the
//!    rank-1 Jacobian (its column space) — a fold point off the critical
//!    curve by δ maps only O(δ²) inside the boundary;
//! 3. insert new fold points where consecutive tangents turn by more than
//!    25°, and interpolate the image curve by cubic Hermite segments;
//! 4. take the outer boundary of the arrangement of all image curves
//!    ([`crate::geometry::outer_boundary`]).

use crate::error::{Result, finite_vec, positive};
use crate::folds::{Traced, hermite_polylines, trace};
use crate::geometry::{self, try_outer_boundary};
use crate::region::{DEFAULT_MARGIN_WAISTS, OffsetRegion, free_drift};
use crate::sample::{SampledMap, coarse_companion};
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// Default polygon tolerance (m): the envelope boundary is drawn within
/// this distance of the map's true fold image (integration error apart).
pub const DEFAULT_TOL: f64 = 0.5e-9;

pub use crate::tick_length::{MAX_OSCILLATIONS_PER_TICK, check_tick_length};

/// Options of [`working_envelope_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnvelopeOptions {
    /// Geometric tolerance of the polygon (m, > 0).
    pub tol: f64,
    /// Grid spacing in waists (`None`: [`crate::sample::default_cell_waists`]).
    pub cell_waists: Option<f64>,
    /// Offset region (`None`: [`OffsetRegion::around_drift`] with 3 waists).
    pub region: Option<OffsetRegion>,
    /// Sample the grid interior with half the RK4 substeps
    /// ([`crate::sample::coarse_companion`]); fold points and the region's
    /// edge always use the full propagator.
    pub coarse_grid: bool,
}

impl Default for EnvelopeOptions {
    fn default() -> Self {
        Self {
            tol: DEFAULT_TOL,
            cell_waists: None,
            region: None,
            coarse_grid: true,
        }
    }
}

/// A 2D working envelope.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// Boundary of the reachable displacements (m), counter-clockwise, first
    /// vertex not repeated.
    pub polygon: Vec<V2>,
    /// Geometric tolerance asked for (m).
    pub tol: f64,
    /// The offset region whose image this is (m).
    pub region: OffsetRegion,
    /// Particle velocity at the start of the tick (m/s).
    pub v0: V2,
    /// Displacement with the trap infinitely far (m): the free drift.
    pub free_displacement: V2,
    /// Whether part of the boundary is the image of the region's edge
    /// (then the region, not the physics, limits the envelope).
    pub touches_region_edge: bool,
    /// Number of fold curves found in the region.
    pub fold_curves: usize,
    /// Force evaluations spent (grid included).
    pub evals: u64,
}

impl Envelope {
    /// Whether displacement `d` (m) is reachable (inside the polygon).
    pub fn contains(&self, d: &V2) -> bool {
        geometry::contains(&self.polygon, d)
    }
    /// Enclosed area (m²).
    pub fn area(&self) -> f64 {
        geometry::signed_area(&self.polygon)
    }
}

/// The working envelope of `prop`'s tick for a particle of velocity `v0`
/// (m/s), over the default region, to `tol` (m; `None`: [`DEFAULT_TOL`]).
/// A tick longer than [`MAX_OSCILLATIONS_PER_TICK`] oscillation periods is refused
/// ([`check_tick_length`], by the grid sampling).
pub fn working_envelope(prop: &Propagator<2>, v0: &V2, tol: Option<f64>) -> Result<Envelope> {
    working_envelope_with(
        prop,
        v0,
        &EnvelopeOptions {
            tol: tol.unwrap_or(DEFAULT_TOL),
            ..Default::default()
        },
    )
}

/// [`working_envelope`] with every option.
pub fn working_envelope_with(
    prop: &Propagator<2>,
    v0: &V2,
    opt: &EnvelopeOptions,
) -> Result<Envelope> {
    finite_vec("velocity [m/s]", v0.as_slice())?;
    positive("tol [m]", opt.tol)?;
    let region = match opt.region {
        Some(r) => r,
        None => OffsetRegion::around_drift(prop, v0, DEFAULT_MARGIN_WAISTS)?,
    };
    let coarse = if opt.coarse_grid {
        coarse_companion(prop, v0)
    } else {
        None
    };
    let map = SampledMap::build_with(prop, coarse.as_ref(), v0, &region, opt.cell_waists)?;
    envelope_from_map(prop, &map, opt.tol)
}

/// Build the envelope from an already sampled map (the haptic loop reuses the
/// map for the inverse solver). `tol` in m.
pub fn envelope_from_map(prop: &Propagator<2>, map: &SampledMap, tol: f64) -> Result<Envelope> {
    envelope_and_folds(prop, map, tol, None)
}

/// [`envelope_from_map`] that also returns, in `folds`, every traced fold
/// point as (offset, displacement) (m): the warm-started tick verifies them.
pub(crate) fn envelope_and_folds(
    prop: &Propagator<2>,
    map: &SampledMap,
    tol: f64,
    folds: Option<&mut Vec<(V2, V2)>>,
) -> Result<Envelope> {
    let tol = positive("tol [m]", tol)?;
    let traced = trace(prop, map, tol)?;
    envelope_from_traced(prop, map, traced, tol, folds)
}

/// The last stage of a build: the fold points (into `folds`), the Hermite
/// polylines of the traced curves and the outer boundary of their
/// arrangement. Evaluates nothing.
pub(crate) fn envelope_from_traced(
    prop: &Propagator<2>,
    map: &SampledMap,
    mut traced: Traced,
    tol: f64,
    folds: Option<&mut Vec<(V2, V2)>>,
) -> Result<Envelope> {
    if let Some(f) = folds {
        f.clear();
        for c in traced.curves.iter().filter(|c| c.edge_dir.is_none()) {
            f.extend(c.pts.iter().map(|p| (p.o, p.d)));
        }
    }
    let lines = hermite_polylines(&traced.curves, tol, &mut traced.edge_only);
    let (fold_curves, edge_only) = (traced.fold_curves, &traced.edge_only);
    let scale = map
        .disp
        .iter()
        .map(|d| (d - map.disp[0]).norm())
        .fold(0.0, f64::max)
        .max(tol);
    let snap = 1e-9 * scale;
    // The region edge's image (last line) is usually a small tangle near the
    // free drift, deep inside the envelope: when its bounding box lies inside
    // the outer boundary of the fold images alone (corners inside, no
    // boundary edge through the box), it cannot change the outer boundary and
    // its thousands of segment pairs are never tested.
    let polygon = match lines.split_last() {
        Some((edge, folds)) if !folds.is_empty() => {
            let inner = try_outer_boundary(folds, snap)?;
            if inner.len() >= 3 && geometry::box_inside(&inner, &geometry::bbox(&edge.0)) {
                inner
            } else {
                try_outer_boundary(&lines, snap)?
            }
        }
        _ => try_outer_boundary(&lines, snap)?,
    };
    let touches_region_edge = polygon
        .iter()
        .any(|p| edge_only.contains(&(p.x.to_bits(), p.y.to_bits())));
    Ok(Envelope {
        polygon,
        tol,
        region: map.region,
        v0: map.v0,
        free_displacement: free_drift(prop.model(), &map.v0, prop.dt()),
        touches_region_edge,
        fold_curves,
        evals: traced.evals,
    })
}
