//! Typed errors: every variant names the field and the allowed range.

use ot_physics::PhysicsError;
use thiserror::Error;
pub use world_form::ValueError;

/// A bad argument to the envelope, inverse-solver, clipping or steering API.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EnvelopeError {
    /// A number outside its allowed range (or NaN / infinite), the parameter named with its
    /// unit, e.g. `tol [m]`.
    #[error(transparent)]
    Value(#[from] ValueError),
    /// The physics layer rejected a state or parameter.
    #[error("physics: {0}")]
    Physics(#[from] PhysicsError),
    /// The clarabel subproblem of the constrained solver failed.
    #[error("convex subproblem failed: {0}")]
    Subproblem(String),
    /// A tick longer than the bound of [`crate::tick_length`]: more periods of the well's
    /// fastest small oscillation (a particle with inertia) than allowed. The map folds once
    /// more per half period, and the envelope's boundary search grows without bound with the
    /// folds.
    #[error("{error}")]
    TickTooLong {
        /// The tick refused (`dt [s]`) and its allowed range.
        error: ValueError,
        /// The longest tick allowed for this trap (s).
        max_dt: f64,
        /// The periods of the fastest oscillation allowed in one tick.
        periods: u32,
        /// The fastest small-oscillation angular frequency, `sqrt(κ_max / m)` (rad/s).
        omega: f64,
    },
    /// The 3D surface method's assumption does not hold for this map.
    #[error("3D envelope needs a star-shaped critical surface: {0}")]
    NotStarShaped(String),
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, EnvelopeError>;

/// Check that `value` is finite and strictly positive ([`ot_physics::error::positive_value`]).
pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64> {
    Ok(ot_physics::error::positive_value(field, value)?)
}

/// Check that every component is finite.
pub(crate) fn finite_vec(field: &'static str, v: &[f64]) -> Result<()> {
    for &x in v {
        if !x.is_finite() {
            return Err(EnvelopeError::Value(ValueError::out_of_range(
                field, x, "finite",
            )));
        }
    }
    Ok(())
}
