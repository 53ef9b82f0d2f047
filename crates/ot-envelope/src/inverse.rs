//! The inverse problem of a tick: every trap offset that moves the particle
//! by a target displacement (paper §2.2, Fig. 7).
//!
//! Seeding is complete on the sampled region: a solution inside a grid cell
//! means the target lies in the cell's image, which lies within the
//! piecewise-linear image of the cell's corners grown by the map's measured
//! nonlinearity along the cell edges (about 4× the interpolation error). Newton with the exact Jacobian of the
//! propagator's own map polishes every candidate to ≤ 1e-12 m.

use crate::error::{Result, finite_vec};
use crate::region::{DEFAULT_MARGIN_WAISTS, OffsetRegion};
use crate::sample::SampledMap;
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// Default residual tolerance of a solution (m): 1e-3 nm.
pub const DEFAULT_RESIDUAL: f64 = 1e-12;

/// Safety factor on the measured nonlinearity of a cell: the cell's image
/// lies within `NL_SAFETY · nl` of the piecewise-linear image of its corners,
/// where `nl` is the largest linearisation error along its edges (the
/// interpolation error inside a cell is about `nl / 4`).
pub const NL_SAFETY: f64 = 1.0;

/// Roots closer than this (in waists, per-axis scaled) are one root.
pub const DEDUP_WAISTS: f64 = 1e-5;

/// Distance from `p` to the triangle `abc` (0 inside).
fn tri_dist(a: &V2, b: &V2, c: &V2, p: &V2) -> f64 {
    let cr = |u: &V2, v: &V2| u.x * v.y - u.y * v.x;
    let s = cr(&(b - a), &(c - a));
    let (d1, d2, d3) = (
        cr(&(b - a), &(p - a)),
        cr(&(c - b), &(p - b)),
        cr(&(a - c), &(p - c)),
    );
    if s != 0.0
        && ((d1 >= 0.0 && d2 >= 0.0 && d3 >= 0.0 && s > 0.0)
            || (d1 <= 0.0 && d2 <= 0.0 && d3 <= 0.0 && s < 0.0))
    {
        return 0.0;
    }
    use crate::geometry::closest_on_segment as cs;
    (cs(a, b, p) - p)
        .norm()
        .min((cs(b, c, p) - p).norm())
        .min((cs(c, a, p) - p).norm())
}

/// The answer of the inverse solver.
#[derive(Debug, Clone, PartialEq)]
pub enum Solutions {
    /// Every offset found in the region (trap centre relative to the
    /// particle, m), at least one, in a deterministic order.
    Found(Vec<V2>),
    /// No trap offset in `region` moves the particle to the target in one tick.
    None {
        /// The searched region (m).
        region: OffsetRegion,
    },
}

impl Solutions {
    /// The offsets (m); empty when there is no solution.
    pub fn offsets(&self) -> &[V2] {
        match self {
            Self::Found(v) => v,
            Self::None { .. } => &[],
        }
    }
}

/// How a steering solution was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// Newton continued from the previous trap position (same branch).
    Continued,
    /// The solution with the smallest trap move among all found.
    SmallestMove,
    /// Newton seeded from a fold point of the (warm-started) envelope whose
    /// image is near the target (no grid needed).
    FoldSeeded,
}

/// Counters of one solve.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolveStats {
    /// Grid cells whose grown image box held the target.
    pub candidates: usize,
    /// Newton runs started.
    pub newton_runs: usize,
    /// Force evaluations spent (grid excluded).
    pub evals: u64,
}

/// Per cell: the grown image box (m) and its margin (m).
#[derive(Debug, Clone, Default)]
struct CellBoxes {
    boxes: Vec<(V2, V2)>,
    margins: Vec<f64>,
}

/// The inverse solver of one tick (one propagator, one velocity): holds the
/// sampled map, answers many targets.
#[derive(Debug, Clone)]
pub struct TrapSolver<'a> {
    pub(crate) prop: &'a Propagator<2>,
    pub(crate) map: SampledMap,
    /// Per cell: box of its corner images grown by the nonlinearity margin
    /// (m) and that margin (m); built on the first full solve only
    /// (continuation never needs them).
    boxes: std::cell::OnceCell<CellBoxes>,
    /// Residual tolerance (m).
    pub residual: f64,
    pub(crate) w: V2,
}

/// Damped Newton on one tick map for one velocity, independent of any
/// sampled map (the warm-started tick uses it without a grid).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Newton<'p> {
    /// The tick map.
    pub prop: &'p Propagator<2>,
    /// Start velocity (m/s).
    pub v0: V2,
    /// Waists (m): steps are limited to half a waist in these units.
    pub w: V2,
    /// The offsets searched (m); iterates far outside give up.
    pub region: OffsetRegion,
    /// Residual tolerance (m).
    pub residual: f64,
    /// Extra steps once the residual is met (2 where distinct roots must be
    /// told apart, 0 for a single continued root).
    pub polish: u8,
}

impl Newton<'_> {
    /// Newton from `start` (m) towards `target` (m), damped, with steps of
    /// at most half a waist; gives up when the iterate comes within 1/20 of
    /// `cell` (m, per axis) of one of the `known` roots. `Some((offset,
    /// residual))` when the residual falls below the tolerance inside the
    /// region.
    pub(crate) fn run(
        &self,
        start: &V2,
        target: &V2,
        evals: &mut u64,
        known: &[(V2, bool)],
        cell: &V2,
    ) -> Result<Option<(V2, f64)>> {
        let mut o = *start;
        let f = self.prop.flow_offset_jacobian(&o, &self.v0)?;
        *evals += f.evals;
        let (mut r, mut j) = (f.displacement - target, f.d_offset);
        let mut rn = r.norm();
        let mut polish = 0u8;
        for _ in 0..40 {
            if rn <= self.residual {
                // two more steps while they still gain: converged roots agree
                // to rounding, so distinct roots are told apart reliably
                polish += 1;
                if polish > self.polish {
                    break;
                }
            }
            let step = match j.try_inverse() {
                Some(inv) => -(inv * r),
                None => -(j.transpose() * r) / (j.norm_squared() + f64::MIN_POSITIVE),
            };
            let zs = step.component_div(&self.w).norm();
            let mut step = if zs > 0.5 { step * (0.5 / zs) } else { step };
            let mut accepted = false;
            for _ in 0..6 {
                let cand = o + step;
                let f = self.prop.flow_offset_jacobian(&cand, &self.v0)?;
                *evals += f.evals;
                let rc = f.displacement - target;
                if rc.norm() < rn {
                    (o, r, j, rn) = (cand, rc, f.d_offset, rc.norm());
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                if rn <= self.residual {
                    break;
                }
                return Ok(None);
            }
            if rn > self.residual
                && known
                    .iter()
                    .any(|(k, _)| (o - k).component_div(cell).amax() < 0.05)
            {
                return Ok(None);
            }
            // Leave early when the iterate has wandered far outside the region.
            let out = (o - self.region.centre())
                .component_div(&(self.region.hi - self.region.lo))
                .amax();
            if out > 1.0 {
                return Ok(None);
            }
        }
        Ok((rn <= self.residual && self.region.contains(&o)).then_some((o, rn)))
    }
}

/// Every offset in the default region (3 waists around the drift path) that
/// moves a particle of velocity `v0` (m/s) by `target` (m) in one tick of
/// `prop`'s model and Δt, **under the true dynamics**: `prop`'s map samples
/// the region and seeds Newton, then every root is polished with the
/// default method ([`ot_physics::Method::default`], within
/// [`ot_physics::DEFAULT_TOL_M`] = 0.01 nm of converged dynamics) to a
/// residual of [`DEFAULT_RESIDUAL`]. So each returned offset reproduces the
/// target within 0.011 nm of converged dynamics whatever `prop`'s own error
/// (RK4×8 at Δt = 1 µs is 0.21 nm off). A root of `prop`'s map whose polish
/// leaves the region is dropped. For the roots of `prop`'s own map, use
/// [`TrapSolver::solve`].
pub fn solve_trap(prop: &Propagator<2>, v0: &V2, target: &V2) -> Result<Solutions> {
    let solver = TrapSolver::new(prop, v0, None, None)?;
    let (sol, _) = solver.solve(target)?;
    if matches!(prop.method(), ot_physics::Method::Adaptive { rtol } if rtol <= ot_physics::DEFAULT_RTOL)
    {
        return Ok(sol);
    }
    let truth = Propagator::new(*prop.model(), ot_physics::Method::default(), prop.dt())?;
    let nw = Newton {
        prop: &truth,
        v0: *v0,
        w: solver.w,
        region: solver.map.region,
        residual: DEFAULT_RESIDUAL,
        polish: 2,
    };
    let mut found: Vec<V2> = Vec::new();
    let mut evals = 0;
    for o in sol.offsets() {
        if let Some((p, _)) = nw.run(o, target, &mut evals, &[], &solver.map.h)? {
            let zp = p.component_div(&solver.w);
            if !found
                .iter()
                .any(|f| (f.component_div(&solver.w) - zp).norm() < DEDUP_WAISTS)
            {
                found.push(p);
            }
        }
    }
    found.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    Ok(if found.is_empty() {
        Solutions::None {
            region: solver.map.region,
        }
    } else {
        Solutions::Found(found)
    })
}

impl<'a> TrapSolver<'a> {
    /// Sample the map for `v0` (m/s) over `region` (`None`: 3 waists around
    /// the drift path) with `cell_waists` spacing (`None`: default).
    pub fn new(
        prop: &'a Propagator<2>,
        v0: &V2,
        region: Option<OffsetRegion>,
        cell_waists: Option<f64>,
    ) -> Result<Self> {
        let region = match region {
            Some(r) => r,
            None => OffsetRegion::around_drift(prop, v0, DEFAULT_MARGIN_WAISTS)?,
        };
        let map = SampledMap::build(prop, v0, &region, cell_waists)?;
        Ok(Self::from_map(prop, map))
    }

    /// Reuse a sampled map (the envelope's, in the haptic loop). Cheap: the
    /// per-cell boxes of the full solve are built lazily, on its first call.
    pub fn from_map(prop: &'a Propagator<2>, map: SampledMap) -> Self {
        Self {
            prop,
            map,
            boxes: std::cell::OnceCell::new(),
            residual: DEFAULT_RESIDUAL,
            w: prop.model().well.waists(),
        }
    }

    fn cell_boxes(&self) -> &CellBoxes {
        self.boxes.get_or_init(|| {
            let map = &self.map;
            let [nx, ny] = map.n;
            let mut boxes = Vec::with_capacity((nx - 1) * (ny - 1));
            let mut margins = Vec::with_capacity((nx - 1) * (ny - 1));
            for i in 0..nx - 1 {
                for j in 0..ny - 1 {
                    let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                    let (mut lo, mut hi) = (map.disp[map.idx(i, j)], map.disp[map.idx(i, j)]);
                    let mut nl: f64 = 0.0;
                    for k in 0..4 {
                        let (a, b) = (c[k], c[(k + 1) % 4]);
                        let (ia, ib) = (map.idx(a.0, a.1), map.idx(b.0, b.1));
                        lo = lo.inf(&map.disp[ib]);
                        hi = hi.sup(&map.disp[ib]);
                        let step = map.offset(b.0, b.1) - map.offset(a.0, a.1);
                        let e1 = map.disp[ib] - map.disp[ia] - map.jac[ia] * step;
                        let e2 = map.disp[ia] - map.disp[ib] + map.jac[ib] * step;
                        nl = nl.max(e1.amax()).max(e2.amax());
                    }
                    let g = NL_SAFETY * nl + map.interior_error + 1e-12;
                    boxes.push((lo - V2::repeat(g), hi + V2::repeat(g)));
                    margins.push(g);
                }
            }
            CellBoxes { boxes, margins }
        })
    }

    /// The sampled map.
    pub fn map(&self) -> &SampledMap {
        &self.map
    }

    /// Newton from `start` (m) towards `target` (m), damped, with steps of at
    /// most half a waist; `Some((offset, residual))` when the residual falls
    /// below the tolerance inside the region.
    pub fn newton(&self, start: &V2, target: &V2, evals: &mut u64) -> Result<Option<(V2, f64)>> {
        self.newton_avoiding(start, target, evals, &[])
    }

    /// [`TrapSolver::newton`] that gives up as soon as the iterate comes
    /// within 1/20 cell of one of the `known` roots (it would find it again).
    fn newton_avoiding(
        &self,
        start: &V2,
        target: &V2,
        evals: &mut u64,
        known: &[(V2, bool)],
    ) -> Result<Option<(V2, f64)>> {
        let nw = Newton {
            prop: self.prop,
            v0: self.map.v0,
            w: self.w,
            region: self.map.region,
            residual: self.residual,
            polish: 2,
        };
        nw.run(start, target, evals, known, &self.map.h)
    }

    fn scaled(&self, o: &V2) -> V2 {
        o.component_div(&self.w)
    }

    /// All offsets in the region that move the particle by `target` (m).
    pub fn solve(&self, target: &V2) -> Result<(Solutions, SolveStats)> {
        finite_vec("target [m]", target.as_slice())?;
        let [nx, ny] = self.map.n;
        let cells = self.cell_boxes();
        let mut stats = SolveStats::default();
        // candidate cells, best first (smallest image distance of a corner)
        let mut cand: Vec<(f64, usize, usize)> = Vec::new();
        for i in 0..nx - 1 {
            for j in 0..ny - 1 {
                let (lo, hi) = cells.boxes[i * (ny - 1) + j];
                if target.x >= lo.x && target.x <= hi.x && target.y >= lo.y && target.y <= hi.y && {
                    let d = |a: usize, b: usize| self.map.disp[self.map.idx(a, b)];
                    let (p00, p10, p11, p01) = (d(i, j), d(i + 1, j), d(i + 1, j + 1), d(i, j + 1));
                    let m = cells.margins[i * (ny - 1) + j];
                    tri_dist(&p00, &p10, &p11, target) <= m
                        || tri_dist(&p00, &p11, &p01, target) <= m
                        || tri_dist(&p00, &p10, &p01, target) <= m
                        || tri_dist(&p10, &p11, &p01, target) <= m
                } {
                    let best = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)]
                        .iter()
                        .map(|&(a, b)| (self.map.disp[self.map.idx(a, b)] - target).norm())
                        .fold(f64::INFINITY, f64::min);
                    cand.push((best, i, j));
                }
            }
        }
        cand.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        stats.candidates = cand.len();
        let mut found: Vec<(V2, bool)> = Vec::new();
        let h = self.map.h;
        for &(_, i, j) in &cand {
            let lo = self.map.offset(i, j);
            let hi = lo + h;
            let corners = [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)];
            let dets: Vec<f64> = corners.iter().map(|&(a, b)| self.map.det(a, b)).collect();
            let fold = dets.iter().any(|d| *d >= 0.0) && dets.iter().any(|d| *d < 0.0);
            // seeds: linear step from the best corner (of each det sign in a fold cell)
            let mut seeds: Vec<(V2, bool)> = Vec::new();
            for sign in [true, false] {
                let best = corners
                    .iter()
                    .zip(&dets)
                    .filter(|(_, d)| !fold || ((**d >= 0.0) == sign))
                    .map(|(&(a, b), _)| (a, b))
                    .min_by(|x, y| {
                        let dx = (self.map.disp[self.map.idx(x.0, x.1)] - target).norm();
                        let dy = (self.map.disp[self.map.idx(y.0, y.1)] - target).norm();
                        dx.total_cmp(&dy)
                    });
                let Some((a, b)) = best else { continue };
                let k = self.map.idx(a, b);
                let oc = self.map.offset(a, b);
                let s = match self.map.jac[k].try_inverse() {
                    Some(inv) => oc + inv * (target - self.map.disp[k]),
                    None => oc,
                };
                let s = s.sup(&(lo - h * 0.5)).inf(&(hi + h * 0.5));
                seeds.push((s, self.map.jac[k].determinant() >= 0.0));
                if !fold {
                    break;
                }
            }
            for (s, side) in seeds {
                // a seed within half a cell of a found solution on the same
                // side of the fold would converge to it again
                if found
                    .iter()
                    .any(|(f, fs)| *fs == side && (f - s).component_div(&h).amax() < 0.5)
                {
                    continue;
                }
                stats.newton_runs += 1;
                if let Some((o, _)) = self.newton_avoiding(&s, target, &mut stats.evals, &found)? {
                    let zo = self.scaled(&o);
                    if !found
                        .iter()
                        .any(|(f, _)| (self.scaled(f) - zo).norm() < DEDUP_WAISTS)
                    {
                        let det = self
                            .prop
                            .flow_offset_jacobian(&o, &self.map.v0)?
                            .d_offset
                            .determinant();
                        found.push((o, det >= 0.0));
                    }
                }
            }
        }
        let mut found: Vec<V2> = found.into_iter().map(|f| f.0).collect();
        found.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        let sol = if found.is_empty() {
            Solutions::None {
                region: self.map.region,
            }
        } else {
            Solutions::Found(found)
        };
        Ok((sol, stats))
    }

    /// The steering choice for `target` (m): continuity with the previous
    /// trap offset `prev` (m, the previous trap position relative to the
    /// particle now) first — Newton continued from it — and otherwise the
    /// solution with the smallest trap move. `None` when unreachable.
    pub fn steer(&self, target: &V2, prev: Option<&V2>) -> Result<Option<(V2, Choice)>> {
        let mut evals = 0;
        if let Some(p) = prev {
            finite_vec("previous offset [m]", p.as_slice())?;
            if let Some((o, _)) = self.newton(p, target, &mut evals)? {
                return Ok(Some((o, Choice::Continued)));
            }
        }
        let (sol, _) = self.solve(target)?;
        let anchor = prev.copied().unwrap_or_else(V2::zeros);
        Ok(sol
            .offsets()
            .iter()
            .min_by(|a, b| (*a - anchor).norm().total_cmp(&(*b - anchor).norm()))
            .map(|o| (*o, Choice::SmallestMove)))
    }
}
