//! The pure steering controller (paper §2.4): per tick, from the particle
//! state and the cursor, where to put the trap and what the hand feels.
//! No I/O, no clock; the haptic loop wraps it.

use crate::clip::{ClipMode, clip_command};
use crate::envelope::{Envelope, EnvelopeOptions, envelope_from_map};
use crate::error::{Result, finite_vec, positive};
use crate::inverse::{Choice, TrapSolver};
use crate::region::{DEFAULT_MARGIN_WAISTS, OffsetRegion};
use crate::sample::{SampledMap, coarse_companion};
use nalgebra::Vector2;
use ot_physics::Propagator;
use serde::Deserialize;

type V2 = Vector2<f64>;

/// What never changes during a steering session.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteerParams {
    /// Spring stiffness of the haptic wall on the excess (N/m, > 0).
    pub stiffness: f64,
    /// Clipping rule.
    #[serde(default)]
    pub mode: ClipMode,
    /// Envelope tolerance (m, > 0).
    #[serde(default = "default_tol")]
    pub tol: f64,
    /// Region half-width beyond the drift path (waists, > 0).
    #[serde(default = "default_margin")]
    pub margin_waists: f64,
}

fn default_tol() -> f64 {
    crate::envelope::DEFAULT_TOL
}
fn default_margin() -> f64 {
    DEFAULT_MARGIN_WAISTS
}

impl SteerParams {
    /// Check every field.
    pub fn validate(&self) -> Result<()> {
        positive("stiffness [N/m]", self.stiffness)?;
        positive("tol [m]", self.tol)?;
        positive("margin_waists [waists]", self.margin_waists)?;
        Ok(())
    }
}

/// The particle at the start of a tick (world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleState {
    /// Position (m).
    pub position: V2,
    /// Velocity (m/s).
    pub velocity: V2,
}

/// One tick's decision.
#[derive(Debug, Clone, PartialEq)]
pub struct SteerOutput {
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
    /// The tick's working envelope (m).
    pub envelope: Envelope,
}

/// The steering controller: parameters plus the previous trap position.
#[derive(Debug, Clone)]
pub struct Controller {
    params: SteerParams,
    prev_trap: Option<V2>,
}

impl Controller {
    /// A controller with validated parameters and no history.
    pub fn new(params: SteerParams) -> Result<Self> {
        params.validate()?;
        Ok(Self {
            params,
            prev_trap: None,
        })
    }

    /// Forget the previous trap position (on grab).
    pub fn reset(&mut self) {
        self.prev_trap = None;
    }

    /// One tick: the cursor commands the particle to `cursor` (world, m).
    /// Computes the envelope of this tick, clips the command, solves for the
    /// trap offset (continuity first, then smallest move) and returns the
    /// trap position and the spring force on the excess.
    pub fn step(
        &mut self,
        prop: &Propagator<2>,
        particle: &ParticleState,
        cursor: &V2,
    ) -> Result<SteerOutput> {
        finite_vec("particle.position [m]", particle.position.as_slice())?;
        finite_vec("cursor [m]", cursor.as_slice())?;
        let v0 = particle.velocity;
        let region = OffsetRegion::around_drift(prop, &v0, self.params.margin_waists)?;
        let coarse = coarse_companion(prop, &v0);
        let map = SampledMap::build_with(prop, coarse.as_ref(), &v0, &region, None)?;
        let opts = EnvelopeOptions {
            tol: self.params.tol,
            ..Default::default()
        };
        let envelope = envelope_from_map(prop, &map, opts.tol)?;
        let command = cursor - particle.position;
        let clipped = clip_command(&envelope, &command, self.params.mode)?;
        let solver = TrapSolver::from_map(prop, map);
        let prev = self.prev_trap.map(|t| t - particle.position);
        // The clipped point lies on the polygon, up to `tol` from the true
        // boundary: pull it inward by 2 tol so that it is reachable.
        let mut target = clipped.allowed;
        let mut found = solver.steer(&target, prev.as_ref())?;
        if found.is_none() && clipped.excess.norm() > 0.0 {
            let back = clipped.excess / clipped.excess.norm();
            target -= back * (2.0 * self.params.tol);
            found = solver.steer(&target, prev.as_ref())?;
        }
        let (offset, choice) = match found {
            Some(x) => x,
            None => {
                // Unreachable even after the pull-back (a boundary sliver
                // thinner than the tolerance): park the trap at the region's
                // corner, where the particle drifts almost freely, and report
                // the displacement that really happens.
                let o = region.hi;
                target = prop.flow(&o, &v0)?.0;
                (o, Choice::SmallestMove)
            }
        };
        let trap = particle.position + offset;
        self.prev_trap = Some(trap);
        let excess = command - target;
        Ok(SteerOutput {
            trap,
            allowed: target,
            excess,
            force: -excess * self.params.stiffness,
            choice,
            envelope,
        })
    }
}
