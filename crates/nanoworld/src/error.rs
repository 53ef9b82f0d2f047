//! Typed errors: bad parameters, bad tick input, bad curve requests.

use thiserror::Error;
use world_form::ValueError;

/// A parameter (scene value or run-time setting) outside its allowed range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// A field holds a value outside its allowed range; the field is the dotted path as in
    /// the scene table (e.g. `interaction.game.tip_atom.snap_gap_m`), counts are converted to
    /// f64.
    #[error(transparent)]
    Value(#[from] ValueError),
    /// A field that is no longer a parameter: its value now comes from the device's
    /// [`world_form::Limits`] handed to [`crate::World::new`].
    #[error(
        "`{field}` is no longer a nanoworld parameter: the limit now comes from the device \
         (world_form::Limits given to World::new; in a scene file, the [device] model mapped by \
         mapping.force_scale); remove it"
    )]
    MovedToDevice {
        /// The removed field.
        field: &'static str,
    },
    /// A field that fixes the world's geometry was changed through [`crate::World::set_params`].
    #[error("{field} cannot change at run time (it fixes the geometry); build a new World instead")]
    NotChangeableAtRunTime {
        /// Dotted path of the field.
        field: &'static str,
    },
}

impl ParamError {
    /// The dotted path of the offending field (as in the scene's `[nanoworld.params]` table).
    pub fn field(&self) -> &str {
        match self {
            ParamError::Value(e) => e.field(),
            ParamError::NotChangeableAtRunTime { field } | ParamError::MovedToDevice { field } => {
                field
            }
        }
    }

    pub(crate) fn range(field: impl Into<String>, value: f64, allowed: impl Into<String>) -> Self {
        Self::Value(ValueError::out_of_range(
            field.into(),
            value,
            allowed.into(),
        ))
    }
}

/// Bad input to [`crate::World::step`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// A tip (cursor) position component is NaN or infinite.
    #[error("{error}")]
    NonFinitePosition {
        /// `x`, `y` or `z`.
        axis: char,
        /// The offending value (m) and its range.
        error: ValueError,
    },
    /// A tip (cursor) position component is finite but farther than
    /// [`crate::MAX_POSITION_M`] from the origin along its axis.
    #[error("{error}")]
    PositionOutOfRange {
        /// `x`, `y` or `z`.
        axis: char,
        /// The offending value (m) and its range.
        error: ValueError,
    },
    /// The tick length is not in [[`crate::MIN_DT_S`], 1] s.
    #[error(transparent)]
    BadDt(ValueError),
}

/// Bad request to [`crate::force_distance_curve`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CurveError {
    /// The world parameters are invalid.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// A curve setting (named as in [`crate::CurveSpec`]) is out of range.
    #[error(transparent)]
    OutOfRange(ValueError),
    /// A tick of the sweep failed (cannot happen with a valid spec; kept typed, not panicking).
    #[error(transparent)]
    Step(#[from] StepError),
}
