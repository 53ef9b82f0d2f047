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

/// The sensitivity of the phase to one block `x0` of the initial phase
/// (`r0` or `v0`): the two `D×D` blocks `∂r/∂x0` and `∂v/∂x0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Partials<const D: usize> {
    /// `∂r/∂x0` (dimensionless by `r0`, s by `v0`).
    pub r: SMatrix<f64, D, D>,
    /// `∂v/∂x0` (1/s by `r0`, dimensionless by `v0`).
    pub v: SMatrix<f64, D, D>,
}

/// Phase plus its sensitivity to the first `N` blocks of the initial phase
/// `(r0, v0)`: `d[0]` = `(∂r/∂r0, ∂v/∂r0)` (dimensionless, 1/s) and, with
/// `N` = 2, `d[1]` = `(∂r/∂v0, ∂v/∂v0)` (s, dimensionless). `N` is 1 or 2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseJac<const D: usize, const N: usize> {
    /// The phase itself.
    pub p: Phase<D>,
    /// The sensitivities by `r0` and (`N` = 2) by `v0`.
    pub d: [Partials<D>; N],
}

/// Phase plus its sensitivity to the whole initial phase: the four `D×D`
/// blocks of `∂(r, v)(t) / ∂(r0, v0)` (dimensionless, s, 1/s, dimensionless).
pub type PhaseVar<const D: usize> = PhaseJac<D, 2>;

/// Phase plus its sensitivity to the initial position only: `∂r/∂r0` and
/// `∂v/∂r0` (dimensionless, 1/s). What the envelope and the inverse solver
/// need (∂/∂offset = −∂/∂r0): half the variational work of [`PhaseVar`],
/// which also carries `∂/∂v0`.
pub type PhaseSens<const D: usize> = PhaseJac<D, 1>;

impl<const D: usize, const N: usize> PhaseJac<D, N> {
    /// Sensitivities by `r0` or by `(r0, v0)`, nothing else.
    const BLOCKS: () = assert!(N == 1 || N == 2, "PhaseJac: N is 1 (r0) or 2 (r0, v0)");

    /// Start from `p` with `∂r/∂r0 = I`, `∂v/∂r0 = 0` and, with `N` = 2,
    /// `∂r/∂v0 = 0`, `∂v/∂v0 = I`.
    pub fn identity(p: Phase<D>) -> Self {
        let () = Self::BLOCKS;
        Self {
            p,
            d: std::array::from_fn(|k| {
                let (one, zero) = (SMatrix::identity(), SMatrix::zeros());
                if k == 0 {
                    Partials { r: one, v: zero }
                } else {
                    Partials { r: zero, v: one }
                }
            }),
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

impl<const D: usize, const N: usize> OdeState for PhaseJac<D, N> {
    #[inline(always)]
    fn zero_like(&self) -> Self {
        Self {
            p: self.p.zero_like(),
            d: [Partials {
                r: SMatrix::zeros(),
                v: SMatrix::zeros(),
            }; N],
        }
    }
    #[inline(always)]
    fn combine(&self, h: f64, terms: &[(f64, &Self)]) -> Self {
        let mut out = *self;
        for (c, k) in terms {
            let s = h * c;
            out.p.r.axpy(s, &k.p.r, 1.0);
            out.p.v.axpy(s, &k.p.v, 1.0);
            for (o, kd) in out.d.iter_mut().zip(&k.d) {
                o.r += kd.r * s;
                o.v += kd.v * s;
            }
        }
        out
    }

    /// Error control on the phase and on the sensitivities (a particle at
    /// rest at the centre has a zero phase error but a nonzero Jacobian).
    /// Sensitivity scales: `rtol` for `∂r/∂r0` and `∂v/∂v0`, `rtol/ω` for
    /// `∂r/∂v0`, `rtol·ω` for `∂v/∂r0`, with `ω = atol_v/atol_r`.
    #[inline]
    fn error_ratio(err: &Self, y0: &Self, y1: &Self, tol: &Tolerance) -> f64 {
        let () = Self::BLOCKS;
        let w = tol.atol_v / tol.atol_r;
        // absolute scales of (∂r, ∂v): by r0, then by v0
        let atol = [(tol.rtol, tol.rtol * w), (tol.rtol / w, tol.rtol)];
        let block =
            |e: &SMatrix<f64, D, D>, a: &SMatrix<f64, D, D>, b: &SMatrix<f64, D, D>, atol: f64| {
                let mut worst: f64 = 0.0;
                for i in 0..D * D {
                    let sc = atol + tol.rtol * a[i].abs().max(b[i].abs());
                    worst = worst.max((e[i] / sc).abs());
                }
                worst
            };
        let mut worst = Phase::error_ratio(&err.p, &y0.p, &y1.p, tol);
        for (k, (ar, av)) in atol.into_iter().enumerate().take(N) {
            let (e, a, b) = (&err.d[k], &y0.d[k], &y1.d[k]);
            worst = worst
                .max(block(&e.r, &a.r, &b.r, ar))
                .max(block(&e.v, &a.v, &b.v, av));
        }
        worst
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
