//! The bounded region of trap offsets searched by the solver and the
//! envelope, and the free drift of the particle that positions it.

use crate::error::{EnvelopeError, Result, ValueError, finite_vec, positive};
use nalgebra::Vector2;
use ot_physics::{Propagator, TrapModel};

/// Default half-width of the search region beyond the drift path, in waists
/// per axis: at 3 waists the well force is 1/512 of its central scale, so
/// offsets farther out move the particle by a few nm from its free drift.
pub const DEFAULT_MARGIN_WAISTS: f64 = 3.0;

/// Axis-aligned box of trap offsets (trap centre relative to the particle, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffsetRegion {
    /// Lower corner (m).
    pub lo: Vector2<f64>,
    /// Upper corner (m).
    pub hi: Vector2<f64>,
}

impl OffsetRegion {
    /// A box from its corners (m); each `hi` component must exceed `lo`'s.
    pub fn new(lo: Vector2<f64>, hi: Vector2<f64>) -> Result<Self> {
        finite_vec("region.lo [m]", lo.as_slice())?;
        finite_vec("region.hi [m]", hi.as_slice())?;
        for i in 0..2 {
            if hi[i] <= lo[i] {
                return Err(EnvelopeError::Value(ValueError::out_of_range(
                    "region.hi - region.lo [m]",
                    hi[i] - lo[i],
                    "> 0 on each axis",
                )));
            }
        }
        Ok(Self { lo, hi })
    }

    /// The default region for a tick: every offset within `margin` waists
    /// (per axis) of the particle's free drift path `{s(t), 0 ≤ t ≤ Δt}`
    /// (where a trap at offset `s(t)` is met by the drifting particle).
    pub fn around_drift(prop: &Propagator<2>, v0: &Vector2<f64>, margin: f64) -> Result<Self> {
        let margin = positive("margin [waists]", margin)?;
        finite_vec("velocity [m/s]", v0.as_slice())?;
        let w = prop.model().well.waists();
        let (mut lo, mut hi) = (Vector2::zeros(), Vector2::zeros());
        for k in 0..=16 {
            let s = free_drift(prop.model(), v0, prop.dt() * f64::from(k) / 16.0);
            lo = lo.inf(&s);
            hi = hi.sup(&s);
        }
        Self::new(lo - w * margin, hi + w * margin)
    }

    /// Whether `o` (m) lies in the closed box.
    pub fn contains(&self, o: &Vector2<f64>) -> bool {
        (0..2).all(|i| o[i] >= self.lo[i] && o[i] <= self.hi[i])
    }

    /// Centre of the box (m).
    pub fn centre(&self) -> Vector2<f64> {
        (self.lo + self.hi) * 0.5
    }
}

/// Displacement (m) after `t` (s) of a particle with velocity `v0` (m/s)
/// and no trap: only the external force, drag and inertia the model has.
pub fn free_drift(model: &TrapModel<2>, v0: &Vector2<f64>, t: f64) -> Vector2<f64> {
    let f = model.external_force;
    match (model.mass, model.drag) {
        (Some(m), None) => v0 * t + f * (0.5 * t * t / m),
        (Some(m), Some(g)) => {
            let tau = m / g;
            let vinf = f / g;
            vinf * t + (v0 - vinf) * (tau * (-(-t / tau).exp_m1()))
        }
        (None, Some(g)) => f * (t / g),
        (None, None) => Vector2::zeros(),
    }
}
