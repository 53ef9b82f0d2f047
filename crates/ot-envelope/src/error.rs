//! Typed errors: every variant names the field and the allowed range.

use ot_physics::PhysicsError;
use thiserror::Error;

/// A bad argument to the envelope, inverse-solver, clipping or steering API.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EnvelopeError {
    /// A number outside its allowed range (or NaN / infinite).
    #[error("{field} = {} is out of range: allowed {allowed}", world_form::numbers::fmt_num(*value))]
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
    /// A tick longer than [`crate::envelope::MAX_OSCILLATIONS_PER_TICK`] periods of the well's
    /// fastest small oscillation (a particle with inertia): the map folds once more per
    /// half period, and the envelope's boundary search grows without bound with the folds.
    #[error(
        "dt [s] = {dt:e} is out of range: allowed ≤ {max_dt:.4e} s, {periods} periods of the \
         well's fastest oscillation (ω = {omega:.4e} rad/s); a longer tick folds the map so \
         often that the envelope's boundary search grows without bound"
    )]
    TickTooLong {
        /// The tick asked for (s).
        dt: f64,
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
