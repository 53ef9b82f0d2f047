//! Shared constants of the paper problem.
#![allow(dead_code)]

use ot_physics::TrapModel;

/// P0 = 1e-6 nJ (J).
pub const DEPTH: f64 = 1e-15;
/// Beam waists a, b (m).
pub const WAISTS: [f64; 2] = [600e-9, 300e-9];
/// m = 1e-12 g (kg).
pub const MASS: f64 = 1e-15;
/// Δt = 1 µs (s).
pub const DT: f64 = 1e-6;
/// 1 nm (m).
pub const NM: f64 = 1e-9;

/// The paper's conservative 2D model.
pub fn paper_model() -> TrapModel<2> {
    TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .build()
        .expect("paper constants are valid")
}

/// Small-oscillation angular frequency along x (rad/s).
pub fn omega_x() -> f64 {
    (2.0 * std::f64::consts::LN_2 * DEPTH / (MASS * WAISTS[0] * WAISTS[0])).sqrt()
}
