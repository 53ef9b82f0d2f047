//! One tick of device input: cursor position and the hand's grip commands.

use serde::{Deserialize, Serialize};

use crate::error::InputError;

/// What the hand is told to do this tick: hold (grab and carry) and the three quarter-turn
/// commands. These are the hand's commands, not a device's buttons: the haptic loop maps a
/// device's buttons onto them (Falcon centre → `hold`, plus / minus / forward → `turn_x` /
/// `turn_y` / `turn_z`; Touch button 1 → `hold`, button 2 → `turn_z`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Grip {
    /// Held down: grab the nearest brick within reach on the press edge and carry it; let go:
    /// drop it, or throw it when the hand moves faster than
    /// [`crate::Params::throw_min_speed_m_per_s`].
    pub hold: bool,
    /// Turns the carried brick by +90° about the world x axis (on the press edge).
    pub turn_x: bool,
    /// Turns the carried brick by +90° about the world y axis (on the press edge).
    pub turn_y: bool,
    /// Turns the carried brick by +90° about the world z axis (on the press edge).
    pub turn_z: bool,
}

/// A validated cursor sample: position in the world frame (m) and the grip commands.
///
/// Built only through [`CursorInput::new`], which rejects non-finite positions and positions
/// outside the workspace box, so [`crate::World::step`] never sees bad numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CursorInput {
    position_m: [f64; 3],
    grip: Grip,
}

impl CursorInput {
    /// Validates a sample. `workspace_half_extent_m` is the world's
    /// [`crate::Params::workspace_half_extent_m`] (use [`crate::World::input`] to fill it in).
    pub fn new(
        position_m: [f64; 3],
        grip: Grip,
        workspace_half_extent_m: f64,
    ) -> Result<CursorInput, InputError> {
        for (axis, &value) in position_m.iter().enumerate() {
            if !value.is_finite() {
                return Err(InputError::NotFinite { axis, value });
            }
            if value.abs() > workspace_half_extent_m {
                return Err(InputError::OutsideWorkspace {
                    axis,
                    value,
                    limit: workspace_half_extent_m,
                });
            }
        }
        Ok(CursorInput { position_m, grip })
    }

    /// Cursor position in the world frame, m.
    pub fn position_m(&self) -> [f64; 3] {
        self.position_m
    }

    /// The grip commands.
    pub fn grip(&self) -> Grip {
        self.grip
    }
}
