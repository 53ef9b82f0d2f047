//! Right-hand sides: the equations of motion and their variational
//! equations, for the effects a [`TrapModel`] switched on.

use crate::model::TrapModel;
use crate::state::{OdeSystem, Partials, Phase, PhaseJac};
use nalgebra::{SMatrix, SVector};

/// Which equations of motion a model needs, with its coefficients
/// precomputed (no division or option test per evaluation).
#[derive(Debug, Clone, Copy)]
enum Kind {
    /// `v̇ = (F + F_ext)/m`.
    Conservative { inv_mass: f64 },
    /// `v̇ = (F + F_ext)/m − (γ/m) v`.
    Damped { inv_mass: f64, rate: f64 },
    /// `ṙ = (F + F_ext)/γ`.
    Overdamped { inv_drag: f64 },
}

impl Kind {
    fn of<const D: usize>(m: &TrapModel<D>) -> Self {
        match (m.mass, m.drag) {
            (Some(mass), None) => Self::Conservative {
                inv_mass: 1.0 / mass,
            },
            (Some(mass), Some(g)) => Self::Damped {
                inv_mass: 1.0 / mass,
                rate: g / mass,
            },
            // A validated model without mass has drag.
            (None, g) => Self::Overdamped {
                inv_drag: 1.0 / g.unwrap_or(f64::INFINITY),
            },
        }
    }
}

/// Deterministic equations of motion (noise is handled by `langevin`).
///
/// With inertia: `ṙ = v`, `v̇ = (F(r) − γv + F_ext)/m`. Overdamped:
/// `ṙ = (F(r) + F_ext)/γ` with `v̇ = 0` (the velocity slot is unused).
#[derive(Debug, Clone, Copy)]
pub struct Dynamics<'a, const D: usize> {
    model: &'a TrapModel<D>,
    kind: Kind,
}

/// The equations of motion together with their variational equations: by
/// the whole initial phase (`N` = 2, the default: [`crate::PhaseVar`]) or by
/// the initial position only (`N` = 1: [`OffsetVariational`]).
#[derive(Debug, Clone, Copy)]
pub struct Variational<'a, const D: usize, const N: usize = 2> {
    model: &'a TrapModel<D>,
    kind: Kind,
}

/// The equations of motion with the variational equations of `∂/∂r0` only
/// (what `∂ displacement/∂ offset` needs): `D²·2` fewer products per
/// evaluation than [`Variational`].
pub type OffsetVariational<'a, const D: usize> = Variational<'a, D, 1>;

impl<'a, const D: usize, const N: usize> Variational<'a, D, N> {
    /// The variational equations of `model`.
    pub fn new(model: &'a TrapModel<D>) -> Self {
        Self {
            model,
            kind: Kind::of(model),
        }
    }
}

impl<const D: usize, const N: usize> OdeSystem for Variational<'_, D, N> {
    type State = PhaseJac<D, N>;
    #[inline]
    fn max_step(&self, y: &PhaseJac<D, N>) -> f64 {
        crossing_limit(self.model, &y.p)
    }
    /// Each block of sensitivities `(∂r, ∂v)` by `x0` follows the linearised
    /// motion: `∂ṙ = ∂v`, `∂v̇ = (H ∂r)/m − (γ/m) ∂v` (overdamped:
    /// `∂ṙ = (H ∂r)/γ`), with `H` the force Jacobian at `r`.
    #[inline(always)]
    fn rhs(&self, y: &PhaseJac<D, N>) -> PhaseJac<D, N> {
        let (fw, h) = self.model.well.force_and_gradient(&y.p.r);
        let f = fw + self.model.external_force;
        match self.kind {
            Kind::Conservative { inv_mass } => PhaseJac {
                p: Phase {
                    r: y.p.v,
                    v: f * inv_mass,
                },
                d: y.d.map(|c| Partials {
                    r: c.v,
                    v: (h * c.r) * inv_mass,
                }),
            },
            Kind::Damped { inv_mass, rate } => PhaseJac {
                p: Phase {
                    r: y.p.v,
                    v: f * inv_mass - y.p.v * rate,
                },
                d: y.d.map(|c| Partials {
                    r: c.v,
                    v: (h * c.r) * inv_mass - c.v * rate,
                }),
            },
            Kind::Overdamped { inv_drag } => PhaseJac {
                p: Phase {
                    r: f * inv_drag,
                    v: SVector::zeros(),
                },
                d: y.d.map(|c| Partials {
                    r: (h * c.r) * inv_drag,
                    v: SMatrix::zeros(),
                }),
            },
        }
    }
}

impl<'a, const D: usize> Dynamics<'a, D> {
    /// The equations of motion of `model`.
    pub fn new(model: &'a TrapModel<D>) -> Self {
        Self {
            model,
            kind: Kind::of(model),
        }
    }
}

/// Largest step (s) that cannot carry the particle across the well unseen.
///
/// Inside six largest waists of the centre (where the force exceeds 1e-11 of
/// its peak) a step may move the particle by at most half the smallest
/// waist; outside, moving away, there is no limit; outside, approaching, a
/// step may reach the edge of that region but not beyond.
#[inline]
fn crossing_limit<const D: usize>(model: &TrapModel<D>, y: &Phase<D>) -> f64 {
    let speed = y.v.norm();
    if model.mass.is_none() || speed == 0.0 {
        return f64::INFINITY;
    }
    let reach = 6.0 * model.well.waists().max();
    let dist = y.r.norm();
    if dist > reach && y.r.dot(&y.v) >= 0.0 {
        return f64::INFINITY;
    }
    (0.5 * model.length_scale()).max(dist - reach) / speed
}

impl<const D: usize> OdeSystem for Dynamics<'_, D> {
    type State = Phase<D>;
    #[inline]
    fn max_step(&self, y: &Phase<D>) -> f64 {
        crossing_limit(self.model, y)
    }
    #[inline(always)]
    fn rhs(&self, y: &Phase<D>) -> Phase<D> {
        let f = self.model.well.force(&y.r) + self.model.external_force;
        match self.kind {
            Kind::Conservative { inv_mass } => Phase {
                r: y.v,
                v: f * inv_mass,
            },
            Kind::Damped { inv_mass, rate } => Phase {
                r: y.v,
                v: f * inv_mass - y.v * rate,
            },
            Kind::Overdamped { inv_drag } => Phase {
                r: f * inv_drag,
                v: SVector::zeros(),
            },
        }
    }
}
