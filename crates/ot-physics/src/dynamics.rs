//! Right-hand sides: the equations of motion and their variational
//! equations, for the effects a [`TrapModel`] switched on.

use crate::model::TrapModel;
use crate::state::{OdeSystem, Phase, PhaseVar};
use nalgebra::SVector;

/// Deterministic equations of motion (noise is handled by `langevin`).
///
/// With inertia: `ṙ = v`, `v̇ = (F(r) − γv + F_ext)/m`. Overdamped:
/// `ṙ = (F(r) + F_ext)/γ` with `v̇ = 0` (the velocity slot is unused).
#[derive(Debug, Clone, Copy)]
pub struct Dynamics<'a, const D: usize> {
    /// The model integrated.
    pub model: &'a TrapModel<D>,
}

/// The equations of motion together with their variational equations.
#[derive(Debug, Clone, Copy)]
pub struct Variational<'a, const D: usize> {
    /// The model integrated.
    pub model: &'a TrapModel<D>,
}

impl<const D: usize> Dynamics<'_, D> {
    /// Acceleration (m/s²) with inertia, or drift velocity (m/s) overdamped.
    #[inline(always)]
    fn accel(&self, y: &Phase<D>) -> SVector<f64, D> {
        let m = self.model;
        let mut f = m.well.force(&y.r) + m.external_force;
        if let Some(g) = m.drag {
            if m.mass.is_some() {
                f.axpy(-g, &y.v, 1.0);
            }
        }
        match (m.mass, m.drag) {
            (Some(mass), _) => f / mass,
            (None, Some(g)) => f / g,
            (None, None) => SVector::zeros(),
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
        let a = self.accel(y);
        if self.model.mass.is_some() {
            Phase { r: y.v, v: a }
        } else {
            Phase {
                r: a,
                v: SVector::zeros(),
            }
        }
    }
}

impl<const D: usize> OdeSystem for Variational<'_, D> {
    type State = PhaseVar<D>;
    #[inline]
    fn max_step(&self, y: &PhaseVar<D>) -> f64 {
        crossing_limit(self.model, &y.p)
    }
    #[inline(always)]
    fn rhs(&self, y: &PhaseVar<D>) -> PhaseVar<D> {
        let m = self.model;
        let (fw, h) = m.well.force_and_gradient(&y.p.r);
        let mut f = fw + m.external_force;
        match m.mass {
            Some(mass) => {
                let inv = 1.0 / mass;
                let (jvr, jvv) = match m.drag {
                    Some(g) => {
                        f.axpy(-g, &y.p.v, 1.0);
                        ((h * y.jrr - y.jvr * g) * inv, (h * y.jrv - y.jvv * g) * inv)
                    }
                    None => ((h * y.jrr) * inv, (h * y.jrv) * inv),
                };
                PhaseVar {
                    p: Phase {
                        r: y.p.v,
                        v: f * inv,
                    },
                    jrr: y.jvr,
                    jrv: y.jvv,
                    jvr,
                    jvv,
                }
            }
            None => {
                let g = m.drag.unwrap_or(f64::INFINITY);
                let inv = 1.0 / g;
                PhaseVar {
                    p: Phase {
                        r: f * inv,
                        v: SVector::zeros(),
                    },
                    jrr: (h * y.jrr) * inv,
                    jrv: (h * y.jrv) * inv,
                    jvr: nalgebra::SMatrix::zeros(),
                    jvv: nalgebra::SMatrix::zeros(),
                }
            }
        }
    }
}
