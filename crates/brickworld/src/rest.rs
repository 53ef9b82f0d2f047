//! The quiet world: while no brick moves faster than [`QUIET_SPEED_M_PER_S`], resting contacts
//! are reused between steps instead of recomputed.
//!
//! rapier 0.36 reuses ("recycles") a contact pair whose colliders' relative pose moved less than
//! its recycle distance since the pair's last full update, but never a pair in which either
//! collider has active hooks, and the brick world's [`crate::impact::hook::ImpactHook`] needs
//! the hooks for two jobs: the impact rule (a fast landing merged to one point) and skipping
//! idle speculative contacts,
//! which exist because rapier's 2 cm prediction distance looks several steps ahead for the
//! impact rule. While every brick is slower than [`QUIET_SPEED_M_PER_S`], neither job has
//! anything to do that a short prediction distance does not do as well:
//! - no contact approaches at the impact rule's [`IMPACT_MIN_SPEED_M_PER_S`] (two bricks close at
//!   most twice the quiet speed);
//! - every contact and pair the hook would keep lies within [`quiet_prediction_m`] (the hook
//!   keeps points within [`SPECULATIVE_KEEP_M`] and pairs within it plus
//!   [`PAIR_LOOKAHEAD_STEPS`] steps of their closing speed), and nothing farther is computed.
//!
//! So a step is quiet when every awake brick has been slower than [`QUIET_SPEED_M_PER_S`]
//! for [`QUIET_AFTER_S`] (resting, not at the apex of a bounce), no brick is carried, and the
//! hand touches nothing (what the hand feels is computed from contacts computed afresh). In a
//! quiet step the brick colliders run without hooks at the short prediction distance, and
//! rapier recycles their resting pairs; the first step that is not quiet turns the hooks and
//! the 2 cm prediction back on for every brick before it is solved. The decision reads only
//! the world's state, so a replay makes the same decisions on the same ticks. Changing
//! friction, restitution or mass makes the next step a full one: a recycled pair keeps the
//! material it was computed with.
//!
//! **Where nothing can sleep** (`Params::sleeping` off), a step that turns quiet also marks
//! every brick collider moved, so that rapier fits its broad-phase box to the short prediction
//! distance and drops the pairs of neighbours no longer within it, each otherwise checked every
//! step (20 bricks laid 5 mm apart keep their 20 ground pairs of 75, test); marking a collider
//! wakes the bodies it touches, hence only where none sleeps.
//!
//! **What it costs in accuracy.** A recycled pair keeps its contact normal and points, frozen
//! to the bodies, until the pair moved [`RECYCLE_DISTANCE_M`] (0.1 mm); rapier measures that
//! motion with the larger collider's extent, so a brick on the 100 m ground slab refreshes its
//! ground pair after a turn of 0.7 µrad. Measured (BENCHMARKS.md, `brickworld-report errors`):
//! the error table is unchanged at both shipped settings but for the 200-brick wall's drift
//! from 1 s to 5 s under the scene's, 0.0174 → 0.0127 mm (tests `quiet::a_quiet_wall_stands`,
//! `fast_solver::a_wall_of_200_bricks_stands`); settings that let the wall creep without quiet
//! steps let it creep more (1 iteration at 250 Hz: 5.9 → 12.1 mm in 4 s). A drop onto a resting
//! stack gives the same impacts on the same ticks as with no quiet steps (test).
//! A brick that falls asleep after creeping quiet to the edge of its broad-phase box (rapier's
//! boxes are padded beyond the shape) can keep a box fattened by the short prediction only; a
//! fast brick then meets it 11 mm ahead instead of 20 mm: 2.5 steps at 4.4 m/s (a 1 m drop),
//! where the impact rule reads the manifold 2 steps ahead.

use rapier3d_f64::prelude::{ActiveHooks, ColliderHandle, PhysicsWorld, RigidBodyHandle};

use crate::impact::IMPACT_MIN_SPEED_M_PER_S;
use crate::impact::hook::{PAIR_LOOKAHEAD_STEPS, SPECULATIVE_KEEP_M};

/// Largest speed, m/s, of any point of any awake brick for the world to count as quiet: two
/// bricks then close at most at 0.04 m/s, below the impact rule's 0.05 m/s.
pub const QUIET_SPEED_M_PER_S: f64 = 0.02;
const _: () = assert!(2.0 * QUIET_SPEED_M_PER_S < IMPACT_MIN_SPEED_M_PER_S);

/// Relative motion, m, of two colliders within which rapier reuses their contacts (a resting
/// pair's frozen normal and contact points are recomputed whenever it moved farther).
pub const RECYCLE_DISTANCE_M: f64 = 1e-4;

/// How long, s, every brick must have been slow before a step runs quiet: resting, not the
/// apex of a bounce or a pause in a rattle.
pub const QUIET_AFTER_S: f64 = 0.05;

/// The hooks every brick collider has outside quiet steps.
pub(crate) const BRICK_HOOKS: ActiveHooks =
    ActiveHooks::FILTER_CONTACT_PAIRS.union(ActiveHooks::MODIFY_SOLVER_CONTACTS);

/// The prediction distance, m, of a quiet step of `dt_s`: the hook's keep distance plus its
/// pair lookahead at twice the quiet speed (two bricks closing), plus the keep distance again
/// as a margin.
pub fn quiet_prediction_m(dt_s: f64) -> f64 {
    2.0 * SPECULATIVE_KEEP_M + PAIR_LOOKAHEAD_STEPS * dt_s * 2.0 * QUIET_SPEED_M_PER_S
}

/// Whether the last step was quiet, what decides the next, and rapier's own prediction distance
/// to go back to.
#[derive(Debug, Clone)]
pub(crate) struct ContactMode {
    quiet: bool,
    /// The next step must not be quiet, so that every pair is computed afresh.
    refresh: bool,
    /// Consecutive steps, the coming one included, with every brick slow before it.
    slow_steps: u32,
    /// rapier's normalized prediction distance outside quiet steps.
    normal_prediction: f64,
}

impl ContactMode {
    /// The mode of a world built with `phys`'s parameters (not quiet), and the recycle
    /// distance set.
    pub(crate) fn new(phys: &mut PhysicsWorld) -> ContactMode {
        let p = &mut phys.integration_parameters;
        p.normalized_contact_recycle_distance = RECYCLE_DISTANCE_M / p.length_unit;
        ContactMode {
            quiet: false,
            refresh: false,
            slow_steps: 0,
            normal_prediction: p.normalized_prediction_distance,
        }
    }

    /// Makes the next step a full one, every brick pair computed afresh: rapier keeps a
    /// recycled pair's contacts as computed, with the friction and restitution of then (a
    /// brick at rest on a ramp kept its old friction after `set_friction`, and did not slide).
    pub(crate) fn refresh(&mut self) {
        self.refresh = true;
    }

    /// Whether the last step ran quiet.
    pub(crate) fn is_quiet(&self) -> bool {
        self.quiet
    }

    /// Sets the mode of the coming step from the bricks (`(body, collider)`, no point farther
    /// than `radius_m` from the centre of mass) and returns whether it is quiet: if `allowed`
    /// and every awake brick is dynamic and has been slower than [`QUIET_SPEED_M_PER_S`] at
    /// every point for [`QUIET_AFTER_S`]. Then no impact can be solved or reported (two bricks
    /// close slower than the impact rule's [`IMPACT_MIN_SPEED_M_PER_S`]), and the hook has
    /// nothing to do. With `refit` (no brick can sleep), a step that turns quiet also fits the
    /// bricks' broad-phase boxes to the short prediction distance.
    pub(crate) fn before_step(
        &mut self,
        phys: &mut PhysicsWorld,
        bricks: impl Iterator<Item = (RigidBodyHandle, ColliderHandle)> + Clone,
        radius_m: f64,
        allowed: bool,
        refit: bool,
    ) -> bool {
        let refresh = std::mem::take(&mut self.refresh);
        let slow = allowed && !refresh && all_slow(phys, bricks.clone(), radius_m);
        self.slow_steps = if slow {
            self.slow_steps.saturating_add(1)
        } else {
            0
        };
        // (The tolerance: 50 steps of 1 ms are 0.05 s, whatever the rounding.)
        let quiet =
            f64::from(self.slow_steps) * phys.integration_parameters.dt >= QUIET_AFTER_S - 1e-12;
        if quiet == self.quiet {
            return quiet;
        }
        self.quiet = quiet;
        let p = &mut phys.integration_parameters;
        p.normalized_prediction_distance = if quiet {
            quiet_prediction_m(p.dt) / p.length_unit
        } else {
            self.normal_prediction
        };
        for (_, collider) in bricks {
            if let Some(co) = phys.colliders.get_mut(collider) {
                co.set_active_hooks(if quiet {
                    ActiveHooks::empty()
                } else {
                    BRICK_HOOKS
                });
                if quiet && refit {
                    // The collider's broad-phase box still has the 2 cm margin: marking the
                    // collider moved has rapier fit it to the short one, and drop the pairs of
                    // neighbours no longer within it. (It also wakes the bodies it touches, so
                    // only where none can sleep.)
                    if let Some(pose) = co.position_wrt_parent().copied() {
                        co.set_position_wrt_parent(pose);
                    }
                }
            }
        }
        quiet
    }
}

/// Whether every awake brick is dynamic and no point of it moves faster than the quiet speed
/// (`radius_m` bounds a point's distance from the centre of mass).
fn all_slow(
    phys: &PhysicsWorld,
    mut bricks: impl Iterator<Item = (RigidBodyHandle, ColliderHandle)>,
    radius_m: f64,
) -> bool {
    bricks.all(|(body, _)| {
        phys.bodies.get(body).is_none_or(|rb| {
            rb.is_sleeping()
                || (rb.is_dynamic()
                    && rb.linvel().length() + rb.angvel().length() * radius_m
                        <= QUIET_SPEED_M_PER_S)
        })
    })
}
