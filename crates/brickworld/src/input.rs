//! One tick of device input: cursor position and the four buttons.

use serde::{Deserialize, Serialize};

use crate::error::InputError;

/// The four buttons of a Novint Falcon grip.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Buttons {
    /// Centre button: hold to grab and carry a brick, release to drop (or throw) it.
    pub center: bool,
    /// Turns the carried brick by +90° about the world x axis (on the press edge).
    pub rotate_x: bool,
    /// Turns the carried brick by +90° about the world y axis (on the press edge).
    pub rotate_y: bool,
    /// Turns the carried brick by +90° about the world z axis (on the press edge).
    pub rotate_z: bool,
}

/// A validated cursor sample: position in the world frame (m) and buttons.
///
/// Built only through [`CursorInput::new`], which rejects non-finite positions and positions
/// outside the workspace box, so [`crate::World::step`] never sees bad numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CursorInput {
    position_m: [f64; 3],
    buttons: Buttons,
}

impl CursorInput {
    /// Validates a sample. `workspace_half_extent_m` is the world's
    /// [`crate::Params::workspace_half_extent_m`] (use [`crate::World::input`] to fill it in).
    pub fn new(
        position_m: [f64; 3],
        buttons: Buttons,
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
        Ok(CursorInput {
            position_m,
            buttons,
        })
    }

    /// Cursor position in the world frame, m.
    pub fn position_m(&self) -> [f64; 3] {
        self.position_m
    }

    /// Button states.
    pub fn buttons(&self) -> Buttons {
        self.buttons
    }
}
