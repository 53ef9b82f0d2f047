//! A full envelope build (grid, fold tracing, outer boundary) split into
//! slices of bounded work, to be run one slice per haptic tick while the
//! steering controller serves the previous envelope translated to the
//! current velocity ([`crate::tick::TickController`]).
//!
//! Work is counted in force evaluations of the tick map, never in wall time:
//! a slice of budget `B` starts work items while it has spent less than `B`
//! evaluations and finishes every item it starts, so it spends at most
//! `B − 1 +` [`max_item_evals`]. The items (one grid vertex; the crossings
//! of one vertex's two grid edges; one fold point inserted by refinement)
//! run in the one-shot build's order, so the finished build is the one-shot
//! build bit for bit whatever the budget, and how a build is split over
//! ticks depends only on the tick sequence. The last stage (Hermite
//! polylines and the outer boundary of their arrangement, no evaluations)
//! runs alone in a slice of its own.
//!
//! ```
//! use ot_envelope::spread::EnvelopeBuild;
//! use ot_physics::{Method, Propagator, TrapModel};
//! use nalgebra::Vector2;
//! let model = TrapModel::builder(1e-15, [600e-9, 300e-9]).mass(1e-15).build()?;
//! let tick = Propagator::new(model, Method::Rk4 { substeps: 2 }, 0.2e-6)?;
//! let v0 = Vector2::new(0.02, 0.0);
//! let mut spread = EnvelopeBuild::new(&tick, &v0, 3.75, Some(0.6), 0.5e-9)?;
//! let mut slices = 0;
//! while !spread.advance(&tick, Some(256))?.done {
//!     slices += 1;
//! }
//! let mut one_shot = EnvelopeBuild::new(&tick, &v0, 3.75, Some(0.6), 0.5e-9)?;
//! assert!(one_shot.advance(&tick, None)?.done);
//! assert!(slices > 5);
//! assert_eq!(spread.take().map(|b| b.envelope), one_shot.take().map(|b| b.envelope));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::envelope::{Envelope, envelope_from_traced};
use crate::error::{EnvelopeError, Result, ValueError, finite_vec, positive};
use crate::folds::{TraceJob, Traced};
use crate::region::OffsetRegion;
use crate::sample::{MapJob, SampledMap, Slice, coarse_companion};
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// Largest number of force evaluations one work item of a build can spend,
/// for a tick map whose flow with its offset Jacobian costs `flow_evals`
/// evaluations: a refinement point (up to 5 flows with the Jacobian).
pub fn max_item_evals(flow_evals: u64) -> u64 {
    5 * flow_evals
}

/// A finished build: the sampled map, the envelope and its fold points.
#[derive(Debug, Clone)]
pub struct BuiltEnvelope {
    /// The tick map sampled on the build's grid (the inverse solver's input).
    pub map: SampledMap,
    /// The working envelope for the build's velocity.
    pub envelope: Envelope,
    /// Every traced fold point as (offset, displacement) (m).
    pub folds: Vec<(V2, V2)>,
}

/// What one slice did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SliceReport {
    /// Force evaluations spent in this slice.
    pub evals: u64,
    /// Whether this slice was the geometry stage (outer boundary; no evaluations).
    pub geometry: bool,
    /// Whether the build is complete (after this slice).
    pub done: bool,
}

#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Stage {
    Sample(MapJob),
    Trace(SampledMap, TraceJob),
    Geometry(SampledMap, Traced),
    Done(BuiltEnvelope),
    Taken,
}

impl std::fmt::Debug for Traced {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Traced")
            .field("fold_curves", &self.fold_curves)
            .field("evals", &self.evals)
            .finish_non_exhaustive()
    }
}

/// A resumable full envelope build for one velocity.
#[derive(Debug, Clone)]
pub struct EnvelopeBuild {
    v0: V2,
    tol: f64,
    stage: Stage,
}

impl EnvelopeBuild {
    /// A build of the envelope of `prop`'s tick for velocity `v0` (m/s), over
    /// the region `margin_waists` waists around the drift path, with a grid
    /// of `cell_waists` waists per cell (`None`: the default spacing) and
    /// polygon tolerance `tol` (m). Lays out the grid; evaluates nothing.
    pub fn new(
        prop: &Propagator<2>,
        v0: &V2,
        margin_waists: f64,
        cell_waists: Option<f64>,
        tol: f64,
    ) -> Result<Self> {
        finite_vec("velocity [m/s]", v0.as_slice())?;
        let tol = positive("tol [m]", tol)?;
        let region = OffsetRegion::around_drift(prop, v0, margin_waists)?;
        let coarse = coarse_companion(prop, v0);
        let job = MapJob::new(prop, coarse, v0, &region, cell_waists)?;
        Ok(Self {
            v0: *v0,
            tol,
            stage: Stage::Sample(job),
        })
    }

    /// The velocity the build is for (m/s).
    pub fn velocity(&self) -> V2 {
        self.v0
    }

    /// Whether the build is complete (and not yet taken).
    pub fn is_done(&self) -> bool {
        matches!(self.stage, Stage::Done(_))
    }

    /// Runs one slice of at most `budget` force evaluations (plus the last
    /// item's; see [`max_item_evals`]); `None`: to completion. A budget of 0
    /// is refused (it would never finish).
    pub fn advance(&mut self, prop: &Propagator<2>, budget: Option<u64>) -> Result<SliceReport> {
        if budget == Some(0) {
            return Err(EnvelopeError::Value(ValueError::out_of_range(
                "budget [force evaluations]",
                0.0,
                "≥ 1",
            )));
        }
        let mut slice = budget.map_or_else(Slice::unlimited, Slice::new);
        let mut geometry = false;
        loop {
            match std::mem::replace(&mut self.stage, Stage::Taken) {
                Stage::Sample(mut job) => {
                    if job.run(prop, &mut slice)? {
                        let trace = TraceJob::new(prop, &job.map);
                        self.stage = Stage::Trace(job.map, trace);
                    } else {
                        self.stage = Stage::Sample(job);
                        break;
                    }
                }
                Stage::Trace(map, mut job) => {
                    if job.run(prop, &map, self.tol, &mut slice)? {
                        self.stage = Stage::Geometry(map, job.finish());
                    } else {
                        self.stage = Stage::Trace(map, job);
                        break;
                    }
                }
                Stage::Geometry(map, traced) => {
                    if budget.is_some() && slice.spent > 0 {
                        // the geometry stage runs alone in a slice
                        self.stage = Stage::Geometry(map, traced);
                        break;
                    }
                    let mut folds = Vec::new();
                    let envelope =
                        envelope_from_traced(prop, &map, traced, self.tol, Some(&mut folds))?;
                    geometry = true;
                    self.stage = Stage::Done(BuiltEnvelope {
                        map,
                        envelope,
                        folds,
                    });
                    break;
                }
                s @ (Stage::Done(_) | Stage::Taken) => {
                    self.stage = s;
                    break;
                }
            }
        }
        Ok(SliceReport {
            evals: slice.spent,
            geometry,
            done: self.is_done(),
        })
    }

    /// The finished build (once; `None` before it is done or after it was taken).
    pub fn take(&mut self) -> Option<BuiltEnvelope> {
        match std::mem::replace(&mut self.stage, Stage::Taken) {
            Stage::Done(b) => Some(b),
            s => {
                self.stage = s;
                None
            }
        }
    }
}
