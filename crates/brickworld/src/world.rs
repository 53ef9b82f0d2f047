//! The macro world: state, the step function, and read access for renderers and recorders.

use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::parry::shape::{Ball, Cuboid};
use rapier3d_f64::prelude::{
    ActiveHooks, ColliderBuilder, ColliderHandle, FrictionModel, PairContacts, PhysicsWorld,
    QueryFilter, RigidBodyBuilder, RigidBodyHandle, RigidBodyType,
};

use serde::Serialize;

use crate::blueprint::{self, Score};
use crate::error::{InputError, ParamError, WorldError};
use crate::estimator::MotionEstimator;
use crate::impact::{IMPACT_MIN_SPEED_M_S, ImpactHook, is_support};
use crate::impacts::ImpactTracker;
use crate::input::{Buttons, CursorInput};
use crate::params::{AccelEstimator, BrickPlacement, BrickProps, DeviceLimits, Lo, Params, range};
use crate::proxy::{self, HeldShape};

/// Identifier of a brick: its index in creation order (stable, never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct BrickId(pub u32);

/// What the cursor can touch (serialized `"ground"`, `{"brick": 3}`, `{"obstacle": 0}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Touch {
    /// The ground plane `z = 0`.
    Ground,
    /// A brick.
    Brick(BrickId),
    /// A fixed obstacle, by its index in [`Params::obstacles`].
    Obstacle(usize),
}

/// A body taking part in an impact (serialized `"cursor"`, `"ground"`, `{"brick": 3}`,
/// `{"obstacle": 0}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Body {
    /// The cursor sphere (the hand).
    Cursor,
    /// The ground plane.
    Ground,
    /// A brick.
    Brick(BrickId),
    /// A fixed obstacle, by its index in [`Params::obstacles`].
    Obstacle(usize),
}

impl From<Touch> for Body {
    fn from(t: Touch) -> Body {
        match t {
            Touch::Ground => Body::Ground,
            Touch::Brick(b) => Body::Brick(b),
            Touch::Obstacle(i) => Body::Obstacle(i),
        }
    }
}

/// A world axis (for the rotate buttons).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z (up).
    Z,
}

/// Something that happened during a step, in the order it happened.
///
/// Its serialized form (the recording's event detail) is JSON with a `type` tag and named
/// fields, e.g. `{"type":"impact","a":{"brick":0},"b":"ground","impulse_n_s":1.2,...}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Event {
    /// A brick appeared in the loading zone.
    Spawned {
        /// The new brick.
        brick: BrickId,
    },
    /// The centre button was pressed near a brick, which is now carried.
    Grabbed {
        /// The carried brick.
        brick: BrickId,
    },
    /// The centre button was pressed with no brick within reach.
    GrabMissed,
    /// The centre button was released; the brick left the hand with this velocity (m/s).
    Released {
        /// The brick let go.
        brick: BrickId,
        /// Its initial velocity, m/s (the grip point's velocity).
        velocity_m_s: [f64; 3],
    },
    /// Same release, faster than [`Params::throw_min_speed_m_s`]: a throw.
    Thrown {
        /// The thrown brick.
        brick: BrickId,
        /// Its initial velocity, m/s.
        velocity_m_s: [f64; 3],
    },
    /// The carried brick turned by +90° about a world axis (through the grip point).
    Rotated {
        /// The carried brick.
        brick: BrickId,
        /// The axis.
        axis: Axis,
    },
    /// A rotate button was pressed but the turned brick would overlap something; nothing moved.
    RotationBlocked {
        /// The carried brick.
        brick: BrickId,
        /// The axis.
        axis: Axis,
    },
    /// The cursor (or carried brick) started touching something.
    TouchBegan {
        /// What is touched.
        target: Touch,
    },
    /// The cursor (or carried brick) stopped touching something.
    TouchEnded {
        /// What was touched.
        target: Touch,
    },
    /// A blueprint slot became filled by a resting brick.
    SlotFilled {
        /// Slot index in [`Params::blueprint`].
        slot: usize,
        /// The brick in it.
        brick: BrickId,
    },
    /// A blueprint slot lost its brick.
    SlotVacated {
        /// Slot index.
        slot: usize,
        /// The brick that left.
        brick: BrickId,
    },
    /// A collision: a contact that began this step with bodies approaching faster than
    /// [`IMPACT_MIN_SPEED_M_S`] (see [`crate::impacts`]). Between the cursor and what it touches,
    /// the impulse is the brick mass × the cursor's approach speed (the cursor has no mass in
    /// the world; this is the impulse that would stop a brick arriving at that speed).
    Impact {
        /// One body.
        a: Body,
        /// The other.
        b: Body,
        /// Normal impulse of the contact over the step, N·s.
        impulse_n_s: f64,
        /// Approach speed along the contact normal just before the step, m/s.
        speed_m_s: f64,
        /// Centroid of the contact, m.
        point_m: [f64; 3],
    },
}

/// What one step produced for the device and the logs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepReport {
    /// Index of the tick just simulated (0 for the first step).
    pub tick: u64,
    /// Force to render on the device, N, world frame: the sum below, scaled down to
    /// [`DeviceLimits::max_force_n`] if larger (then `saturated` is true). Always finite.
    pub force_n: [f64; 3],
    /// Whether `force_n` was scaled down to the device limit.
    pub saturated: bool,
    /// Proxy spring `k (p - c)`, N (`-k d n` against one surface).
    pub spring_force_n: [f64; 3],
    /// Local stiffness of the rendered force field this tick, N/m: `proxy_stiffness_n_m` while
    /// the cursor (or carried brick) touches something, 0 in free space (where `p = c`).
    pub stiffness_n_m: f64,
    /// Weight of the carried brick `-M g z`, N (zero when nothing is carried or gravity is off).
    pub weight_force_n: [f64; 3],
    /// Inertial force of the carried brick `-M a`, N (zero when nothing is carried or inertia is off).
    pub inertia_force_n: [f64; 3],
    /// Grip-point acceleration estimate used for the inertial force, m/s².
    pub acceleration_m_s2: [f64; 3],
    /// Deepest penetration of the cursor sphere or carried brick into anything at the start of the
    /// tick (bodies that moved into it), m, before it was pushed out.
    pub proxy_penetration_m: f64,
    /// Events, in the order they happened.
    pub events: Vec<Event>,
}

/// A brick as a renderer or recorder sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BrickView {
    /// Its id.
    pub id: BrickId,
    /// Centre, m, world frame.
    pub position_m: [f64; 3],
    /// Orientation as a unit quaternion `[x, y, z, w]`.
    pub orientation_xyzw: [f64; 4],
    /// Half-extents along its local axes, m.
    pub half_extents_m: [f64; 3],
    /// Linear velocity, m/s.
    pub velocity_m_s: [f64; 3],
    /// Whether the cursor is carrying it.
    pub held: bool,
    /// Whether the physics engine has put it to sleep (resting, not simulated).
    pub sleeping: bool,
}

/// A fixed box as a renderer sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoxView {
    /// Centre, m.
    pub position_m: [f64; 3],
    /// Orientation `[x, y, z, w]`.
    pub orientation_xyzw: [f64; 4],
    /// Half-extents, m.
    pub half_extents_m: [f64; 3],
}

/// A blueprint slot and whether it is filled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlotView {
    /// Target centre, m.
    pub position_m: [f64; 3],
    /// Target orientation `[x, y, z, w]`.
    pub orientation_xyzw: [f64; 4],
    /// The brick filling it, if any.
    pub filled_by: Option<BrickId>,
}

/// Horizontal distance (m) from a body's centre of mass within which a support load counts as
/// central (no moment), so that an impact may pass through the body's supports merged at their
/// centroid (see [`crate::impact::ImpactHook`]).
pub const CENTRAL_LOAD_M: f64 = 1e-3;

/// Half-extent of the ground slab in x and y, m (the ground is a 100 m × 100 m slab whose top
/// face is the plane z = 0).
pub const GROUND_HALF_EXTENT_M: f64 = 50.0;
/// Range of [`World::nearest_m`], m: farther solids count as none.
pub const NEAREST_MAX_M: f64 = 1.0;

/// A brick slower than this (m/s) counts as resting for the blueprint.
pub const RESTING_SPEED_M_S: f64 = 0.05;

const TAG_GROUND: u128 = 0;
const TAG_OBSTACLE: u128 = 1 << 64;
const TAG_BRICK: u128 = 2 << 64;

/// Speed (m/s, farthest point of the brick) below which a brick may start to count as resting;
/// rapier's own threshold for the sleep timer (its default is 0.05 m/s, which freezes a brick
/// gliding at 4 cm/s on frictionless ground).
pub const SLEEP_SPEED_M_S: f64 = 2e-3;
/// Net acceleration (m/s², farthest point) at or above which a slow brick is never put to sleep:
/// over rapier's 0.5 s sleep window its velocity must change by less than this × the window.
/// A brick starting from rest on a ramp 0.01° steeper than the friction angle (μ = 0.6)
/// accelerates at g·δ·(cos θ + μ sin θ) ≈ 2e-3 m/s² and keeps sliding; one with less net
/// acceleration may sleep after moving under 0.5 mm in its first second. Resting bricks and
/// stacks sleep (tests `resting_brick_and_brick_below_friction_angle_fall_asleep`,
/// `stack_of_ten_bricks_stays_put_for_60_s`).
pub const SLEEP_MAX_ACCEL_M_S2: f64 = 1e-3;

#[derive(Debug, Clone, Copy)]
struct Brick {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    /// Linear and angular velocity when the brick last became slow (start of rapier's sleep
    /// window), and the tick then.
    slow_since: Option<(u64, Vector, Vector)>,
}

#[derive(Debug, Clone, Copy)]
struct Held {
    brick: BrickId,
    offset: Vector,
    rotation: Rotation,
}

/// The macro world: bricks on a ground plane under gravity, a cursor proxy, the house task.
///
/// Parameters ([`Params`]) are fixed at creation except for the run-time switches, which have
/// validated setters. [`World::step`] advances one tick of `dt_s`.
pub struct World {
    params: Params,
    device: DeviceLimits,
    phys: PhysicsWorld,
    ground: ColliderHandle,
    obstacles: Vec<ColliderHandle>,
    bricks: Vec<Brick>,
    held: Option<Held>,
    proxy: Vector,
    cursor: Vector,
    buttons: Buttons,
    motion: MotionEstimator,
    touching: Vec<Touch>,
    in_zone: bool,
    slots: Vec<Option<BrickId>>,
    tick: u64,
    started: bool,
    impacts: ImpactTracker,
    /// The proxy's speed over the last tick, m/s (for cursor impacts).
    proxy_speed: f64,
}

fn arr(v: Vector) -> [f64; 3] {
    v.to_array()
}

fn quat(r: Rotation) -> [f64; 4] {
    [r.x, r.y, r.z, r.w]
}

fn tag_of(user_data: u128) -> Touch {
    let idx = (user_data & u64::MAX as u128) as u64;
    match user_data >> 64 {
        0 => Touch::Ground,
        1 => Touch::Obstacle(idx as usize),
        _ => Touch::Brick(BrickId(idx as u32)),
    }
}

impl World {
    /// Builds a world. Fails with the first out-of-range parameter, naming it.
    pub fn new(params: Params, device: DeviceLimits) -> Result<World, ParamError> {
        params.validate()?;
        params.validate_for_device(&device)?;
        let mut phys = PhysicsWorld::new();
        phys.gravity = Vector::new(0.0, 0.0, -params.gravity_m_s2);
        phys.integration_parameters.dt = params.dt_s;
        phys.integration_parameters.num_solver_iterations = params.solver_iterations;
        // rapier's default friction model (one friction constraint per manifold plus a twist
        // constraint) matches Coulomb's law on a ramp: onset at tan θ = μ within 0.1° and the
        // sliding acceleration to 4 digits; the per-point `Coulomb` model slides up to 1° early
        // and 50 % too fast (docs/brickworld.md).
        phys.integration_parameters.friction_model = FrictionModel::Simplified;
        phys.integration_parameters
            .contact_softness
            .natural_frequency = params.contact_frequency_hz;
        // Contacts with the ground and obstacles keep rapier's 2:1 ratio to brick-brick contacts.
        phys.integration_parameters
            .static_contact_softness
            .natural_frequency = 2.0 * params.contact_frequency_hz;
        let ground = phys.insert_body(RigidBodyBuilder::fixed());
        let ground_collider = phys.insert_collider(
            ColliderBuilder::cuboid(GROUND_HALF_EXTENT_M, GROUND_HALF_EXTENT_M, 1.0)
                .translation(Vector::new(0.0, 0.0, -1.0))
                .friction(params.friction)
                .restitution(params.restitution)
                .user_data(TAG_GROUND),
            Some(ground),
        );
        let mut obstacles = Vec::new();
        for (i, o) in params.obstacles.iter().enumerate() {
            let rot = blueprint::placement_rotation(&BrickPlacement {
                center_m: o.center_m,
                rotation_deg: o.rotation_deg,
            });
            let h = o.half_extents_m;
            let co = phys.insert_collider(
                ColliderBuilder::cuboid(h[0], h[1], h[2])
                    .position(Pose::from_parts(Vector::from_array(o.center_m), rot))
                    .friction(params.friction)
                    .restitution(params.restitution)
                    .user_data(TAG_OBSTACLE | i as u128),
                Some(ground),
            );
            obstacles.push(co);
        }
        let motion = MotionEstimator::new(params.dt_s, params.accel_estimator);
        let slots = vec![None; params.blueprint.slots.len()];
        let initial = params.bricks.clone();
        // Until the first sample: the top centre of the workspace.
        let top = Vector::new(0.0, 0.0, params.workspace_half_extent_m);
        let mut world = World {
            params,
            device,
            phys,
            ground: ground_collider,
            obstacles,
            bricks: Vec::new(),
            held: None,
            proxy: top,
            cursor: top,
            buttons: Buttons::default(),
            motion,
            touching: Vec::new(),
            impacts: ImpactTracker::default(),
            proxy_speed: 0.0,
            in_zone: false,
            slots,
            tick: 0,
            started: false,
        };
        for b in &initial {
            world.insert_brick(b);
        }
        // Make the scene-query structure see the initial bodies without advancing time.
        world.refresh_queries();
        Ok(world)
    }

    /// Updates broad-phase and contacts with no time passing (rapier: a step with `dt = 0`).
    fn refresh_queries(&mut self) {
        let dt = self.phys.integration_parameters.dt;
        self.phys.integration_parameters.dt = 0.0;
        self.phys.step_with_events(&ImpactHook::default(), &());
        self.phys.integration_parameters.dt = dt;
    }

    fn insert_brick(&mut self, placement: &BrickPlacement) -> BrickId {
        self.insert_brick_with(placement, &BrickProps::default())
    }

    fn insert_brick_with(&mut self, placement: &BrickPlacement, props: &BrickProps) -> BrickId {
        let id = BrickId(self.bricks.len() as u32);
        let pose = Pose::from_parts(
            Vector::from_array(placement.center_m),
            blueprint::placement_rotation(placement),
        );
        let body = self.phys.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(pose)
                .can_sleep(self.params.sleeping),
        );
        let h = self.params.brick_half_extents_m;
        let collider = self.phys.insert_collider(
            ColliderBuilder::cuboid(h[0], h[1], h[2])
                .mass(props.mass_kg.unwrap_or(self.params.brick_mass_kg))
                .friction(props.friction.unwrap_or(self.params.friction))
                .restitution(props.restitution.unwrap_or(self.params.restitution))
                .user_data(TAG_BRICK | id.0 as u128)
                .active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS),
            Some(body),
        );
        if let Some(rb) = self.phys.bodies.get_mut(body) {
            rb.activation_mut().normalized_linear_threshold = SLEEP_SPEED_M_S;
            if props.velocity_m_s != [0.0; 3] {
                rb.set_linvel(Vector::from_array(props.velocity_m_s), true);
            }
        }
        self.bricks.push(Brick {
            body,
            collider,
            slow_since: None,
        });
        id
    }

    /// Adds a brick at `placement` (centre m, rotation vector deg). The pose is validated like
    /// [`Params::bricks`]; the count is limited by [`Params::max_bricks`].
    pub fn add_brick(&mut self, placement: BrickPlacement) -> Result<BrickId, WorldError> {
        self.check_placement(&placement)?;
        let id = self.insert_brick(&placement);
        self.refresh_queries();
        Ok(id)
    }

    fn check_placement(&self, placement: &BrickPlacement) -> Result<(), WorldError> {
        for i in 0..3 {
            range(
                &format!("brick.center_m[{i}]"),
                placement.center_m[i],
                Lo::Closed(-100.0),
                100.0,
            )?;
            range(
                &format!("brick.rotation_deg[{i}]"),
                placement.rotation_deg[i],
                Lo::Closed(-3600.0),
                3600.0,
            )?;
        }
        if self.bricks.len() >= self.params.max_bricks {
            return Err(WorldError::TooManyBricks {
                max: self.params.max_bricks,
            });
        }
        Ok(())
    }

    /// Adds a brick like [`World::add_brick`] with its own initial velocity, mass, friction and
    /// restitution ([`BrickProps`]; `None` takes the world's value). The run-time switches
    /// ([`World::set_friction`], ...) later set every brick, this one included.
    pub fn add_brick_with(
        &mut self,
        placement: BrickPlacement,
        props: BrickProps,
    ) -> Result<BrickId, WorldError> {
        for i in 0..3 {
            range(
                &format!("brick.velocity_m_s[{i}]"),
                props.velocity_m_s[i],
                Lo::Closed(-100.0),
                100.0,
            )?;
        }
        if let Some(m) = props.mass_kg {
            range("brick.mass_kg", m, Lo::Closed(1e-3), 100.0)?;
        }
        if let Some(mu) = props.friction {
            range("brick.friction", mu, Lo::Closed(0.0), 10.0)?;
        }
        if let Some(e) = props.restitution {
            range("brick.restitution", e, Lo::Closed(0.0), 1.0)?;
        }
        self.check_placement(&placement)?;
        let id = self.insert_brick_with(&placement, &props);
        self.refresh_queries();
        Ok(id)
    }

    /// Validates a device sample against this world's workspace box.
    pub fn input(&self, position_m: [f64; 3], buttons: Buttons) -> Result<CursorInput, InputError> {
        CursorInput::new(position_m, buttons, self.params.workspace_half_extent_m)
    }

    // ----- run-time switches -------------------------------------------------------------

    /// Sets the magnitude of gravity, m/s² in `[0, 100]` (0 = off). Wakes every brick.
    pub fn set_gravity(&mut self, g_m_s2: f64) -> Result<(), ParamError> {
        range("gravity_m_s2", g_m_s2, Lo::Closed(0.0), 100.0)?;
        self.params.gravity_m_s2 = g_m_s2;
        self.phys.gravity = Vector::new(0.0, 0.0, -g_m_s2);
        self.phys.wake_up_all(true);
        Ok(())
    }

    /// Sets the coefficient of restitution of every contact, in `[0, 1]`.
    pub fn set_restitution(&mut self, e: f64) -> Result<(), ParamError> {
        range("restitution", e, Lo::Closed(0.0), 1.0)?;
        self.params.restitution = e;
        for (_, co) in self.phys.all_colliders_mut() {
            co.set_restitution(e);
        }
        self.phys.wake_up_all(true);
        Ok(())
    }

    /// Sets the friction coefficient of every contact, in `[0, 10]` (0 = frictionless).
    /// Wakes every brick, so that bricks held only by friction slide at once.
    pub fn set_friction(&mut self, mu: f64) -> Result<(), ParamError> {
        range("friction", mu, Lo::Closed(0.0), 10.0)?;
        self.params.friction = mu;
        for (_, co) in self.phys.all_colliders_mut() {
            co.set_friction(mu);
        }
        self.phys.wake_up_all(true);
        Ok(())
    }

    /// Switches the inertial force `-M a` of a carried brick on or off.
    pub fn set_inertia(&mut self, on: bool) {
        self.params.inertia = on;
    }

    /// Sets the mass of every brick, kg in `[1e-3, 100]` (inertia tensor scales with it).
    pub fn set_brick_mass(&mut self, kg: f64) -> Result<(), ParamError> {
        range("brick_mass_kg", kg, Lo::Closed(1e-3), 100.0)?;
        self.params.brick_mass_kg = kg;
        for b in &self.bricks {
            if let Some(co) = self.phys.colliders.get_mut(b.collider) {
                co.set_mass(kg);
            }
        }
        self.phys.wake_up_all(true);
        Ok(())
    }

    /// Chooses the acceleration estimator for the inertial force (history is kept).
    pub fn set_accel_estimator(&mut self, kind: AccelEstimator) -> Result<(), ParamError> {
        let mut p = self.params.clone();
        p.accel_estimator = kind;
        p.validate()?;
        self.params.accel_estimator = kind;
        let newest = self.proxy.to_array();
        self.motion = MotionEstimator::new(self.params.dt_s, kind);
        self.motion.reset(newest);
        Ok(())
    }

    // ----- read access -------------------------------------------------------------------

    /// The parameters in force (switches included).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The device limits this world renders to.
    pub fn device(&self) -> &DeviceLimits {
        &self.device
    }

    /// Number of ticks simulated so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Simulated time, s (`tick · dt_s`).
    pub fn time_s(&self) -> f64 {
        self.tick as f64 * self.params.dt_s
    }

    /// Number of bricks.
    pub fn brick_count(&self) -> usize {
        self.bricks.len()
    }

    /// One brick.
    pub fn brick(&self, id: BrickId) -> Result<BrickView, WorldError> {
        let b = self
            .bricks
            .get(id.0 as usize)
            .ok_or(WorldError::UnknownBrick(id.0))?;
        let rb = &self.phys.bodies[b.body];
        Ok(BrickView {
            id,
            position_m: arr(rb.translation()),
            orientation_xyzw: quat(*rb.rotation()),
            half_extents_m: self.params.brick_half_extents_m,
            velocity_m_s: arr(rb.linvel()),
            held: self.held.is_some_and(|h| h.brick == id),
            sleeping: rb.is_sleeping(),
        })
    }

    /// All bricks in id order.
    pub fn bricks(&self) -> impl Iterator<Item = BrickView> + '_ {
        (0..self.bricks.len() as u32).filter_map(|i| self.brick(BrickId(i)).ok())
    }

    /// The fixed obstacles, in [`Params::obstacles`] order.
    pub fn obstacles(&self) -> impl Iterator<Item = BoxView> + '_ {
        self.obstacles.iter().filter_map(|h| {
            let co = self.phys.colliders.get(*h)?;
            let c = co.shape().as_cuboid()?;
            Some(BoxView {
                position_m: arr(co.position().translation),
                orientation_xyzw: quat(co.position().rotation),
                half_extents_m: arr(c.half_extents),
            })
        })
    }

    /// The ground slab as a renderer sees it: its top face is the plane z = 0.
    pub fn ground(&self) -> BoxView {
        let co = &self.phys.colliders[self.ground];
        let half = co
            .shape()
            .as_cuboid()
            .map_or([GROUND_HALF_EXTENT_M, GROUND_HALF_EXTENT_M, 1.0], |c| {
                arr(c.half_extents)
            });
        BoxView {
            position_m: arr(co.position().translation),
            orientation_xyzw: quat(co.position().rotation),
            half_extents_m: half,
        }
    }

    /// Centre of the cursor sphere (the god-object / proxy), m. Before the first step: the top
    /// centre of the workspace, `[0, 0, workspace_half_extent_m]`.
    pub fn proxy_position_m(&self) -> [f64; 3] {
        arr(self.proxy)
    }

    /// Last device cursor position, m (same placeholder as the proxy before the first step).
    pub fn cursor_position_m(&self) -> [f64; 3] {
        arr(self.cursor)
    }

    /// The carried brick, if any.
    pub fn held_brick(&self) -> Option<BrickId> {
        self.held.map(|h| h.brick)
    }

    /// What the cursor (or carried brick) touches now, sorted.
    pub fn touching(&self) -> &[Touch] {
        &self.touching
    }

    /// The blueprint slots and their state, in [`Params::blueprint`] order.
    pub fn slots(&self) -> impl Iterator<Item = SlotView> + '_ {
        self.params
            .blueprint
            .slots
            .iter()
            .zip(&self.slots)
            .map(|(s, f)| SlotView {
                position_m: s.center_m,
                orientation_xyzw: quat(blueprint::placement_rotation(s)),
                filled_by: *f,
            })
    }

    /// The house-task score.
    pub fn score(&self) -> Score {
        Score {
            filled: self.slots.iter().filter(|s| s.is_some()).count(),
            total: self.slots.len(),
        }
    }

    /// Distance from the cursor sphere's surface to the nearest solid (ground, obstacle or
    /// brick other than the carried one), m: 0 when touching, `f64::INFINITY` when nothing is
    /// within [`NEAREST_MAX_M`] (the proximity sound's input).
    pub fn nearest_m(&self) -> f64 {
        let mut filter = QueryFilter::default();
        if let Some(h) = self.held {
            filter = filter.exclude_collider(self.bricks[h.brick.0 as usize].collider);
        }
        let r = self.params.proxy_radius_m;
        let qp = self.phys.query_pipeline_with_filter(filter);
        match qp.project_point(self.proxy, NEAREST_MAX_M + r, true) {
            Some((_, proj)) if proj.is_inside => 0.0,
            Some((_, proj)) => ((proj.point - self.proxy).length() - r).max(0.0),
            None => f64::INFINITY,
        }
    }

    /// Number of bricks the physics engine currently simulates (awake), for cost accounting.
    pub fn awake_brick_count(&self) -> usize {
        self.bricks
            .iter()
            .filter(|b| !self.phys.bodies[b.body].is_sleeping())
            .count()
    }

    // ----- the step ----------------------------------------------------------------------

    /// Advances the world by one tick of `dt_s` with the device sample `input`.
    pub fn step(&mut self, input: &CursorInput) -> StepReport {
        let mut events = Vec::new();
        let c = Vector::from_array(input.position_m());
        self.cursor = c;
        if !self.started {
            // The first sample: the proxy comes down from the top of the workspace onto the
            // cursor, so it starts outside every solid even if the cursor starts inside one.
            self.proxy = Vector::new(c.x, c.y, self.params.workspace_half_extent_m);
            self.started = true;
        }
        let buttons = input.buttons();
        let prev = self.buttons;
        self.buttons = buttons;

        // 1. Buttons: release before grab so one tick can't do both on one brick.
        if prev.center && !buttons.center {
            self.release(&mut events);
        }
        if !prev.center && buttons.center {
            self.grab(&mut events);
        }
        for (now, before, axis) in [
            (buttons.rotate_x, prev.rotate_x, Axis::X),
            (buttons.rotate_y, prev.rotate_y, Axis::Y),
            (buttons.rotate_z, prev.rotate_z, Axis::Z),
        ] {
            if now && !before {
                self.rotate(axis, &mut events);
            }
        }

        // 2. God-object update.
        let ball = Ball::new(self.params.proxy_radius_m);
        let held_shape = self.held_shape();
        let exclude = self.held.map(|h| self.bricks[h.brick.0 as usize].collider);
        let upd = {
            let mut filter = QueryFilter::default();
            if let Some(ex) = exclude {
                filter = filter.exclude_collider(ex);
            }
            let qp = self.phys.query_pipeline_with_filter(filter);
            proxy::update_proxy(&qp, &ball, &held_shape, self.proxy, c)
        };
        let moved = (upd.position - self.proxy).length() / self.params.dt_s;
        let approach_speed = moved.max(self.proxy_speed);
        self.proxy_speed = if self.tick == 0 { 0.0 } else { moved };
        self.proxy = upd.position;
        if self.tick == 0 {
            self.motion.reset(self.proxy.to_array());
        }
        self.motion.push(self.proxy.to_array());
        if let Some(h) = self.held {
            let body = self.bricks[h.brick.0 as usize].body;
            if let Some(rb) = self.phys.bodies.get_mut(body) {
                rb.set_next_kinematic_position(Pose::from_parts(self.proxy + h.offset, h.rotation));
            }
        }

        // 3. The force the device renders this tick: spring + weight + inertia, scaled down
        //    to the device limit. The hand pushes the world with exactly the reaction of the
        //    spring part of it (action = reaction at the coupling): a proxy pressed deep into a
        //    brick pushes with at most the device's force, not with the stretched spring's.
        let spring = (self.proxy - c) * self.params.proxy_stiffness_n_m;
        let m = self.params.brick_mass_kg;
        let accel = Vector::from_array(self.motion.acceleration());
        let (weight, inertia) = if self.held.is_some() {
            let w = Vector::new(0.0, 0.0, -m * self.params.gravity_m_s2);
            let i = if self.params.inertia {
                -accel * m
            } else {
                Vector::ZERO
            };
            (w, i)
        } else {
            (Vector::ZERO, Vector::ZERO)
        };
        let total = spring + weight + inertia;
        let mag = total.length();
        let scale = if mag > self.device.max_force_n {
            self.device.max_force_n / mag
        } else {
            1.0
        };
        let (force, saturated) = (total * scale, scale < 1.0);
        let felt_spring = spring * scale;

        // 4. Touch bookkeeping and the hand's push on dynamic bricks.
        let mut touching: Vec<Touch> = upd
            .contacts
            .iter()
            .filter_map(|ct| {
                self.phys
                    .colliders
                    .get(ct.collider)
                    .map(|co| tag_of(co.user_data))
            })
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
                if self.tick > 0 && approach_speed >= IMPACT_MIN_SPEED_M_S {
                    events.push(Event::Impact {
                        a: Body::Cursor,
                        b: Body::from(*t),
                        impulse_n_s: self.params.brick_mass_kg * approach_speed,
                        speed_m_s: approach_speed,
                        point_m: arr(self.proxy),
                    });
                }
            }
        }
        self.touching = touching;
        let pushes: Vec<(RigidBodyHandle, Vector)> = upd
            .contacts
            .iter()
            .filter_map(|ct| {
                let co = self.phys.colliders.get(ct.collider)?;
                let body = co.parent()?;
                let rb = self.phys.bodies.get(body)?;
                (rb.body_type() == RigidBodyType::Dynamic).then_some((body, ct.point))
            })
            .collect();
        if !pushes.is_empty() && felt_spring.length_squared() > 0.0 {
            // The hand pushes with the reaction of the spring it feels, shared by the contacts,
            // at the contact points, as the impulse of that force over this tick. (A user force
            // at a point would be the natural call, but rapier 0.36 does not resist the torque
            // of user forces with contacts: 10 N pressed 5 cm off-centre launched a resting
            // 0.5 kg brick 0.45 m up. Velocity impulses are resisted correctly.)
            let share = -felt_spring * (self.params.dt_s / pushes.len() as f64);
            for (body, point) in pushes {
                if let Some(rb) = self.phys.bodies.get_mut(body) {
                    rb.apply_impulse_at_point(share, point, true);
                }
            }
        }

        // 5. Loading zone.
        self.loading_zone(c, &mut events);

        // 6. Rigid-body physics (the sleep veto first: see `veto_sleep`).
        self.veto_sleep();
        let hook = ImpactHook {
            impacted: self.impacted_bodies(),
        };
        self.impacts
            .before_step(&self.phys, self.bricks.iter().map(|b| b.body));
        self.phys.step_with_events(&hook, &());
        {
            let colliders = &self.phys.colliders;
            let body_of = |c: ColliderHandle| {
                colliders
                    .get(c)
                    .map_or(Body::Ground, |co| Body::from(tag_of(co.user_data)))
            };
            self.impacts.after_step(&self.phys, body_of, &mut events);
        }

        // 7. Blueprint.
        self.update_slots(&mut events);

        // 8. Device force (computed in 3).
        let report = StepReport {
            tick: self.tick,
            force_n: arr(force),
            saturated,
            spring_force_n: arr(spring),
            stiffness_n_m: if self.touching.is_empty() {
                0.0
            } else {
                self.params.proxy_stiffness_n_m
            },
            weight_force_n: arr(weight),
            inertia_force_n: arr(inertia),
            acceleration_m_s2: arr(accel),
            proxy_penetration_m: upd.penetration_before_m,
            events,
        };
        self.tick += 1;
        report
    }

    /// The bodies of an impact about to be solved (see [`ImpactHook`]): a body touched by a
    /// support contact (within 45° of vertical) approaching faster than
    /// [`IMPACT_MIN_SPEED_M_S`] at its centroid — a new contact, or a resting one that the body
    /// above has just driven down — whose load passes through the body's centre of mass
    /// (within [`CENTRAL_LOAD_M`]), and, through such central supports, the bodies below and
    /// above it. An off-centre load keeps every support point: its lever arms are physical.
    fn impacted_bodies(&self) -> Vec<RigidBodyHandle> {
        let phys = &self.phys;
        let body_of = |c: ColliderHandle| {
            let h = phys.colliders.get(c)?.parent()?;
            let rb = phys.bodies.get(h)?;
            (rb.body_type() == RigidBodyType::Dynamic).then_some(h)
        };
        // Whether a load through `point` passes (within CENTRAL_LOAD_M) through the vertical of
        // the body's centre of mass: then it has no moment and a centroid support is exact.
        let central = |h: RigidBodyHandle, point: Vector| {
            phys.bodies.get(h).is_some_and(|rb| {
                let c = rb.center_of_mass();
                (point.x - c.x).hypot(point.y - c.y) <= CENTRAL_LOAD_M
            })
        };
        let mut seeds: Vec<RigidBodyHandle> = Vec::new();
        // Supports between two bodies: (body, other, contact centroid), either way round.
        let mut links: Vec<(RigidBodyHandle, RigidBodyHandle, Vector)> = Vec::new();
        for pair in phys.narrow_phase.contact_pairs() {
            let PairContacts::Rigid(rc) = &pair.contacts else {
                continue;
            };
            let (b1, b2) = (body_of(pair.collider1), body_of(pair.collider2));
            let (Some(c1), Some(c2)) = (
                phys.colliders.get(pair.collider1),
                phys.colliders.get(pair.collider2),
            ) else {
                continue;
            };
            if b1.is_none() && b2.is_none() {
                continue;
            }
            let vel = |h: Option<RigidBodyHandle>, p: Vector| {
                h.and_then(|h| phys.bodies.get(h))
                    .map_or(Vector::ZERO, |rb| rb.velocity_at_point(p))
            };
            for m in &rc.manifolds {
                if m.points.is_empty() || !is_support(m.data.normal) {
                    continue;
                }
                let n = m.data.normal;
                let mut centroid = Vector::ZERO;
                for p in &m.points {
                    centroid += (c1.position() * p.local_p1 + c2.position() * p.local_p2) * 0.5;
                }
                centroid /= m.points.len() as f64;
                // Approach of the contact as a whole (at its centroid): a rocking body's corners
                // approach while its centroid does not, and that is no impact.
                let fast = (vel(b1, centroid) - vel(b2, centroid)).dot(n) >= IMPACT_MIN_SPEED_M_S;
                if fast {
                    for h in [b1, b2].into_iter().flatten() {
                        if central(h, centroid) && !seeds.contains(&h) {
                            seeds.push(h);
                        }
                    }
                }
                if let (Some(a), Some(b)) = (b1, b2) {
                    links.push((a, b, centroid));
                    links.push((b, a, centroid));
                }
            }
        }
        // Follow central supports through the stack.
        loop {
            let mut grew = false;
            for (a, b, at) in &links {
                if seeds.contains(a) && !seeds.contains(b) && central(*b, *at) {
                    seeds.push(*b);
                    grew = true;
                }
            }
            if !grew {
                return seeds;
            }
        }
    }

    /// The sleep policy: rapier puts a body to sleep once it has been slower than
    /// [`SLEEP_SPEED_M_S`] for 0.5 s. That alone freezes a brick that starts sliding from rest
    /// with a small net force (it stays slow for its first half second). So a slow brick is
    /// allowed to fall asleep only if its velocity also stayed constant over that window (net
    /// acceleration below [`SLEEP_MAX_ACCEL_M_S2`]): a brick under an unbalanced force is kept
    /// awake, and sleep only skips bricks that are truly at rest.
    fn veto_sleep(&mut self) {
        if !self.params.sleeping {
            return;
        }
        let dt = self.params.dt_s;
        let tick = self.tick;
        for b in &mut self.bricks {
            let Some(rb) = self.phys.bodies.get_mut(b.body) else {
                continue;
            };
            if rb.is_sleeping() || rb.body_type() != RigidBodyType::Dynamic {
                b.slow_since = None;
                continue;
            }
            let (v, w) = (rb.linvel(), rb.angvel());
            let act = rb.activation();
            let (timer, window) = (act.time_since_can_sleep, act.time_until_sleep);
            let Some((t0, v0, w0)) = b.slow_since.filter(|_| timer > 0.0) else {
                b.slow_since = Some((tick, v, w));
                continue;
            };
            if timer + dt < window {
                continue;
            }
            // Rapier would let it sleep this step: only if its velocity did not drift.
            let elapsed = (tick - t0) as f64 * dt;
            let reach = self.params.brick_half_extents_m;
            let r = (reach[0] * reach[0] + reach[1] * reach[1] + reach[2] * reach[2]).sqrt();
            let change = (v - v0).length() + (w - w0).length() * r;
            if change >= SLEEP_MAX_ACCEL_M_S2 * elapsed.max(dt) {
                rb.wake_up(true);
                b.slow_since = Some((tick, v, w));
            }
        }
    }

    fn held_shape(&self) -> Option<HeldShape> {
        self.held.map(|h| {
            let e = self.params.brick_half_extents_m;
            HeldShape {
                cuboid: Cuboid::new(Vector::from_array(e)),
                offset: h.offset,
                rotation: h.rotation,
            }
        })
    }

    fn grab(&mut self, events: &mut Vec<Event>) {
        if self.held.is_some() {
            return;
        }
        let reach = Ball::new(
            self.params.proxy_radius_m + self.params.grab_distance_m + 2.0 * proxy::SKIN_M,
        );
        let pose = Pose::from_translation(self.proxy);
        let mut best: Option<(f64, BrickId)> = None;
        {
            let qp = self.phys.query_pipeline();
            for (_, co) in qp.intersect_shape(pose, &reach) {
                if let Touch::Brick(id) = tag_of(co.user_data) {
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
        let b = self.bricks[id.0 as usize];
        self.wake_neighbours(b.collider);
        if let Some(rb) = self.phys.bodies.get_mut(b.body) {
            let pos = *rb.position();
            rb.set_body_type(RigidBodyType::KinematicPositionBased, true);
            rb.set_linvel(Vector::ZERO, true);
            rb.set_angvel(Vector::ZERO, true);
            self.held = Some(Held {
                brick: id,
                offset: pos.translation - self.proxy,
                rotation: pos.rotation,
            });
            events.push(Event::Grabbed { brick: id });
        }
    }

    fn release(&mut self, events: &mut Vec<Event>) {
        let Some(h) = self.held.take() else {
            return;
        };
        let b = self.bricks[h.brick.0 as usize];
        let v = Vector::from_array(self.motion.velocity());
        if let Some(rb) = self.phys.bodies.get_mut(b.body) {
            rb.set_body_type(RigidBodyType::Dynamic, true);
            rb.set_linvel(v, true);
            rb.set_angvel(Vector::ZERO, true);
        }
        self.wake_neighbours(b.collider);
        events.push(Event::Released {
            brick: h.brick,
            velocity_m_s: arr(v),
        });
        if v.length() >= self.params.throw_min_speed_m_s {
            events.push(Event::Thrown {
                brick: h.brick,
                velocity_m_s: arr(v),
            });
        }
    }

    fn rotate(&mut self, axis: Axis, events: &mut Vec<Event>) {
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
        let b = self.bricks[h.brick.0 as usize];
        let e = self.params.brick_half_extents_m;
        let cuboid = Cuboid::new(Vector::from_array(e));
        let pose = Pose::from_parts(self.proxy + offset, rotation);
        let blocked = {
            let qp = self
                .phys
                .query_pipeline_with_filter(QueryFilter::default().exclude_collider(b.collider));
            qp.intersect_shape(pose, &cuboid).next().is_some()
        };
        if blocked {
            events.push(Event::RotationBlocked {
                brick: h.brick,
                axis,
            });
            return;
        }
        self.wake_neighbours(b.collider);
        if let Some(rb) = self.phys.bodies.get_mut(b.body) {
            rb.set_position(pose, true);
        }
        self.held = Some(Held {
            brick: h.brick,
            offset,
            rotation,
        });
        events.push(Event::Rotated {
            brick: h.brick,
            axis,
        });
    }

    /// Wakes every body in contact with `collider` (rapier does not always wake sleeping
    /// neighbours when a body changes type or is teleported).
    fn wake_neighbours(&mut self, collider: ColliderHandle) {
        let others: Vec<RigidBodyHandle> = self
            .phys
            .narrow_phase
            .contact_pairs_with(collider)
            .filter_map(|p| {
                let other = if p.collider1 == collider {
                    p.collider2
                } else {
                    p.collider1
                };
                self.phys.colliders.get(other)?.parent()
            })
            .collect();
        for h in others {
            if let Some(rb) = self.phys.bodies.get_mut(h) {
                if rb.body_type() == RigidBodyType::Dynamic {
                    rb.wake_up(true);
                }
            }
        }
    }

    fn loading_zone(&mut self, c: Vector, events: &mut Vec<Event>) {
        let Some(z) = self.params.loading_zone.clone() else {
            return;
        };
        let inside = c.x >= z.min_m[0]
            && c.x <= z.max_m[0]
            && c.y >= z.min_m[1]
            && c.y <= z.max_m[1]
            && c.z <= z.height_m;
        let entered = inside && !self.in_zone;
        self.in_zone = inside;
        if !entered || self.bricks.len() >= self.params.max_bricks {
            return;
        }
        let e = self.params.brick_half_extents_m;
        let spawn = BrickPlacement {
            center_m: [z.spawn_m[0], z.spawn_m[1], e[2]],
            rotation_deg: [0.0; 3],
        };
        // The spot must be clear (slightly shrunk box: resting on the ground is not overlap).
        let probe = Cuboid::new(Vector::from_array(e) * 0.99);
        let pose = Pose::from_translation(Vector::from_array(spawn.center_m));
        let clear = {
            let qp = self.phys.query_pipeline();
            let ball = Ball::new(self.params.proxy_radius_m);
            let proxy_pose = Pose::from_translation(self.proxy);
            let hits_scene = qp.intersect_shape(pose, &probe).next().is_some();
            let pos12 = pose.inv_mul(&proxy_pose);
            let hits_proxy = qp
                .dispatcher
                .intersection_test(&pos12, &probe, &ball)
                .map_or(true, |h| h.intersecting);
            !hits_scene && !hits_proxy
        };
        if clear {
            let id = self.insert_brick(&spawn);
            events.push(Event::Spawned { brick: id });
        }
    }

    fn update_slots(&mut self, events: &mut Vec<Event>) {
        if self.slots.is_empty() {
            return;
        }
        let held = self.held.map(|h| h.brick);
        for (si, slot) in self.params.blueprint.slots.iter().enumerate() {
            let mut best: Option<(f64, BrickId)> = None;
            for (bi, b) in self.bricks.iter().enumerate() {
                let id = BrickId(bi as u32);
                if Some(id) == held {
                    continue;
                }
                let rb = &self.phys.bodies[b.body];
                if rb.linvel().length() > RESTING_SPEED_M_S {
                    continue;
                }
                if let Some(d) = blueprint::fills(
                    &self.params.blueprint,
                    slot,
                    rb.translation(),
                    *rb.rotation(),
                ) && best.is_none_or(|(bd, _)| d < bd)
                {
                    best = Some((d, id));
                }
            }
            let now = best.map(|(_, id)| id);
            let before = self.slots[si];
            if now != before {
                if let Some(b) = before {
                    events.push(Event::SlotVacated { slot: si, brick: b });
                }
                if let Some(b) = now {
                    events.push(Event::SlotFilled { slot: si, brick: b });
                }
                self.slots[si] = now;
            }
        }
    }
}
