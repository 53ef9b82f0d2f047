//! Shared test fixtures: the paper's constants.
#![allow(dead_code)]

use nalgebra::Vector2;
use ot_physics::{Method, Propagator, TrapModel};

/// The paper's trap: P0 = 1e-15 J, a = 600 nm, b = 300 nm, m = 1e-15 kg.
pub fn paper_model(waists: [f64; 2]) -> TrapModel<2> {
    TrapModel::builder(1e-15, waists)
        .mass(1e-15)
        .build()
        .expect("valid model")
}

/// RK4 with `n` substeps over `dt` (s).
pub fn prop(waists: [f64; 2], n: u32, dt: f64) -> Propagator<2> {
    Propagator::new(paper_model(waists), Method::Rk4 { substeps: n }, dt).expect("valid propagator")
}

/// The paper's tick: Δt = 1 µs, RK4 × 8 (within 0.21 nm of converged).
pub fn paper() -> Propagator<2> {
    prop([600e-9, 300e-9], 8, 1e-6)
}

pub fn v(x: f64, y: f64) -> Vector2<f64> {
    Vector2::new(x, y)
}

pub const NM: f64 = 1e-9;

/// `x` rounds to `printed` at `decimals` decimals (two-sided): a figure held to the digit it
/// is printed with.
pub fn assert_printed(what: &str, x: f64, printed: f64, decimals: i32) {
    let half = 0.5 * 10f64.powi(-decimals);
    assert!(
        (x - printed).abs() <= half + 1e-12,
        "{what}: {x} does not print as {printed:.*}",
        decimals as usize
    );
}
