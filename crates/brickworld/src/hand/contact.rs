//! The god-object: its move towards the device cursor (a rigidly carried brick with it), what
//! it touches, its push on the dynamic bricks it touches, and the nearest solid around it.

use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::parry::shape::{Ball, Cuboid};
use rapier3d_f64::prelude::{
    Collider, ColliderHandle, QueryFilter, RigidBodyHandle, RigidBodyType,
};

use super::{Hand, NEAREST_MAX_M};
use crate::bricks::BrickSet;
use crate::event::{Body, Event, Touch};
use crate::impact::IMPACT_MIN_SPEED_M_PER_S;
use crate::params::Params;
use crate::proxy::{self, HeldShape, ProxyUpdate};

impl Hand {
    /// Moves the god-object towards the cursor `c` (a rigidly carried brick with it, as a
    /// kinematic body); returns the update and the approach speed for impacts, m/s.
    pub(super) fn move_proxy(
        &mut self,
        c: Vector,
        tick: u64,
        params: &Params,
        bricks: &mut BrickSet,
    ) -> (ProxyUpdate, f64) {
        let ball = Ball::new(params.proxy_radius_m);
        let held_shape = self
            .held
            .filter(|h| !h.coupled)
            .and(self.held_shape(params));
        let exclude = self.held.map(|h| bricks.collider(h.brick));
        let ghost = self.letting_go;
        let pass = move |h: ColliderHandle, _: &Collider| Some(h) != ghost;
        let upd = {
            let mut filter = QueryFilter::default().predicate(&pass);
            if let Some(ex) = exclude {
                filter = filter.exclude_collider(ex);
            }
            let qp = bricks.phys.query_pipeline_with_filter(filter);
            proxy::update_proxy(&qp, &ball, &held_shape, self.proxy, c)
        };
        // The brick let go of is solid again once the cursor sphere has left it.
        if let Some(g) = self.letting_go {
            let apart = bricks.phys.colliders.get(g).is_none_or(|co| {
                rapier3d_f64::parry::query::intersection_test(
                    &Pose::from_translation(upd.position),
                    &ball,
                    co.position(),
                    co.shape(),
                )
                .map_or(true, |hit| !hit.intersecting)
            });
            if apart {
                self.letting_go = None;
            }
        }
        let moved = (upd.position - self.proxy).length() / params.dt_s;
        let approach_speed = moved.max(self.proxy_speed);
        self.proxy_speed = if tick == 0 { 0.0 } else { moved };
        self.proxy = upd.position;
        if tick == 0 {
            self.motion.reset(self.proxy.to_array());
        }
        self.motion.push(self.proxy.to_array());
        self.grip_velocity.push(self.proxy.to_array());
        if let Some(h) = self.held.filter(|h| !h.coupled) {
            let body = bricks.body(h.brick);
            if let Some(rb) = bricks.phys.bodies.get_mut(body) {
                rb.set_next_kinematic_position(Pose::from_parts(self.proxy + h.offset, h.rotation));
            }
        }
        (upd, approach_speed)
    }

    /// What the cursor (or carried brick) touches after the update: `TouchEnded` and
    /// `TouchBegan` events, and an `Impact` for a touch begun at speed.
    pub(super) fn touches(
        &mut self,
        upd: &ProxyUpdate,
        tick: u64,
        approach_speed: f64,
        params: &Params,
        bricks: &BrickSet,
        events: &mut Vec<Event>,
    ) {
        let mut touching: Vec<Touch> = upd
            .contacts
            .iter()
            .filter_map(|ct| bricks.touch_of(ct.collider))
            .collect();
        touching.sort();
        touching.dedup();
        for t in &self.touching {
            if touching.binary_search(t).is_err() {
                events.push(Event::TouchEnded { target: *t });
            }
        }
        for t in &touching {
            if self.touching.binary_search(t).is_err() {
                events.push(Event::TouchBegan { target: *t });
                if tick > 0 && approach_speed >= IMPACT_MIN_SPEED_M_PER_S {
                    events.push(Event::Impact {
                        a: Body::Cursor,
                        b: Body::from(*t),
                        impulse_n_s: params.brick_mass_kg * approach_speed,
                        speed_m_per_s: approach_speed,
                        point_m: self.proxy.to_array(),
                    });
                }
            }
        }
        self.touching = touching;
    }

    /// Distance from the cursor sphere's surface to the nearest solid other than the carried
    /// brick, m: 0 when touching, `f64::INFINITY` beyond [`NEAREST_MAX_M`].
    pub(crate) fn nearest_m(&self, params: &Params, bricks: &BrickSet) -> f64 {
        let r = params.proxy_radius_m;
        match self.nearest_point(bricks, NEAREST_MAX_M + r) {
            Some((_, true)) => 0.0,
            Some((point, false)) => ((point - self.proxy).length() - r).max(0.0),
            None => f64::INFINITY,
        }
    }

    /// The nearest solid's point to the proxy within `max_m` of its centre and whether the
    /// proxy is inside it; the carried brick and a brick being let go of are not solids here.
    fn nearest_point(&self, bricks: &BrickSet, max_m: f64) -> Option<(Vector, bool)> {
        let ghost = self.letting_go;
        let pass = move |h: ColliderHandle, _: &Collider| Some(h) != ghost;
        let mut filter = QueryFilter::default().predicate(&pass);
        if let Some(h) = self.held {
            filter = filter.exclude_collider(bricks.collider(h.brick));
        }
        let qp = bricks.phys.query_pipeline_with_filter(filter);
        qp.project_point(self.proxy, max_m, true)
            .map(|(_, proj)| (proj.point, proj.is_inside))
    }

    /// The nearest solid's surface point and outward normal from the proxy (the carried brick
    /// excluded), when it is within `range_m` of the cursor sphere's surface.
    pub(crate) fn nearest_surface(
        &self,
        params: &Params,
        bricks: &BrickSet,
        range_m: f64,
    ) -> Option<(Vector, Vector)> {
        let (point, inside) = self.nearest_point(bricks, range_m + params.proxy_radius_m)?;
        let d = self.proxy - point;
        let len = d.length();
        (!inside && len > 0.0).then(|| (point, d / len))
    }

    fn held_shape(&self, params: &Params) -> Option<HeldShape> {
        self.held.map(|h| {
            let e = params.brick_half_extents_m;
            HeldShape {
                cuboid: Cuboid::new(Vector::from_array(e)),
                offset: h.offset,
                rotation: h.rotation,
            }
        })
    }
}

/// The hand's push on the dynamic bricks it touches: the reaction of the spring it feels
/// (`felt_spring`, N), shared by the contacts, at the contact points, as the impulse of that
/// force over this tick.
pub(super) fn push_bricks(
    upd: &ProxyUpdate,
    felt_spring: Vector,
    params: &Params,
    bricks: &mut BrickSet,
) {
    let pushes: Vec<(RigidBodyHandle, Vector)> = upd
        .contacts
        .iter()
        .filter_map(|ct| {
            let co = bricks.phys.colliders.get(ct.collider)?;
            let body = co.parent()?;
            let rb = bricks.phys.bodies.get(body)?;
            (rb.body_type() == RigidBodyType::Dynamic).then_some((body, ct.point))
        })
        .collect();
    if !pushes.is_empty() && felt_spring.length_squared() > 0.0 {
        // (A user force at a point would be the natural call, but rapier 0.36 does not resist
        // the torque of user forces with contacts: 10 N pressed 5 cm off-centre launched a
        // resting 0.5 kg brick 0.45 m up. Velocity impulses are resisted correctly.)
        let share = -felt_spring * (params.dt_s / pushes.len() as f64);
        for (body, point) in pushes {
            if let Some(rb) = bricks.phys.bodies.get_mut(body) {
                rb.apply_impulse_at_point(share, point, true);
            }
        }
    }
}
