//! Thermal mode, validated in the harmonic limit: a 1 µm polystyrene bead
//! in water at 20 °C, κ = 0.1 pN/nm, sampled at 78 125 Hz for 10 s.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

use nalgebra::Vector2;
use ot_physics::analysis::{autocorrelation, block_periodogram, fit_corner_aliased, mean_variance};
use ot_physics::langevin::{Scheme, ThermalRun, simulate};
use ot_physics::{BOLTZMANN, Phase, PhysicsError, TrapModel};

const KAPPA: f64 = 1e-4; // N/m
const RADIUS: f64 = 0.5e-6; // m
const ETA: f64 = 1.002e-3; // Pa s, water at 20 °C
const TEMP: f64 = 293.15; // K
const WAIST: f64 = 1e-6; // m: harmonic to ~3e-5 at σ ≈ 6.4 nm
const FS: f64 = 78_125.0; // Hz

fn bead_mass() -> f64 {
    1050.0 * 4.0 / 3.0 * std::f64::consts::PI * RADIUS.powi(3)
}

fn bead(mass: Option<f64>) -> TrapModel<2> {
    let depth = KAPPA * WAIST * WAIST / (2.0 * std::f64::consts::LN_2);
    TrapModel::builder(depth, [WAIST, WAIST])
        .maybe_mass(mass)
        .stokes_drag(RADIUS, ETA)
        .temperature(Some(TEMP))
        .build()
        .expect("bead parameters are valid")
}

fn run(
    model: &TrapModel<2>,
    seconds: f64,
    scheme: Scheme,
    substeps: u32,
    seed: u64,
) -> Vec<Vector2<f64>> {
    let start = Phase {
        r: Vector2::zeros(),
        v: Vector2::zeros(),
    };
    simulate(
        model,
        start,
        &ThermalRun {
            duration: seconds,
            sample_rate: FS,
            substeps,
            scheme,
            seed,
        },
    )
    .expect("valid run")
}

#[test]
fn harmonic_bead_variance_spectrum_and_autocorrelation() {
    let model = bead(Some(bead_mass()));
    let gamma = model.drag.unwrap();
    let kt = BOLTZMANN * TEMP;
    // m/γ ≈ 58 ns ≪ 12.8 µs: Auto picks the overdamped exact-OU scheme.
    let xs = run(&model, 10.0, Scheme::Auto, 1, 20261121);
    assert_eq!(xs.len(), 781_250);
    let x: Vec<f64> = xs.iter().map(|p| p.x).collect();
    let y: Vec<f64> = xs.iter().map(|p| p.y).collect();
    for (axis, s) in [("x", &x), ("y", &y)] {
        let (_, var) = mean_variance(s);
        let rel = var / (kt / KAPPA) - 1.0;
        assert!(
            rel.abs() < 0.01,
            "{axis}: variance off by {:.2}%",
            100.0 * rel
        );
        let fc_true = KAPPA / (2.0 * std::f64::consts::PI * gamma);
        let (f, p) = block_periodogram(s, FS, 4096);
        let fc = fit_corner_aliased(&f, &p, FS).unwrap();
        assert!(
            (fc / fc_true - 1.0).abs() < 0.02,
            "{axis}: fc {fc} Hz vs {fc_true} Hz"
        );
        let ac = autocorrelation(s, 40);
        for (k, c) in ac.iter().enumerate() {
            let expected = (-KAPPA * k as f64 / (FS * gamma)).exp();
            assert!(
                (c - expected).abs() < 0.02,
                "{axis}: lag {k}: {c} vs {expected}"
            );
        }
    }
}

#[test]
fn baoab_samples_kt_over_kappa_from_underdamped_to_overdamped() {
    // BAOAB's position marginal in a harmonic well is exact for any friction;
    // m/γ from 100 h to h/1000, with h·sqrt(κ/m) = 0.5 for stability.
    let kt = BOLTZMANN * TEMP;
    let gamma = 6.0 * std::f64::consts::PI * ETA * RADIUS;
    for ratio in [100.0, 1.0, 1e-3] {
        // m = ratio·h·γ and κh²/m = 0.25  ⇒  h = 0.25·ratio·γ/κ (≤ 1/fs)
        let h = (0.25 * ratio * gamma / KAPPA).min(1.0 / FS);
        let m = ratio * h * gamma;
        let model = bead(Some(m));
        let substeps = ((1.0 / FS) / h).ceil().max(1.0) as u32;
        let xs = run(&model, 2.0, Scheme::Baoab, substeps, 7);
        let (_, var) = mean_variance(&xs.iter().map(|p| p.x).collect::<Vec<_>>());
        let rel = var / (kt / KAPPA) - 1.0;
        assert!(
            rel.abs() < 0.03,
            "m/γ = {ratio} h: variance off by {:.2}%",
            100.0 * rel
        );
    }
}

#[test]
fn same_seed_same_bits_other_seed_other_path() {
    let model = bead(None);
    let a = run(&model, 0.01, Scheme::Overdamped, 2, 42);
    let b = run(&model, 0.01, Scheme::Overdamped, 2, 42);
    let c = run(&model, 0.01, Scheme::Overdamped, 2, 43);
    assert!(
        a.iter()
            .zip(&b)
            .all(|(p, q)| p.x.to_bits() == q.x.to_bits() && p.y.to_bits() == q.y.to_bits())
    );
    assert_ne!(a, c);
}

#[test]
fn thermal_run_errors_are_typed() {
    let model = bead(None);
    let start = Phase {
        r: Vector2::zeros(),
        v: Vector2::zeros(),
    };
    let mut cfg = ThermalRun {
        duration: 1.0,
        sample_rate: 0.0,
        substeps: 1,
        scheme: Scheme::Auto,
        seed: 1,
    };
    let e = simulate(&model, start, &cfg).unwrap_err();
    assert_eq!(
        e.to_string(),
        "sample_rate [Hz] = 0 is out of range: allowed finite and > 0"
    );
    cfg.sample_rate = FS;
    cfg.scheme = Scheme::Baoab;
    let e = simulate(&model, start, &cfg).unwrap_err();
    assert!(matches!(
        e,
        PhysicsError::Missing {
            field: "mass [kg]",
            ..
        }
    ));
    cfg.scheme = Scheme::Auto;
    cfg.substeps = 0;
    assert!(matches!(
        simulate(&model, start, &cfg).unwrap_err(),
        PhysicsError::Value(ref v) if v.field() == "substeps"
    ));
    let cold = TrapModel::builder(1e-15, [1e-6, 1e-6])
        .stokes_drag(RADIUS, ETA)
        .build()
        .unwrap();
    cfg.substeps = 1;
    assert!(matches!(
        simulate(&cold, start, &cfg).unwrap_err(),
        PhysicsError::Missing { .. }
    ));
}
