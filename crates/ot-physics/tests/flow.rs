//! The flow map of a tick: Jacobians from the variational equations agree
//! with finite differences; batches agree with single calls.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::{Vector2, Vector3};
use ot_physics::{Method, PhysicsError, Propagator, TrapModel};
use proptest::prelude::*;

fn check_jacobian(p: &Propagator<2>, o: Vector2<f64>, v0: Vector2<f64>, tol: f64) {
    let f = p.flow_jacobian(&o, &v0).unwrap();
    let (d, _, _) = p.flow(&o, &v0).unwrap();
    assert!(
        (f.displacement - d).norm() < 1e-6 * NM,
        "flow and flow_jacobian agree"
    );
    let ho = 1e-3 * NM;
    let hv = 1e-6;
    for j in 0..2 {
        let e = Vector2::from_fn(|i, _| if i == j { 1.0 } else { 0.0 });
        let fd_o = (p.flow(&(o + e * ho), &v0).unwrap().0 - p.flow(&(o - e * ho), &v0).unwrap().0)
            / (2.0 * ho);
        let fd_v = (p.flow(&o, &(v0 + e * hv)).unwrap().0 - p.flow(&o, &(v0 - e * hv)).unwrap().0)
            / (2.0 * hv);
        for i in 0..2 {
            assert!(
                (f.d_offset[(i, j)] - fd_o[i]).abs() < tol,
                "{:?} ∂d{i}/∂o{j}: {} vs {}",
                p.method(),
                f.d_offset[(i, j)],
                fd_o[i]
            );
            assert!(
                (f.d_velocity[(i, j)] - fd_v[i]).abs() < tol * DT,
                "∂d{i}/∂v{j}"
            );
        }
    }
}

#[test]
fn jacobian_matches_central_differences_for_every_method() {
    let model = paper_model();
    for (m, tol) in [
        (Method::PaperRk4, 1e-6),
        (Method::Rk4 { substeps: 16 }, 1e-6),
        (Method::Dopri5 { rtol: 1e-10 }, 1e-5),
        (Method::Adaptive { rtol: 1e-10 }, 1e-5),
    ] {
        let p = Propagator::new(model, m, DT).unwrap();
        for (o, v) in [
            (Vector2::new(-100.0, -50.0), Vector2::zeros()),
            (Vector2::new(420.0, -310.0), Vector2::new(0.1, 0.1)),
            (Vector2::new(-900.0, 150.0), Vector2::new(-0.08, 0.03)),
        ] {
            check_jacobian(&p, o * NM, v, tol);
        }
    }
}

#[test]
fn fixed_step_jacobian_is_the_exact_derivative_of_the_discrete_map() {
    // RK4 commutes with linearisation: the variational RK4 step is the
    // derivative of the RK4 step, to rounding (checked with a tight FD).
    let p = Propagator::new(paper_model(), Method::Rk4 { substeps: 8 }, DT).unwrap();
    check_jacobian(
        &p,
        Vector2::new(250.0, 130.0) * NM,
        Vector2::new(0.03, -0.02),
        1e-7,
    );
}

#[test]
fn overdamped_flow_relaxes_exponentially_and_ignores_velocity() {
    let model = TrapModel::builder(DEPTH, WAISTS)
        .stokes_drag(0.5e-6, 1e-3)
        .build()
        .unwrap();
    let rate = model.well.stiffness().x / model.drag.unwrap(); // κ/γ (1/s)
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    // 2 nm from the centre the well is harmonic to ~1e-5.
    let o = Vector2::new(2e-9, 0.0);
    let f = p.flow_jacobian(&o, &Vector2::new(5.0, 5.0)).unwrap();
    assert_eq!(f.d_velocity, nalgebra::Matrix2::zeros());
    let expected = 2e-9 * (1.0 - (-rate * DT).exp());
    assert!((f.displacement.x - expected).abs() < 1e-4 * expected);
    assert_eq!(f.displacement.y, 0.0);
    assert!((f.d_offset[(0, 0)] - (1.0 - (-rate * DT).exp())).abs() < 1e-4);
}

#[test]
fn three_d_jacobian_is_symmetric_about_the_axis() {
    let model = TrapModel::builder(DEPTH, [600e-9, 300e-9, 1500e-9])
        .mass(MASS)
        .build()
        .unwrap();
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let a = p
        .flow_jacobian(&Vector3::new(100e-9, 50e-9, 200e-9), &Vector3::zeros())
        .unwrap();
    let b = p
        .flow_jacobian(&Vector3::new(100e-9, 50e-9, -200e-9), &Vector3::zeros())
        .unwrap();
    // mirror z → −z: displacement z flips, x/y unchanged
    assert!((a.displacement.x - b.displacement.x).abs() < 1e-6 * NM);
    assert!((a.displacement.z + b.displacement.z).abs() < 1e-6 * NM);
    assert!((a.d_offset[(0, 2)] + b.d_offset[(0, 2)]).abs() < 1e-6);
}

#[test]
fn lockstep_batches_of_fixed_step_methods_are_bit_identical_to_single_calls() {
    for m in [
        Method::PaperRk4,
        Method::Rk4 { substeps: 8 },
        Method::Rk8 { substeps: 4 },
    ] {
        let p = Propagator::new(paper_model(), m, DT).unwrap();
        // 11 offsets: two lockstep groups of four and a remainder of three
        let offsets: Vec<_> = (0..11)
            .map(|i| Vector2::new(f64::from(i) * 97e-9 - 500e-9, 40e-9 * f64::from(i % 3)))
            .collect();
        let vels: Vec<_> = (0..11)
            .map(|i| Vector2::new(0.01 * f64::from(i), -0.02))
            .collect();
        let mut out = vec![Vector2::zeros(); 11];
        p.flow_batch(&offsets, &vels, &mut out).unwrap();
        for ((o, v), d) in offsets.iter().zip(&vels).zip(&out) {
            let single = p.flow(o, v).unwrap().0;
            assert_eq!(d.x.to_bits(), single.x.to_bits(), "{m:?}");
            assert_eq!(d.y.to_bits(), single.y.to_bits(), "{m:?}");
        }
        let mut bad = offsets.clone();
        bad[5].x = f64::NAN;
        let e = p.flow_batch(&bad, &vels, &mut out).unwrap_err();
        assert_eq!(
            e.to_string(),
            "offset [m] = NaN is out of range: allowed finite"
        );
    }
}

#[test]
fn batch_matches_single_calls_and_checks_lengths() {
    let p = Propagator::new(paper_model(), Method::default(), DT).unwrap();
    let offsets: Vec<_> = (0..50)
        .map(|i| Vector2::new(f64::from(i) * 30e-9 - 750e-9, 100e-9))
        .collect();
    let v = [Vector2::new(0.1, 0.1)];
    let mut out = vec![Vector2::zeros(); 50];
    let evals = p.flow_batch(&offsets, &v, &mut out).unwrap();
    assert!(evals > 50 * 12);
    for (o, d) in offsets.iter().zip(&out) {
        assert_eq!(
            *d,
            p.flow(o, &v[0]).unwrap().0,
            "bit-identical to single calls"
        );
    }
    let e = p
        .flow_batch(&offsets, &[Vector2::zeros(); 3], &mut out)
        .unwrap_err();
    assert_eq!(e.to_string(), "velocities has length 3: expected 1 or 50");
    let e = p.flow_batch(&offsets, &v, &mut out[..10]).unwrap_err();
    assert!(matches!(
        e,
        PhysicsError::Length {
            field: "out",
            got: 10,
            ..
        }
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// For any offset and velocity the displacement is finite, and the
    /// conservative flow never gains energy beyond the tolerance.
    #[test]
    fn flow_is_finite_and_conserves_energy(ox in -3e-6f64..3e-6, oy in -3e-6f64..3e-6,
                                           vx in -0.3f64..0.3, vy in -0.3f64..0.3) {
        let model = paper_model();
        let p = Propagator::new(model, Method::default(), DT).unwrap();
        let o = Vector2::new(ox, oy);
        let v0 = Vector2::new(vx, vy);
        let (d, v, _) = p.flow(&o, &v0).unwrap();
        prop_assert!(d.iter().chain(v.iter()).all(|x| x.is_finite()));
        let e = |r: &Vector2<f64>, v: &Vector2<f64>| 0.5 * MASS * v.norm_squared() + model.well.potential(r);
        let e0 = e(&-o, &v0);
        let e1 = e(&(d - o), &v);
        // the default tolerance is rtol 1e-6 on the phase: energy to ~1e-6 P0
        prop_assert!((e1 - e0).abs() < 1e-5 * DEPTH, "ΔE = {:e} J", e1 - e0);
    }
}

#[test]
fn offset_only_jacobian_matches_the_full_variational_flow() {
    // Same discrete map: displacement, velocity and ∂d/∂offset agree with
    // flow_jacobian to rounding, at a quarter fewer matrix products.
    let model = paper_model();
    for m in [
        Method::PaperRk4,
        Method::Rk4 { substeps: 3 },
        Method::Rk8 { substeps: 2 },
        Method::Adaptive { rtol: 1e-10 },
    ] {
        let p = Propagator::new(model, m, DT).unwrap();
        for (o, v) in [
            (Vector2::new(-100.0, -50.0), Vector2::zeros()),
            (Vector2::new(420.0, -310.0), Vector2::new(0.1, 0.1)),
        ] {
            let o = o * NM;
            let full = p.flow_jacobian(&o, &v).unwrap();
            let part = p.flow_offset_jacobian(&o, &v).unwrap();
            assert!((full.displacement - part.displacement).norm() < 1e-6 * NM);
            assert!((full.velocity - part.velocity).norm() < 1e-9);
            assert!(
                (full.d_offset - part.d_offset).amax() < 1e-9,
                "{m:?}: {} vs {}",
                full.d_offset,
                part.d_offset
            );
            if !matches!(m, Method::Adaptive { .. }) {
                assert_eq!(full.evals, part.evals);
            }
        }
    }
}
