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
    ColliderHandle, ContactModificationContext, PairContacts, PhysicsHooks, PhysicsWorld,
    RigidBodyHandle, RigidBodyType, SolverContact,
};

/// Approach speed (m/s) below which a new contact is treated as a gentle placement, not an impact.
pub const IMPACT_MIN_SPEED_M_PER_S: f64 = 0.05;

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
}

impl ImpactHook {
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
        if !Self::any_fast_support(phys) {
            return ImpactHook::default();
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
        // Supports between two bodies: (body, other, contact centroid), either way round.
        let mut links: Vec<(RigidBodyHandle, RigidBodyHandle, Vector)> = Vec::new();
        for_each_support(phys, false, |s| {
            if s.approach_m_per_s >= IMPACT_MIN_SPEED_M_PER_S {
                for h in [s.body1, s.body2].into_iter().flatten() {
                    if central(h, s.centroid) && !seeds.contains(&h) {
                        seeds.push(h);
                    }
                }
            }
            if let (Some(a), Some(b)) = (s.body1, s.body2) {
                links.push((a, b, s.centroid));
                links.push((b, a, s.centroid));
            }
            true
        });
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
                return ImpactHook { impacted: seeds };
            }
        }
    }
}

impl ImpactHook {
    /// Whether any support contact approaches faster than [`IMPACT_MIN_SPEED_M_PER_S`] at its
    /// centroid: the seed test of [`ImpactHook::for_step`], skipping contacts whose bodies are
    /// all at rest (then the approach is exactly zero).
    fn any_fast_support(phys: &PhysicsWorld) -> bool {
        let mut fast = false;
        for_each_support(phys, true, |s| {
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
/// order, until `f` returns false. With `skip_still`, contacts whose bodies have zero linear
/// and angular velocity (or are not dynamic) are skipped: their approach is exactly zero.
fn for_each_support(phys: &PhysicsWorld, skip_still: bool, mut f: impl FnMut(Support) -> bool) {
    let moving = |h: Option<RigidBodyHandle>| {
        h.and_then(|h| phys.bodies.get(h))
            .is_some_and(|rb| rb.linvel() != Vector::ZERO || rb.angvel() != Vector::ZERO)
    };
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
        if b1.is_none() && b2.is_none() || skip_still && !moving(b1) && !moving(b2) {
            continue;
        }
        let (Some(c1), Some(c2)) = (
            phys.colliders.get(pair.collider1),
            phys.colliders.get(pair.collider2),
        ) else {
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
        if n < 2 {
            return;
        }
        if in_impact && is_support(*m.normal) {
            merge(m.solver_contacts);
            return;
        }
        if m.manifold.points.iter().any(|p| p.data.impulse != 0.0) {
            return;
        }
        let inv = 1.0 / n as f64;
        let mut a1 = Vector::ZERO;
        let mut a2 = Vector::ZERO;
        for c in m.solver_contacts.iter() {
            a1 += c.anchor1;
            a2 += c.anchor2;
        }
        a1 *= inv;
        a2 *= inv;
        let vel = |h: Option<rapier3d_f64::prelude::RigidBodyHandle>, p: Vector| {
            h.and_then(|h| bodies.get(h))
                .map_or(Vector::ZERO, |rb| rb.velocity_at_point(p))
        };
        // The normal points from body 1 toward body 2: approaching when (v1 - v2)·n > 0.
        let approach = (vel(rb1, a1) - vel(rb2, a2)).dot(*m.normal);
        if approach < IMPACT_MIN_SPEED_M_PER_S {
            return;
        }
        merge(m.solver_contacts);
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
