//! Impact events: which contacts began this step, how fast they closed and what impulse the
//! solver spent on them (the loudness of a collision sound).
//!
//! A contact pair (two colliders) that carries normal impulse after a step and carried none
//! after the previous one is a new contact. It is an impact when its bodies approached faster
//! than [`IMPACT_MIN_SPEED_M_PER_S`] along the contact normal just before the step (velocities
//! taken before the step, at the manifold's centroid); its impulse is the sum of the normal
//! impulses of all its points over the step, N·s. Resting contacts (which carry impulse every
//! step) and gentle placements raise nothing; a bouncing brick raises one impact per bounce
//! until the bounces are slower than the threshold.

use rapier3d_f64::math::Vector;
use rapier3d_f64::prelude::{
    ColliderHandle, ContactPair, PairContacts, PhysicsWorld, RigidBodyHandle, RigidPairContacts,
};

use super::IMPACT_MIN_SPEED_M_PER_S;
use crate::event::{Body, Event};

/// Tracks the contact pairs that carried impulse, step to step.
#[derive(Debug, Default, Clone)]
pub struct ImpactTracker {
    /// Pairs (sorted handles) that carried impulse after the previous step, sorted.
    prev: Vec<Key>,
    cur: Vec<Key>,
    /// Velocities (linear, angular) of dynamic bodies just before the step.
    before: Vec<(RigidBodyHandle, Vector, Vector)>,
    /// `prev` was not kept up to date over quiet steps: rebuild it before the next other step.
    stale: bool,
}

/// A collider pair by the handles' raw parts, smaller first.
type Key = ((u32, u32), (u32, u32));

fn key(a: ColliderHandle, b: ColliderHandle) -> Key {
    let (a, b) = (a.0.into_raw_parts(), b.0.into_raw_parts());
    if a <= b { (a, b) } else { (b, a) }
}

impl ImpactTracker {
    /// Remembers the velocities of `bodies` before the step. A `quiet` step (see
    /// [`crate::rest`]: no two bodies close at [`IMPACT_MIN_SPEED_M_PER_S`]) has no impact, and
    /// the tracker skips it: before the next other step it rebuilds, from the contacts as they
    /// are, the pairs that carried impulse after the last one.
    pub fn before_step(
        &mut self,
        phys: &PhysicsWorld,
        bodies: impl Iterator<Item = RigidBodyHandle>,
        quiet: bool,
    ) {
        if quiet {
            self.stale = true;
            return;
        }
        if std::mem::take(&mut self.stale) {
            self.prev.clear();
            for pair in phys.narrow_phase.contact_pairs() {
                if carried_impulse(pair).is_some() && super::pair_colliders(phys, pair).is_some() {
                    self.prev.push(key(pair.collider1, pair.collider2));
                }
            }
            self.prev.sort_unstable();
        }
        self.before.clear();
        for h in bodies {
            if let Some(rb) = phys.bodies.get(h) {
                self.before.push((h, rb.linvel(), rb.angvel()));
            }
        }
    }

    /// Velocity of body `h` at `point` before the step (zero for fixed bodies; kinematic bodies,
    /// the carried brick, use their current velocity).
    fn velocity_at(
        &self,
        phys: &PhysicsWorld,
        h: Option<RigidBodyHandle>,
        point: Vector,
    ) -> Vector {
        let Some(h) = h else {
            return Vector::ZERO;
        };
        let Some(rb) = phys.bodies.get(h) else {
            return Vector::ZERO;
        };
        let (v, w) = self
            .before
            .iter()
            .find(|(b, _, _)| *b == h)
            .map_or((rb.linvel(), rb.angvel()), |(_, v, w)| (*v, *w));
        v + w.cross(point - rb.center_of_mass())
    }

    /// Appends an [`Event::Impact`] for each contact that began this step fast enough;
    /// `body_of` names a collider's body. A `quiet` step is skipped (see
    /// [`ImpactTracker::before_step`]).
    pub fn after_step(
        &mut self,
        phys: &PhysicsWorld,
        body_of: impl Fn(ColliderHandle) -> Body,
        quiet: bool,
        events: &mut Vec<Event>,
    ) {
        if quiet {
            return;
        }
        self.cur.clear();
        let mut found: Vec<(Key, ColliderHandle, ColliderHandle, f64, f64, Vector)> = Vec::new();
        for pair in phys.narrow_phase.contact_pairs() {
            let Some((rc, impulse, points)) = carried_impulse(pair) else {
                continue;
            };
            let Some((c1, c2)) = super::pair_colliders(phys, pair) else {
                continue;
            };
            let k = key(pair.collider1, pair.collider2);
            self.cur.push(k);
            if self.prev.binary_search(&k).is_ok() {
                // A contact that carried impulse last step too (resting, sliding, asleep):
                // no impact, and no need for its geometry.
                continue;
            }
            let mut centroid = Vector::ZERO;
            let mut normal = Vector::ZERO;
            for m in &rc.manifolds {
                for p in &m.points {
                    centroid += (c1.position() * p.local_p1 + c2.position() * p.local_p2) * 0.5;
                }
                if !m.points.is_empty() {
                    normal = m.data.normal;
                }
            }
            let centroid = centroid / points as f64;
            // The normal points from body 1 toward body 2: approaching when (v1 − v2)·n > 0.
            let approach = (self.velocity_at(phys, c1.parent(), centroid)
                - self.velocity_at(phys, c2.parent(), centroid))
            .dot(normal);
            if approach >= IMPACT_MIN_SPEED_M_PER_S {
                found.push((
                    k,
                    pair.collider1,
                    pair.collider2,
                    impulse,
                    approach,
                    centroid,
                ));
            }
        }
        self.cur.sort_unstable();
        std::mem::swap(&mut self.prev, &mut self.cur);
        // A deterministic order: by the colliders' handles.
        found.sort_by_key(|x| x.0);
        for (_, a, b, impulse, speed, p) in found {
            events.push(Event::Impact {
                a: body_of(a),
                b: body_of(b),
                impulse_n_s: impulse,
                speed_m_per_s: speed,
                point_m: p.to_array(),
            });
        }
    }
}

/// A pair's rigid contacts, their total normal impulse (N·s) and number of points, if the pair
/// carried impulse on the last step.
fn carried_impulse(pair: &ContactPair) -> Option<(&RigidPairContacts, f64, usize)> {
    let PairContacts::Rigid(rc) = &pair.contacts else {
        return None;
    };
    let mut impulse = 0.0;
    let mut points = 0usize;
    for m in &rc.manifolds {
        for p in &m.points {
            impulse += p.data.impulse;
            points += 1;
        }
    }
    (impulse > 0.0 && points > 0).then_some((rc, impulse, points))
}
