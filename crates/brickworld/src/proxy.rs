//! The god-object (proxy): the cursor's stand-in that never enters a solid.
//!
//! Each tick the proxy moves from where it was toward the device cursor, stopping at the first
//! surface and sliding along it (up to three constraint planes, the classic god-object of
//! Zilles & Salisbury). When a brick is carried, the god-object is the cursor sphere plus the
//! carried brick, so neither enters another body. Bodies that moved into the proxy since the
//! last tick are first pushed out along the contact normal. The force on the device is then the
//! spring `F = k (p - c)` from the cursor `c` to the proxy `p`, i.e. `F = -k d n` for a plane.

use rapier3d_f64::math::{Pose, Rotation, Vector};
use rapier3d_f64::parry::query::ShapeCastOptions;
use rapier3d_f64::parry::shape::{Ball, Cuboid, Shape};
use rapier3d_f64::prelude::{ColliderHandle, QueryPipeline};

/// Gap kept between the proxy and a surface it rests on, m (keeps casts out of penetration).
pub const SKIN_M: f64 = 1e-6;

/// The carried brick as part of the god-object.
#[derive(Debug, Clone, Copy)]
pub struct HeldShape {
    /// Brick half-extents, m.
    pub cuboid: Cuboid,
    /// Brick centre minus proxy centre, world frame, m.
    pub offset: Vector,
    /// Brick orientation.
    pub rotation: Rotation,
}

/// One surface the proxy touched this tick.
#[derive(Debug, Clone, Copy)]
pub struct ProxyContact {
    /// The collider touched.
    pub collider: ColliderHandle,
    /// Outward normal of that collider at the contact, world frame.
    pub normal: Vector,
    /// Contact point on that collider, world frame, m.
    pub point: Vector,
}

/// Result of one proxy update.
#[derive(Debug, Clone, Default)]
pub struct ProxyUpdate {
    /// New proxy centre, m.
    pub position: Vector,
    /// Deepest penetration of the god-object found before pushing it out, m (0 if none).
    pub penetration_before_m: f64,
    /// Surfaces touched (from push-outs and sweeps), in the order found.
    pub contacts: Vec<ProxyContact>,
}

/// The parts of the god-object at proxy centre `p`: the cursor ball, then the carried brick.
fn parts<'a>(
    ball: &'a Ball,
    held: &'a Option<HeldShape>,
    p: Vector,
) -> impl Iterator<Item = (Pose, &'a dyn Shape)> + 'a {
    let b = std::iter::once((Pose::from_translation(p), ball as &dyn Shape));
    let h = held.iter().map(move |h| {
        (
            Pose::from_parts(p + h.offset, h.rotation),
            &h.cuboid as &dyn Shape,
        )
    });
    b.chain(h)
}

/// Deepest contact of the god-object at `p` with the scene: (depth m > 0, contact).
fn deepest_penetration(
    qp: &QueryPipeline,
    ball: &Ball,
    held: &Option<HeldShape>,
    p: Vector,
    only_fixed: bool,
) -> Option<(f64, ProxyContact)> {
    let mut best: Option<(f64, ProxyContact)> = None;
    for (pose, shape) in parts(ball, held, p) {
        for (handle, co) in qp.intersect_shape(pose, shape) {
            let fixed = co
                .parent()
                .and_then(|h| qp.bodies.get(h))
                .is_none_or(|rb| rb.is_fixed());
            if only_fixed && !fixed {
                continue;
            }
            let pos12 = pose.inv_mul(co.position());
            if let Ok(Some(c)) = qp.dispatcher.contact(&pos12, shape, co.shape(), 0.0) {
                let depth = -c.dist;
                if depth > 0.0 && best.as_ref().is_none_or(|(d, _)| depth > *d) {
                    // normal1 points from the proxy shape toward the collider (local frame).
                    let n_world = pose.rotation * c.normal1;
                    best = Some((
                        depth,
                        ProxyContact {
                            collider: handle,
                            normal: -n_world,
                            point: co.position().transform_point(c.point2),
                        },
                    ));
                }
            }
        }
    }
    best
}

/// Removes from `d` every component that points into one of `planes` (outward normals).
fn constrain(d: Vector, planes: &[Vector]) -> Vector {
    let violated = |v: Vector| planes.iter().any(|n| v.dot(*n) < -1e-15);
    if !violated(d) {
        return d;
    }
    // Single-plane projections.
    for n in planes {
        let v = d - n * d.dot(*n).min(0.0);
        if !violated(v) {
            return v;
        }
    }
    // Creases between two planes.
    for i in 0..planes.len() {
        for j in (i + 1)..planes.len() {
            let c = planes[i].cross(planes[j]);
            let l = c.length();
            if l < 1e-9 {
                continue;
            }
            let c = c / l;
            let v = c * d.dot(c);
            if !violated(v) {
                return v;
            }
        }
    }
    Vector::ZERO
}

/// Moves the god-object from `start` toward `target` (both m, world frame).
pub fn update_proxy(
    qp: &QueryPipeline,
    ball: &Ball,
    held: &Option<HeldShape>,
    start: Vector,
    target: Vector,
) -> ProxyUpdate {
    let mut p = start;
    let mut out = ProxyUpdate::default();
    // 1. Push out of anything that moved into the god-object; the fixed ground and obstacles
    //    last, so that a cursor caught between a brick and the ground ends in the brick (which
    //    the hand then pushes away), never under the ground.
    for only_fixed in [false, false, false, false, true, true, true, true] {
        match deepest_penetration(qp, ball, held, p, only_fixed) {
            Some((depth, c)) => {
                if out.penetration_before_m == 0.0 {
                    out.penetration_before_m = depth;
                }
                p += c.normal * (depth + 2.0 * SKIN_M);
                out.contacts.push(c);
            }
            None if only_fixed => break,
            None => {}
        }
    }
    // 2. Sweep toward the target, sliding on the surfaces met.
    let mut planes: Vec<Vector> = out.contacts.iter().map(|c| c.normal).collect();
    let options = ShapeCastOptions {
        max_time_of_impact: 1.0,
        target_distance: SKIN_M,
        stop_at_penetration: false,
        compute_impact_geometry_on_penetration: true,
    };
    for _ in 0..4 {
        let full = target - p;
        let d = constrain(full, &planes);
        if d.length_squared() < 1e-24 {
            break;
        }
        let mut first: Option<(f64, ProxyContact)> = None;
        for (pose, shape) in parts(ball, held, p) {
            if let Some((handle, hit)) = qp.cast_shape(&pose, d, shape, options)
                && first.as_ref().is_none_or(|(t, _)| hit.time_of_impact < *t)
            {
                first = Some((
                    hit.time_of_impact,
                    ProxyContact {
                        collider: handle,
                        normal: hit.normal1,
                        point: hit.witness1,
                    },
                ));
            }
        }
        match first {
            None => {
                // Unconstrained: land exactly on the cursor (no rounding residue in the force).
                p = if d == full { target } else { p + d };
                break;
            }
            Some((toi, c)) => {
                p += d * toi + c.normal * SKIN_M;
                let duplicate = planes.iter().any(|n| n.dot(c.normal) > 1.0 - 1e-9);
                out.contacts.push(c);
                if duplicate {
                    if toi == 0.0 {
                        break;
                    }
                } else {
                    planes.push(c.normal);
                }
                if planes.len() >= 3 {
                    break;
                }
            }
        }
    }
    out.position = p;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constrain_slides_on_planes_and_stops_in_corners() {
        let z = Vector::Z;
        let x = Vector::X;
        // Into the floor: keep only the tangential part.
        let d = constrain(Vector::new(0.3, 0.2, -1.0), &[z]);
        assert_eq!(d, Vector::new(0.3, 0.2, 0.0));
        // Away from the floor: unchanged.
        let d = constrain(Vector::new(0.3, 0.2, 1.0), &[z]);
        assert_eq!(d, Vector::new(0.3, 0.2, 1.0));
        // Into floor and wall: along their crease.
        let d = constrain(Vector::new(-1.0, 0.5, -1.0), &[z, x]);
        assert!((d - Vector::new(0.0, 0.5, 0.0)).length() < 1e-15);
        // Into three planes meeting in a corner: no motion.
        let d = constrain(Vector::new(-1.0, -1.0, -1.0), &[z, x, Vector::Y]);
        assert_eq!(d, Vector::ZERO);
    }
}
