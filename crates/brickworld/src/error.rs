//! Typed errors: every one names the offending field and the allowed range.

use thiserror::Error;
use world_form::ValueError;

/// A scene parameter (or a run-time switch) is outside its allowed range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// A number (or a count, as f64) outside its range; the field is the dotted path in
    /// backticks (`` `blueprint.slots[2].center_m[0]` ``), the range an interval, e.g.
    /// `(0, 1e4]`.
    #[error("parameter {0}")]
    Value(ValueError),
    /// A structural constraint between fields does not hold (e.g. `min < max`).
    #[error("parameter `{field}` is invalid: {reason}")]
    Inconsistent {
        /// Dotted path of the field.
        field: String,
        /// What must hold.
        reason: String,
    },
}

impl ParamError {
    /// `field` (dotted path) = `value` outside `range` (an interval, e.g. `[0, 100]`).
    pub fn out_of_range(field: &str, value: f64, range: impl Into<String>) -> Self {
        ParamError::Value(ValueError::out_of_range(
            format!("`{field}`"),
            value,
            range.into(),
        ))
    }

    /// The dotted path of the offending field (as in the scene's `[brickworld.params]` table).
    pub fn field(&self) -> &str {
        match self {
            ParamError::Value(e) => e.field().trim_matches('`'),
            ParamError::Inconsistent { field, .. } => field,
        }
    }
}

impl WorldError {
    /// The dotted path of the offending parameter, when a parameter is what was refused.
    pub fn field(&self) -> Option<&str> {
        match self {
            WorldError::Param(p) => Some(p.field()),
            _ => None,
        }
    }
}

use world_form::fmt_num as num;

/// A cursor sample from a device or script cannot be used.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InputError {
    /// A position component is NaN or infinite.
    #[error("cursor input `position_m[{axis}]` = {} is not finite", num(*value))]
    NotFinite {
        /// Component index 0..3 (x, y, z).
        axis: usize,
        /// The rejected value.
        value: f64,
    },
    /// A position component is outside the world's workspace box.
    #[error(
        "cursor input `position_m[{axis}]` = {} m is outside the workspace: allowed [-{limit}, {limit}] m",
        num(*value)
    )]
    OutsideWorkspace {
        /// Component index 0..3 (x, y, z).
        axis: usize,
        /// The rejected value in m.
        value: f64,
        /// The workspace half-extent in m (`Params::workspace_half_extent_m`).
        limit: f64,
    },
}

/// An operation on a built world was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum WorldError {
    /// Bad parameter.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// Bad cursor input.
    #[error(transparent)]
    Input(#[from] InputError),
    /// `add_brick` would exceed `Params::max_bricks`.
    #[error("cannot add brick: `max_bricks` = {max} reached")]
    TooManyBricks {
        /// The limit in force.
        max: usize,
    },
    /// A brick id that this world never issued.
    #[error("unknown brick id {0}")]
    UnknownBrick(u32),
}
