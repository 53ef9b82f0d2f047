//! The steering tick of the optical-tweezers scene, warm-started: the
//! working envelope of the previous full build is translated by the change
//! of the free drift, a few of its fold points are re-mapped and checked
//! against it, and the clipped target is solved by Newton continued from the
//! previous trap or seeded from the fold points.
//!
//! The next full build (grid, fold tracing, outer boundary) is spread over
//! ticks ([`crate::spread`]): once the velocity has moved more than
//! [`TickParams::spread_dv`] from the last build's, a build for the current
//! velocity starts, and each tick runs one slice of at most
//! [`TickParams::build_evals_per_tick`] force evaluations of it (plus one
//! work item) while the last build is served, translated; the finished
//! build is swapped in at the start of the next tick. A build runs whole
//! within one tick only when the served envelope would no longer be
//! trusted: the velocity has moved more than [`TickParams::warm_dv`] from
//! the served build's, a fold check fails, or no seed converges. The first
//! build can be made before the first tick ([`TickController::prebuild`],
//! [`TickController::prepare`]). A warm tick allocates nothing once the
//! buffers have grown.
//!
//! Everything the warm start depends on is deterministic state (the tick
//! inputs seen so far): same inputs, same bits, on replay too.

use crate::clip::clip_to_polygon;
use crate::error::{Result, finite_vec, positive};
use crate::geometry::{closest_on_segment, nearest_on_boundary};
use crate::inverse::{Choice, DEFAULT_RESIDUAL, Newton, TrapSolver};
use crate::region::{OffsetRegion, free_drift};
use crate::sample::SampledMap;
use crate::spread::{BuiltEnvelope, EnvelopeBuild};
use crate::steer::{ParticleState, SteerParams};
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// Default velocity change (m/s) from the build in service past which the
/// translated envelope is no longer served and a whole rebuild runs: 30
/// nm/µs (at the scene's tick and grid, the translation is then within
/// 0.08 nm of converged dynamics; the spread build starts at
/// [`DEFAULT_SPREAD_DV`]).
pub const DEFAULT_WARM_DV: f64 = 0.03;
/// Default distance (m) a re-mapped fold point may lie from the translated
/// envelope: 0.1 nm.
pub const DEFAULT_VERIFY_TOL: f64 = 1e-10;
/// Default fold points re-mapped per warm tick.
pub const DEFAULT_VERIFY_POINTS: usize = 3;
/// Default velocity change (m/s) from the last build at which a spread
/// rebuild starts: 5 nm/µs, half of [`DEFAULT_WARM_DV`].
pub const DEFAULT_SPREAD_DV: f64 = 0.005;
/// Default force evaluations of a spread build per tick: 256 (at the
/// scene's RK4×2 tick map, 32 grid vertices; a build at the budget grid
/// takes about 10 ticks).
pub const DEFAULT_BUILD_EVALS_PER_TICK: u64 = 256;
/// Fold points tried as Newton seeds when continuation fails.
const FOLD_SEEDS: usize = 3;

/// Settings of the warm-started tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickParams {
    /// Spring, clipping rule, envelope tolerance and region margin.
    pub steer: SteerParams,
    /// Whether to warm start (false: a full build every tick, the old way).
    pub warm_start: bool,
    /// Largest velocity change from the last full build (m/s, > 0).
    pub warm_dv: f64,
    /// Largest distance of a re-mapped fold point from the translated
    /// envelope (m, > 0).
    pub verify_tol: f64,
    /// Fold points re-mapped per warm tick (≥ 1).
    pub verify_points: usize,
    /// Velocity change from the last build at which a spread rebuild starts
    /// (m/s, > 0, ≤ `warm_dv`).
    pub spread_dv: f64,
    /// Force evaluations of a spread build per tick (≥ 1); `None`: no
    /// spread build, a rebuild runs whole in the tick that needs it.
    pub build_evals_per_tick: Option<u64>,
    /// Grid spacing of a full build (waists per cell; `None`:
    /// [`crate::sample::default_cell_waists`]); [`crate::grid::choose_grid`]
    /// sizes it from the envelope tolerance.
    pub cell_waists: Option<f64>,
}

impl TickParams {
    /// Default warm-start settings around `steer`.
    pub fn new(steer: SteerParams) -> Self {
        Self {
            steer,
            warm_start: true,
            warm_dv: DEFAULT_WARM_DV,
            verify_tol: DEFAULT_VERIFY_TOL,
            verify_points: DEFAULT_VERIFY_POINTS,
            spread_dv: DEFAULT_SPREAD_DV,
            build_evals_per_tick: Some(DEFAULT_BUILD_EVALS_PER_TICK),
            cell_waists: None,
        }
    }

    /// Check every field.
    pub fn validate(&self) -> Result<()> {
        self.steer.validate()?;
        positive("warm_dv [m/s]", self.warm_dv)?;
        positive("verify_tol [m]", self.verify_tol)?;
        positive("spread_dv [m/s]", self.spread_dv)?;
        if self.spread_dv > self.warm_dv {
            return Err(crate::error::EnvelopeError::Value(
                crate::error::ValueError::out_of_range(
                    "spread_dv [m/s]",
                    self.spread_dv,
                    "≤ warm_dv",
                ),
            ));
        }
        if self.build_evals_per_tick == Some(0) {
            return Err(crate::error::EnvelopeError::Value(
                crate::error::ValueError::out_of_range(
                    "build_evals_per_tick",
                    0.0,
                    "≥ 1 (or none: no spread build)",
                ),
            ));
        }
        if let Some(c) = self.cell_waists {
            positive("cell_waists [waists]", c)?;
        }
        if !(1..=64).contains(&self.verify_points) {
            return Err(crate::error::EnvelopeError::Value(
                crate::error::ValueError::out_of_range(
                    "verify_points",
                    self.verify_points as f64,
                    "1 ..= 64",
                ),
            ));
        }
        Ok(())
    }
}

/// Counters of a steering session (deterministic: part of the state).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TickStats {
    /// Ticks stepped.
    pub ticks: u64,
    /// Full envelope builds put in service (whole or spread; the prebuild included).
    pub rebuilds: u64,
    /// Of which built in slices over several ticks.
    pub spread_builds: u64,
    /// Slices of spread builds run.
    pub build_slices: u64,
    /// Most force evaluations one slice spent.
    pub max_slice_evals: u64,
    /// Spread builds dropped unfinished for a whole build.
    pub dropped_builds: u64,
    /// Of which forced by a failed fold check.
    pub verify_failures: u64,
    /// Ticks solved by Newton continued from the previous trap.
    pub continued: u64,
    /// Ticks solved by Newton from a fold point.
    pub fold_seeded: u64,
    /// Ticks that needed the full grid solve.
    pub full_solves: u64,
    /// Ticks with no solution at all (trap parked at the region's corner).
    pub parked: u64,
}

/// One tick's decision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickOutput {
    /// Where to put the trap centre for this tick (world, m).
    pub trap: V2,
    /// Displacement the particle will make (m): the clipped command.
    pub allowed: V2,
    /// `command − allowed` (m).
    pub excess: V2,
    /// Reaction force on the stylus, `−k · excess` (N).
    pub force: V2,
    /// How the trap offset was chosen.
    pub choice: Choice,
    /// Whether a whole envelope build ran in this tick.
    pub rebuilt: bool,
    /// Force evaluations a spread build spent in this tick (0: none ran).
    pub slice_evals: u64,
}

/// Edges examined on each side of a fold point's vertex by the warm check.
const VERIFY_WINDOW: usize = 12;

/// Distance (m) from `p` to the polygon edges within [`VERIFY_WINDOW`]
/// edges of vertex `v` (the whole polygon when it is small).
fn window_distance(poly: &[V2], v: usize, p: &V2) -> f64 {
    let n = poly.len();
    if n <= 2 * VERIFY_WINDOW + 2 {
        return nearest_on_boundary(poly, p).1;
    }
    let mut best = f64::INFINITY;
    for k in 0..2 * VERIFY_WINDOW {
        let i = (v + n - VERIFY_WINDOW + k) % n;
        let q = closest_on_segment(&poly[i], &poly[(i + 1) % n], p);
        best = best.min((q - p).norm());
    }
    best
}

/// The warm-started steering controller: settings, the last full build
/// (velocity, polygon, fold points, sampled map) and reused buffers.
#[derive(Debug, Clone)]
pub struct TickController {
    params: TickParams,
    prev_trap: Option<V2>,
    /// Velocity (m/s) and free drift (m) of the last full build.
    base_v0: V2,
    base_free: V2,
    base_valid: bool,
    base_poly: Vec<V2>,
    /// Fold points (offset, displacement; m) whose images are vertices of
    /// the base polygon.
    base_folds: Vec<(V2, V2)>,
    /// The base polygon vertex index of each of `base_folds`.
    base_fold_vertex: Vec<usize>,
    /// Every fold point of the last build (scratch).
    all_folds: Vec<(V2, V2)>,
    /// Sorted bit keys of the base polygon's vertices with their indices (scratch).
    keys: Vec<((u64, u64), usize)>,
    /// The last build's sampled map (for the full solve).
    map: Option<SampledMap>,
    /// This tick's envelope polygon (m).
    poly: Vec<V2>,
    /// Rotating start of the fold points checked.
    verify_next: usize,
    /// The spread build under way.
    pending: Option<EnvelopeBuild>,
    stats: TickStats,
}

impl TickController {
    /// A controller with validated settings and no history.
    pub fn new(params: TickParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            prev_trap: None,
            base_v0: V2::zeros(),
            base_free: V2::zeros(),
            base_valid: false,
            base_poly: Vec::new(),
            base_folds: Vec::new(),
            base_fold_vertex: Vec::new(),
            all_folds: Vec::new(),
            keys: Vec::new(),
            map: None,
            poly: Vec::new(),
            verify_next: 0,
            pending: None,
            stats: TickStats::default(),
        })
    }

    /// Forget the previous trap position (on grab); the last build stays.
    pub fn reset(&mut self) {
        self.prev_trap = None;
    }

    /// Continue the next tick's solve from the trap at `trap` (world, m): on
    /// grab, the trap the particle sits in.
    pub fn continue_from(&mut self, trap: &V2) {
        self.prev_trap = Some(*trap);
    }

    /// Builds the envelope for velocity `v0` (m/s) now, whole (before the
    /// first tick: the first grabbed tick is then warm). Does nothing when
    /// warm start is off.
    pub fn prebuild(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<()> {
        finite_vec("velocity [m/s]", v0.as_slice())?;
        if self.params.warm_start {
            self.pending = None;
            self.rebuild(prop, v0)?;
        }
        Ok(())
    }

    /// Between grabs: keeps the last build fresh for a particle of velocity
    /// `v0` (m/s) with the spread build of a tick (one slice, started when
    /// the velocity has moved more than `spread_dv` from the last build's),
    /// so the next grab finds a warm envelope. Returns the force
    /// evaluations spent. Does nothing without warm start or spread builds.
    pub fn prepare(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<u64> {
        finite_vec("velocity [m/s]", v0.as_slice())?;
        if !self.params.warm_start || self.params.build_evals_per_tick.is_none() {
            return Ok(0);
        }
        let spent = self.advance_pending(prop)?;
        self.maybe_start(prop, v0)?;
        Ok(spent)
    }

    /// The velocity (m/s) of the build in service (`None`: none yet).
    pub fn build_velocity(&self) -> Option<V2> {
        self.base_valid.then_some(self.base_v0)
    }

    /// Whether a spread build is under way.
    pub fn building(&self) -> bool {
        self.pending.is_some()
    }

    /// This tick's working envelope (m, counter-clockwise).
    pub fn envelope(&self) -> &[V2] {
        &self.poly
    }

    /// The counters so far.
    pub fn stats(&self) -> TickStats {
        self.stats
    }

    /// The settings.
    pub fn params(&self) -> &TickParams {
        &self.params
    }

    /// A whole build for `v0`, put in service now.
    fn rebuild(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<()> {
        if self.pending.take().is_some() {
            self.stats.dropped_builds += 1;
        }
        let mut b = EnvelopeBuild::new(
            prop,
            v0,
            self.params.steer.margin_waists,
            self.params.cell_waists,
            self.params.steer.tol,
        )?;
        b.advance(prop, None)?;
        if let Some(built) = b.take() {
            self.install(built);
        }
        Ok(())
    }

    /// One slice of the spread build under way; a finished build is put in
    /// service. Returns the force evaluations spent.
    fn advance_pending(&mut self, prop: &Propagator<2>) -> Result<u64> {
        let Some(b) = self.pending.as_mut() else {
            return Ok(0);
        };
        let r = match b.advance(prop, self.params.build_evals_per_tick) {
            Ok(r) => r,
            Err(e) => {
                self.pending = None;
                return Err(e);
            }
        };
        self.stats.build_slices += 1;
        self.stats.max_slice_evals = self.stats.max_slice_evals.max(r.evals);
        if r.done {
            if let Some(built) = b.take() {
                self.install(built);
                self.stats.spread_builds += 1;
            }
            self.pending = None;
        }
        Ok(r.evals)
    }

    /// Starts a spread build for `v0` when none is under way, spread builds
    /// are on, and the build in service is missing or `spread_dv` away.
    fn maybe_start(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<()> {
        if self.pending.is_none()
            && self.params.build_evals_per_tick.is_some()
            && (!self.base_valid || (v0 - self.base_v0).norm() > self.params.spread_dv)
        {
            self.pending = Some(EnvelopeBuild::new(
                prop,
                v0,
                self.params.steer.margin_waists,
                self.params.cell_waists,
                self.params.steer.tol,
            )?);
        }
        Ok(())
    }

    /// Puts a finished build in service.
    fn install(&mut self, built: BuiltEnvelope) {
        self.base_poly = built.envelope.polygon;
        self.base_free = built.envelope.free_displacement;
        self.base_v0 = built.envelope.v0;
        self.all_folds = built.folds;
        self.keys.clear();
        self.keys.extend(
            self.base_poly
                .iter()
                .enumerate()
                .map(|(i, p)| ((p.x.to_bits(), p.y.to_bits()), i)),
        );
        self.keys.sort_unstable();
        self.base_folds.clear();
        self.base_fold_vertex.clear();
        for f in &self.all_folds {
            let key = (f.1.x.to_bits(), f.1.y.to_bits());
            if let Ok(k) = self.keys.binary_search_by(|e| e.0.cmp(&key)) {
                self.base_folds.push(*f);
                self.base_fold_vertex.push(self.keys[k].1);
            }
        }
        self.poly.clear();
        self.poly.extend_from_slice(&self.base_poly);
        self.map = Some(built.map);
        self.base_valid = true;
        self.verify_next = 0;
        self.stats.rebuilds += 1;
    }

    /// Translate the base envelope to `v0` and check it at a few fold
    /// points; `false` when a check fails (or there is nothing to check).
    fn warm(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<bool> {
        if !self.params.warm_start
            || !self.base_valid
            || self.base_folds.is_empty()
            || (v0 - self.base_v0).norm() > self.params.warm_dv
        {
            return Ok(false);
        }
        let shift = free_drift(prop.model(), v0, prop.dt()) - self.base_free;
        self.poly.clear();
        self.poly.extend(self.base_poly.iter().map(|p| p + shift));
        let n = self.base_folds.len();
        let k = self.params.verify_points.min(n);
        for i in 0..k {
            let j = (self.verify_next + i * n / k) % n;
            let (o, _) = self.base_folds[j];
            let (d, _, _) = prop.flow(&o, v0)?;
            // distance to the polygon edges around the fold's own vertex: at
            // least the distance to the whole boundary, so never laxer
            if window_distance(&self.poly, self.base_fold_vertex[j], &d) > self.params.verify_tol {
                self.stats.verify_failures += 1;
                return Ok(false);
            }
        }
        self.verify_next = (self.verify_next + 1) % n;
        Ok(true)
    }

    /// Newton continued from `prev`, then from the fold points whose
    /// translated images are nearest the target.
    fn quick_solve(
        &self,
        nw: &Newton<'_>,
        target: &V2,
        prev: Option<&V2>,
        shift: &V2,
    ) -> Result<Option<(V2, Choice)>> {
        let mut evals = 0;
        if let Some(p) = prev
            && let Some((o, _)) = nw.run(p, target, &mut evals, &[], &nw.w)?
        {
            return Ok(Some((o, Choice::Continued)));
        }
        let mut best = [(f64::INFINITY, usize::MAX); FOLD_SEEDS];
        for (k, (_, d)) in self.base_folds.iter().enumerate() {
            let dist = (d + shift - target).norm();
            if dist < best[FOLD_SEEDS - 1].0 {
                best[FOLD_SEEDS - 1] = (dist, k);
                best.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            }
        }
        for &(_, k) in best.iter().filter(|b| b.1 != usize::MAX) {
            let (o, _) = self.base_folds[k];
            if let Some((o, _)) = nw.run(&o, target, &mut evals, &[], &nw.w)? {
                return Ok(Some((o, Choice::FoldSeeded)));
            }
        }
        Ok(None)
    }

    /// One tick: the cursor commands the particle to `cursor` (world, m).
    pub fn step(
        &mut self,
        prop: &Propagator<2>,
        particle: &ParticleState,
        cursor: &V2,
    ) -> Result<TickOutput> {
        finite_vec("particle.position [m]", particle.position.as_slice())?;
        finite_vec("particle.velocity [m/s]", particle.velocity.as_slice())?;
        finite_vec("cursor [m]", cursor.as_slice())?;
        self.stats.ticks += 1;
        let v0 = particle.velocity;
        let (slice_evals, mut rebuilt) = self.serve(prop, &v0)?;
        let tol = self.params.steer.tol;
        let free = free_drift(prop.model(), &v0, prop.dt());
        let command = cursor - particle.position;
        let clipped = clip_to_polygon(&self.poly, &free, &command, self.params.steer.mode)?;
        let region = OffsetRegion::around_drift(prop, &v0, self.params.steer.margin_waists)?;
        let nw = Newton {
            prop,
            v0,
            w: prop.model().well.waists(),
            region,
            residual: DEFAULT_RESIDUAL,
            // one root continued: no extra steps past the residual
            polish: 0,
        };
        let prev = self.prev_trap.map(|t| t - particle.position);
        let shift = free - self.base_free;
        // The clipped point lies on the polygon, up to `tol` from the true
        // boundary: pull it inward by 2 tol when it is not reachable.
        let back = if clipped.excess.norm() > 0.0 {
            clipped.excess / clipped.excess.norm() * (2.0 * tol)
        } else {
            V2::zeros()
        };
        let mut solved = solve_pulled_back(clipped.allowed, back, |t| {
            self.quick_solve(&nw, t, prev.as_ref(), &shift)
        })?;
        if solved.is_none() {
            solved = self.full_solve(
                prop,
                &v0,
                clipped.allowed,
                back,
                prev.as_ref(),
                &mut rebuilt,
            )?;
        }
        let (target, (offset, choice)) = match solved {
            Some(s) => s,
            None => self.park(prop, &region, &v0)?,
        };
        match choice {
            Choice::Continued => self.stats.continued += 1,
            Choice::FoldSeeded => self.stats.fold_seeded += 1,
            Choice::SmallestMove => {}
        }
        let trap = particle.position + offset;
        self.prev_trap = Some(trap);
        let excess = command - target;
        Ok(TickOutput {
            trap,
            allowed: target,
            excess,
            force: -excess * self.params.steer.stiffness,
            choice,
            rebuilt,
            slice_evals,
        })
    }

    /// Puts an envelope for `v0` in service: the pending build advanced (with warm start),
    /// then the base envelope translated when its checks pass, else a rebuild. Returns the
    /// force evaluations the pending build spent and whether this tick rebuilt.
    fn serve(&mut self, prop: &Propagator<2>, v0: &V2) -> Result<(u64, bool)> {
        let slice_evals = if self.params.warm_start {
            self.advance_pending(prop)?
        } else {
            0
        };
        if self.warm(prop, v0)? {
            self.maybe_start(prop, v0)?;
            Ok((slice_evals, false))
        } else {
            self.rebuild(prop, v0)?;
            Ok((slice_evals, true))
        }
    }

    /// The full solve on a grid for velocity `v0` (the build in service when it is for this
    /// very velocity, else a rebuild unless this tick has `rebuilt` already), for `allowed`
    /// then `allowed − back` (m): the target reached and its offset, or `None`.
    fn full_solve(
        &mut self,
        prop: &Propagator<2>,
        v0: &V2,
        allowed: V2,
        back: V2,
        prev: Option<&V2>,
        rebuilt: &mut bool,
    ) -> Result<Option<(V2, (V2, Choice))>> {
        let fresh = self.base_valid
            && self.map.as_ref().is_some_and(|m| {
                m.v0.x.to_bits() == v0.x.to_bits() && m.v0.y.to_bits() == v0.y.to_bits()
            });
        if !*rebuilt && !fresh {
            self.rebuild(prop, v0)?;
            *rebuilt = true;
        }
        self.stats.full_solves += 1;
        let Some(map) = self.map.take() else {
            return Ok(None);
        };
        let solver = TrapSolver::from_map(prop, map);
        let solved = solve_pulled_back(allowed, back, |t| solver.steer(t, prev))?;
        self.map = Some(solver.map);
        Ok(solved)
    }

    /// Unreachable even after the pull-back (a boundary sliver thinner than
    /// the tolerance): parks the trap at the region's corner, where the
    /// particle drifts almost freely. Returns the displacement that really
    /// happens (m) and the offset (m).
    fn park(
        &mut self,
        prop: &Propagator<2>,
        region: &OffsetRegion,
        v0: &V2,
    ) -> Result<(V2, (V2, Choice))> {
        self.stats.parked += 1;
        let o = region.hi;
        let target = prop.flow(&o, v0)?.0;
        Ok((target, (o, Choice::SmallestMove)))
    }
}

/// `solve` for the clipped point `allowed` (m), then, when that fails and the clip pulled it
/// back by `back` (m, nonzero), for `allowed − back`: the target reached and its solution.
fn solve_pulled_back(
    allowed: V2,
    back: V2,
    mut solve: impl FnMut(&V2) -> Result<Option<(V2, Choice)>>,
) -> Result<Option<(V2, (V2, Choice))>> {
    if let Some(found) = solve(&allowed)? {
        return Ok(Some((allowed, found)));
    }
    if back != V2::zeros() {
        let target = allowed - back;
        return Ok(solve(&target)?.map(|found| (target, found)));
    }
    Ok(None)
}
