//! Integrator state types and the small vector-space interface the
//! Runge–Kutta methods need.

use nalgebra::{SMatrix, SVector};

/// A state the generic Runge–Kutta methods can combine and measure.
pub trait OdeState: Copy {
    /// `self + h · Σ c_i k_i`.
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self;
    /// A state of zeros with the same shape.
    fn zero_like(&self) -> Self;
    /// Error ratio of the local error estimate `err` for a step `y0 → y1`:
    /// `max_i |err_i| / (atol_i + rtol · max(|y0_i|, |y1_i|))`; ≤ 1 accepts.
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64;
}

/// An autonomous ODE `y' = f(y)` (the trap does not move during a step).
pub trait OdeSystem {
    /// The state type.
    type State: OdeState;
    /// The right-hand side `f(y)`.
    fn rhs(&self, y: &Self::State) -> Self::State;
    /// Largest step (s) the adaptive methods may take from `y`, whatever
    /// their error estimate says: an embedded pair cannot see a feature it
    /// steps over entirely (a fast particle crossing the well).
    #[inline]
    fn max_step(&self, _y: &Self::State) -> f64 {
        f64::INFINITY
    }
}

/// Error tolerances of an adaptive method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance on positions (m).
    pub atol_r: f64,
    /// Absolute tolerance on velocities (m/s).
    pub atol_v: f64,
}

/// Position (m) and velocity (m/s) of the particle relative to the trap centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Phase<const D: usize> {
    /// Position relative to the trap centre (m).
    pub r: SVector<f64, D>,
    /// Velocity (m/s).
    pub v: SVector<f64, D>,
}

/// Phase plus its sensitivity to the initial phase: the four `D×D` blocks
/// of `∂(r, v)(t) / ∂(r0, v0)` (dimensionless, s, 1/s, dimensionless).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseVar<const D: usize> {
    /// The phase itself.
    pub p: Phase<D>,
    /// `∂r/∂r0` (dimensionless).
    pub jrr: SMatrix<f64, D, D>,
    /// `∂r/∂v0` (s).
    pub jrv: SMatrix<f64, D, D>,
    /// `∂v/∂r0` (1/s).
    pub jvr: SMatrix<f64, D, D>,
    /// `∂v/∂v0` (dimensionless).
    pub jvv: SMatrix<f64, D, D>,
}

/// Phase plus its sensitivity to the initial position only: the two `D×D`
/// blocks `∂r/∂r0` and `∂v/∂r0` (dimensionless, 1/s). What the envelope and
/// the inverse solver need (∂/∂offset = −∂/∂r0): half the variational work of
/// [`PhaseVar`], which also carries `∂/∂v0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseSens<const D: usize> {
    /// The phase itself.
    pub p: Phase<D>,
    /// `∂r/∂r0` (dimensionless).
    pub jrr: SMatrix<f64, D, D>,
    /// `∂v/∂r0` (1/s).
    pub jvr: SMatrix<f64, D, D>,
}

impl<const D: usize> PhaseSens<D> {
    /// Start from `p` with `∂r/∂r0 = I`, `∂v/∂r0 = 0`.
    pub fn identity(p: Phase<D>) -> Self {
        Self {
            p,
            jrr: SMatrix::identity(),
            jvr: SMatrix::zeros(),
        }
    }
}

impl<const D: usize> OdeState for PhaseSens<D> {
    #[inline(always)]
    fn zero_like(&self) -> Self {
        Self {
            p: self.p.zero_like(),
            jrr: SMatrix::zeros(),
            jvr: SMatrix::zeros(),
        }
    }
    #[inline(always)]
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut out = *self;
        for (c, k) in terms {
            let s = h * c;
            out.p.r.axpy(s, &k.p.r, 1.0);
            out.p.v.axpy(s, &k.p.v, 1.0);
            out.jrr += k.jrr * s;
            out.jvr += k.jvr * s;
        }
        out
    }

    /// As [`PhaseVar`]'s error control, on the two blocks carried.
    #[inline]
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64 {
        let w = tol.atol_v / tol.atol_r;
        let block =
            |e: &SMatrix<f64, D, D>, a: &SMatrix<f64, D, D>, b: &SMatrix<f64, D, D>, atol: f64| {
                let mut worst: f64 = 0.0;
                for i in 0..D * D {
                    let sc = atol + tol.rtol * a[i].abs().max(b[i].abs());
                    worst = worst.max((e[i] / sc).abs());
                }
                worst
            };
        Phase::error_ratio(&err.p, &y0.p, &y1.p, tol)
            .max(block(&err.jrr, &y0.jrr, &y1.jrr, tol.rtol))
            .max(block(&err.jvr, &y0.jvr, &y1.jvr, tol.rtol * w))
    }
}

impl<const D: usize> PhaseVar<D> {
    /// Start from `p` with identity sensitivities.
    pub fn identity(p: Phase<D>) -> Self {
        Self {
            p,
            jrr: SMatrix::identity(),
            jrv: SMatrix::zeros(),
            jvr: SMatrix::zeros(),
            jvv: SMatrix::identity(),
        }
    }
}

impl<const D: usize> OdeState for Phase<D> {
    #[inline(always)]
    fn zero_like(&self) -> Self {
        Self {
            r: SVector::zeros(),
            v: SVector::zeros(),
        }
    }
    #[inline(always)]
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut r = self.r.data.0[0];
        let mut v = self.v.data.0[0];
        for (c, k) in terms {
            let s = h * c;
            let (kr, kv) = (&k.r.data.0[0], &k.v.data.0[0]);
            for i in 0..D {
                r[i] += s * kr[i];
                v[i] += s * kv[i];
            }
        }
        Self {
            r: SVector::from(r),
            v: SVector::from(v),
        }
    }

    #[inline]
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..D {
            let sr = tol.atol_r + tol.rtol * y0.r[i].abs().max(y1.r[i].abs());
            let sv = tol.atol_v + tol.rtol * y0.v[i].abs().max(y1.v[i].abs());
            worst = worst.max((err.r[i] / sr).abs()).max((err.v[i] / sv).abs());
        }
        worst
    }
}

impl<const D: usize> OdeState for PhaseVar<D> {
    #[inline(always)]
    fn zero_like(&self) -> Self {
        Self {
            p: self.p.zero_like(),
            jrr: SMatrix::zeros(),
            jrv: SMatrix::zeros(),
            jvr: SMatrix::zeros(),
            jvv: SMatrix::zeros(),
        }
    }
    #[inline(always)]
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut out = *self;
        for (c, k) in terms {
            let s = h * c;
            out.p.r.axpy(s, &k.p.r, 1.0);
            out.p.v.axpy(s, &k.p.v, 1.0);
            out.jrr += k.jrr * s;
            out.jrv += k.jrv * s;
            out.jvr += k.jvr * s;
            out.jvv += k.jvv * s;
        }
        out
    }

    /// Error control on the phase and on the sensitivities (a particle at
    /// rest at the centre has a zero phase error but a nonzero Jacobian).
    /// Sensitivity scales: `rtol` for `∂r/∂r0` and `∂v/∂v0`, `rtol/ω` for
    /// `∂r/∂v0`, `rtol·ω` for `∂v/∂r0`, with `ω = atol_v/atol_r`.
    #[inline]
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64 {
        let w = tol.atol_v / tol.atol_r;
        let block =
            |e: &SMatrix<f64, D, D>, a: &SMatrix<f64, D, D>, b: &SMatrix<f64, D, D>, atol: f64| {
                let mut worst: f64 = 0.0;
                for i in 0..D * D {
                    let sc = atol + tol.rtol * a[i].abs().max(b[i].abs());
                    worst = worst.max((e[i] / sc).abs());
                }
                worst
            };
        Phase::error_ratio(&err.p, &y0.p, &y1.p, tol)
            .max(block(&err.jrr, &y0.jrr, &y1.jrr, tol.rtol))
            .max(block(&err.jrv, &y0.jrv, &y1.jrv, tol.rtol / w))
            .max(block(&err.jvr, &y0.jvr, &y1.jvr, tol.rtol * w))
            .max(block(&err.jvv, &y0.jvv, &y1.jvv, tol.rtol))
    }
}

/// `L` independent states advanced in lockstep by the fixed-step methods.
///
/// The lanes share nothing but the instruction stream: each lane performs
/// exactly the operations, in the same order, that it would alone, so the
/// results are bit-identical to `L` separate integrations — while the CPU
/// overlaps the lanes' independent dependency chains (the `exp` of one lane
/// runs while another combines its stages).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lanes<S, const L: usize>(pub [S; L]);

impl<S: OdeState, const L: usize> OdeState for Lanes<S, L> {
    #[inline(always)]
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut out = self.0;
        for (c, k) in terms {
            for (o, kl) in out.iter_mut().zip(&k.0) {
                *o = o.combine(h, &[(*c, kl)]);
            }
        }
        Lanes(out)
    }
    #[inline(always)]
    fn zero_like(&self) -> Self {
        Lanes(self.0.map(|s| s.zero_like()))
    }
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64 {
        (0..L)
            .map(|l| S::error_ratio(&err.0[l], &y0.0[l], &y1.0[l], tol))
            .fold(0.0, f64::max)
    }
}

/// A system applied lane by lane to `L` [`Lanes`].
#[derive(Debug, Clone, Copy)]
pub struct LaneSystem<'a, S, const L: usize>(pub &'a S);

impl<S: OdeSystem, const L: usize> OdeSystem for LaneSystem<'_, S, L> {
    type State = Lanes<S::State, L>;
    #[inline(always)]
    fn rhs(&self, y: &Self::State) -> Self::State {
        Lanes(std::array::from_fn(|l| self.0.rhs(&y.0[l])))
    }
    fn max_step(&self, y: &Self::State) -> f64 {
        y.0.iter()
            .map(|s| self.0.max_step(s))
            .fold(f64::INFINITY, f64::min)
    }
}
