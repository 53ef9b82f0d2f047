//! Symplectic splitting methods for the conservative case (inertia on, no
//! drag, no noise): velocity Verlet and its Yoshida compositions.

use crate::model::TrapModel;
use crate::state::Phase;
use nalgebra::SVector;

/// Yoshida's 4th-order triple-jump weights `(w1, w0, w1)`.
fn yoshida4_weights() -> [f64; 3] {
    let c = 2f64.powf(1.0 / 3.0);
    let w1 = 1.0 / (2.0 - c);
    [w1, -c * w1, w1]
}

/// 6th-order weights: the 4th-order method composed by a second triple jump.
fn yoshida6_weights() -> [f64; 9] {
    let c = 2f64.powf(1.0 / 5.0);
    let z1 = 1.0 / (2.0 - c);
    let z0 = -c * z1;
    let w = yoshida4_weights();
    let mut out = [0.0; 9];
    for (j, z) in [z1, z0, z1].iter().enumerate() {
        for (i, wi) in w.iter().enumerate() {
            out[3 * j + i] = z * wi;
        }
    }
    out
}

/// Which composition to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Composition {
    /// Störmer–Verlet, order 2, one force evaluation per substep.
    Verlet,
    /// Yoshida 4th order, three force evaluations per substep.
    Yoshida4,
    /// Yoshida 6th order, nine force evaluations per substep.
    Yoshida6,
}

impl Composition {
    /// Force evaluations per substep (after the first, reused across substeps).
    pub fn stages(self) -> u32 {
        match self {
            Self::Verlet => 1,
            Self::Yoshida4 => 3,
            Self::Yoshida6 => 9,
        }
    }
}

#[inline(always)]
fn accel<const D: usize>(m: &TrapModel<D>, inv_mass: f64, r: &SVector<f64, D>) -> SVector<f64, D> {
    (m.well.force(r) + m.external_force) * inv_mass
}

/// `n` substeps of the composition over `t` (s). The model must be
/// conservative (checked by the caller). Returns the end phase and the
/// number of force evaluations.
pub fn symplectic<const D: usize>(
    model: &TrapModel<D>,
    y0: &Phase<D>,
    t: f64,
    n: u32,
    comp: Composition,
) -> (Phase<D>, u64) {
    let inv_mass = 1.0 / model.mass.unwrap_or(f64::INFINITY);
    let weights: &[f64] = match comp {
        Composition::Verlet => &[1.0],
        Composition::Yoshida4 => &yoshida4_weights(),
        Composition::Yoshida6 => &yoshida6_weights(),
    };
    let h = t / f64::from(n);
    let mut r = y0.r;
    let mut v = y0.v;
    let mut a = accel(model, inv_mass, &r);
    let mut evals = 1u64;
    for _ in 0..n {
        for w in weights {
            let hw = h * w;
            v.axpy(0.5 * hw, &a, 1.0);
            r.axpy(hw, &v, 1.0);
            a = accel(model, inv_mass, &r);
            v.axpy(0.5 * hw, &a, 1.0);
            evals += 1;
        }
    }
    (Phase { r, v }, evals)
}
