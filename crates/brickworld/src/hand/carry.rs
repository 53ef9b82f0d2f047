//! Carrying a brick: rigidly (a kinematic body that moves with the proxy, the paper's way) or
//! through the virtual coupling (a dynamic body pulled by a spring and a Maxwell damper from
//! the grip point), the switch between the two, and what the device's local model needs to
//! know of a coupled brick (its body and the surfaces it touches).

use rapier3d_f64::math::Pose;
use rapier3d_f64::math::Vector;
use rapier3d_f64::parry::query::{self, ShapeCastOptions};
use rapier3d_f64::parry::shape::Cuboid;
use rapier3d_f64::prelude::{QueryFilter, RigidBodyType};
use world_form::Limits;

use super::{Hand, Held};
use crate::bricks::BrickSet;
use crate::params::{Inertia, Params};

impl Hand {
    /// The carried brick's coupling in the state the next tick starts from: the brick's
    /// centre less the grip offset, its velocity, its mass, the coupling's springs and damper
    /// (as [`Hand::coupling_pull`] uses them) and the dashpot's share; `None` unless a brick
    /// is carried through the coupling.
    pub(crate) fn carried_body(
        &self,
        params: &Params,
        limits: &Limits,
        bricks: &BrickSet,
    ) -> Option<haptic_types::local::Body> {
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
        Some(haptic_types::local::Body {
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
    ///
    /// A plane stands for a face: a face of either brick that the other's nearest feature
    /// faces, or a contact already made. A neighbour's edge or corner seen across a gap is
    /// not one: a brick lowered past a neighbour's edge with room to spare sees that edge
    /// first straight below it, then at every angle to the side, and a plane at any of those
    /// angles stops the device's body where the world's brick goes on. Such a collider is
    /// announced only where the brick, moving on at `velocity_m_per_s`, strikes it within
    /// the margin, as the plane of the surface it strikes there.
    pub(crate) fn carried_contacts(
        &self,
        params: &Params,
        bricks: &BrickSet,
        grip_m: [f64; 3],
        velocity_m_per_s: [f64; 3],
        margin_m: f64,
    ) -> Vec<haptic_types::local::Plane> {
        let mut out: Vec<haptic_types::local::Plane> = Vec::new();
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
        let v = Vector::from_array(velocity_m_per_s);
        let heading = (v.length() > 0.0 && v.is_finite()).then(|| v.normalize());
        let qp = bricks
            .phys
            .query_pipeline_with_filter(QueryFilter::default().exclude_collider(me));
        let mut found: Vec<(f64, Vector)> = qp
            .intersect_shape(pose, &grown)
            .filter_map(|(_, co)| {
                let c =
                    query::contact(&pose, &brick, co.position(), co.shape(), margin_m).ok()??;
                let n = c.normal2;
                if !(n.is_finite() && c.dist.is_finite()) {
                    return None;
                }
                if c.dist <= 0.0 || faces(n, &pose) || faces(n, co.position()) {
                    return Some((c.dist, n));
                }
                let dir = heading?;
                let options = ShapeCastOptions::with_max_time_of_impact(margin_m);
                let hit = query::cast_shapes(
                    &pose,
                    dir,
                    &brick,
                    co.position(),
                    Vector::ZERO,
                    co.shape(),
                    options,
                )
                .ok()??;
                let n = hit.normal2;
                // The gap along the surface's normal to the grip point where it strikes.
                let gap = -hit.time_of_impact * n.dot(dir);
                (n.is_finite() && gap.is_finite()).then_some((gap, n))
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
            out.push(haptic_types::local::Plane {
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
    pub(super) fn coupling_pull(
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
}

/// Whether `n` is (to rounding) the normal of a face of the cuboid at `pose`: the contact's
/// normal of a face, not of an edge or a corner.
fn faces(n: Vector, pose: &Pose) -> bool {
    [Vector::X, Vector::Y, Vector::Z]
        .into_iter()
        .any(|a| (pose.rotation * a).dot(n).abs() > 1.0 - 1e-9)
}
