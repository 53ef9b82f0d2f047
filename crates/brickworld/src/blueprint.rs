//! The house-building task: the slots a brick must fill, which brick fills each, and the score.

use rapier3d_f64::math::{Rotation, Vector};
use serde::Serialize;

use crate::bricks::{BrickSet, quat};
use crate::event::{BrickId, Event};
use crate::params::{Blueprint, BrickPlacement, Params};

/// A brick slower than this (m/s) counts as resting for the blueprint.
pub const RESTING_SPEED_M_PER_S: f64 = 0.05;

/// A blueprint slot and whether it is filled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlotView {
    /// Target centre, m.
    pub position_m: [f64; 3],
    /// Target orientation `[x, y, z, w]`.
    pub orientation_xyzw: [f64; 4],
    /// The brick filling it, if any.
    pub filled_by: Option<BrickId>,
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
    let ang = cuboid_orientation_error_rad(slot.rotation(), rotation);
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

/// Which brick fills each slot of [`Params::blueprint`] (a resting brick not in the hand).
#[derive(Debug, Clone, Default)]
pub(crate) struct Slots {
    filled_by: Vec<Option<BrickId>>,
}

impl Slots {
    /// Every slot of `blueprint` empty.
    pub(crate) fn new(blueprint: &Blueprint) -> Slots {
        Slots {
            filled_by: vec![None; blueprint.slots.len()],
        }
    }

    /// Re-assigns each slot to the closest resting brick (not `held`) that fills it, and reports
    /// the slots that were vacated and filled.
    pub(crate) fn update(
        &mut self,
        params: &Params,
        bricks: &BrickSet,
        held: Option<BrickId>,
        events: &mut Vec<Event>,
    ) {
        if self.filled_by.is_empty() {
            return;
        }
        for (si, slot) in params.blueprint.slots.iter().enumerate() {
            let mut best: Option<(f64, BrickId)> = None;
            for bi in 0..bricks.len() {
                let id = BrickId(bi as u32);
                if Some(id) == held {
                    continue;
                }
                let rb = &bricks.phys.bodies[bricks.body(id)];
                if rb.linvel().length() > RESTING_SPEED_M_PER_S {
                    continue;
                }
                if let Some(d) = fills(&params.blueprint, slot, rb.translation(), *rb.rotation())
                    && best.is_none_or(|(bd, _)| d < bd)
                {
                    best = Some((d, id));
                }
            }
            let now = best.map(|(_, id)| id);
            let before = self.filled_by[si];
            if now != before {
                if let Some(b) = before {
                    events.push(Event::SlotVacated { slot: si, brick: b });
                }
                if let Some(b) = now {
                    events.push(Event::SlotFilled { slot: si, brick: b });
                }
                self.filled_by[si] = now;
            }
        }
    }

    /// The slots of `blueprint` and their state, in order.
    pub(crate) fn views<'a>(
        &'a self,
        blueprint: &'a Blueprint,
    ) -> impl Iterator<Item = SlotView> + 'a {
        blueprint
            .slots
            .iter()
            .zip(&self.filled_by)
            .map(|(s, f)| SlotView {
                position_m: s.center_m,
                orientation_xyzw: quat(s.rotation()),
                filled_by: *f,
            })
    }

    /// The house-task score.
    pub(crate) fn score(&self) -> Score {
        Score {
            filled: self.filled_by.iter().filter(|s| s.is_some()).count(),
            total: self.filled_by.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(deg: [f64; 3]) -> Rotation {
        BrickPlacement {
            center_m: [0.0; 3],
            rotation_deg: deg,
        }
        .rotation()
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
