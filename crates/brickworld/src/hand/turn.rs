//! A turn command: the carried brick turns by +90° about a world axis through the grip point,
//! unless the turned brick would overlap something.

use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::parry::shape::Cuboid;
use rapier3d_f64::prelude::QueryFilter;

use super::{Hand, Held};
use crate::bricks::BrickSet;
use crate::event::{Axis, Event};
use crate::params::Params;

impl Hand {
    /// A turn command: the carried brick turns by +90° about a world axis through the grip
    /// point, unless the turned brick would overlap something.
    pub(super) fn turn(
        &mut self,
        axis: Axis,
        params: &Params,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        let Some(h) = self.held else {
            return;
        };
        let a = match axis {
            Axis::X => Vector::X,
            Axis::Y => Vector::Y,
            Axis::Z => Vector::Z,
        };
        let r = Rotation::from_axis_angle(a, std::f64::consts::FRAC_PI_2);
        let offset = r * h.offset;
        let rotation = (r * h.rotation).normalize();
        let collider = bricks.collider(h.brick);
        let e = params.brick_half_extents_m;
        let cuboid = Cuboid::new(Vector::from_array(e));
        // A coupled brick turns about the grip point where it hangs now: its lead on the brick
        // (the sag under its weight) is kept, so the felt force does not jump.
        let lead = match bricks.phys.bodies.get(bricks.body(h.brick)) {
            Some(rb) if h.coupled => self.proxy + h.offset - rb.translation(),
            _ => Vector::ZERO,
        };
        let pose = Pose::from_parts(self.proxy + offset - lead, rotation);
        let blocked = {
            let qp = bricks
                .phys
                .query_pipeline_with_filter(QueryFilter::default().exclude_collider(collider));
            qp.intersect_shape(pose, &cuboid).next().is_some()
        };
        if blocked {
            events.push(Event::RotationBlocked {
                brick: h.brick,
                axis,
            });
            return;
        }
        bricks.wake_neighbours(collider);
        if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(h.brick)) {
            rb.set_position(pose, true);
        }
        self.held = Some(Held {
            offset,
            rotation,
            ..h
        });
        events.push(Event::Rotated {
            brick: h.brick,
            axis,
        });
    }
}
