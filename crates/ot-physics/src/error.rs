//! Typed errors for every parameter the crate accepts.

use thiserror::Error;
pub use world_form::ValueError;

/// A bad parameter or an unsupported combination of effects and method.
///
/// Every variant names the offending field and, where it applies, the range
/// that would have been accepted, so callers (scene files, the Python wheel)
/// can show the message unchanged.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PhysicsError {
    /// A number lies outside its allowed range (or is NaN / infinite); the field is named
    /// with its unit (e.g. `waist_x [m]`).
    #[error(transparent)]
    Value(#[from] ValueError),
    /// An effect was switched on without a parameter it needs.
    #[error("{field} is required by {needed_by}")]
    Missing {
        /// The missing parameter.
        field: &'static str,
        /// The effect or method that needs it.
        needed_by: &'static str,
    },
    /// The chosen integrator cannot handle the model's effects.
    #[error("method {method} cannot integrate this model: {reason}")]
    Unsupported {
        /// The integrator name as users type it.
        method: &'static str,
        /// Why not, and what to use instead.
        reason: &'static str,
    },
    /// An array has the wrong length.
    #[error("{field} has length {got}: expected {expected}")]
    Length {
        /// The argument.
        field: &'static str,
        /// What was expected, e.g. `1 or 1000`.
        expected: String,
        /// What was given.
        got: usize,
    },
    /// An unknown method name.
    #[error("unknown method {name:?}: allowed {allowed}")]
    UnknownMethod {
        /// What was asked for.
        name: String,
        /// The accepted names.
        allowed: &'static str,
    },
    /// The work was stopped on request (see [`crate::cancel`]): Ctrl-C in the Python wheel.
    #[error("interrupted")]
    Interrupted,
}

/// Result alias used across the crate.
pub type Result<T> = std::result::Result<T, PhysicsError>;

/// Check that `value` is finite and strictly positive; the error names `field` and the range
/// (the check of every crate built on this one).
pub fn positive_value(field: &'static str, value: f64) -> std::result::Result<f64, ValueError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(ValueError::out_of_range(field, value, "finite and > 0"))
    }
}

/// Check that `value` is finite and strictly positive ([`positive_value`]).
pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64> {
    Ok(positive_value(field, value)?)
}

/// Check that `value` is finite (any sign).
pub(crate) fn finite(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(PhysicsError::Value(ValueError::out_of_range(
            field, value, "finite",
        )))
    }
}
