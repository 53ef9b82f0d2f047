//! Typed errors: bad parameters, bad tick input, bad curve requests.

use thiserror::Error;

/// A parameter (scene value or run-time setting) outside its allowed range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ParamError {
    /// `field` holds `value`, which is outside `allowed`.
    #[error("{field} = {} is out of range: allowed {allowed}", world_form::numbers::fmt_num(*value))]
    OutOfRange {
        /// Dotted path of the field, as in the scene table (e.g. `interaction.game.tip_atom.snap_gap_m`).
        field: String,
        /// The offending value (counts are converted to f64).
        value: f64,
        /// The allowed range, in words and numbers.
        allowed: String,
    },
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
            ParamError::OutOfRange { field, .. } => field,
            ParamError::NotChangeableAtRunTime { field } | ParamError::MovedToDevice { field } => {
                field
            }
        }
    }

    pub(crate) fn range(field: impl Into<String>, value: f64, allowed: impl Into<String>) -> Self {
        Self::OutOfRange {
            field: field.into(),
            value,
            allowed: allowed.into(),
        }
    }
}

/// Bad input to [`crate::World::step`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum StepError {
    /// A tip (cursor) position component is NaN or infinite.
    #[error("tip position {axis} = {value} is out of range: allowed a finite number of metres")]
    NonFinitePosition {
        /// `x`, `y` or `z`.
        axis: char,
        /// The offending value (m).
        value: f64,
    },
    /// A tip (cursor) position component is finite but farther than
    /// [`crate::MAX_POSITION_M`] from the origin along its axis.
    #[error("tip position {axis} = {} is out of range: allowed |{axis}| <= 1 m", world_form::numbers::fmt_num(*value))]
    PositionOutOfRange {
        /// `x`, `y` or `z`.
        axis: char,
        /// The offending value (m).
        value: f64,
    },
    /// The tick length is not in [[`crate::MIN_DT_S`], 1] s.
    #[error("dt_s = {} is out of range: allowed 1e-9 <= dt_s <= 1 s", world_form::numbers::fmt_num(*_0))]
    BadDt(f64),
}

/// Bad request to [`crate::force_distance_curve`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CurveError {
    /// The world parameters are invalid.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// A curve setting is out of range.
    #[error("{field} = {} is out of range: allowed {allowed}", world_form::numbers::fmt_num(*value))]
    OutOfRange {
        /// Name of the setting in [`crate::CurveSpec`].
        field: &'static str,
        /// The offending value.
        value: f64,
        /// The allowed range.
        allowed: String,
    },
    /// A tick of the sweep failed (cannot happen with a valid spec; kept typed, not panicking).
    #[error(transparent)]
    Step(#[from] StepError),
}
