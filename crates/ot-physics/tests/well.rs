//! The Gaussian well: force is minus the gradient, exact zeros, validation.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::{Vector2, Vector3};
use ot_physics::{GaussianWell, PhysicsError, TrapModel, Well2, Well3};
use proptest::prelude::*;

#[test]
fn force_is_minus_gradient_and_jacobian_matches_finite_differences() {
    let w = Well3::new(DEPTH, [600e-9, 300e-9, 900e-9]).unwrap();
    let r = Vector3::new(210e-9, -95e-9, 400e-9);
    let h = 1e-13;
    let (f, jac) = w.force_and_gradient(&r);
    assert_eq!(f, w.force(&r));
    for i in 0..3 {
        let mut rp = r;
        let mut rm = r;
        rp[i] += h;
        rm[i] -= h;
        let grad = (w.potential(&rp) - w.potential(&rm)) / (2.0 * h);
        assert!((f[i] + grad).abs() < 1e-7 * f.norm(), "axis {i}");
        let col = (w.force(&rp) - w.force(&rm)) / (2.0 * h);
        for j in 0..3 {
            assert!(
                (jac[(j, i)] - col[j]).abs() < 1e-6 * jac.norm(),
                "J[{j},{i}]"
            );
        }
    }
    // the Jacobian of a gradient field is symmetric
    assert!((jac - jac.transpose()).norm() < 1e-15 * jac.norm());
}

#[test]
fn half_depth_at_each_waist_and_small_oscillation_stiffness() {
    let w = Well2::new(DEPTH, WAISTS).unwrap();
    assert!((w.potential(&Vector2::new(600e-9, 0.0)) + 0.5 * DEPTH).abs() < 1e-15 * DEPTH);
    assert!((w.potential(&Vector2::new(0.0, 300e-9)) + 0.5 * DEPTH).abs() < 1e-15 * DEPTH);
    let k = w.stiffness();
    let ln2 = std::f64::consts::LN_2;
    assert!((k.x - 2.0 * ln2 * DEPTH / 600e-9f64.powi(2)).abs() < 1e-15 * k.x);
    // Hooke's law near the centre: F = -κ r to second order
    let r = Vector2::new(1e-12, -1e-12);
    let f = w.force(&r);
    assert!((f.x + k.x * r.x).abs() < 1e-9 * k.x * 1e-12);
}

#[test]
fn force_is_exactly_zero_far_outside_and_at_the_centre() {
    let w = Well2::new(DEPTH, WAISTS).unwrap();
    for r in [
        Vector2::new(30e-6, 0.0),
        Vector2::new(1.0, -1.0),
        Vector2::new(1e200, 1e200),
        Vector2::new(f64::MAX, -f64::MAX),
    ] {
        let f = w.force(&r);
        assert_eq!(f, Vector2::zeros(), "r = {r:?}");
        let (f2, j) = w.force_and_gradient(&r);
        assert_eq!(f2, Vector2::zeros());
        assert!(j.iter().all(|x| *x == 0.0));
        assert_eq!(w.potential(&r), -0.0);
    }
    assert_eq!(w.force(&Vector2::zeros()), Vector2::zeros());
}

#[test]
fn bad_parameters_give_typed_errors_naming_the_field() {
    let cases: [(f64, &str); 4] = [
        (0.0, "0"),
        (-1.0, "-1"),
        (f64::NAN, "NaN"),
        (f64::INFINITY, "inf"),
    ];
    for (v, shown) in cases {
        let e = Well2::new(v, WAISTS).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("depth [J] = {shown} is out of range: allowed finite and > 0")
        );
        let e = Well2::new(DEPTH, [600e-9, v]).unwrap_err();
        assert!(matches!(
            e,
            PhysicsError::Value(ref v) if v.field() == "waist_y [m]"
        ));
        let e = TrapModel::builder(DEPTH, WAISTS)
            .mass(v)
            .build()
            .unwrap_err();
        assert!(matches!(
            e,
            PhysicsError::Value(ref v) if v.field() == "mass [kg]"
        ));
        let e = TrapModel::builder(DEPTH, WAISTS)
            .mass(MASS)
            .stokes_drag(v, 1e-3)
            .build()
            .unwrap_err();
        assert!(matches!(
            e,
            PhysicsError::Value(ref v) if v.field() == "radius [m]"
        ));
        let e = TrapModel::builder(DEPTH, WAISTS)
            .mass(MASS)
            .stokes_drag(0.5e-6, v)
            .build()
            .unwrap_err();
        assert!(matches!(
            e,
            PhysicsError::Value(ref v) if v.field() == "viscosity [Pa s]"
        ));
        let e = TrapModel::builder(DEPTH, WAISTS)
            .mass(MASS)
            .stokes_drag(0.5e-6, 1e-3)
            .temperature(Some(v))
            .build()
            .unwrap_err();
        assert!(matches!(
            e,
            PhysicsError::Value(ref v) if v.field() == "temperature [K]"
        ));
    }
    let e = Well3::new(DEPTH, [1e-6, 1e-6, -2e-6]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "waist_z [m] = -2e-6 is out of range: allowed finite and > 0"
    );
    let e = TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .external_force([f64::NAN, 0.0])
        .build()
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "external_force [N] = NaN is out of range: allowed finite"
    );
}

#[test]
fn effects_need_their_parameters() {
    let e = TrapModel::builder(DEPTH, WAISTS).build().unwrap_err();
    assert!(matches!(
        e,
        PhysicsError::Missing {
            needed_by: "any dynamics",
            ..
        }
    ));
    let e = TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .temperature(Some(293.15))
        .build()
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "radius [m] and viscosity [Pa s] is required by thermal noise (fluctuation-dissipation needs drag)"
    );
    let e = TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .radius(Some(0.5e-6))
        .build()
        .unwrap_err();
    assert!(matches!(
        e,
        PhysicsError::Missing {
            field: "viscosity [Pa s]",
            ..
        }
    ));
    // Stokes: γ = 6πηr
    let m = TrapModel::builder(DEPTH, WAISTS)
        .stokes_drag(0.5e-6, 1e-3)
        .build()
        .unwrap();
    let g = m.drag.unwrap();
    assert!((g - 6.0 * std::f64::consts::PI * 1e-3 * 0.5e-6).abs() < 1e-24);
    assert!(m.mass.is_none() && m.kt.is_none());
}

proptest! {
    /// The force is finite and restoring (F·r ≤ 0) everywhere, and never
    /// larger than its analytic maximum along the stiffer axis.
    #[test]
    fn force_is_finite_and_restoring(x in -1e3f64..1e3, y in -1e3f64..1e3, scale in -12i32..3) {
        let w: GaussianWell<2> = Well2::new(DEPTH, WAISTS).unwrap();
        let r = Vector2::new(x, y) * 10f64.powi(scale) * 1e-6;
        let f = w.force(&r);
        prop_assert!(f.iter().all(|c| c.is_finite()));
        prop_assert!(f.dot(&r) <= 0.0);
        // |F_i| ≤ 2 ln2 P0/w_i · max_u u e^{-ln2 u²} = P0 sqrt(2 ln2 / e) / w_i
        let fmax = DEPTH * (2.0 * std::f64::consts::LN_2 / std::f64::consts::E).sqrt();
        prop_assert!(f.x.abs() <= fmax / WAISTS[0] * (1.0 + 1e-12));
        prop_assert!(f.y.abs() <= fmax / WAISTS[1] * (1.0 + 1e-12));
    }
}
