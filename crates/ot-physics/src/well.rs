//! The elliptic Gaussian potential well of an optical trap.

use crate::error::{Result, positive};
use nalgebra::{SMatrix, SVector};

/// `ln 2`, the constant that makes each waist a half-depth radius.
pub const LN2: f64 = std::f64::consts::LN_2;

/// Gaussian well `P(r) = -P0 · exp(-ln2 · Σ r_i² / w_i²)` in `D` dimensions.
///
/// `r` is the particle position relative to the trap centre (m). In 2D the
/// waists are the paper's `(a, b)`; in 3D the third waist is the axial one.
/// At `|r_i| = w_i` on an axis the depth has fallen to one half.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianWell<const D: usize> {
    depth: f64,
    waists: SVector<f64, D>,
    /// `ln2 / w_i²` (1/m²), precomputed.
    k: [f64; D],
}

/// The paper's 2D well.
pub type Well2 = GaussianWell<2>;
/// A 3D well with an axial waist.
pub type Well3 = GaussianWell<3>;

const WAIST_FIELDS: [&str; 3] = ["waist_x [m]", "waist_y [m]", "waist_z [m]"];

impl<const D: usize> GaussianWell<D> {
    /// A well of depth `depth` (J, > 0) and half-depth radii `waists` (m, > 0 each).
    pub fn new(depth: f64, waists: [f64; D]) -> Result<Self> {
        let depth = positive("depth [J]", depth)?;
        let mut w = SVector::<f64, D>::zeros();
        for (i, &wi) in waists.iter().enumerate() {
            w[i] = positive(WAIST_FIELDS[i.min(2)], wi)?;
        }
        let k = std::array::from_fn(|i| LN2 / (w[i] * w[i]));
        Ok(Self {
            depth,
            waists: w,
            k,
        })
    }

    /// Depth `P0` (J).
    pub fn depth(&self) -> f64 {
        self.depth
    }

    /// Half-depth radii (m).
    pub fn waists(&self) -> SVector<f64, D> {
        self.waists
    }

    /// Potential energy at `r` (J); exactly 0 far outside the well.
    pub fn potential(&self, r: &SVector<f64, D>) -> f64 {
        -self.depth * self.envelope(r)
    }

    /// `q = ln2 Σ r_i²/w_i²` (dimensionless), the Gaussian's exponent at `r` (m).
    #[inline(always)]
    pub fn exponent(&self, r: &SVector<f64, D>) -> f64 {
        self.k
            .iter()
            .zip(&r.data.0[0])
            .map(|(k, x)| k * x * x)
            .sum()
    }

    /// `exp(-ln2 Σ r_i²/w_i²)`, in [0, 1].
    #[inline(always)]
    fn envelope(&self, r: &SVector<f64, D>) -> f64 {
        crate::fastexp::exp(-self.exponent(r))
    }

    /// Restoring force `-∇P` at `r` (N). Exactly zero (never NaN) where the
    /// Gaussian underflows, however far away `r` is.
    #[inline(always)]
    pub fn force(&self, r: &SVector<f64, D>) -> SVector<f64, D> {
        let e = self.envelope(r);
        // e == 0 far away: return exact zeros (r·0 could be inf·0 = NaN).
        if e == 0.0 {
            return SVector::zeros();
        }
        let s = -2.0 * self.depth * e;
        let ra = &r.data.0[0];
        let mut f = [0.0; D];
        for ((fi, k), x) in f.iter_mut().zip(&self.k).zip(ra) {
            *fi = s * k * x;
        }
        SVector::from(f)
    }

    /// Force (N) and its Jacobian `∂F_i/∂r_j` (N/m) at `r`.
    #[inline]
    pub fn force_and_gradient(&self, r: &SVector<f64, D>) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
        let e = self.envelope(r);
        if e == 0.0 {
            return (SVector::zeros(), SMatrix::zeros());
        }
        let s = -2.0 * self.depth * e;
        let kr = SVector::<f64, D>::from(self.k).component_mul(r);
        let f = kr * s;
        // ∂F_i/∂r_j = s (k_i δ_ij − 2 k_i r_i k_j r_j)
        let mut h = kr * kr.transpose() * (-2.0 * s);
        for i in 0..D {
            h[(i, i)] += s * self.k[i];
        }
        (f, h)
    }

    /// Small-oscillation stiffness per axis `κ_i = 2 ln2 P0 / w_i²` (N/m).
    pub fn stiffness(&self) -> SVector<f64, D> {
        SVector::<f64, D>::from(self.k) * (2.0 * self.depth)
    }
}
