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
use crate::impact::events::ImpactTracker;
use crate::impact::hook::ImpactHook;
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
    /// Keep the contacts the hook would skip as idle (the crate's tests compare the two ways).
    keep_idle_contacts: bool,
    /// Never run a step quiet (see [`crate::rest`]; the crate's tests compare the two ways).
    never_quiet: bool,
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
            keep_idle_contacts: false,
            never_quiet: false,
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
        let before = self.held_static_lead(None);
        self.params.gravity_m_per_s2 = g_m_per_s2;
        self.bricks.set_gravity(g_m_per_s2);
        self.hand.rebalance(before, self.held_static_lead(None));
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
        if self.hand.set_inertia(mode, &mut self.bricks) {
            // A brick that becomes coupled in the hand starts at rest on its coupling.
            let lead = self.held_static_lead(None);
            self.hand.rebalance(Vector::ZERO, lead);
        }
    }

    /// The carried brick's static lead on its coupling (zero unless coupled), m; with
    /// `mass_kg` when its mass was just set.
    fn held_static_lead(&self, mass_kg: Option<f64>) -> Vector {
        self.hand
            .held_static_lead(&self.params, &self.limits, &self.bricks, mass_kg)
    }

    /// Sets the mass of every brick, kg in `[1e-3, 100]` (inertia tensor scales with it).
    pub fn set_brick_mass(&mut self, kg: f64) -> Result<(), ParamError> {
        range("brick_mass_kg", kg, Lo::Closed(1e-3), 100.0)?;
        let before = self.held_static_lead(None);
        self.params.brick_mass_kg = kg;
        self.bricks.set_brick_mass(kg);
        self.hand.rebalance(before, self.held_static_lead(Some(kg)));
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

    /// Outward normals of the surfaces the god-object touched in the last step.
    pub(crate) fn hand_contact_normals(&self) -> &[Vector] {
        self.hand.contact_normals()
    }

    /// The nearest surface within `range_m` of the cursor sphere (the carried brick
    /// excluded): its point and outward normal.
    pub(crate) fn nearest_surface(&self, range_m: f64) -> Option<(Vector, Vector)> {
        self.hand
            .nearest_surface(&self.params, &self.bricks, range_m)
    }

    /// The brick carried through the coupling, in the state the next step starts from.
    pub(crate) fn carried_body(&self) -> Option<haptic_types::local::Body> {
        self.hand
            .carried_body(&self.params, &self.limits, &self.bricks)
    }

    /// The carried brick's contacts as planes on its grip point at `grip_m`.
    pub(crate) fn carried_contacts(
        &self,
        grip_m: [f64; 3],
        velocity_m_per_s: [f64; 3],
        margin_m: f64,
    ) -> Vec<haptic_types::local::Plane> {
        self.hand.carried_contacts(
            &self.params,
            &self.bricks,
            grip_m,
            velocity_m_per_s,
            margin_m,
        )
    }

    /// Whether the last step ran quiet: every awake brick slower than
    /// [`crate::rest::QUIET_SPEED_M_PER_S`], resting contacts reused (see [`crate::rest`]).
    pub fn quiet(&self) -> bool {
        self.bricks.quiet()
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
        // A quiet step (see `crate::rest`) has no impact to solve or report and no hook. It
        // is never taken while the hand touches or carries something: what the hand feels is
        // computed from contacts computed afresh.
        bricks.veto_sleep(params, self.tick);
        let hand_free = self.hand.touching().is_empty() && self.hand.held_brick().is_none();
        let quiet = bricks.prepare_step(!self.keep_idle_contacts && !self.never_quiet && hand_free);
        let mut hook = if quiet {
            ImpactHook::quiet(&bricks.phys)
        } else {
            ImpactHook::for_step(&bricks.phys)
        };
        hook.keep_idle = self.keep_idle_contacts;
        self.impacts
            .before_step(&bricks.phys, bricks.bodies(), quiet);
        bricks.step(&hook);
        self.impacts
            .after_step(&bricks.phys, |c| bricks.body_of(c), quiet, &mut events);

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

impl World {
    /// The primitives the device may render until the next tick: a plane for each surface the
    /// god-object touches (deduplicated by normal) and for the nearest surface within
    /// [`crate::local::NEAR_SURFACE_M`], each `n·c ≥ n·proxy` at the proxy stiffness; and the carried brick.
    pub fn local_primitives(&self) -> haptic_types::local::WorldPrimitives {
        let p = self.params();
        let proxy = Vector::from_array(self.proxy_position_m());
        let k = p.proxy_stiffness_n_per_m;
        let mut planes: Vec<haptic_types::local::Plane> =
            Vec::with_capacity(crate::local::MAX_PLANES);
        let mut push = |n: Vector, offset: f64| {
            let dup = planes
                .iter()
                .any(|q| Vector::from_array(q.normal).dot(n) > 1.0 - 1e-9);
            if !dup
                && planes.len() < crate::local::MAX_PLANES
                && n.is_finite()
                && offset.is_finite()
            {
                planes.push(haptic_types::local::Plane {
                    normal: n.to_array(),
                    offset_m: offset,
                    stiffness_n_per_m: k,
                });
            }
        };
        for n in self.hand_contact_normals() {
            push(*n, n.dot(proxy));
        }
        if let Some((point, n)) = self.nearest_surface(crate::local::NEAR_SURFACE_M) {
            push(n, n.dot(point) + p.proxy_radius_m);
        }
        let body = self.carried_body();
        let body_planes = match &body {
            Some(b) => {
                let speed = Vector::from_array(b.velocity_m_per_s).length();
                self.carried_contacts(
                    b.position_m,
                    b.velocity_m_per_s,
                    crate::local::NEAR_SURFACE_M.max(speed * crate::local::LOOKAHEAD_S),
                )
            }
            None => Vec::new(),
        };
        haptic_types::local::WorldPrimitives {
            planes,
            body,
            body_planes,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod quiet_tests;
#[cfg(test)]
mod unit_tests;

#[cfg(test)]
mod tests {
    use super::*;

    fn at(c: [f64; 3]) -> BrickPlacement {
        BrickPlacement {
            center_m: c,
            rotation_deg: [0.0; 3],
        }
    }

    /// A floor of 5 × 4 bricks laid 5 mm apart on the ground, sleeping off.
    pub(super) fn floor() -> Params {
        floor_with_gaps(0.005)
    }

    /// A floor of 5 × 4 bricks laid `gap_m` apart on the ground, sleeping off.
    pub(super) fn floor_with_gaps(gap_m: f64) -> Params {
        let mut p = Params {
            sleeping: false,
            ..Params::default()
        };
        let h = p.brick_half_extents_m;
        for i in 0..5 {
            for j in 0..4 {
                p.bricks.push(at([
                    i as f64 * (2.0 * h[0] + gap_m),
                    j as f64 * (2.0 * h[1] + gap_m),
                    h[2],
                ]));
            }
        }
        p
    }

    /// Every brick's pose and velocity, bit for bit.
    fn state(w: &World) -> Vec<u64> {
        w.bricks()
            .flat_map(|b| {
                let mut v = b.position_m.to_vec();
                v.extend(b.orientation_xyzw);
                v.extend(b.velocity_m_per_s);
                v
            })
            .map(f64::to_bits)
            .collect()
    }

    /// `ticks` steps of a world of `p` and `extra`, keeping idle contacts or not, never quiet
    /// or quiet when it can be.
    fn run(
        p: &Params,
        (keep_idle, never_quiet): (bool, bool),
        ticks: usize,
        extra: &[(BrickPlacement, BrickProps)],
    ) -> World {
        let mut w = World::new(p, &Limits::FALCON).unwrap();
        w.keep_idle_contacts = keep_idle;
        w.never_quiet = never_quiet;
        for (pl, props) in extra {
            w.add_brick_with(*pl, *props).unwrap();
        }
        let input = w.input([1.5, 1.5, 1.5], Grip::default()).unwrap();
        for _ in 0..ticks {
            w.step(&input);
        }
        w
    }

    /// Solver contacts (points) of the pairs rapier holds now, and how many are farther apart
    /// than 0.1 mm.
    fn solver_contacts(w: &World) -> (usize, usize) {
        let mut n = (0, 0);
        for pair in w.bricks.phys.narrow_phase.contact_pairs() {
            for m in pair.solver_manifolds() {
                n.0 += m.data.solver_contacts.len();
                n.1 += m
                    .data
                    .solver_contacts
                    .iter()
                    .filter(|c| c.dist > 1e-4)
                    .count();
            }
        }
        n
    }

    /// A floor of 5 × 4 bricks laid 5 mm apart, nothing asleep: with the hook's skipping only
    /// the 4 ground contacts of each brick reach the solver; without it rapier also solves the
    /// idle speculative contacts between neighbours (within its 2 cm prediction distance).
    /// The floor stays put either way, to the micrometre.
    #[test]
    fn idle_speculative_contacts_of_a_floor_are_skipped() {
        let p = floor();
        let skip = run(&p, (false, false), 500, &[]);
        let keep = run(&p, (true, true), 500, &[]);
        assert_eq!(solver_contacts(&skip), (80, 0));
        let (n, idle) = solver_contacts(&keep);
        assert!(n > 80 && idle == n - 80, "{n} solver contacts, {idle} idle");
        for (a, b) in skip.bricks().zip(keep.bricks()) {
            for k in 0..3 {
                assert!((a.position_m[k] - b.position_m[k]).abs() < 1e-6);
                assert!((a.position_m[k] - p.bricks[a.id.0 as usize].center_m[k]).abs() < 1e-4);
            }
        }
    }

    /// Where no contact is idle the skipping changes nothing, to the bit (neither run quiet,
    /// whose recycled contacts differ in the last bits: see `crate::rest`): a settling stack of
    /// ten bricks (every contact touching), and a brick dropped from 1.5 m beside it onto the
    /// ground (its pair with the ground is within rapier's prediction distance only once it
    /// is within 4 steps of closing anyway).
    #[test]
    fn skipping_idle_contacts_changes_nothing_when_none_is_idle() {
        let mut p = Params::default();
        let h = p.brick_half_extents_m;
        p.bricks = (0..10)
            .map(|i| at([0.0, 0.0, h[2] * (2 * i + 1) as f64]))
            .collect();
        let drop = [(at([0.6, 0.0, h[2] + 1.5]), BrickProps::default())];
        let skip = run(&p, (false, true), 2000, &drop);
        let keep = run(&p, (true, true), 2000, &drop);
        assert_eq!(state(&skip), state(&keep));
        // The dropped brick did land and rest.
        let b = skip.brick(BrickId(10)).unwrap();
        assert!((b.position_m[2] - h[2]).abs() < 1e-3, "{:?}", b.position_m);
    }

    /// The skipping depends only on the world's state: a wall of 100 bricks knocked over twice
    /// gives the same bricks, bit for bit.
    #[test]
    fn a_knocked_over_wall_is_deterministic() {
        let p = Params::default();
        let h = p.brick_half_extents_m;
        let mut wall = Vec::new();
        for c in 0..10 {
            for i in 0..10 {
                let x =
                    (i as f64 - 4.5) * (2.0 * h[0] + 0.001) + if c % 2 == 0 { 0.0 } else { h[0] };
                let props = BrickProps {
                    velocity_m_per_s: if c >= 5 { [0.0, 1.0, 0.0] } else { [0.0; 3] },
                    ..BrickProps::default()
                };
                wall.push((at([x, 0.0, h[2] * (2 * c + 1) as f64]), props));
            }
        }
        let a = run(&p, (false, false), 1500, &wall);
        let b = run(&p, (false, false), 1500, &wall);
        assert_eq!(state(&a), state(&b));
        // The top half fell: some brick of it is now below its start height by a course.
        let fell = a
            .bricks()
            .filter(|v| {
                v.id.0 >= 50 && v.position_m[2] < wall[v.id.0 as usize].0.center_m[2] - 2.0 * h[2]
            })
            .count();
        assert!(fell >= 10, "{fell} bricks fell");
    }
}
