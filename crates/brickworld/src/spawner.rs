//! The spawner: the loading zone that supplies a new brick each time the cursor enters it.

use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::parry::shape::{Ball, Cuboid};

use crate::bricks::BrickSet;
use crate::event::Event;
use crate::params::{BrickPlacement, BrickProps, Params};

/// Whether the cursor was inside the loading zone after the last tick.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Spawner {
    in_zone: bool,
}

impl Spawner {
    /// One tick with the device cursor at `cursor` and the proxy at `proxy` (m): when the cursor
    /// enters the zone ([`Params::loading_zone`]; below its height), a brick appears resting
    /// flat at the spawn spot if the spot is clear of bricks and of the cursor sphere and
    /// [`Params::max_bricks`] allows one more.
    pub(crate) fn step(
        &mut self,
        cursor: Vector,
        proxy: Vector,
        params: &Params,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        let Some(z) = params.loading_zone.as_ref() else {
            return;
        };
        let c = cursor;
        let inside = c.x >= z.min_m[0]
            && c.x <= z.max_m[0]
            && c.y >= z.min_m[1]
            && c.y <= z.max_m[1]
            && c.z <= z.height_m;
        let entered = inside && !self.in_zone;
        self.in_zone = inside;
        if !entered || bricks.len() >= params.max_bricks {
            return;
        }
        let e = params.brick_half_extents_m;
        let spawn = BrickPlacement {
            center_m: [z.spawn_m[0], z.spawn_m[1], e[2]],
            rotation_deg: [0.0; 3],
        };
        // The spot must be clear (slightly shrunk box: resting on the ground is not overlap).
        let probe = Cuboid::new(Vector::from_array(e) * 0.99);
        let pose = Pose::from_translation(Vector::from_array(spawn.center_m));
        let clear = {
            let qp = bricks.phys.query_pipeline();
            let ball = Ball::new(params.proxy_radius_m);
            let proxy_pose = Pose::from_translation(proxy);
            let hits_scene = qp.intersect_shape(pose, &probe).next().is_some();
            let pos12 = pose.inv_mul(&proxy_pose);
            let hits_proxy = qp
                .dispatcher
                .intersection_test(&pos12, &probe, &ball)
                .map_or(true, |h| h.intersecting);
            !hits_scene && !hits_proxy
        };
        if clear {
            let id = bricks.insert(params, &spawn, &BrickProps::default());
            events.push(Event::Spawned { brick: id });
        }
    }
}
