//! The brick set: the rapier bodies and colliders of the ground, the fixed obstacles and the
//! bricks, how bricks are placed (and the checks on a placement), the sleep policy, the
//! run-time material switches applied to every collider, and the views a renderer reads.
//!
//! rapier's `PhysicsWorld` (its body and collider sets, broad and narrow phase, solver) lives
//! here; the hand, the spawner and the blueprint read and move bodies through this set.

use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::prelude::{
    ActiveHooks, ColliderBuilder, ColliderHandle, FrictionModel, IntegrationParameters,
    PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, RigidBodyType,
};
use serde::Serialize;

use crate::error::WorldError;
use crate::event::{Body, BrickId, Touch};
use crate::impact::hook::ImpactHook;
use crate::params::{BrickPlacement, BrickProps, Lo, Params, finite3, placement, range};
use crate::rest::{BRICK_HOOKS, ContactMode};

/// rapier's `length_unit` for the brick world, m: 1/32 (a power of two, see
/// [`scale_to_length_unit`]).
///
/// rapier's broad phase pads every collider's box by `0.04 × length_unit` beyond its contact
/// margin, so that a box is moved in its tree only when the collider leaves the padding: with
/// rapier's default unit (1, for worlds in metres) that is 4 cm around a 6 cm-thick brick, and
/// every brick is paired with each neighbour within 10 cm, all of them pairs the impact hook
/// then filters out step after step. At 1/32 the padding is 1.25 mm. Every other parameter
/// that rapier scales by the unit is divided by it ([`scale_to_length_unit`]), so each physical
/// value is what it was, bit for bit (the goldens replay unchanged); a knocked-over wall and a
/// wall swept by the hand cost about a tenth less (BENCHMARKS.md, "Quiet steps").
pub const LENGTH_UNIT: f64 = 1.0 / 32.0;

/// Sets rapier's `length_unit` to [`LENGTH_UNIT`] and divides every parameter rapier scales
/// by it, so that each physical value stays as it was to the bit (a division by a power of
/// two is exact).
fn scale_to_length_unit(p: &mut IntegrationParameters) {
    let l = LENGTH_UNIT / p.length_unit;
    p.length_unit = LENGTH_UNIT;
    p.normalized_allowed_linear_error /= l;
    p.normalized_max_corrective_velocity /= l;
    p.normalized_prediction_distance /= l;
    p.normalized_max_linear_velocity /= l;
    p.normalized_contact_recycle_distance /= l;
}

/// Half-extent of the ground slab in x and y, m (the ground is a 100 m × 100 m slab whose top
/// face is the plane z = 0).
pub const GROUND_HALF_EXTENT_M: f64 = 50.0;

/// Speed (m/s, farthest point of the brick) below which a brick may start to count as resting;
/// rapier's own threshold for the sleep timer (its default is 0.05 m/s, which freezes a brick
/// gliding at 4 cm/s on frictionless ground).
pub const SLEEP_SPEED_M_PER_S: f64 = 2e-3;
/// Net acceleration (m/s², farthest point) at or above which a slow brick is never put to sleep:
/// over rapier's 0.5 s sleep window its velocity must change by less than this × the window.
/// A brick starting from rest on a ramp 0.01° steeper than the friction angle (μ = 0.6)
/// accelerates at g·δ·(cos θ + μ sin θ) ≈ 2e-3 m/s² and keeps sliding; one with less net
/// acceleration may sleep after moving under 0.5 mm in its first second. Resting bricks and
/// stacks sleep (tests `resting_brick_and_brick_below_friction_angle_fall_asleep`,
/// `stack_of_ten_bricks_stays_put_for_60_s`).
pub const SLEEP_MAX_ACCEL_M_PER_S2: f64 = 1e-3;

const TAG_GROUND: u128 = 0;
const TAG_OBSTACLE: u128 = 1 << 64;
const TAG_BRICK: u128 = 2 << 64;

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
    pub velocity_m_per_s: [f64; 3],
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

/// A unit quaternion as `[x, y, z, w]`.
pub(crate) fn quat(r: Rotation) -> [f64; 4] {
    [r.x, r.y, r.z, r.w]
}

/// What a collider is, from the tag in its user data.
fn tag_of(user_data: u128) -> Touch {
    let idx = (user_data & u64::MAX as u128) as u64;
    match user_data >> 64 {
        0 => Touch::Ground,
        1 => Touch::Obstacle(idx as usize),
        _ => Touch::Brick(BrickId(idx as u32)),
    }
}

#[derive(Debug, Clone, Copy)]
struct Brick {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    /// Linear and angular velocity when the brick last became slow (start of rapier's sleep
    /// window), and the tick then.
    slow_since: Option<(u64, Vector, Vector)>,
}

/// The rigid bodies of the world: ground, obstacles and bricks in rapier's physics world.
pub(crate) struct BrickSet {
    /// rapier's bodies, colliders, contact graph and solver.
    pub(crate) phys: PhysicsWorld,
    ground: ColliderHandle,
    obstacles: Vec<ColliderHandle>,
    bricks: Vec<Brick>,
    /// Whether the coming step is quiet (see [`crate::rest`]).
    contacts: ContactMode,
    /// Largest distance, m, of a brick's point from its centre.
    radius_m: f64,
    /// Whether bricks may sleep ([`Params::sleeping`]).
    sleeping: bool,
}

impl BrickSet {
    /// The ground, the obstacles and the initial bricks of `params` (validated), with the
    /// scene queries up to date.
    pub(crate) fn new(params: &Params) -> BrickSet {
        let mut phys = PhysicsWorld::new();
        phys.gravity = Vector::new(0.0, 0.0, -params.gravity_m_per_s2);
        phys.integration_parameters.dt = params.dt_s;
        phys.integration_parameters.num_solver_iterations = params.solver_iterations;
        scale_to_length_unit(&mut phys.integration_parameters);
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
        let ground_body = phys.insert_body(RigidBodyBuilder::fixed());
        let ground = phys.insert_collider(
            ColliderBuilder::cuboid(GROUND_HALF_EXTENT_M, GROUND_HALF_EXTENT_M, 1.0)
                .translation(Vector::new(0.0, 0.0, -1.0))
                .friction(params.friction)
                .restitution(params.restitution)
                .user_data(TAG_GROUND),
            Some(ground_body),
        );
        let mut obstacles = Vec::new();
        for (i, o) in params.obstacles.iter().enumerate() {
            let rot = BrickPlacement {
                center_m: o.center_m,
                rotation_deg: o.rotation_deg,
            }
            .rotation();
            let h = o.half_extents_m;
            let co = phys.insert_collider(
                ColliderBuilder::cuboid(h[0], h[1], h[2])
                    .position(Pose::from_parts(Vector::from_array(o.center_m), rot))
                    .friction(params.friction)
                    .restitution(params.restitution)
                    .user_data(TAG_OBSTACLE | i as u128),
                Some(ground_body),
            );
            obstacles.push(co);
        }
        let contacts = ContactMode::new(&mut phys);
        let h = params.brick_half_extents_m;
        let mut set = BrickSet {
            phys,
            ground,
            obstacles,
            bricks: Vec::new(),
            contacts,
            radius_m: h[0].hypot(h[1]).hypot(h[2]),
            sleeping: params.sleeping,
        };
        for b in &params.bricks {
            set.insert(params, b, &BrickProps::default());
        }
        // Make the scene-query structure see the initial bodies without advancing time.
        set.refresh_queries();
        set
    }

    /// Updates broad-phase and contacts with no time passing (rapier: a step with `dt = 0`).
    pub(crate) fn refresh_queries(&mut self) {
        let dt = self.phys.integration_parameters.dt;
        self.phys.integration_parameters.dt = 0.0;
        self.phys.step_with_events(&ImpactHook::default(), &());
        self.phys.integration_parameters.dt = dt;
    }

    /// Decides whether the coming step is quiet (see [`crate::rest`]; never when `allowed` is
    /// false) and sets rapier up for it; returns whether it is.
    pub(crate) fn prepare_step(&mut self, allowed: bool) -> bool {
        let bricks = self.bricks.iter().map(|b| (b.body, b.collider));
        self.contacts.before_step(
            &mut self.phys,
            bricks,
            self.radius_m,
            allowed,
            !self.sleeping,
        )
    }

    /// Whether the last step ran quiet (see [`crate::rest`]).
    pub(crate) fn quiet(&self) -> bool {
        self.contacts.is_quiet()
    }

    /// Advances rapier by one `dt_s` with the contact-modification `hook`.
    pub(crate) fn step(&mut self, hook: &ImpactHook) {
        self.phys.step_with_events(hook, &());
    }

    /// Adds a dynamic brick (no checks: see [`BrickSet::check_placement`]); `props` override
    /// the world's mass, friction, restitution and give an initial velocity.
    pub(crate) fn insert(
        &mut self,
        params: &Params,
        placement: &BrickPlacement,
        props: &BrickProps,
    ) -> BrickId {
        let id = BrickId(self.bricks.len() as u32);
        let pose = Pose::from_parts(Vector::from_array(placement.center_m), placement.rotation());
        let body = self.phys.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(pose)
                .can_sleep(params.sleeping),
        );
        let h = params.brick_half_extents_m;
        let collider = self.phys.insert_collider(
            ColliderBuilder::cuboid(h[0], h[1], h[2])
                .mass(props.mass_kg.unwrap_or(params.brick_mass_kg))
                .friction(props.friction.unwrap_or(params.friction))
                .restitution(props.restitution.unwrap_or(params.restitution))
                .user_data(TAG_BRICK | id.0 as u128)
                .active_hooks(if self.contacts.is_quiet() {
                    ActiveHooks::empty()
                } else {
                    BRICK_HOOKS
                }),
            Some(body),
        );
        if let Some(rb) = self.phys.bodies.get_mut(body) {
            rb.activation_mut().normalized_linear_threshold =
                SLEEP_SPEED_M_PER_S / self.phys.integration_parameters.length_unit;
            if props.velocity_m_per_s != [0.0; 3] {
                rb.set_linvel(Vector::from_array(props.velocity_m_per_s), true);
            }
        }
        self.bricks.push(Brick {
            body,
            collider,
            slow_since: None,
        });
        id
    }

    /// Checks a placement (centre in ±100 m, rotation in ±3600°) and that one more brick fits
    /// under [`Params::max_bricks`].
    pub(crate) fn check_placement(
        &self,
        params: &Params,
        p: &BrickPlacement,
    ) -> Result<(), WorldError> {
        placement("brick", p)?;
        if self.bricks.len() >= params.max_bricks {
            return Err(WorldError::TooManyBricks {
                max: params.max_bricks,
            });
        }
        Ok(())
    }

    /// Checks one brick's own properties against the ranges of the world's.
    pub(crate) fn check_props(props: &BrickProps) -> Result<(), WorldError> {
        finite3("brick.velocity_m_per_s", &props.velocity_m_per_s, 100.0)?;
        if let Some(m) = props.mass_kg {
            range("brick.mass_kg", m, Lo::Closed(1e-3), 100.0)?;
        }
        if let Some(mu) = props.friction {
            range("brick.friction", mu, Lo::Closed(0.0), 10.0)?;
        }
        if let Some(e) = props.restitution {
            range("brick.restitution", e, Lo::Closed(0.0), 1.0)?;
        }
        Ok(())
    }

    /// Number of bricks.
    pub(crate) fn len(&self) -> usize {
        self.bricks.len()
    }

    /// The rigid body of brick `id` (an id this set issued).
    pub(crate) fn body(&self, id: BrickId) -> RigidBodyHandle {
        self.bricks[id.0 as usize].body
    }

    /// The collider of brick `id` (an id this set issued).
    pub(crate) fn collider(&self, id: BrickId) -> ColliderHandle {
        self.bricks[id.0 as usize].collider
    }

    /// Every brick's rigid body, in id order.
    pub(crate) fn bodies(&self) -> impl Iterator<Item = RigidBodyHandle> + '_ {
        self.bricks.iter().map(|b| b.body)
    }

    /// What a collider is (ground, obstacle or brick), if it exists.
    pub(crate) fn touch_of(&self, collider: ColliderHandle) -> Option<Touch> {
        self.phys
            .colliders
            .get(collider)
            .map(|co| tag_of(co.user_data))
    }

    /// The body a collider belongs to, for impact events (the ground if it is gone).
    pub(crate) fn body_of(&self, collider: ColliderHandle) -> Body {
        self.touch_of(collider).map_or(Body::Ground, Body::from)
    }

    /// One brick; `held` is the carried brick, if any.
    pub(crate) fn view(
        &self,
        params: &Params,
        id: BrickId,
        held: Option<BrickId>,
    ) -> Result<BrickView, WorldError> {
        let b = self
            .bricks
            .get(id.0 as usize)
            .ok_or(WorldError::UnknownBrick(id.0))?;
        let rb = &self.phys.bodies[b.body];
        Ok(BrickView {
            id,
            position_m: rb.translation().to_array(),
            orientation_xyzw: quat(*rb.rotation()),
            half_extents_m: params.brick_half_extents_m,
            velocity_m_per_s: rb.linvel().to_array(),
            held: held == Some(id),
            sleeping: rb.is_sleeping(),
        })
    }

    /// The fixed obstacles, in [`Params::obstacles`] order.
    pub(crate) fn obstacles(&self) -> impl Iterator<Item = BoxView> + '_ {
        self.obstacles.iter().filter_map(|h| {
            let co = self.phys.colliders.get(*h)?;
            let c = co.shape().as_cuboid()?;
            Some(BoxView {
                position_m: co.position().translation.to_array(),
                orientation_xyzw: quat(co.position().rotation),
                half_extents_m: c.half_extents.to_array(),
            })
        })
    }

    /// The ground slab: its top face is the plane z = 0.
    pub(crate) fn ground(&self) -> BoxView {
        let co = &self.phys.colliders[self.ground];
        let half = co
            .shape()
            .as_cuboid()
            .map_or([GROUND_HALF_EXTENT_M, GROUND_HALF_EXTENT_M, 1.0], |c| {
                c.half_extents.to_array()
            });
        BoxView {
            position_m: co.position().translation.to_array(),
            orientation_xyzw: quat(co.position().rotation),
            half_extents_m: half,
        }
    }

    /// Number of bricks rapier currently simulates (awake).
    pub(crate) fn awake_count(&self) -> usize {
        self.bricks
            .iter()
            .filter(|b| !self.phys.bodies[b.body].is_sleeping())
            .count()
    }

    /// The sleep policy: rapier puts a body to sleep once it has been slower than
    /// [`SLEEP_SPEED_M_PER_S`] for 0.5 s. That alone freezes a brick that starts sliding from rest
    /// with a small net force (it stays slow for its first half second). So a slow brick is
    /// allowed to fall asleep only if its velocity also stayed constant over that window (net
    /// acceleration below [`SLEEP_MAX_ACCEL_M_PER_S2`]): a brick under an unbalanced force is kept
    /// awake, and sleep only skips bricks that are truly at rest. `tick` is the tick about to
    /// be simulated.
    pub(crate) fn veto_sleep(&mut self, params: &Params, tick: u64) {
        if !params.sleeping {
            return;
        }
        let dt = params.dt_s;
        for b in &mut self.bricks {
            // Read through `get`: `get_mut` would flag every brick as changed by the user, and
            // rapier would re-process all of them (sleeping ones too) on every step.
            let Some(rb) = self.phys.bodies.get(b.body) else {
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
            let reach = params.brick_half_extents_m;
            let r = (reach[0] * reach[0] + reach[1] * reach[1] + reach[2] * reach[2]).sqrt();
            let change = (v - v0).length() + (w - w0).length() * r;
            if change >= SLEEP_MAX_ACCEL_M_PER_S2 * elapsed.max(dt) {
                if let Some(rb) = self.phys.bodies.get_mut(b.body) {
                    rb.wake_up(true);
                }
                b.slow_since = Some((tick, v, w));
            }
        }
    }

    /// Wakes every body in contact with `collider` (rapier does not always wake sleeping
    /// neighbours when a body changes type or is teleported).
    pub(crate) fn wake_neighbours(&mut self, collider: ColliderHandle) {
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

    // ----- run-time switches (values already checked) ---------------------------------

    /// Gravity `g` (m/s²) along −z; wakes every body.
    pub(crate) fn set_gravity(&mut self, g_m_per_s2: f64) {
        self.phys.gravity = Vector::new(0.0, 0.0, -g_m_per_s2);
        self.phys.wake_up_all(true);
    }

    /// Restitution of every collider; wakes every body.
    pub(crate) fn set_restitution(&mut self, e: f64) {
        for (_, co) in self.phys.all_colliders_mut() {
            co.set_restitution(e);
        }
        // A recycled contact keeps the material it was computed with (see `crate::rest`).
        self.contacts.refresh();
        self.phys.wake_up_all(true);
    }

    /// Friction coefficient of every collider; wakes every body.
    pub(crate) fn set_friction(&mut self, mu: f64) {
        for (_, co) in self.phys.all_colliders_mut() {
            co.set_friction(mu);
        }
        // A recycled contact keeps the material it was computed with (see `crate::rest`).
        self.contacts.refresh();
        self.phys.wake_up_all(true);
    }

    /// Mass of every brick, kg; wakes every body.
    pub(crate) fn set_brick_mass(&mut self, kg: f64) {
        for b in &self.bricks {
            if let Some(co) = self.phys.colliders.get_mut(b.collider) {
                co.set_mass(kg);
            }
            // The body's mass at once, not at the engine's next step: an impulse applied before
            // that step (the coupling's pull on a carried brick) must move the new mass.
            if let Some(rb) = self.phys.bodies.get_mut(b.body) {
                rb.recompute_mass_properties_from_colliders(&self.phys.colliders);
            }
        }
        self.contacts.refresh();
        self.phys.wake_up_all(true);
    }
}
