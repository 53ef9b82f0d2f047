//! The tick map sampled on a grid of trap offsets: displacement, Jacobian
//! and its determinant at every vertex. Built once per (propagator,
//! velocity); the envelope and the inverse solver both read it.

use crate::error::{EnvelopeError, Result, ValueError, finite_vec, positive};
use crate::region::OffsetRegion;
use nalgebra::{Matrix2, Vector2};
use ot_physics::{OffsetFlow, Propagator};

/// Largest grid the sampler accepts (vertices).
pub const MAX_VERTICES: usize = 4_000_000;

/// Default grid spacing (waists per axis) for a propagator: 0.3 waist for
/// the paper's tick (ωΔt ≈ 3.9 rad of the fastest oscillation), finer for
/// longer ticks whose map folds more often (1.2/ωΔt), and finer again by
/// `ωh` when the integrator's own step `h` exceeds 1/ω (the one-step RK4 of
/// the paper: its polynomial map is far more curved than the true flow).
pub fn default_cell_waists(prop: &Propagator<2>) -> f64 {
    let omega_dt = prop.model().fastest_rate() * prop.dt();
    let steps = match prop.method() {
        ot_physics::Method::PaperRk4 => 1.0,
        ot_physics::Method::Rk4 { substeps } | ot_physics::Method::Symplectic { substeps, .. } => {
            f64::from(substeps)
        }
        _ => f64::INFINITY,
    };
    let omega_h = omega_dt / steps;
    (1.2 / omega_dt.max(1e-9) / omega_h.max(1.0)).clamp(0.02, 0.3)
}

/// The flow map of one tick sampled on a regular grid of offsets.
#[derive(Debug, Clone)]
pub struct SampledMap {
    /// The sampled region (m).
    pub region: OffsetRegion,
    /// Vertices per axis.
    pub n: [usize; 2],
    /// Grid spacing per axis (m).
    pub h: Vector2<f64>,
    /// Particle velocity at the start of the tick (m/s).
    pub v0: Vector2<f64>,
    /// Displacement at each vertex (m), index `i * n[1] + j`.
    pub disp: Vec<Vector2<f64>>,
    /// `∂ displacement / ∂ offset` at each vertex (dimensionless).
    pub jac: Vec<Matrix2<f64>>,
    /// Force evaluations spent building the grid.
    pub evals: u64,
    /// Estimated bound on the displacement error of interior vertices (m):
    /// zero when every vertex used the main propagator, else twice the
    /// largest difference seen between the coarse and the main map at probe
    /// vertices (the 8 where the well acts most, and a 1-in-4 lattice).
    pub interior_error: f64,
}

/// The coarse companion of a propagator for sampling grid interiors: RK4
/// with half the substeps, used only in the gentle regime where it keeps
/// every fold sign of the full map — the method is RK4 with at least 8
/// substeps, the tick spans at most one oscillation (`rate·Δt ≤ 2π`) and the
/// coarse step resolves it (`rate·Δt/(n/2) ≤ 1`), with `rate` the larger of
/// the well's fastest frequency and the crossing rate `|v0|/w_min`. The
/// paper's tick qualifies; long ticks and fast particles sample at full
/// accuracy. The fold *signs* need far less accuracy than the fold *points*,
/// which are always computed with the full propagator.
pub fn coarse_companion(prop: &Propagator<2>, v0: &Vector2<f64>) -> Option<Propagator<2>> {
    let model = prop.model();
    let rate = model.fastest_rate().max(v0.norm() / model.length_scale());
    match prop.method() {
        ot_physics::Method::Rk4 { substeps } if substeps >= 8 => {
            let half = substeps / 2;
            let omega_dt = rate * prop.dt();
            if omega_dt <= std::f64::consts::TAU && omega_dt / f64::from(half) <= 1.0 {
                Propagator::new(
                    *model,
                    ot_physics::Method::Rk4 { substeps: half },
                    prop.dt(),
                )
                .ok()
            } else {
                None
            }
        }
        _ => None,
    }
}

impl SampledMap {
    /// Sample `prop`'s tick map for velocity `v0` (m/s) over `region` with a
    /// spacing of `cell_waists` waists per axis (`None`: [`default_cell_waists`]).
    pub fn build(
        prop: &Propagator<2>,
        v0: &Vector2<f64>,
        region: &OffsetRegion,
        cell_waists: Option<f64>,
    ) -> Result<Self> {
        Self::build_with(prop, None, v0, region, cell_waists)
    }

    /// [`SampledMap::build`] with the interior vertices sampled by `coarse`
    /// (the region's edge always by `prop`), and the interior error measured.
    pub fn build_with(
        prop: &Propagator<2>,
        coarse: Option<&Propagator<2>>,
        v0: &Vector2<f64>,
        region: &OffsetRegion,
        cell_waists: Option<f64>,
    ) -> Result<Self> {
        let mut job = MapJob::new(prop, coarse.copied(), v0, region, cell_waists)?;
        job.run(prop, &mut Slice::unlimited())?;
        Ok(job.map)
    }

    /// Flat index of vertex `(i, j)`.
    /// Flat index of vertex `(i, j)`.
    #[inline]
    pub fn idx(&self, i: usize, j: usize) -> usize {
        i * self.n[1] + j
    }

    /// Offset of vertex `(i, j)` (m).
    #[inline]
    pub fn offset(&self, i: usize, j: usize) -> Vector2<f64> {
        self.region.lo + Vector2::new(self.h.x * i as f64, self.h.y * j as f64)
    }

    /// `det(∂ displacement / ∂ offset)` at vertex `(i, j)`.
    #[inline]
    pub fn det(&self, i: usize, j: usize) -> f64 {
        self.jac[self.idx(i, j)].determinant()
    }
}

/// A budget of force evaluations for one slice of a resumable build: work
/// items run while the slice is open, and an item once started is finished,
/// so a slice spends at most its budget plus one item's cost. Counting
/// evaluations, not time, keeps a spread build's result and its split over
/// ticks a function of the inputs only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Slice {
    /// Evaluations this slice may start work with.
    pub(crate) budget: u64,
    /// Evaluations spent so far.
    pub(crate) spent: u64,
}

impl Slice {
    /// A slice of `budget` force evaluations.
    pub(crate) fn new(budget: u64) -> Self {
        Self { budget, spent: 0 }
    }
    /// A slice that never closes (a one-shot build).
    pub(crate) fn unlimited() -> Self {
        Self::new(u64::MAX)
    }
    /// Whether another work item may start.
    pub(crate) fn open(&self) -> bool {
        self.spent < self.budget
    }
    /// Charge `evals` force evaluations.
    pub(crate) fn spend(&mut self, evals: u64) {
        self.spent = self.spent.saturating_add(evals);
    }
}

/// The grid sampling of [`SampledMap::build_with`] as a resumable job: one
/// work item per vertex (then per interior-error probe), in the one-shot
/// build's order, so the finished map is the one-shot map bit for bit.
#[derive(Debug, Clone)]
pub(crate) struct MapJob {
    /// The map being filled (complete once [`MapJob::run`] returns true).
    pub(crate) map: SampledMap,
    coarse: Option<Propagator<2>>,
    /// Next vertex to sample (flat index).
    next: usize,
    /// Interior-error probe vertices (computed once the grid is sampled).
    probes: Option<Vec<(usize, usize)>>,
    next_probe: usize,
}

impl MapJob {
    /// Validates the settings (the tick within [`crate::tick_length::check_tick_length`]:
    /// every sampling of the map, so every envelope, inverse solve and steering step, is
    /// bounded there) and lays out the grid; samples nothing yet.
    pub(crate) fn new(
        prop: &Propagator<2>,
        coarse: Option<Propagator<2>>,
        v0: &Vector2<f64>,
        region: &OffsetRegion,
        cell_waists: Option<f64>,
    ) -> Result<Self> {
        crate::tick_length::check_tick_length(prop)?;
        finite_vec("velocity [m/s]", v0.as_slice())?;
        let model = prop.model();
        let s = match cell_waists {
            Some(s) => positive("cell_waists [waists]", s)?,
            None => default_cell_waists(prop),
        };
        let w = model.well.waists();
        let ext = region.hi - region.lo;
        let mut n = [0usize; 2];
        let mut h = Vector2::zeros();
        for i in 0..2 {
            let cells = (ext[i] / (s * w[i])).ceil().max(1.0);
            if cells.is_nan() || cells >= MAX_VERTICES as f64 {
                return Err(EnvelopeError::Value(ValueError::out_of_range(
                    "cell_waists [waists]",
                    s,
                    "large enough for at most 4e6 grid vertices",
                )));
            }
            n[i] = cells as usize + 1;
            h[i] = ext[i] / cells;
        }
        if n[0] * n[1] > MAX_VERTICES {
            return Err(EnvelopeError::Value(ValueError::out_of_range(
                "cell_waists [waists]",
                s,
                "large enough for at most 4e6 grid vertices",
            )));
        }
        Ok(Self {
            map: SampledMap {
                region: *region,
                n,
                h,
                v0: *v0,
                disp: Vec::with_capacity(n[0] * n[1]),
                jac: Vec::with_capacity(n[0] * n[1]),
                evals: 0,
                interior_error: 0.0,
            },
            coarse,
            next: 0,
            probes: None,
            next_probe: 0,
        })
    }

    /// Runs work items while `slice` is open; true once the map is complete.
    pub(crate) fn run(&mut self, prop: &Propagator<2>, slice: &mut Slice) -> Result<bool> {
        let m = &mut self.map;
        let n = m.n;
        while self.next < n[0] * n[1] {
            if !slice.open() {
                return Ok(false);
            }
            let (i, j) = (self.next / n[1], self.next % n[1]);
            let o = m.region.lo + Vector2::new(m.h.x * i as f64, m.h.y * j as f64);
            let edge = i == 0 || j == 0 || i + 1 == n[0] || j + 1 == n[1];
            let p = if edge {
                prop
            } else {
                self.coarse.as_ref().unwrap_or(prop)
            };
            let f: OffsetFlow<2> = p.flow_offset_jacobian(&o, &m.v0)?;
            m.disp.push(f.displacement);
            m.jac.push(f.d_offset);
            m.evals += f.evals;
            slice.spend(f.evals);
            self.next += 1;
        }
        if self.coarse.is_none() || n[0] <= 2 || n[1] <= 2 {
            return Ok(true);
        }
        let probes = match &self.probes {
            Some(p) => p,
            None => {
                let free = crate::region::free_drift(prop.model(), &m.v0, prop.dt());
                let disp = &m.disp;
                let mut inner: Vec<(f64, usize, usize)> = (1..n[0] - 1)
                    .flat_map(|i| (1..n[1] - 1).map(move |j| (i, j)))
                    .map(|(i, j)| ((disp[i * n[1] + j] - free).norm(), i, j))
                    .collect();
                inner.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
                // probes: the 8 vertices where the well acts most, and every
                // fourth vertex of the interior lattice
                let lattice = (1..n[0] - 1)
                    .step_by(4)
                    .flat_map(|i| (1..n[1] - 1).step_by(4).map(move |j| (i, j)));
                self.probes.insert(
                    inner
                        .iter()
                        .take(8)
                        .map(|p| (p.1, p.2))
                        .chain(lattice)
                        .collect(),
                )
            }
        };
        while self.next_probe < probes.len() {
            if !slice.open() {
                return Ok(false);
            }
            let (i, j) = probes[self.next_probe];
            let o = m.region.lo + Vector2::new(m.h.x * i as f64, m.h.y * j as f64);
            let (d, _, e) = prop.flow(&o, &m.v0)?;
            m.evals += e;
            slice.spend(e);
            m.interior_error = f64::max(m.interior_error, 2.0 * (d - m.disp[i * n[1] + j]).norm());
            self.next_probe += 1;
        }
        Ok(true)
    }
}
