//! `hold` released: the carried brick leaves the hand with the grip point's velocity (a throw
//! when fast enough) and is passed through until the cursor sphere has left it.

use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::RigidBodyType;

use super::Hand;
use crate::bricks::BrickSet;
use crate::event::Event;
use crate::params::Params;

impl Hand {
    /// `hold` released: the brick leaves the hand with the grip point's velocity (a throw when
    /// faster than [`Params::throw_min_speed_m_per_s`]).
    pub(super) fn release(
        &mut self,
        params: &Params,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        let Some(h) = self.held.take() else {
            return;
        };
        let v = Vector::from_array(self.grip_velocity.velocity());
        if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(h.brick)) {
            if h.coupled {
                // A coupled brick leaves with the hand's velocity, as a rigidly carried one
                // does: the coupling's own motion (its lag behind a hand that speeds up, its
                // swing) is not thrown with it.
                rb.lock_rotations(false, true);
                rb.set_linvel(v, true);
            } else {
                rb.set_body_type(RigidBodyType::Dynamic, true);
                rb.set_linvel(v, true);
                rb.set_angvel(Vector::ZERO, true);
            }
        }
        bricks.wake_neighbours(bricks.collider(h.brick));
        self.letting_go = Some(bricks.collider(h.brick));
        events.push(Event::Released {
            brick: h.brick,
            velocity_m_per_s: v.to_array(),
        });
        if v.length() >= params.throw_min_speed_m_per_s {
            events.push(Event::Thrown {
                brick: h.brick,
                velocity_m_per_s: v.to_array(),
            });
        }
    }
}
