//! Simultaneous-impact restitution for flat landings (a rapier contact-modification hook).
//!
//! rapier 0.36 applies restitution in one sequential (Gauss–Seidel) pass over the contact
//! points after the velocity solve. For a single point (a ball, a brick landing on an edge or a
//! corner) that pass is exact: the first rebound apex of a ball is `e² h` within 1 % at 1 kHz.
//! For a brick landing flat, its four corner points are processed one after the other with
//! clamped accumulated impulses: the first corner's impulse sets the brick spinning and the
//! rebound comes out near `(0.6 e)²`, not `e²` (measured: e = 0.5 gives 0.10 instead of 0.25).
//!
//! Physically the four corners hit at once and, by symmetry, the brick rebounds without spin at
//! `e v`. This hook reproduces that: on the step of an impact — a manifold of several points, none
//! of which carried an impulse on the previous step, approaching faster than
//! [`IMPACT_MIN_SPEED_M_PER_S`] — it replaces the points by one point at their centroid, so the
//! single-point restitution pass (exact) applies the whole impulse through the centroid. Resting
//! and sliding contacts (which carried impulse) and slow approaches are left untouched, so stacks
//! keep their full four-point support.

use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    Collider, ColliderHandle, ContactModificationContext, PairContacts, PairFilterContext,
    PhysicsHooks, PhysicsWorld, RigidBody, RigidBodyHandle, RigidBodySet, RigidBodyType,
    SolverContact, SolverFlags,
};

use super::IMPACT_MIN_SPEED_M_PER_S;

/// Separation (m) up to which a contact is always computed and solved; a farther
/// (speculative) one only if its bodies approach fast enough to close the gap soon
/// ([`PAIR_LOOKAHEAD_STEPS`], [`SOLVER_LOOKAHEAD_STEPS`]).
///
/// rapier computes contacts for every pair of colliders closer than its prediction distance
/// (2 cm by default, tuned for 60 Hz games, where a body at 1 m/s moves 17 mm a step) and makes
/// a solver constraint of every such point. At 1 kHz that puts every pair of bricks laid within
/// 2 cm of each other through the narrow phase and into the solver, four points a pair, though
/// none of them can act: a contact `d` apart acts only if its bodies close `d` within the step.
/// In a floor of bricks laid 5 mm apart, 77 % of the solver contacts were such idle constraints,
/// and with the narrow phase they made 80 % of a tick's cost (docs/brickworld.md). The prediction
/// distance itself stays: the impact rule of [`ImpactHook`] looks ahead through it (the
/// contacts it reads are those of the previous step). The hook skips the idle work instead:
/// [`ImpactHook::filter_contact_pair`] drops pairs whose bounding boxes are farther apart than
/// this plus [`PAIR_LOOKAHEAD_STEPS`] steps of their largest closing speed, and
/// [`ImpactHook::modify_solver_contacts`] drops, on a manifold with no impact, the points
/// farther than this whose approach would not close the gap in [`SOLVER_LOOKAHEAD_STEPS`]
/// steps. A carried kinematic brick keeps all its contacts (the hand moves it).
pub const SPECULATIVE_KEEP_M: f64 = 1e-3;

/// Steps of closing speed within which a pair of colliders is given to the narrow phase (see
/// [`SPECULATIVE_KEEP_M`]). The impact rule needs an approaching pair's manifold two steps
/// before the landing (it reads the contacts of the previous step), and a manifold built on
/// the step before that from nothing can hold two points of a flat landing instead of four
/// (measured: a centred 1 m drop then kicks the brick on top sideways at 0.025 m/s); four steps
/// leave the manifold two updates to settle.
pub const PAIR_LOOKAHEAD_STEPS: f64 = 4.0;

/// Steps of approach within which a speculative solver contact is kept (see
/// [`SPECULATIVE_KEEP_M`]): the step itself, and one more for the speed a body gains within
/// the step from another contact.
pub const SOLVER_LOOKAHEAD_STEPS: f64 = 2.0;

/// Horizontal distance (m) from a body's centre of mass within which a support load counts as
/// central (no moment), so that an impact may pass through the body's supports merged at their
/// centroid (see [`ImpactHook`]).
pub const CENTRAL_LOAD_M: f64 = 1e-3;

/// The hook, with the bodies that take part in an impact this step.
///
/// A flat landing on a brick that rests on the ground (or on a stack) passes the impact down
/// through the resting contacts below within the same step. Those contacts carry impulse, so
/// the rule above leaves their four points to the sequential pass, which loads one corner
/// first: the struck brick spins a little, friction turns the spin into a sideways slide, and
/// the brick on top is kicked sideways (a centred 0.5 m drop was kicked at 0.06 m/s and came to
/// rest 0.5 mm off centre, a 1.5 m drop 17 mm). So on an impact step every support manifold
/// (normal within 45° of vertical) of a body in `impacted` is also merged to its centroid. A
/// body is in `impacted` (see [`ImpactHook::for_step`]) when the impact's load passes through
/// its centre of mass — then the load has no moment and a support without lever arm is exact —
/// and the rule follows such central supports down (and up) the stack. An off-centre load keeps
/// every support point: its lever arms are physical (a brick landing across two others).
#[derive(Debug, Default, Clone)]
pub struct ImpactHook {
    /// Bodies taking part in an impact on this step.
    pub impacted: Vec<RigidBodyHandle>,
    /// The step the contacts are solved over, s (0: no time passes, and every contact farther
    /// than [`SPECULATIVE_KEEP_M`] is idle). See [`SPECULATIVE_KEEP_M`].
    pub dt_s: f64,
    /// Where the colliders of the awake dynamic bodies are and how fast they can close a gap,
    /// by collider index, taken before the step (see [`ImpactHook::filter_contact_pair`]).
    reach: Vec<Option<Reach>>,
    /// Keep every contact rapier computes (the idle ones too): the crate's tests compare the
    /// two ways.
    pub(crate) keep_idle: bool,
}

/// A collider of an awake dynamic body before the step: its world AABB and the largest speed of
/// any of its points.
#[derive(Debug, Clone, Copy)]
struct Reach {
    /// The collider handle's generation (a slot reused by another collider does not match).
    generation: u32,
    /// World AABB, m.
    mins: Vector,
    maxs: Vector,
    /// Linear velocity of the body, m/s.
    v: Vector,
    /// Largest speed of a point of the collider through the rotation alone, m/s.
    spin: f64,
    /// Angular speed of the body, rad/s.
    w: f64,
}

impl Reach {
    /// The collider `co` of the dynamic body `rb`, placed by the body's pose (a collider's own
    /// pose is brought up to date only inside the step).
    fn of(co: &Collider, rb: &RigidBody, generation: u32) -> Reach {
        let pose = co
            .position_wrt_parent()
            .map_or(*rb.position(), |p| *rb.position() * *p);
        let aabb = co.shape().compute_aabb(&pose);
        let w = rb.angvel().length();
        let spin = if w == 0.0 {
            0.0
        } else {
            let s = co.shape().compute_bounding_sphere(&pose);
            w * ((s.center - rb.center_of_mass()).length() + s.radius)
        };
        Reach {
            generation,
            mins: aabb.mins,
            maxs: aabb.maxs,
            v: rb.linvel(),
            spin,
            w,
        }
    }

    /// A collider that does not move (on a fixed body, a sleeping body, or none).
    fn still(co: &Collider) -> Reach {
        let aabb = co.compute_aabb();
        Reach {
            generation: 0,
            mins: aabb.mins,
            maxs: aabb.maxs,
            v: Vector::ZERO,
            spin: 0.0,
            w: 0.0,
        }
    }
}

impl ImpactHook {
    /// The hook of a quiet step (see [`crate::rest`]): no brick has hooks then, so it keeps no
    /// table and has no impact.
    pub fn quiet(phys: &PhysicsWorld) -> ImpactHook {
        ImpactHook {
            impacted: Vec::new(),
            dt_s: phys.integration_parameters.dt,
            reach: Vec::new(),
            keep_idle: false,
        }
    }

    /// The bodies of an impact about to be solved (see [`ImpactHook`]): a body touched by a
    /// support contact (within 45° of vertical) approaching faster than
    /// [`IMPACT_MIN_SPEED_M_PER_S`] at its centroid — a new contact, or a resting one that the body
    /// above has just driven down — whose load passes through the body's centre of mass
    /// (within [`CENTRAL_LOAD_M`]), and, through such central supports, the bodies below and
    /// above it. An off-centre load keeps every support point: its lever arms are physical.
    /// `phys` is the world before the step.
    pub fn for_step(phys: &PhysicsWorld) -> ImpactHook {
        // Most steps of a resting or sleeping world have no fast support contact at all: find
        // that out cheaply first (a contact between bodies that do not move cannot approach),
        // and only then build the support links the impact would follow.
        let dt_s = phys.integration_parameters.dt;
        let reach = Self::reach_table(phys);
        if !Self::any_fast_support(phys, &reach) {
            return ImpactHook {
                impacted: Vec::new(),
                dt_s,
                reach,
                keep_idle: false,
            };
        }
        // Whether a load through `point` passes (within CENTRAL_LOAD_M) through the vertical of
        // the body's centre of mass: then it has no moment and a centroid support is exact.
        let central = |h: RigidBodyHandle, point: Vector| {
            phys.bodies.get(h).is_some_and(|rb| {
                let c = rb.center_of_mass();
                (point.x - c.x).hypot(point.y - c.y) <= CENTRAL_LOAD_M
            })
        };
        let mut seeds: Vec<RigidBodyHandle> = Vec::new();
        // Which bodies are in `seeds`, by the handle's index (no body is removed within a
        // step, so an index names one body): the same answers as `seeds.contains`, in O(1).
        let mut member: Vec<bool> = Vec::new();
        let index = |h: RigidBodyHandle| h.0.into_raw_parts().0 as usize;
        let is_member = |member: &[bool], h: RigidBodyHandle| member.get(index(h)) == Some(&true);
        let add = |member: &mut Vec<bool>, seeds: &mut Vec<RigidBodyHandle>, h: RigidBodyHandle| {
            let i = index(h);
            if member.len() <= i {
                member.resize(i + 1, false);
            }
            member[i] = true;
            seeds.push(h);
        };
        // Supports between two bodies: (body, other, contact centroid), either way round.
        let mut links: Vec<(RigidBodyHandle, RigidBodyHandle, Vector)> = Vec::new();
        for_each_support(phys, None, |s| {
            if s.approach_m_per_s >= IMPACT_MIN_SPEED_M_PER_S {
                for h in [s.body1, s.body2].into_iter().flatten() {
                    if central(h, s.centroid) && !is_member(&member, h) {
                        add(&mut member, &mut seeds, h);
                    }
                }
            }
            if let (Some(a), Some(b)) = (s.body1, s.body2) {
                links.push((a, b, s.centroid));
                links.push((b, a, s.centroid));
            }
            true
        });
        // Follow central supports through the stack (nothing to follow without a seed).
        let mut grew = !seeds.is_empty();
        while grew {
            grew = false;
            for (a, b, at) in &links {
                if is_member(&member, *a) && !is_member(&member, *b) && central(*b, *at) {
                    add(&mut member, &mut seeds, *b);
                    grew = true;
                }
            }
        }
        ImpactHook {
            impacted: seeds,
            dt_s,
            reach,
            keep_idle: false,
        }
    }
}

impl ImpactHook {
    /// The [`Reach`] of every collider of an awake dynamic body, by collider index.
    fn reach_table(phys: &PhysicsWorld) -> Vec<Option<Reach>> {
        let mut table: Vec<Option<Reach>> = Vec::new();
        for h in phys.islands.active_bodies() {
            let Some(rb) = phys.bodies.get(h) else {
                continue;
            };
            if rb.body_type() != RigidBodyType::Dynamic {
                continue;
            }
            for ch in rb.colliders() {
                let Some(co) = phys.colliders.get(*ch) else {
                    continue;
                };
                let (i, generation) = ch.0.into_raw_parts();
                let i = i as usize;
                if table.len() <= i {
                    table.resize(i + 1, None);
                }
                table[i] = Some(Reach::of(co, rb, generation));
            }
        }
        table
    }

    /// The [`Reach`] of a collider of a pair: `None` for a kinematic body's (see [`Motion`]).
    fn reach(
        &self,
        ctx: &PairFilterContext,
        ch: ColliderHandle,
        body: Option<RigidBodyHandle>,
    ) -> Option<Reach> {
        let (i, generation) = ch.0.into_raw_parts();
        if let Some(Some(r)) = self.reach.get(i as usize) {
            if r.generation == generation {
                return Some(*r);
            }
        }
        let co = ctx.colliders.get(ch)?;
        match body.and_then(|h| ctx.bodies.get(h)) {
            None => Some(Reach::still(co)),
            Some(rb) => match rb.body_type() {
                RigidBodyType::Fixed => Some(Reach::still(co)),
                RigidBodyType::Dynamic => Some(Reach::of(co, rb, generation)),
                _ => None,
            },
        }
    }

    /// Whether any support contact approaches faster than [`IMPACT_MIN_SPEED_M_PER_S`] at its
    /// centroid: the seed test of [`ImpactHook::for_step`], skipping contacts whose bodies are
    /// all at rest (then the approach is exactly zero).
    fn any_fast_support(phys: &PhysicsWorld, reach: &[Option<Reach>]) -> bool {
        // No contact's bound exceeds twice the largest collider's bound: when that is below
        // the impact speed, every contact would be skipped below, and none is fast. (A
        // resting world, every brick awake, answers here without walking its contacts.)
        if 2.0 * max_speed_bound(phys, reach) < IMPACT_MIN_SPEED_M_PER_S {
            return false;
        }
        let mut fast = false;
        for_each_support(phys, Some(reach), |s| {
            fast = s.approach_m_per_s >= IMPACT_MIN_SPEED_M_PER_S;
            !fast
        });
        fast
    }
}

/// One support manifold (normal within 45° of vertical) of a contact with a dynamic body.
struct Support {
    /// The dynamic bodies on either side (`None`: fixed or kinematic).
    body1: Option<RigidBodyHandle>,
    body2: Option<RigidBodyHandle>,
    /// Centroid of the manifold's points, world frame, m.
    centroid: Vector,
    /// Approach of the contact as a whole at its centroid, along the normal from body 1 to
    /// body 2, m/s (a rocking body's corners approach while its centroid does not, and that is
    /// no impact).
    approach_m_per_s: f64,
}

/// Calls `f` on every support manifold of the contacts before the step, in the narrow phase's
/// order, until `f` returns false. With `skip_slow` (the step's [`Reach`] table), contacts
/// whose bodies move too slowly for any point of theirs to approach at
/// [`IMPACT_MIN_SPEED_M_PER_S`] are skipped.
fn for_each_support(
    phys: &PhysicsWorld,
    skip_slow: Option<&[Option<Reach>]>,
    mut f: impl FnMut(Support) -> bool,
) {
    let vel = |h: Option<RigidBodyHandle>, p: Vector| {
        h.and_then(|h| phys.bodies.get(h))
            .map_or(Vector::ZERO, |rb| rb.velocity_at_point(p))
    };
    for pair in phys.narrow_phase.contact_pairs() {
        let PairContacts::Rigid(rc) = &pair.contacts else {
            continue;
        };
        let (b1, b2) = (
            dynamic_body(phys, pair.collider1),
            dynamic_body(phys, pair.collider2),
        );
        if b1.is_none() && b2.is_none() {
            continue;
        }
        // A manifold's centroid lies within the prediction distance of both colliders, so its
        // approach is at most the sum of the two bounds: below the impact speed, skip it.
        if let Some(table) = skip_slow {
            if speed_bound(phys, table, pair.collider1, b1)
                + speed_bound(phys, table, pair.collider2, b2)
                < IMPACT_MIN_SPEED_M_PER_S
            {
                continue;
            }
        }
        let Some((c1, c2)) = super::pair_colliders(phys, pair) else {
            continue;
        };
        for m in &rc.manifolds {
            if m.points.is_empty() || !is_support(m.data.normal) {
                continue;
            }
            let centroid = manifold_centroid(c1, c2, &m.points);
            let approach_m_per_s = (vel(b1, centroid) - vel(b2, centroid)).dot(m.data.normal);
            if !f(Support {
                body1: b1,
                body2: b2,
                centroid,
                approach_m_per_s,
            }) {
                return;
            }
        }
    }
}

/// Bound on the speed, m/s, of any point within the prediction distance of collider `c` of
/// body `h` moving with it (0 for no dynamic body: its velocity counts as zero), from the
/// step's [`Reach`] `table`.
fn speed_bound(
    phys: &PhysicsWorld,
    table: &[Option<Reach>],
    c: ColliderHandle,
    h: Option<RigidBodyHandle>,
) -> f64 {
    let Some(rb) = h.and_then(|h| phys.bodies.get(h)) else {
        return 0.0;
    };
    let (i, generation) = c.0.into_raw_parts();
    let r = match table.get(i as usize) {
        Some(Some(r)) if r.generation == generation => *r,
        // Not in the table (asleep, or woken since): a body at rest moves no point.
        _ if rb.linvel() == Vector::ZERO && rb.angvel() == Vector::ZERO => return 0.0,
        _ => match phys.colliders.get(c) {
            Some(co) => Reach::of(co, rb, generation),
            None => return f64::INFINITY,
        },
    };
    r.v.length() + r.spin + r.w * phys.integration_parameters.prediction_distance()
}

/// The largest [`speed_bound`] of any collider of a dynamic body, m/s (infinite if one is
/// NaN, so that nothing is skipped on its account).
fn max_speed_bound(phys: &PhysicsWorld, table: &[Option<Reach>]) -> f64 {
    let mut max = 0.0_f64;
    for (h, rb) in phys.bodies.iter() {
        if rb.body_type() != RigidBodyType::Dynamic {
            continue;
        }
        for c in rb.colliders() {
            let b = speed_bound(phys, table, *c, Some(h));
            if b.is_nan() {
                return f64::INFINITY;
            }
            max = max.max(b);
        }
    }
    max
}

/// The dynamic body a collider is attached to (`None`: fixed, kinematic or unattached).
fn dynamic_body(phys: &PhysicsWorld, c: ColliderHandle) -> Option<RigidBodyHandle> {
    let h = phys.colliders.get(c)?.parent()?;
    let rb = phys.bodies.get(h)?;
    (rb.body_type() == RigidBodyType::Dynamic).then_some(h)
}

/// Centroid of a manifold's points, world frame, m (each point the midpoint of its two
/// colliders' witness points).
fn manifold_centroid(
    c1: &rapier3d_f64::prelude::Collider,
    c2: &rapier3d_f64::prelude::Collider,
    points: &[rapier3d_f64::prelude::TrackedContact<rapier3d_f64::prelude::ContactData>],
) -> Vector {
    let mut centroid = Vector::ZERO;
    for p in points {
        centroid += (c1.position() * p.local_p1 + c2.position() * p.local_p2) * 0.5;
    }
    centroid / points.len() as f64
}

impl PhysicsHooks for ImpactHook {
    /// Skips a pair whose colliders' bounding boxes are farther apart than
    /// [`SPECULATIVE_KEEP_M`] plus [`PAIR_LOOKAHEAD_STEPS`] steps of their largest closing speed
    /// (relative linear velocity plus each body's spin times its reach): its contacts could not
    /// act. Positions and velocities are those before the step.
    fn filter_contact_pair(&self, ctx: &PairFilterContext) -> Option<SolverFlags> {
        let keep = Some(SolverFlags::COMPUTE_RIGID_IMPULSES);
        if self.keep_idle {
            return keep;
        }
        let (Some(a), Some(b)) = (
            self.reach(ctx, ctx.collider1, ctx.rigid_body1),
            self.reach(ctx, ctx.collider2, ctx.rigid_body2),
        ) else {
            return keep;
        };
        // Largest separation along an axis: a lower bound of the distance between the shapes.
        let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max_element();
        if gap <= SPECULATIVE_KEEP_M {
            return keep;
        }
        let closing = (a.v - b.v).length() + a.spin + b.spin;
        (gap < SPECULATIVE_KEEP_M + PAIR_LOOKAHEAD_STEPS * self.dt_s * closing)
            .then_some(SolverFlags::COMPUTE_RIGID_IMPULSES)
    }

    fn modify_solver_contacts(&self, ctx: &mut ContactModificationContext) {
        let bodies = ctx.bodies;
        let (rb1, rb2) = (ctx.rigid_body1, ctx.rigid_body2);
        let in_impact = [rb1, rb2]
            .into_iter()
            .flatten()
            .any(|h| self.impacted.contains(&h));
        let Some(m) = ctx.rigid_mut() else {
            return;
        };
        let n = m.solver_contacts.len();
        if n >= 2 && in_impact && is_support(*m.normal) {
            merge(m.solver_contacts);
            return;
        }
        if n >= 2 && !m.manifold.points.iter().any(|p| p.data.impulse != 0.0) {
            let inv = 1.0 / n as f64;
            let mut a1 = Vector::ZERO;
            let mut a2 = Vector::ZERO;
            for c in m.solver_contacts.iter() {
                a1 += c.anchor1;
                a2 += c.anchor2;
            }
            a1 *= inv;
            a2 *= inv;
            let vel = |h: Option<RigidBodyHandle>, p: Vector| {
                h.and_then(|h| bodies.get(h))
                    .map_or(Vector::ZERO, |rb| rb.velocity_at_point(p))
            };
            // The normal points from body 1 toward body 2: approaching when (v1 - v2)·n > 0.
            if (vel(rb1, a1) - vel(rb2, a2)).dot(*m.normal) >= IMPACT_MIN_SPEED_M_PER_S {
                merge(m.solver_contacts);
                return;
            }
        }
        // No impact: drop the speculative contacts that cannot act over this step.
        if self.keep_idle
            || m.solver_contacts
                .iter()
                .all(|c| c.dist <= SPECULATIVE_KEEP_M)
        {
            return;
        }
        let (Some(m1), Some(m2)) = (Motion::of(bodies, rb1), Motion::of(bodies, rb2)) else {
            return;
        };
        let (normal, reach) = (*m.normal, SOLVER_LOOKAHEAD_STEPS * self.dt_s);
        m.solver_contacts.retain(|c| {
            c.dist <= SPECULATIVE_KEEP_M
                || c.dist
                    < SPECULATIVE_KEEP_M + reach * (m1.at(c.anchor1) - m2.at(c.anchor2)).dot(normal)
        });
    }
}

/// The motion of a contact's body as the hook needs it: `None` for a kinematic body, whose
/// velocity before the step does not bound its motion over the step (the hand moves it), so
/// its contacts are always kept.
#[derive(Clone, Copy)]
struct Motion {
    /// Linear velocity of the centre of mass, m/s.
    v: Vector,
    /// Angular velocity, rad/s.
    w: Vector,
    /// Centre of mass, world frame, m.
    com: Vector,
}

impl Motion {
    /// A fixed body (or none) does not move; a dynamic body moves with its velocity.
    fn of(bodies: &RigidBodySet, h: Option<RigidBodyHandle>) -> Option<Motion> {
        let still = Motion {
            v: Vector::ZERO,
            w: Vector::ZERO,
            com: Vector::ZERO,
        };
        let Some(rb) = h.and_then(|h| bodies.get(h)) else {
            return Some(still);
        };
        match rb.body_type() {
            RigidBodyType::Fixed => Some(still),
            RigidBodyType::Dynamic => Some(Motion {
                v: rb.linvel(),
                w: rb.angvel(),
                com: rb.center_of_mass(),
            }),
            _ => None,
        }
    }

    /// Velocity of the point `p` (world frame, m) moving with the body, m/s.
    fn at(&self, p: Vector) -> Vector {
        self.v + self.w.cross(p - self.com)
    }
}

/// Whether a contact normal is within 45° of vertical: a support (a face resting on the one
/// below), as opposed to a side contact.
pub(crate) fn is_support(normal: Vector) -> bool {
    normal.z.abs() >= std::f64::consts::FRAC_1_SQRT_2
}

/// Replaces the solver contacts by one at their centroid (mean anchors and distance).
fn merge(contacts: &mut Vec<SolverContact>) {
    let n = contacts.len();
    if n < 2 {
        return;
    }
    let inv = 1.0 / n as f64;
    let mut c0 = contacts[0];
    let (mut a1, mut a2, mut dist) = (Vector::ZERO, Vector::ZERO, 0.0);
    for c in contacts.iter() {
        a1 += c.anchor1;
        a2 += c.anchor2;
        dist += c.dist;
    }
    c0.anchor1 = a1 * inv;
    c0.anchor2 = a2 * inv;
    c0.dist = dist * inv;
    contacts.truncate(1);
    contacts[0] = c0;
}
