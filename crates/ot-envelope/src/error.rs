//! Typed errors: every variant names the field and the allowed range.

use ot_physics::PhysicsError;
use thiserror::Error;

/// A bad argument to the envelope, inverse-solver, clipping or steering API.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EnvelopeError {
    /// A number outside its allowed range (or NaN / infinite).
    #[error("{field} = {value:e} is out of range: allowed {allowed}")]
    OutOfRange {
        /// Parameter name with its unit, e.g. `tol [m]`.
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// Human-readable allowed range.
        allowed: &'static str,
    },
    /// The physics layer rejected a state or parameter.
    #[error("physics: {0}")]
    Physics(#[from] PhysicsError),
    /// The clarabel subproblem of the constrained solver failed.
    #[error("convex subproblem failed: {0}")]
    Subproblem(String),
    /// The 3D surface method's assumption does not hold for this map.
    #[error("3D envelope needs a star-shaped critical surface: {0}")]
    NotStarShaped(String),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, EnvelopeError>;

/// Check that `value` is finite and strictly positive.
pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(EnvelopeError::OutOfRange {
            field,
            value,
            allowed: "finite and > 0",
        })
    }
}

/// Check that every component is finite.
pub(crate) fn finite_vec(field: &'static str, v: &[f64]) -> Result<()> {
    for &x in v {
        if !x.is_finite() {
            return Err(EnvelopeError::OutOfRange {
                field,
                value: x,
                allowed: "finite",
            });
        }
    }
    Ok(())
}
