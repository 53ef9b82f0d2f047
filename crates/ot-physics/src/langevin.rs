//! Thermal noise: Langevin dynamics with a seeded, portable random stream.
//!
//! Two schemes, chosen by [`Scheme`]:
//!
//! * **BAOAB** (Leimkuhler & Matthews 2013) for the underdamped equation
//!   `m dv = (F − γv) dt + sqrt(2γkT) dW`. Its friction step is the exact
//!   Ornstein–Uhlenbeck update of the velocity, so it is stable for any γ;
//!   its position sampling of a harmonic well is exact for any friction. It
//!   needs `h·sqrt(κ/m) < 2`: use substeps for a stiff, light particle.
//! * **Overdamped local linearisation** for `γ dr = F dt + sqrt(2γkT) dW`:
//!   each step linearises the force about the current position and applies
//!   the exact Ornstein–Uhlenbeck update of that linear model (mean and
//!   covariance, in the eigenbasis of the force Jacobian). In a harmonic well
//!   this is exact for any step; it stays stable and accurate when
//!   `m/γ ≪ Δt`, where BAOAB would need `h ≲ m/γ` to resolve the dynamics.
//!
//! Random numbers: ChaCha8 seeded from a `u64`, standard normals from
//! `rand_distr` — the same seed gives the same bits on every run.

use crate::error::{PhysicsError, Result, ValueError, positive};
use crate::model::TrapModel;
use crate::state::Phase;
use nalgebra::{DMatrix, Matrix2, Matrix3, SMatrix, SVector, SymmetricEigen};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// Which thermal integrator to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// Overdamped when `m/γ < h/100` (or no mass), BAOAB otherwise.
    Auto,
    /// BAOAB splitting (needs a mass).
    Baoab,
    /// Overdamped local linearisation (ignores the mass).
    Overdamped,
}

impl Scheme {
    /// Parse `"auto"`, `"baoab"` or `"overdamped"`.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "auto" => Ok(Self::Auto),
            "baoab" => Ok(Self::Baoab),
            "overdamped" => Ok(Self::Overdamped),
            _ => Err(PhysicsError::UnknownMethod {
                name: name.to_string(),
                allowed: "\"auto\", \"baoab\", \"overdamped\"",
            }),
        }
    }
}

/// Settings of a thermal run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalRun {
    /// Simulated duration (s).
    pub duration: f64,
    /// Output sample rate (Hz); samples are instantaneous positions.
    pub sample_rate: f64,
    /// Integration substeps per sample interval (≥ 1).
    pub substeps: u32,
    /// Scheme.
    pub scheme: Scheme,
    /// RNG seed.
    pub seed: u64,
}

/// Positions (m, relative to the trap centre) sampled at `sample_rate`,
/// starting at `start` (not included: the first sample is one interval in).
pub fn simulate<const D: usize>(
    model: &TrapModel<D>,
    start: Phase<D>,
    run: &ThermalRun,
) -> Result<Vec<SVector<f64, D>>> {
    let duration = positive("duration [s]", run.duration)?;
    let fs = positive("sample_rate [Hz]", run.sample_rate)?;
    if run.substeps == 0 || run.substeps > 1_000_000 {
        return Err(PhysicsError::Value(ValueError::out_of_range(
            "substeps",
            f64::from(run.substeps),
            "1 ..= 1000000",
        )));
    }
    let n_samples = (duration * fs).round();
    if !(1.0..=1e9).contains(&n_samples) {
        return Err(PhysicsError::Value(ValueError::out_of_range(
            "duration [s] × sample_rate [Hz]",
            n_samples,
            "1 ..= 1e9 samples",
        )));
    }
    let (Some(kt), Some(gamma)) = (model.kt, model.drag) else {
        return Err(PhysicsError::Missing {
            field: "temperature [K], radius [m] and viscosity [Pa s]",
            needed_by: "thermal simulation",
        });
    };
    let h = 1.0 / (fs * f64::from(run.substeps));
    let scheme = match (run.scheme, model.mass) {
        (Scheme::Auto, Some(m)) if m / gamma >= h / 100.0 => Scheme::Baoab,
        (Scheme::Auto, _) => Scheme::Overdamped,
        (Scheme::Baoab, None) => {
            return Err(PhysicsError::Missing {
                field: "mass [kg]",
                needed_by: "the BAOAB scheme",
            });
        }
        (s, _) => s,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(run.seed);
    let mut out = Vec::with_capacity(n_samples as usize);
    let mut y = start;
    match scheme {
        Scheme::Baoab => {
            let m = model.mass.unwrap_or(1.0);
            let c = (-gamma * h / m).exp();
            let sig = ((1.0 - c * c) * kt / m).sqrt();
            let mut a = accel(model, &y.r) / m;
            for _ in 0..n_samples as usize {
                for _ in 0..run.substeps {
                    y.v.axpy(0.5 * h, &a, 1.0);
                    y.r.axpy(0.5 * h, &y.v, 1.0);
                    let xi = normal_vec::<D>(&mut rng);
                    y.v = y.v * c + xi * sig;
                    y.r.axpy(0.5 * h, &y.v, 1.0);
                    a = accel(model, &y.r) / m;
                    y.v.axpy(0.5 * h, &a, 1.0);
                }
                out.push(y.r);
            }
        }
        Scheme::Overdamped | Scheme::Auto => {
            let diff = 2.0 * kt / gamma;
            for _ in 0..n_samples as usize {
                for _ in 0..run.substeps {
                    overdamped_step(model, gamma, diff, h, &mut y.r, &mut rng);
                }
                out.push(y.r);
            }
        }
    }
    Ok(out)
}

#[inline]
fn accel<const D: usize>(model: &TrapModel<D>, r: &SVector<f64, D>) -> SVector<f64, D> {
    model.well.force(r) + model.external_force
}

#[inline]
fn normal_vec<const D: usize>(rng: &mut ChaCha8Rng) -> SVector<f64, D> {
    SVector::from_fn(|_, _| StandardNormal.sample(rng))
}

/// `φ1(z) = (e^z − 1)/z`, accurate near 0.
#[inline]
pub fn phi1(z: f64) -> f64 {
    if z.abs() < 1e-5 {
        1.0 + z * (0.5 + z / 6.0)
    } else {
        z.exp_m1() / z
    }
}

/// One exact OU step of the force linearised about `r`.
fn overdamped_step<const D: usize>(
    model: &TrapModel<D>,
    gamma: f64,
    diff: f64,
    h: f64,
    r: &mut SVector<f64, D>,
    rng: &mut ChaCha8Rng,
) {
    let (f, jac) = model.well.force_and_gradient(r);
    let f = f + model.external_force;
    let xi = normal_vec::<D>(rng);
    // Symmetric Jacobian: diagonalise (tiny D×D), per-mode exact OU update.
    let (vals, q) = sym_eig(&jac);
    let fq = q.transpose() * f / gamma;
    let mut step = SVector::<f64, D>::zeros();
    for k in 0..D {
        let lam = vals[k] / gamma;
        let mean = h * phi1(lam * h) * fq[k];
        let var = diff * h * phi1(2.0 * lam * h);
        step[k] = mean + var.max(0.0).sqrt() * xi[k];
    }
    *r += q * step;
}

/// Eigenvalues and orthonormal eigenvectors (columns) of a symmetric matrix.
fn sym_eig<const D: usize>(m: &SMatrix<f64, D, D>) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
    fn copy_out<const D: usize>(
        vals: &[f64],
        vec: impl Fn(usize, usize) -> f64,
    ) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        (SVector::from_fn(|i, _| vals[i]), SMatrix::from_fn(vec))
    }
    match D {
        2 => {
            let e = SymmetricEigen::new(Matrix2::from_fn(|i, j| m[(i, j)]));
            copy_out(e.eigenvalues.as_slice(), |i, j| e.eigenvectors[(i, j)])
        }
        3 => {
            let e = SymmetricEigen::new(Matrix3::from_fn(|i, j| m[(i, j)]));
            copy_out(e.eigenvalues.as_slice(), |i, j| e.eigenvectors[(i, j)])
        }
        _ => {
            let e = SymmetricEigen::new(DMatrix::from_fn(D, D, |i, j| m[(i, j)]));
            copy_out(e.eigenvalues.as_slice(), |i, j| e.eigenvectors[(i, j)])
        }
    }
}
