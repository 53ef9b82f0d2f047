//! `hold` pressed: the nearest brick within reach is taken into the hand, rigidly or through
//! the coupling (already at rest under the brick's weight).

use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::parry::shape::Ball;
use rapier3d_f64::prelude::RigidBodyType;
use world_form::Limits;

use super::{Hand, Held};
use crate::bricks::BrickSet;
use crate::event::{BrickId, Event, Touch};
use crate::params::{Inertia, Params};
use crate::proxy;

impl Hand {
    /// `hold` pressed: carry the nearest brick within reach (ties: the lower id).
    pub(super) fn grab(
        &mut self,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        if self.held.is_some() {
            return;
        }
        let reach = Ball::new(params.proxy_radius_m + params.grab_distance_m + 2.0 * proxy::SKIN_M);
        let pose = Pose::from_translation(self.proxy);
        let mut best: Option<(f64, BrickId)> = None;
        {
            let qp = bricks.phys.query_pipeline();
            for (handle, co) in qp.intersect_shape(pose, &reach) {
                if let Some(Touch::Brick(id)) = bricks.touch_of(handle) {
                    let d = (co.position().translation - self.proxy).length();
                    if best.is_none_or(|(bd, bid)| d < bd || (d == bd && id < bid)) {
                        best = Some((d, id));
                    }
                }
            }
        }
        let Some((_, id)) = best else {
            events.push(Event::GrabMissed);
            return;
        };
        bricks.wake_neighbours(bricks.collider(id));
        let coupled = params.inertia == Inertia::Coupling;
        if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(id)) {
            let pos = *rb.position();
            if coupled {
                // A dynamic body that keeps its orientation in the hand; the coupling holds it.
                rb.lock_rotations(true, true);
                rb.set_angvel(Vector::ZERO, true);
            } else {
                rb.set_body_type(RigidBodyType::KinematicPositionBased, true);
                rb.set_linvel(Vector::ZERO, true);
                rb.set_angvel(Vector::ZERO, true);
            }
            // A coupled brick is taken with its coupling already at rest under the brick's
            // weight (the grip point its static lead above it, the dashpot relaxed): the hand
            // feels the weight from the grab on, and the brick does not drop into the
            // coupling and ring.
            let lead = if coupled {
                Self::static_lead(params, limits, rb.mass())
            } else {
                Vector::ZERO
            };
            self.held = Some(Held {
                brick: id,
                offset: pos.translation - self.proxy + lead,
                rotation: pos.rotation,
                coupled,
            });
            self.grip_velocity.reset(self.proxy.to_array());
            self.damper = lead;
            events.push(Event::Grabbed { brick: id });
        }
    }
}
