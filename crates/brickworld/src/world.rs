//! The macro world: the [`World`] (parameters, device limits and the sets — bricks, hand,
//! blueprint slots, spawner, impact tracker), its run-time switches, read access for renderers
//! and recorders, and [`World::step`], which orchestrates one tick.

use rapier3d_f64::math::Vector;
use serde::Serialize;
use world_form::Limits;

use crate::blueprint::{Score, SlotView, Slots};
use crate::bricks::{BoxView, BrickSet, BrickView};
use crate::error::{InputError, ParamError, WorldError};
use crate::event::{BrickId, Event, Touch};
use crate::hand::Hand;
use crate::impact::ImpactHook;
use crate::impacts::ImpactTracker;
use crate::input::{CursorInput, Grip};
use crate::params::{AccelEstimator, BrickPlacement, BrickProps, Inertia, Lo, Params, range};
use crate::spawner::Spawner;

/// What one step produced for the device and the logs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StepReport {
    /// Index of the tick just simulated (0 for the first step).
    pub tick: u64,
    /// Force to render on the device, N, world frame: the sum below, scaled down to
    /// [`Limits::max_force_n`] if larger (then `saturated` is true). Always finite.
    pub force_n: [f64; 3],
    /// Whether `force_n` was scaled down to the device limit.
    pub saturated: bool,
    /// Proxy spring `k (p - c)`, N (`-k d n` against one surface).
    pub spring_force_n: [f64; 3],
    /// Local stiffness of the rendered force field this tick, N/m: `proxy_stiffness_n_per_m` while
    /// the cursor (or carried brick) touches something, 0 in free space (where `p = c`).
    pub stiffness_n_per_m: f64,
    /// Weight of the carried brick `-M g z`, N (zero when nothing is carried or gravity is off).
    pub weight_force_n: [f64; 3],
    /// Inertial force of the carried brick `-M a`, N (the paper's method only; zero otherwise).
    pub inertia_force_n: [f64; 3],
    /// The virtual coupling's pull on the hand, N (`inertia = "coupling"` only: the carried
    /// brick's weight, inertia and contacts as they reach the hand; zero otherwise).
    pub coupling_force_n: [f64; 3],
    /// Grip-point acceleration estimate used for the inertial force, m/s².
    pub acceleration_m_per_s2: [f64; 3],
    /// Deepest penetration of the cursor sphere or carried brick into anything at the start of the
    /// tick (bodies that moved into it), m, before it was pushed out.
    pub proxy_penetration_m: f64,
    /// Events, in the order they happened.
    pub events: Vec<Event>,
}

/// The macro world: bricks on a ground plane under gravity, a cursor proxy, the house task.
///
/// Parameters ([`Params`]) are fixed at creation except for the run-time switches, which have
/// validated setters. [`World::step`] advances one tick of `dt_s`.
pub struct World {
    /// What never changes during a step (the switches change it between steps).
    params: Params,
    /// What the device renders, in the world's units.
    limits: Limits,
    /// Ground, obstacles and bricks: rapier's bodies and colliders.
    bricks: BrickSet,
    /// The cursor proxy and what it carries.
    hand: Hand,
    /// The blueprint's slots and what fills them.
    slots: Slots,
    /// The loading zone.
    spawner: Spawner,
    /// Contacts that carried impulse, step to step (impact events).
    impacts: ImpactTracker,
    /// Ticks simulated so far.
    tick: u64,
}

impl World {
    /// Builds a world from its parameters and the limits of the device it renders to (in the
    /// world's units). Fails with the first out-of-range parameter, naming it.
    pub fn new(params: &Params, limits: &Limits) -> Result<World, ParamError> {
        params.validate()?;
        params.validate_for_device(limits)?;
        Ok(World {
            bricks: BrickSet::new(params),
            hand: Hand::new(params),
            slots: Slots::new(&params.blueprint),
            spawner: Spawner::default(),
            impacts: ImpactTracker::default(),
            params: params.clone(),
            limits: *limits,
            tick: 0,
        })
    }

    /// Adds a brick at `placement` (centre m, rotation vector deg). The pose is validated like
    /// [`Params::bricks`]; the count is limited by [`Params::max_bricks`].
    pub fn add_brick(&mut self, placement: BrickPlacement) -> Result<BrickId, WorldError> {
        self.add_brick_with(placement, BrickProps::default())
    }

    /// Adds a brick like [`World::add_brick`] with its own initial velocity, mass, friction and
    /// restitution ([`BrickProps`]; `None` takes the world's value). The run-time switches
    /// ([`World::set_friction`], ...) later set every brick, this one included.
    pub fn add_brick_with(
        &mut self,
        placement: BrickPlacement,
        props: BrickProps,
    ) -> Result<BrickId, WorldError> {
        BrickSet::check_props(&props)?;
        self.bricks.check_placement(&self.params, &placement)?;
        let id = self.bricks.insert(&self.params, &placement, &props);
        self.bricks.refresh_queries();
        Ok(id)
    }

    /// Validates a device sample against this world's workspace box.
    pub fn input(&self, position_m: [f64; 3], grip: Grip) -> Result<CursorInput, InputError> {
        CursorInput::new(position_m, grip, self.params.workspace_half_extent_m)
    }

    // ----- run-time switches -------------------------------------------------------------

    /// Sets the magnitude of gravity, m/s² in `[0, 100]` (0 = off). Wakes every brick.
    pub fn set_gravity(&mut self, g_m_per_s2: f64) -> Result<(), ParamError> {
        range("gravity_m_per_s2", g_m_per_s2, Lo::Closed(0.0), 100.0)?;
        self.params.gravity_m_per_s2 = g_m_per_s2;
        self.bricks.set_gravity(g_m_per_s2);
        Ok(())
    }

    /// Sets the coefficient of restitution of every contact, in `[0, 1]`.
    pub fn set_restitution(&mut self, e: f64) -> Result<(), ParamError> {
        range("restitution", e, Lo::Closed(0.0), 1.0)?;
        self.params.restitution = e;
        self.bricks.set_restitution(e);
        Ok(())
    }

    /// Sets the friction coefficient of every contact, in `[0, 10]` (0 = frictionless).
    /// Wakes every brick, so that bricks held only by friction slide at once.
    pub fn set_friction(&mut self, mu: f64) -> Result<(), ParamError> {
        range("friction", mu, Lo::Closed(0.0), 10.0)?;
        self.params.friction = mu;
        self.bricks.set_friction(mu);
        Ok(())
    }

    /// Sets how a carried brick's inertia is felt ([`Inertia`]); a brick in the hand changes
    /// between coupled and rigidly carried where it is.
    pub fn set_inertia(&mut self, mode: Inertia) {
        self.params.inertia = mode;
        self.hand.set_inertia(mode, &mut self.bricks);
    }

    /// Sets the mass of every brick, kg in `[1e-3, 100]` (inertia tensor scales with it).
    pub fn set_brick_mass(&mut self, kg: f64) -> Result<(), ParamError> {
        range("brick_mass_kg", kg, Lo::Closed(1e-3), 100.0)?;
        self.params.brick_mass_kg = kg;
        self.bricks.set_brick_mass(kg);
        Ok(())
    }

    /// Chooses the acceleration estimator for the inertial force (history is kept).
    pub fn set_accel_estimator(&mut self, kind: AccelEstimator) -> Result<(), ParamError> {
        let mut p = self.params.clone();
        p.accel_estimator = kind;
        p.validate()?;
        self.params.accel_estimator = kind;
        self.hand.set_accel_estimator(self.params.dt_s, kind);
        Ok(())
    }

    // ----- read access -------------------------------------------------------------------

    /// The parameters in force (switches included).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The device limits this world renders to, in the world's units.
    pub fn limits(&self) -> &Limits {
        &self.limits
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
        self.bricks.view(&self.params, id, self.hand.held_brick())
    }

    /// All bricks in id order.
    pub fn bricks(&self) -> impl Iterator<Item = BrickView> + '_ {
        (0..self.bricks.len() as u32).filter_map(|i| self.brick(BrickId(i)).ok())
    }

    /// The fixed obstacles, in [`Params::obstacles`] order.
    pub fn obstacles(&self) -> impl Iterator<Item = BoxView> + '_ {
        self.bricks.obstacles()
    }

    /// The ground slab as a renderer sees it: its top face is the plane z = 0.
    pub fn ground(&self) -> BoxView {
        self.bricks.ground()
    }

    /// Centre of the cursor sphere (the god-object / proxy), m. Before the first step: the top
    /// centre of the workspace, `[0, 0, workspace_half_extent_m]`.
    pub fn proxy_position_m(&self) -> [f64; 3] {
        self.hand.proxy().to_array()
    }

    /// Last device cursor position, m (same placeholder as the proxy before the first step).
    pub fn cursor_position_m(&self) -> [f64; 3] {
        self.hand.cursor().to_array()
    }

    /// The carried brick, if any.
    pub fn held_brick(&self) -> Option<BrickId> {
        self.hand.held_brick()
    }

    /// What the cursor (or carried brick) touches now, sorted.
    pub fn touching(&self) -> &[Touch] {
        self.hand.touching()
    }

    /// The blueprint slots and their state, in [`Params::blueprint`] order.
    pub fn slots(&self) -> impl Iterator<Item = SlotView> + '_ {
        self.slots.views(&self.params.blueprint)
    }

    /// The house-task score.
    pub fn score(&self) -> Score {
        self.slots.score()
    }

    /// Distance from the cursor sphere's surface to the nearest solid (ground, obstacle or
    /// brick other than the carried one), m: 0 when touching, `f64::INFINITY` when nothing is
    /// within [`crate::NEAREST_MAX_M`] (the proximity sound's input).
    pub fn nearest_m(&self) -> f64 {
        self.hand.nearest_m(&self.params, &self.bricks)
    }

    /// Number of bricks the physics engine currently simulates (awake), for cost accounting.
    pub fn awake_brick_count(&self) -> usize {
        self.bricks.awake_count()
    }

    // ----- the step ----------------------------------------------------------------------

    /// Advances the world by one tick of `dt_s` with the device sample `input`: the hand
    /// (grip commands, proxy, felt force, its push on bricks), the spawner, the rigid-body
    /// physics (sleep policy, impact hook, impact events), then the blueprint.
    pub fn step(&mut self, input: &CursorInput) -> StepReport {
        let mut events = Vec::new();
        let (params, bricks) = (&self.params, &mut self.bricks);

        // 1.-4. The hand: grip, god-object, force for the device, touches and pushes.
        let felt = self
            .hand
            .step(input, self.tick, params, &self.limits, bricks, &mut events);

        // 5. Loading zone.
        let (cursor, proxy) = (self.hand.cursor(), self.hand.proxy());
        self.spawner
            .step(cursor, proxy, params, bricks, &mut events);

        // 6. Rigid-body physics (the sleep veto first: see `BrickSet::veto_sleep`).
        bricks.veto_sleep(params, self.tick);
        let hook = ImpactHook::for_step(&bricks.phys);
        self.impacts.before_step(&bricks.phys, bricks.bodies());
        bricks.step(&hook);
        self.impacts
            .after_step(&bricks.phys, |c| bricks.body_of(c), &mut events);

        // 7. Blueprint.
        self.slots
            .update(params, bricks, self.hand.held_brick(), &mut events);

        // 8. Device force (computed by the hand).
        let arr = |v: Vector| v.to_array();
        let report = StepReport {
            tick: self.tick,
            force_n: arr(felt.force),
            saturated: felt.saturated,
            spring_force_n: arr(felt.spring),
            stiffness_n_per_m: if self.hand.touching().is_empty() {
                0.0
            } else {
                params.proxy_stiffness_n_per_m
            }
            .max(self.hand.felt_coupling_stiffness(params, &self.limits)),
            weight_force_n: arr(felt.weight),
            inertia_force_n: arr(felt.inertia),
            coupling_force_n: arr(felt.coupling),
            acceleration_m_per_s2: arr(felt.acceleration),
            proxy_penetration_m: felt.penetration_m,
            events,
        };
        self.tick += 1;
        report
    }
}
