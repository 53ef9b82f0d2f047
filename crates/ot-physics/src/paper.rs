//! The optical-tweezers paper's constants and its test problem.
//!
//! Lee, Lyons & LeBrun: a = 600 nm, b = 300 nm, P0 = 1e-6 nJ, m = 1e-12 g,
//! Δt = 1 µs, v0 = 0 or (100, 100) nm/µs.

use crate::error::Result;
use crate::model::TrapModel;
use nalgebra::Vector2;

/// Well depth P0 = 1e-6 nJ (J).
pub const DEPTH: f64 = 1e-15;
/// Beam waists (a, b) = (600, 300) nm (m).
pub const WAISTS: [f64; 2] = [600e-9, 300e-9];
/// Particle mass m = 1e-12 g (kg).
pub const MASS: f64 = 1e-15;
/// Haptic tick Δt = 1 µs (s).
pub const DT: f64 = 1e-6;
/// The paper's moving start, v0 = (100, 100) nm/µs (m/s).
pub const V0_MOVING: [f64; 2] = [0.1, 0.1];
/// Half-width of the square of start offsets in the reports, 1.5 µm (m).
pub const OFFSET_SPAN: f64 = 1.5e-6;

/// The paper's conservative model (inertia on, no drag, no noise).
pub fn model() -> Result<TrapModel<2>> {
    TrapModel::builder(DEPTH, WAISTS).mass(MASS).build()
}

/// An `n × n` grid of trap offsets (m) spanning ±[`OFFSET_SPAN`] on both axes.
pub fn offsets(n: usize) -> Vec<Vector2<f64>> {
    let n = n.max(2);
    let step = 2.0 * OFFSET_SPAN / (n - 1) as f64;
    let mut out = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            out.push(Vector2::new(
                -OFFSET_SPAN + i as f64 * step,
                -OFFSET_SPAN + j as f64 * step,
            ));
        }
    }
    out
}
