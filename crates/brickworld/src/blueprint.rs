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
#[derive(Debug, Clone, Copy, PartialEq)]
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
