//! Impacts, one concept: a contact that begins — its colliders carried no impulse on the
//! previous step — with its bodies approaching faster than [`IMPACT_MIN_SPEED_M_PER_S`] along
//! the contact normal. Slower new contacts are gentle placements; resting and sliding contacts
//! (which carry impulse every step) are never impacts.
//!
//! Two jobs follow from it, one submodule each:
//!
//! * [`hook`]: what the solver does with an impact, during the step: [`hook::ImpactHook`], the
//!   rapier contact hook, solves a flat landing as one simultaneous impact (restitution `e v`
//!   without spin) and, being the one hook rapier takes, also skips the idle speculative
//!   contacts;
//! * [`events`]: what the world reports after the step: [`events::ImpactTracker`] finds the
//!   impacts that happened and raises an [`crate::Event::Impact`] for each, with the impulse
//!   the solver spent (the loudness of a collision sound).
//!
//! The hand uses the same threshold for the cursor's own impacts (`hand`).

pub mod events;
pub mod hook;

use rapier3d_f64::prelude::{Collider, ContactPair, PhysicsWorld};

/// The two colliders of a contact pair (`None` when either was removed), as both jobs read
/// them.
fn pair_colliders<'a>(
    phys: &'a PhysicsWorld,
    pair: &ContactPair,
) -> Option<(&'a Collider, &'a Collider)> {
    Some((
        phys.colliders.get(pair.collider1)?,
        phys.colliders.get(pair.collider2)?,
    ))
}

/// Approach speed (m/s) below which a new contact is treated as a gentle placement, not an impact.
pub const IMPACT_MIN_SPEED_M_PER_S: f64 = 0.05;
