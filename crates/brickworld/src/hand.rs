//! The hand: the cursor proxy (god-object), the grip commands (grab, release, throw, turn),
//! the force the device renders (proxy spring, weight and inertia of the carried brick,
//! scaled down to the device's largest force) and the hand's push on the bricks it touches.

use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::parry::shape::{Ball, Cuboid};
use rapier3d_f64::prelude::{
    Collider, ColliderHandle, QueryFilter, RigidBodyHandle, RigidBodyType,
};
use world_form::Limits;

use crate::bricks::BrickSet;
use crate::estimator::{AdaptiveWindow, MotionEstimator};
use crate::event::{Axis, Body, BrickId, Event, Touch};
use crate::impact::IMPACT_MIN_SPEED_M_PER_S;
use crate::input::{CursorInput, Grip};
use crate::params::{AccelEstimator, Inertia, Params};
use crate::proxy::{self, HeldShape, ProxyUpdate};

/// Range of [`crate::World::nearest_m`], m: farther solids count as none.
pub const NEAREST_MAX_M: f64 = 1.0;

/// The carried brick and how it sits in the hand.
#[derive(Debug, Clone, Copy)]
struct Held {
    brick: BrickId,
    /// Brick centre minus proxy centre, world frame, m.
    offset: Vector,
    /// Brick orientation.
    rotation: Rotation,
    /// Whether the brick is a dynamic body joined by the virtual coupling (else it is carried
    /// kinematically, the paper's way).
    coupled: bool,
}

/// The force one step of the hand sends to the device, and its parts (N, world frame).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Felt {
    /// Spring + weight + inertia, scaled down to [`Limits::max_force_n`] if larger.
    pub force: Vector,
    /// Whether `force` was scaled down.
    pub saturated: bool,
    /// Proxy spring `k (p - c)`, N.
    pub spring: Vector,
    /// Weight of the carried brick, N.
    pub weight: Vector,
    /// Inertial force of the carried brick (the paper's `−M a`), N.
    pub inertia: Vector,
    /// The virtual coupling's pull on the hand (the reaction of its pull on the brick), N,
    /// before the scale-down.
    pub coupling: Vector,
    /// Grip-point acceleration estimate, m/s².
    pub acceleration: Vector,
    /// Deepest penetration found before the proxy was pushed out, m.
    pub penetration_m: f64,
}

/// The haptic cursor: proxy, device cursor, grip state, motion history and touches.
pub(crate) struct Hand {
    /// Centre of the cursor sphere (god-object), m.
    proxy: Vector,
    /// Last device cursor position, m.
    cursor: Vector,
    /// The grip commands of the last sample (for press and release edges).
    grip: Grip,
    /// Velocity and acceleration of the grip point from the proxy's history.
    motion: MotionEstimator,
    /// Velocity of the grip point for a rigidly carried brick's release (adaptive window).
    grip_velocity: AdaptiveWindow,
    /// The coupling dashpot's share of the grip point's lead on the brick, m.
    damper: Vector,
    held: Option<Held>,
    /// What the cursor (or carried brick) touches, sorted.
    touching: Vec<Touch>,
    /// Outward normals of the surfaces the god-object touched in the last update.
    contact_normals: Vec<Vector>,
    /// A brick just let go of that the cursor sphere still overlaps (a coupled brick's
    /// coupling lets the hand sink into it): passed through until they separate, so letting
    /// go never kicks the hand out of the brick.
    letting_go: Option<ColliderHandle>,
    /// The proxy's speed over the last tick, m/s (for cursor impacts).
    proxy_speed: f64,
    /// Whether a sample has arrived.
    started: bool,
}

impl Hand {
    /// A hand at the top centre of the workspace, holding nothing, until the first sample.
    pub(crate) fn new(params: &Params) -> Hand {
        let top = Vector::new(0.0, 0.0, params.workspace_half_extent_m);
        Hand {
            proxy: top,
            cursor: top,
            grip: Grip::default(),
            motion: MotionEstimator::new(params.dt_s, params.accel_estimator),
            grip_velocity: AdaptiveWindow::new(
                params.dt_s,
                params.release_velocity_band_m,
                params.release_velocity_max_window,
            ),
            damper: Vector::ZERO,
            held: None,
            touching: Vec::new(),
            contact_normals: Vec::new(),
            letting_go: None,
            proxy_speed: 0.0,
            started: false,
        }
    }

    /// Centre of the cursor sphere, m.
    pub(crate) fn proxy(&self) -> Vector {
        self.proxy
    }

    /// Last device cursor position, m.
    pub(crate) fn cursor(&self) -> Vector {
        self.cursor
    }

    /// The carried brick, if any.
    pub(crate) fn held_brick(&self) -> Option<BrickId> {
        self.held.map(|h| h.brick)
    }

    /// What the cursor (or carried brick) touches now, sorted.
    pub(crate) fn touching(&self) -> &[Touch] {
        &self.touching
    }

    /// Restarts the acceleration estimate with `kind`, from the proxy's current position.
    pub(crate) fn set_accel_estimator(&mut self, dt_s: f64, kind: AccelEstimator) {
        let newest = self.proxy.to_array();
        self.motion = MotionEstimator::new(dt_s, kind);
        self.motion.reset(newest);
    }

    /// One tick of the hand with the device sample `input`: grip edges (release before grab, so
    /// one tick can't do both on one brick; then the turns), the god-object update, the force
    /// for the device, touch events and the hand's push on dynamic bricks.
    pub(crate) fn step(
        &mut self,
        input: &CursorInput,
        tick: u64,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) -> Felt {
        let c = Vector::from_array(input.position_m());
        self.cursor = c;
        if !self.started {
            // The first sample: the proxy comes down from the top of the workspace onto the
            // cursor, so it starts outside every solid even if the cursor starts inside one.
            self.proxy = Vector::new(c.x, c.y, params.workspace_half_extent_m);
            self.started = true;
        }
        // 1. Grip: release before grab so one tick can't do both on one brick.
        self.grip_edges(input.grip(), params, limits, bricks, events);
        // 2. God-object update (a coupled brick is a body of its own, not part of the proxy).
        let (upd, approach_speed) = self.move_proxy(c, tick, params, bricks);
        // 3. The force the device renders this tick.
        let (felt, felt_spring) =
            self.device_force(c, params, limits, bricks, upd.penetration_before_m);
        // 4. Touch bookkeeping and the hand's push on dynamic bricks.
        self.contact_normals.clear();
        self.contact_normals
            .extend(upd.contacts.iter().map(|ct| ct.normal));
        self.touches(&upd, tick, approach_speed, params, bricks, events);
        push_bricks(&upd, felt_spring, params, bricks);
        felt
    }

    /// The grip's edges since the last tick: a release, then a grab, then the turns.
    fn grip_edges(
        &mut self,
        grip: Grip,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        let prev = self.grip;
        self.grip = grip;
        if prev.hold && !grip.hold {
            self.release(params, bricks, events);
        }
        if !prev.hold && grip.hold {
            self.grab(params, limits, bricks, events);
        }
        for (now, before, axis) in [
            (grip.turn_x, prev.turn_x, Axis::X),
            (grip.turn_y, prev.turn_y, Axis::Y),
            (grip.turn_z, prev.turn_z, Axis::Z),
        ] {
            if now && !before {
                self.turn(axis, params, bricks, events);
            }
        }
    }

    /// Moves the god-object towards the cursor `c` (a rigidly carried brick with it, as a
    /// kinematic body); returns the update and the approach speed for impacts, m/s.
    fn move_proxy(
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

    /// The force the device renders this tick: spring + weight + inertia (or the coupling's
    /// pull), scaled down to the device limit; and the spring's part of it as felt (scaled
    /// alike). The hand pushes the world with exactly the reaction of that part (action =
    /// reaction at the coupling): a proxy pressed deep into a brick pushes with at most the
    /// device's force, not with the stretched spring's. A coupled brick gets the reaction of
    /// the coupling's felt pull.
    fn device_force(
        &mut self,
        c: Vector,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        penetration_m: f64,
    ) -> (Felt, Vector) {
        let spring = (self.proxy - c) * params.proxy_stiffness_n_per_m;
        let m = params.brick_mass_kg;
        let accel = Vector::from_array(self.motion.acceleration());
        let (weight, inertia, coupling) = match self.held {
            Some(h) if h.coupled => {
                let (pull, d) = self.coupling_pull(&h, params, limits, bricks);
                self.damper = d;
                (Vector::ZERO, Vector::ZERO, -pull)
            }
            Some(_) => {
                let w = Vector::new(0.0, 0.0, -m * params.gravity_m_per_s2);
                let i = if params.inertia == Inertia::Paper {
                    -accel * m
                } else {
                    Vector::ZERO
                };
                (w, i, Vector::ZERO)
            }
            None => (Vector::ZERO, Vector::ZERO, Vector::ZERO),
        };
        let total = spring + weight + inertia + coupling;
        let mag = total.length();
        let scale = if mag > limits.max_force_n {
            limits.max_force_n / mag
        } else {
            1.0
        };
        let (force, saturated) = (total * scale, scale < 1.0);
        if let Some(h) = self.held.filter(|h| h.coupled) {
            // The brick gets exactly the reaction of what the hand feels of the coupling: the
            // same force both ways, the scale-down included.
            if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(h.brick)) {
                rb.apply_impulse(-coupling * (scale * params.dt_s), true);
            }
        }
        let felt = Felt {
            force,
            saturated,
            spring,
            weight,
            inertia,
            coupling,
            acceleration: accel,
            penetration_m,
        };
        (felt, spring * scale)
    }

    /// What the cursor (or carried brick) touches after the update: `TouchEnded` and
    /// `TouchBegan` events, and an `Impact` for a touch begun at speed.
    fn touches(
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

    /// Outward normals of the surfaces the god-object touched in the last update.
    pub(crate) fn contact_normals(&self) -> &[Vector] {
        &self.contact_normals
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

    /// The carried brick's coupling in the state the next tick starts from: the brick's
    /// centre less the grip offset, its velocity, its mass, the coupling's springs and damper
    /// (as [`Hand::coupling_pull`] uses them) and the dashpot's share; `None` unless a brick
    /// is carried through the coupling.
    pub(crate) fn carried_body(
        &self,
        params: &Params,
        limits: &Limits,
        bricks: &BrickSet,
    ) -> Option<crate::local::CarriedBody> {
        let h = self.held.filter(|h| h.coupled)?;
        let rb = bricks.phys.bodies.get(bricks.body(h.brick))?;
        let m = rb.mass();
        if m.is_nan() || m <= 0.0 {
            return None;
        }
        let cap = m / (params.dt_s * params.dt_s);
        let c = &params.coupling;
        let k = Self::coupling_stiffness(params, limits);
        let k_series = (c.max_fraction - c.stiffness_fraction) * limits.max_stiffness_n_per_m;
        Some(crate::local::CarriedBody {
            position_m: (rb.translation() - h.offset).to_array(),
            velocity_m_per_s: rb.linvel().to_array(),
            mass_kg: m,
            stiffness_n_per_m: k.min(cap),
            series_stiffness_n_per_m: k_series.min(cap),
            damping_n_s_per_m: 2.0 * c.damping_ratio * (k * m).sqrt(),
            damper_m: self.damper.to_array(),
            external_force_n: [0.0, 0.0, -m * params.gravity_m_per_s2],
            substeps: u32::try_from(params.solver_iterations).unwrap_or(1),
            restitution: params.restitution,
        })
    }

    /// The surfaces the carried brick touches or nears within `margin_m`, as planes on its grip
    /// point at `grip_m`: the direction in which the other body lets it move (the contact's
    /// normal on that body) and how far it may go the other way (the gap); the nearest
    /// surface of each collider, deduplicated by normal, at most [`crate::local::MAX_PLANES`]
    /// (nearest first).
    pub(crate) fn carried_contacts(
        &self,
        params: &Params,
        bricks: &BrickSet,
        grip_m: [f64; 3],
        margin_m: f64,
    ) -> Vec<crate::local::ContactPlane> {
        let mut out: Vec<crate::local::ContactPlane> = Vec::new();
        let Some(h) = self.held.filter(|h| h.coupled) else {
            return out;
        };
        let me = bricks.collider(h.brick);
        let Some(rb) = bricks.phys.bodies.get(bricks.body(h.brick)) else {
            return out;
        };
        let pose = *rb.position();
        let e = Vector::from_array(params.brick_half_extents_m);
        let brick = Cuboid::new(e);
        let grown = Cuboid::new(e + Vector::splat(margin_m));
        let x = Vector::from_array(grip_m);
        let qp = bricks
            .phys
            .query_pipeline_with_filter(QueryFilter::default().exclude_collider(me));
        let mut found: Vec<(f64, Vector)> = qp
            .intersect_shape(pose, &grown)
            .filter_map(|(_, co)| {
                let c = rapier3d_f64::parry::query::contact(
                    &pose,
                    &brick,
                    co.position(),
                    co.shape(),
                    margin_m,
                )
                .ok()??;
                let n = c.normal2;
                (n.is_finite() && c.dist.is_finite()).then_some((c.dist, n))
            })
            .collect();
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (dist, n) in found {
            let dup = out
                .iter()
                .any(|q| Vector::from_array(q.normal).dot(n) > 1.0 - 1e-9);
            if dup || out.len() == crate::local::MAX_PLANES {
                continue;
            }
            out.push(crate::local::ContactPlane {
                normal: n.to_array(),
                offset_m: n.dot(x) - dist.max(0.0),
                stiffness_n_per_m: 0.0,
            });
        }
        out
    }

    /// Where the coupling holds a brick of mass `m_kg` at rest: the grip point's lead on it
    /// under its weight alone, `M g / k` upwards, m (the dashpot relaxed).
    pub(crate) fn static_lead(params: &Params, limits: &Limits, m_kg: f64) -> Vector {
        let k = Self::coupling_stiffness(params, limits).min(m_kg / (params.dt_s * params.dt_s));
        if k > 0.0 && m_kg.is_finite() {
            Vector::new(0.0, 0.0, m_kg * params.gravity_m_per_s2 / k)
        } else {
            Vector::ZERO
        }
    }

    /// The carried brick's static lead (zero unless carried through the coupling), m: with its
    /// mass now, or with `mass_kg` (a mass just set, which the engine applies at its next
    /// step).
    pub(crate) fn held_static_lead(
        &self,
        params: &Params,
        limits: &Limits,
        bricks: &BrickSet,
        mass_kg: Option<f64>,
    ) -> Vector {
        match self.held.filter(|h| h.coupled) {
            Some(h) => bricks
                .phys
                .bodies
                .get(bricks.body(h.brick))
                .map_or(Vector::ZERO, |rb| {
                    Self::static_lead(params, limits, mass_kg.unwrap_or(rb.mass()))
                }),
            None => Vector::ZERO,
        }
    }

    /// A switch changed the carried brick's load (gravity, mass) from one static lead to
    /// another: the grip point and the relaxed dashpot move by the difference, so the felt
    /// force steps to the new weight at once and the brick does not ring on its coupling.
    pub(crate) fn rebalance(&mut self, from: Vector, to: Vector) {
        if let Some(h) = self.held.as_mut().filter(|h| h.coupled) {
            h.offset += to - from;
            self.damper += to - from;
        }
    }

    /// Stiffness of the coupling spring, N/m (world units): a fraction of the device's
    /// largest stable stiffness.
    pub(crate) fn coupling_stiffness(params: &Params, limits: &Limits) -> f64 {
        params.coupling.stiffness_fraction * limits.max_stiffness_n_per_m
    }

    /// Stiffness of the carried brick's coupling felt this tick, N/m (0 when nothing is
    /// carried through it).
    pub(crate) fn felt_coupling_stiffness(&self, params: &Params, limits: &Limits) -> f64 {
        if self.held.is_some_and(|h| h.coupled) {
            Self::coupling_stiffness(params, limits)
        } else {
            0.0
        }
    }

    /// The coupling's pull on the brick this tick, N, and the new state of its damper.
    ///
    /// A spring `k` from the grip point (`proxy + offset`) to the brick's centre, in parallel
    /// with a damper `b = 2 ζ √(k M)` that acts through a series spring
    /// `k_s = (max_fraction − stiffness_fraction) k_max` (a Maxwell element): at low frequency
    /// it damps the brick in the hand, and a sudden change of relative velocity `Δv` (the brick
    /// set down, a step of the hand) makes its force rise at `k_s Δv` per second, never as a
    /// jump. The whole coupling is never stiffer than `max_fraction · k_max`.
    ///
    /// The Maxwell element is written in positions, so no velocity is estimated from encoder
    /// counts: with `x_r = x_t − x` the grip point's lead on the brick and `e` the dashpot's
    /// share of it, `b ė = k_s (x_r − e)` (backward Euler, stable for any `b`, `k_s`) and the
    /// damper pulls with `k_s (x_r − e)`. The force is explicit in the positions,
    /// `F = k x_r + k_s (x_r − e)`, so its change per tick is at most
    /// `(k + k_s) |Δx_r| ≤ max_fraction · k_max · v h`; rapier's symplectic Euler keeps the
    /// spring stable while `k h² / M < 4`, and the springs are capped at `M / h²` (a 1 g brick
    /// at 1 kHz: 1000 N/m) so they always are.
    fn coupling_pull(
        &self,
        h: &Held,
        params: &Params,
        limits: &Limits,
        bricks: &BrickSet,
    ) -> (Vector, Vector) {
        let Some(rb) = bricks.phys.bodies.get(bricks.body(h.brick)) else {
            return (Vector::ZERO, Vector::ZERO);
        };
        let m = rb.mass();
        if m.is_nan() || m <= 0.0 {
            return (Vector::ZERO, Vector::ZERO);
        }
        let dt = params.dt_s;
        let cap = m / (dt * dt);
        let k = Self::coupling_stiffness(params, limits);
        let c = &params.coupling;
        let k_series = (c.max_fraction - c.stiffness_fraction) * limits.max_stiffness_n_per_m;
        let b = 2.0 * c.damping_ratio * (k * m).sqrt();
        let lead = self.proxy + h.offset - rb.translation();
        let (damper, e) = if b > 0.0 && k_series > 0.0 {
            let r = dt * k_series / b;
            let e = (self.damper + lead * r) / (1.0 + r);
            ((lead - e) * k_series.min(cap), e)
        } else {
            (Vector::ZERO, Vector::ZERO)
        };
        (lead * k.min(cap) + damper, e)
    }

    /// Applies a change of the `inertia` switch to a carried brick: it becomes a coupled body
    /// or a kinematically carried one, where it is. Whether it changed.
    pub(crate) fn set_inertia(&mut self, mode: Inertia, bricks: &mut BrickSet) -> bool {
        let Some(h) = self.held else {
            return false;
        };
        let coupled = mode == Inertia::Coupling;
        if coupled == h.coupled {
            return false;
        }
        if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(h.brick)) {
            if coupled {
                rb.set_body_type(RigidBodyType::Dynamic, true);
                rb.lock_rotations(true, true);
                rb.set_linvel(Vector::ZERO, true);
                rb.set_angvel(Vector::ZERO, true);
            } else {
                rb.lock_rotations(false, true);
                rb.set_body_type(RigidBodyType::KinematicPositionBased, true);
            }
            let offset = rb.translation() - self.proxy;
            self.held = Some(Held {
                offset,
                coupled,
                ..h
            });
        }
        self.grip_velocity.reset(self.proxy.to_array());
        self.damper = Vector::ZERO;
        true
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

    /// `hold` pressed: carry the nearest brick within reach (ties: the lower id).
    fn grab(
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

    /// `hold` released: the brick leaves the hand with the grip point's velocity (a throw when
    /// faster than [`Params::throw_min_speed_m_per_s`]).
    fn release(&mut self, params: &Params, bricks: &mut BrickSet, events: &mut Vec<Event>) {
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

    /// A turn command: the carried brick turns by +90° about a world axis through the grip
    /// point, unless the turned brick would overlap something.
    fn turn(
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

/// The hand's push on the dynamic bricks it touches: the reaction of the spring it feels
/// (`felt_spring`, N), shared by the contacts, at the contact points, as the impulse of that
/// force over this tick.
fn push_bricks(upd: &ProxyUpdate, felt_spring: Vector, params: &Params, bricks: &mut BrickSet) {
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
