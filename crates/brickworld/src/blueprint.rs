//! The house-building task: slots a brick must fill, and the score.

use rapier3d_f64::math::{Rotation, Vector};

use crate::params::{Blueprint, BrickPlacement};

/// Orientation of a [`BrickPlacement`] (rotation vector in degrees) as a unit quaternion.
pub fn placement_rotation(p: &BrickPlacement) -> Rotation {
    let v = Vector::from_array(p.rotation_deg) * (std::f64::consts::PI / 180.0);
    Rotation::from_scaled_axis(v)
}

/// Angle (rad) between two orientations of the same cuboid, taking its symmetries into account:
/// a box with three distinct half-extents looks the same after a half turn about any of its axes.
pub fn cuboid_orientation_error_rad(target: Rotation, actual: Rotation) -> f64 {
    let half_turns = [
        Rotation::IDENTITY,
        Rotation::from_xyzw(1.0, 0.0, 0.0, 0.0),
        Rotation::from_xyzw(0.0, 1.0, 0.0, 0.0),
        Rotation::from_xyzw(0.0, 0.0, 1.0, 0.0),
    ];
    half_turns
        .iter()
        .map(|s| {
            let d = target.inverse() * actual * *s;
            2.0 * d.w.abs().min(1.0).acos()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Whether a brick at (`center`, `rotation`) fills `slot` within the blueprint's tolerances;
/// returns the centre distance (m) when it does.
pub fn fills(
    bp: &Blueprint,
    slot: &BrickPlacement,
    center: Vector,
    rotation: Rotation,
) -> Option<f64> {
    let d = (center - Vector::from_array(slot.center_m)).length();
    if d > bp.position_tolerance_m {
        return None;
    }
    let ang = cuboid_orientation_error_rad(placement_rotation(slot), rotation);
    (ang <= bp.angle_tolerance_deg.to_radians()).then_some(d)
}

/// The task's score.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Score {
    /// Slots filled by a resting, not carried brick.
    pub filled: usize,
    /// Number of slots in the blueprint.
    pub total: usize,
}

impl Score {
    /// `filled / total` in [0, 1]; 0 for an empty blueprint.
    pub fn fraction(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            self.filled as f64 / self.total as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(deg: [f64; 3]) -> Rotation {
        placement_rotation(&BrickPlacement {
            center_m: [0.0; 3],
            rotation_deg: deg,
        })
    }

    #[test]
    fn half_turns_of_a_box_are_the_same_orientation() {
        for d in [
            [180.0, 0.0, 0.0],
            [0.0, 180.0, 0.0],
            [0.0, 0.0, 180.0],
            [0.0, 0.0, -180.0],
        ] {
            assert!(
                cuboid_orientation_error_rad(Rotation::IDENTITY, rot(d)) < 1e-12,
                "{d:?}"
            );
        }
        let e = cuboid_orientation_error_rad(Rotation::IDENTITY, rot([0.0, 0.0, 90.0]));
        assert!((e - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let e = cuboid_orientation_error_rad(rot([0.0, 0.0, 90.0]), rot([0.0, 0.0, 93.0]));
        assert!((e - 3f64.to_radians()).abs() < 1e-12);
    }

    #[test]
    fn a_slot_is_filled_within_both_tolerances_only() {
        let bp = Blueprint {
            slots: vec![],
            position_tolerance_m: 0.01,
            angle_tolerance_deg: 5.0,
        };
        let slot = BrickPlacement {
            center_m: [1.0, 0.0, 0.03],
            rotation_deg: [0.0, 0.0, 90.0],
        };
        let c = Vector::new(1.005, 0.0, 0.03);
        assert!(fills(&bp, &slot, c, rot([0.0, 0.0, 94.0])).is_some());
        assert!(
            fills(&bp, &slot, c, rot([0.0, 0.0, -86.0])).is_some(),
            "half-turn symmetric"
        );
        assert!(fills(&bp, &slot, c, rot([0.0, 0.0, 84.0])).is_none());
        assert!(
            fills(
                &bp,
                &slot,
                Vector::new(1.02, 0.0, 0.03),
                rot([0.0, 0.0, 90.0])
            )
            .is_none()
        );
        let s = Score {
            filled: 3,
            total: 4,
        };
        assert_eq!(s.fraction(), 0.75);
        assert_eq!(
            Score {
                filled: 0,
                total: 0
            }
            .fraction(),
            0.0
        );
    }
}
