//! Named integration methods and the [`Propagator`] that applies one to a
//! [`TrapModel`] over a fixed interval.
//!
//! | name          | method                                   | order | evals per (sub)step |
//! |---------------|------------------------------------------|-------|---------------------|
//! | `paper-rk4`   | ONE classical RK4 step per Δt (the paper) | 4     | 4                   |
//! | `rk4`         | classical RK4, `n` equal substeps         | 4     | 4                   |
//! | `rk8`         | DOP853's 8th-order formula, `n` substeps  | 8     | 12                  |
//! | `dopri5`      | Dormand–Prince 5(4), error control        | 5     | 6 (FSAL)            |
//! | `adaptive`    | DOP853 8(5,3), error control (default)    | 8     | 12                  |
//! | `symplectic`  | Störmer–Verlet, `n` substeps              | 2     | 1                   |
//! | `yoshida4`    | Yoshida triple-jump of Verlet             | 4     | 3                   |
//! | `yoshida6`    | Yoshida 6th-order composition             | 6     | 9                   |
//!
//! Thermal noise is integrated by [`crate::langevin`], not here.

mod dop853;
mod dopri5;
mod driver;
mod rk4;
mod symplectic;
mod tableau;

pub use dop853::{dop853, rk8};
pub use dopri5::dopri5;
pub use rk4::{rk4, rk4_step};
pub use symplectic::{Composition, symplectic};

use crate::dynamics::{Dynamics, Variational};
use crate::error::{PhysicsError, Result, ValueError, positive};
use crate::model::TrapModel;
use crate::state::{LaneSystem, Lanes, OdeSystem, Phase, PhaseJac, PhaseSens, PhaseVar, Tolerance};

/// Displacement error the default method guarantees (m): 1e-11 m = 0.01 nm
/// from converged dynamics on every hard-case family (Δt 0.2–20 µs at the
/// paper's constants, moving or at rest; line traps b/a = 1/100; heavy
/// particles), checked in `tests/accuracy.rs` against a converged reference.
pub const DEFAULT_TOL_M: f64 = 1e-11;

/// Default relative tolerance of the adaptive methods, calibrated so that
/// the default flow stays within [`DEFAULT_TOL_M`] (m) of converged dynamics
/// on every hard-case family (see `docs/ot-physics.md`).
pub const DEFAULT_RTOL: f64 = 3e-9;

/// An integration method, as users name it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Exactly the paper's difference equation: one RK4 step of length Δt.
    PaperRk4,
    /// Classical RK4 with `substeps` equal steps per Δt.
    Rk4 {
        /// Number of substeps (≥ 1).
        substeps: u32,
    },
    /// DOP853's 8th-order formula with `substeps` equal steps, no error
    /// control (12 evaluations per step).
    Rk8 {
        /// Number of substeps (≥ 1).
        substeps: u32,
    },
    /// Dormand–Prince 5(4) with error control.
    Dopri5 {
        /// Relative tolerance (dimensionless; absolute scales are the
        /// smallest waist and waist × fastest rate).
        rtol: f64,
    },
    /// DOP853 with error control: the default.
    Adaptive {
        /// Relative tolerance, as for [`Method::Dopri5`].
        rtol: f64,
    },
    /// A symplectic composition with `substeps` equal steps per Δt
    /// (conservative models only).
    Symplectic {
        /// Number of substeps (≥ 1).
        substeps: u32,
        /// Which composition.
        composition: Composition,
    },
}

impl Default for Method {
    fn default() -> Self {
        Self::Adaptive { rtol: DEFAULT_RTOL }
    }
}

/// Accepted method names.
pub const METHOD_NAMES: &str = "\"paper-rk4\", \"rk4\", \"rk8\", \"dopri5\", \"adaptive\", \"symplectic\", \"yoshida4\", \"yoshida6\"";

impl Method {
    /// Build a method from its name, with optional tolerance and substeps
    /// (defaults: `rtol` = [`DEFAULT_RTOL`], 16 substeps).
    pub fn from_name(name: &str, rtol: Option<f64>, substeps: Option<u32>) -> Result<Self> {
        let rtol = rtol.unwrap_or(DEFAULT_RTOL);
        let n = substeps.unwrap_or(16);
        let m = match name {
            "paper-rk4" => Self::PaperRk4,
            "rk4" => Self::Rk4 { substeps: n },
            "rk8" => Self::Rk8 {
                substeps: substeps.unwrap_or(3),
            },
            "dopri5" => Self::Dopri5 { rtol },
            "adaptive" | "dop853" => Self::Adaptive { rtol },
            "symplectic" | "verlet" => Self::Symplectic {
                substeps: n,
                composition: Composition::Verlet,
            },
            "yoshida4" => Self::Symplectic {
                substeps: n,
                composition: Composition::Yoshida4,
            },
            "yoshida6" => Self::Symplectic {
                substeps: n,
                composition: Composition::Yoshida6,
            },
            _ => {
                return Err(PhysicsError::UnknownMethod {
                    name: name.to_string(),
                    allowed: METHOD_NAMES,
                });
            }
        };
        m.validate()?;
        Ok(m)
    }

    /// The method's name as users type it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::PaperRk4 => "paper-rk4",
            Self::Rk4 { .. } => "rk4",
            Self::Rk8 { .. } => "rk8",
            Self::Dopri5 { .. } => "dopri5",
            Self::Adaptive { .. } => "adaptive",
            Self::Symplectic { composition, .. } => match composition {
                Composition::Verlet => "symplectic",
                Composition::Yoshida4 => "yoshida4",
                Composition::Yoshida6 => "yoshida6",
            },
        }
    }

    /// Check the method's own parameters.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Self::Rk4 { substeps } | Self::Rk8 { substeps } | Self::Symplectic { substeps, .. } => {
                if substeps == 0 || substeps > 10_000_000 {
                    return Err(PhysicsError::Value(ValueError::out_of_range(
                        "substeps",
                        f64::from(substeps),
                        "1 ..= 10000000",
                    )));
                }
            }
            Self::Dopri5 { rtol } | Self::Adaptive { rtol } => {
                if !(rtol.is_finite() && (1e-14..=1e-1).contains(&rtol)) {
                    return Err(PhysicsError::Value(ValueError::out_of_range(
                        "rtol",
                        rtol,
                        "1e-14 ..= 0.1",
                    )));
                }
            }
            Self::PaperRk4 => {}
        }
        Ok(())
    }
}

/// Counters of an adaptive integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AdaptiveStats {
    /// Right-hand-side (force) evaluations.
    pub evals: u64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
}

/// Step-size controller settings (Hairer's PI controller).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepControl {
    /// Safety factor (dimensionless).
    pub safety: f64,
    /// Smallest step-size ratio.
    pub fac_min: f64,
    /// Largest step-size ratio.
    pub fac_max: f64,
    /// PI stabilisation exponent β.
    pub beta: f64,
    /// Hard limit on steps per interval.
    pub max_steps: u64,
}

impl Default for StepControl {
    fn default() -> Self {
        Self {
            safety: 0.9,
            fac_min: 0.2,
            fac_max: 10.0,
            beta: 0.04,
            max_steps: 1_000_000,
        }
    }
}

impl StepControl {
    /// Step-size multiplier for error ratio `err` (previous accepted `prev`)
    /// of a method whose local error is of order `q`.
    #[inline]
    pub fn factor(&self, err: f64, prev: f64, q: f64) -> f64 {
        if err <= 0.0 {
            return self.fac_max;
        }
        let expo = 1.0 / q - 0.75 * self.beta;
        let f = self.safety * pow_step(err, -expo) * pow_step(prev, self.beta);
        f.clamp(self.fac_min, self.fac_max)
    }
}

impl StepControl {
    /// [`StepControl::factor`] from logarithms: `ln_err = ln(err)` (err > 0)
    /// and `ln_prev = ln(prev)`, one `exp` instead of two powers; the PI
    /// controller (`beta > 0`) keeps `ln(prev)` from the previous step.
    #[inline]
    pub(crate) fn factor_ln(&self, ln_err: f64, ln_prev: f64, q: f64) -> f64 {
        let expo = 1.0 / q - 0.75 * self.beta;
        let f = self.safety * crate::fastexp::exp(self.beta * ln_prev - expo * ln_err);
        f.clamp(self.fac_min, self.fac_max)
    }
}

/// `ln x` (x > 0, normal) to ~1e-7 absolute: the logarithm of
/// [`pow_step`]; `None` where `x` is not a positive normal number.
#[inline]
pub(crate) fn ln_step(x: f64) -> Option<f64> {
    if !(x.is_normal() && x > 0.0) {
        return None;
    }
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let ln_m = 2.0 * s * (1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 / 9.0))));
    Some(e as f64 * std::f64::consts::LN_2 + ln_m)
}

/// `x^p` for the step-size controller, to ~1e-6 relative (x > 0): a
/// step-size factor needs no more, and libm's `powf` was a visible share of
/// a short adaptive integration. `ln x = e·ln2 + 2·atanh((m−1)/(m+1))` with
/// the mantissa `m ∈ [1, 2)` ([`ln_step`]), then the crate's inlined `exp`.
#[inline]
fn pow_step(x: f64, p: f64) -> f64 {
    if p == 0.0 {
        return 1.0;
    }
    match ln_step(x) {
        Some(ln_x) => crate::fastexp::exp(p * ln_x),
        None => x.powf(p),
    }
}

/// A method bound to a model and an interval Δt, validated once, then
/// applied to many initial states (the batch and haptic-tick use).
#[derive(Debug, Clone, Copy)]
pub struct Propagator<const D: usize> {
    model: TrapModel<D>,
    method: Method,
    dt: f64,
    tol: Tolerance,
    h0: f64,
    /// `dopri5` with inertia: `(2 rtol^{1/5}, κ_max/m (1/s²), (γ/m)² (1/s²))`
    /// for the first step from the local rate ([`Propagator::first_step`]).
    first: Option<(f64, f64, f64)>,
    ctl: StepControl,
}

/// Result of one propagation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Propagated<S> {
    /// The end state.
    pub end: S,
    /// Force evaluations spent.
    pub evals: u64,
}

impl<const D: usize> Propagator<D> {
    /// Bind `method` to `model` over `dt` (s). Fails if the method cannot
    /// integrate the model (thermal noise on; symplectic with drag or
    /// overdamped) or if `dt` is not finite and > 0.
    pub fn new(model: TrapModel<D>, method: Method, dt: f64) -> Result<Self> {
        let dt = positive("dt [s]", dt)?;
        method.validate()?;
        if model.kt.is_some() {
            return Err(PhysicsError::Unsupported {
                method: method.name(),
                reason: "thermal noise is on: use langevin::simulate (BAOAB or overdamped)",
            });
        }
        if matches!(method, Method::Symplectic { .. }) && !model.is_conservative() {
            return Err(PhysicsError::Unsupported {
                method: method.name(),
                reason: "symplectic methods need a conservative model (inertia on, no drag)",
            });
        }
        let rate = model.fastest_rate();
        let l = model.length_scale();
        let rate_or_dt = if rate > 0.0 { rate } else { 1.0 / dt };
        let (rtol, q) = match method {
            Method::Dopri5 { rtol } => (rtol, 5.0),
            Method::Adaptive { rtol } => (rtol, 8.0),
            _ => (DEFAULT_RTOL, 4.0),
        };
        let tol = Tolerance {
            rtol,
            atol_r: rtol * l,
            atol_v: rtol * l * rate_or_dt,
        };
        // First trial step: the local error of order q at rate ω is ~ (ωh)^q.
        let h0 = (2.0 * rtol.powf(1.0 / q) / rate_or_dt).min(dt);
        // dopri5 with inertia: the first step from the local rate
        let first = match (method, model.mass) {
            (Method::Dopri5 { rtol }, Some(m)) => Some((
                6.0 * rtol.powf(0.2),
                model.well.stiffness().max() / m,
                model.drag.map_or(0.0, |g| (g / m) * (g / m)),
            )),
            _ => None,
        };
        let mut ctl = StepControl::default();
        if matches!(method, Method::Adaptive { .. }) {
            ctl.beta = 0.0;
            ctl.fac_min = 0.333;
            ctl.fac_max = 6.0;
        }
        Ok(Self {
            model,
            method,
            dt,
            tol,
            h0,
            first,
            ctl,
        })
    }

    /// The bound model.
    pub fn model(&self) -> &TrapModel<D> {
        &self.model
    }
    /// The bound method.
    pub fn method(&self) -> Method {
        self.method
    }
    /// The interval (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The one dispatch over the methods: `sys` from `y0` over Δt by the
    /// bound method, `h0` (s) the first trial step of the adaptive ones.
    /// Returns the end state and the force evaluations spent. A symplectic
    /// method runs here as RK4 with its substeps (how the sensitivities are
    /// integrated); [`Propagator::phase`] runs the composition itself.
    #[inline]
    fn integrate<S: OdeSystem>(&self, sys: &S, y0: &S::State, h0: f64) -> Result<(S::State, u64)> {
        let dt = self.dt;
        Ok(match self.method {
            Method::PaperRk4 => (rk4(sys, y0, dt, 1), 4),
            Method::Rk4 { substeps } | Method::Symplectic { substeps, .. } => {
                (rk4(sys, y0, dt, substeps), 4 * u64::from(substeps))
            }
            Method::Rk8 { substeps } => (rk8(sys, y0, dt, substeps), 12 * u64::from(substeps)),
            Method::Dopri5 { .. } => {
                let (y, s) = dopri5(sys, y0, dt, &self.tol, h0, &self.ctl)?;
                (y, s.evals)
            }
            Method::Adaptive { .. } => {
                let (y, s) = dop853(sys, y0, dt, &self.tol, h0, &self.ctl)?;
                (y, s.evals)
            }
        })
    }

    /// Propagate a phase over Δt.
    pub fn phase(&self, y0: &Phase<D>) -> Result<Propagated<Phase<D>>> {
        let (end, evals) = match self.method {
            Method::Symplectic {
                substeps,
                composition,
            } => symplectic(&self.model, y0, self.dt, substeps, composition),
            _ => self.integrate(&Dynamics::new(&self.model), y0, self.first_step(y0))?,
        };
        Ok(Propagated {
            end: self.finish(end, y0),
            evals,
        })
    }

    /// Propagate `L` phases in lockstep when the method has fixed steps
    /// (`paper-rk4`, `rk4`, `rk8`): bit-identical to `L` calls of
    /// [`Propagator::phase`], faster because the lanes overlap. `None` for
    /// the adaptive and symplectic methods (their lanes would share steps).
    pub fn phase_lanes<const L: usize>(&self, y0: &[Phase<D>; L]) -> Option<([Phase<D>; L], u64)> {
        if !matches!(
            self.method,
            Method::PaperRk4 | Method::Rk4 { .. } | Method::Rk8 { .. }
        ) {
            return None;
        }
        let inner = Dynamics::new(&self.model);
        // fixed steps have no error control: they cannot fail
        let (end, evals) = self
            .integrate(&LaneSystem::<_, L>(&inner), &Lanes(*y0), self.h0)
            .ok()?;
        let mut out = end.0;
        for (o, y0) in out.iter_mut().zip(y0) {
            *o = self.finish(*o, y0);
        }
        Some((out, evals * L as u64))
    }

    /// First trial step (s) of a `dopri5` propagation from `y0`:
    /// `ωh = 6 rtol^{1/5}` (≈ 0.6 at rtol 1e-5, where the local error
    /// `(ωh)^6/6!` is within an order of magnitude of rtol), with ω the larger
    /// of the well's local rate at the start and at the end of the candidate
    /// step along the start velocity — `ω² ≤ (κ_max/m) e^{−q} (1 + 2q)`,
    /// `q = ln2 Σ r_i²/w_i²`, the Hessian bound of the Gaussian — and never
    /// below the drag rate; never shorter than the fixed first step
    /// `2 rtol^{1/5}/ω_max`. Far out in the Gaussian's tail, where the force
    /// is a tiny fraction of its peak, the first step is the whole tick
    /// instead of a ladder of growing steps from the centre's rate.
    #[inline]
    fn first_step(&self, y0: &Phase<D>) -> f64 {
        let Some((c, kmax_m, floor)) = self.first else {
            return self.h0;
        };
        // ω² ≤ (κ_max/m) e^{−q} (1 + 2q), at least the drag rate squared
        let rate2 = |r: &nalgebra::SVector<f64, D>| {
            let q = self.model.well.exponent(r);
            (kmax_m * crate::fastexp::exp(-q) * (1.0 + 2.0 * q)).max(floor)
        };
        let w0 = rate2(&y0.r);
        let mut h = if w0 > 0.0 { c / w0.sqrt() } else { self.dt };
        h = h.min(self.dt);
        // the rate where the candidate step would take the particle
        if y0.v.iter().any(|v| *v != 0.0) {
            let w1 = rate2(&(y0.r + y0.v * h));
            if w1 > w0 {
                h = h.min(c / w1.sqrt());
            }
        }
        h.max(self.h0)
    }

    /// Overdamped models carry no velocity; report the drift velocity at the end.
    fn finish(&self, mut end: Phase<D>, _y0: &Phase<D>) -> Phase<D> {
        if self.model.mass.is_none() {
            let g = self.model.drag.unwrap_or(f64::INFINITY);
            end.v = (self.model.well.force(&end.r) + self.model.external_force) / g;
        }
        end
    }

    /// Propagate a phase and its sensitivities over Δt (variational
    /// equations). Fixed-step methods give the exact derivative of their own
    /// discrete map; symplectic methods use RK4 with the same substeps for
    /// the sensitivities.
    pub fn phase_var(&self, y0: &Phase<D>) -> Result<Propagated<PhaseVar<D>>> {
        self.sensitivities(y0)
    }

    /// Propagate a phase and its sensitivity to the initial position only
    /// (the offset Jacobian), over Δt. Fixed-step methods give the exact
    /// derivative of their own discrete map, as [`Propagator::phase_var`].
    pub fn phase_sens(&self, y0: &Phase<D>) -> Result<Propagated<PhaseSens<D>>> {
        self.sensitivities(y0)
    }

    /// The phase and its sensitivities by the first `N` blocks of the
    /// initial phase, over Δt: [`Propagator::phase_sens`] (`N` = 1) and
    /// [`Propagator::phase_var`] (`N` = 2).
    fn sensitivities<const N: usize>(&self, y0: &Phase<D>) -> Result<Propagated<PhaseJac<D, N>>> {
        let sys = Variational::<D, N>::new(&self.model);
        let (mut end, evals) = self.integrate(&sys, &PhaseJac::identity(*y0), self.h0)?;
        end.p = self.finish(end.p, y0);
        Ok(Propagated { end, evals })
    }
}

#[cfg(test)]
mod tests {
    use super::pow_step;

    #[test]
    fn step_power_matches_powf_to_a_millionth() {
        for &p in &[-0.2, -0.17, -0.125, 0.04, 1.0 / 3.0] {
            let mut x = 1e-12;
            while x < 1e6 {
                let (a, b) = (pow_step(x, p), x.powf(p));
                assert!((a / b - 1.0).abs() < 1e-6, "{x}^{p}: {a} vs {b}");
                x *= 1.37;
            }
        }
        assert_eq!(pow_step(0.5, 0.0), 1.0);
    }
}
