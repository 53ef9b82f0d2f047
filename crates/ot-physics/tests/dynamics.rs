//! Physics of the integrators: analytic limits, conservation, reversibility,
//! convergence orders and the hard cases.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::{Vector2, Vector3};
use ot_physics::dynamics::Dynamics;
use ot_physics::integrate::{StepControl, dop853, dopri5, rk4, symplectic};
use ot_physics::state::Tolerance;
use ot_physics::{Composition, Method, Phase, PhysicsError, Propagator, TrapModel};

fn reference(model: TrapModel<2>, dt: f64) -> Propagator<2> {
    Propagator::new(model, Method::Adaptive { rtol: 1e-13 }, dt).expect("valid reference")
}

fn energy(model: &TrapModel<2>, y: &Phase<2>) -> f64 {
    0.5 * model.mass.expect("inertia on") * y.v.norm_squared() + model.well.potential(&y.r)
}

#[test]
fn paper_example_matches_the_issue_and_the_paper_step_goes_the_wrong_way() {
    let model = paper_model();
    let offset = Vector2::new(-100.0 * NM, -50.0 * NM);
    let (d, _, _) = reference(model, DT)
        .flow(&offset, &Vector2::zeros())
        .unwrap();
    assert!((d.x / NM + 136.1).abs() < 0.05, "{}", d.x / NM);
    assert!((d.y / NM + 86.7).abs() < 0.05, "{}", d.y / NM);
    let paper = Propagator::new(model, Method::PaperRk4, DT).unwrap();
    let (p, _, evals) = paper.flow(&offset, &Vector2::zeros()).unwrap();
    assert_eq!(evals, 4);
    assert!((p.x / NM + 127.6).abs() < 0.05 && (p.y / NM - 54.6).abs() < 0.05);
}

#[test]
fn default_method_reaches_a_hundredth_of_a_nanometre_on_the_paper_problem() {
    let model = paper_model();
    let reference = reference(model, DT);
    let default = Propagator::new(model, Method::default(), DT).unwrap();
    let mut worst: f64 = 0.0;
    for v0 in [Vector2::zeros(), Vector2::new(0.1, 0.1)] {
        for i in -6..=6 {
            for j in -6..=6 {
                let o = Vector2::new(i as f64 * 250.0 * NM, j as f64 * 250.0 * NM);
                let (a, _, _) = default.flow(&o, &v0).unwrap();
                let (b, _, _) = reference.flow(&o, &v0).unwrap();
                worst = worst.max((a - b).norm());
            }
        }
    }
    assert!(worst < 0.01 * NM, "worst error {} nm", worst / NM);
}

#[test]
fn small_oscillation_frequency_is_sqrt_2ln2_p0_over_m_a2() {
    // Tiny amplitude along x: x(t) = x0 cos(ωt). Anharmonic shift ~ (x0/a)².
    let model = paper_model();
    let w = omega_x();
    let x0 = 1e-3 * 600e-9;
    let period = 2.0 * std::f64::consts::PI / w;
    let p = reference(model, period / 4.0);
    let y0 = Phase {
        r: Vector2::new(x0, 0.0),
        v: Vector2::zeros(),
    };
    // After a quarter period the particle crosses the centre...
    let q = p.phase(&y0).unwrap().end;
    assert!(q.r.x.abs() < 1e-5 * x0, "x(T/4) = {}", q.r.x / x0);
    assert!((q.v.x + w * x0).abs() < 1e-5 * w * x0);
    // ...and after a full period it is back.
    let full = reference(model, period).phase(&y0).unwrap().end;
    assert!((full.r.x - x0).abs() < 1e-5 * x0);
}

#[test]
fn symplectic_energy_error_stays_bounded_over_a_million_steps() {
    let model = paper_model();
    let y0 = Phase {
        r: Vector2::new(400.0 * NM, -150.0 * NM),
        v: Vector2::new(0.05, 0.02),
    };
    let e0 = energy(&model, &y0);
    let h = 0.05 / (omega_x() * 2.0); // ω_y h = 0.05
    let mut y = y0;
    let (mut early, mut late): (f64, f64) = (0.0, 0.0);
    for k in 0..1_000_000u32 {
        y = symplectic(&model, &y, h, 1, Composition::Verlet).0;
        let err = ((energy(&model, &y) - e0) / e0).abs();
        if k < 100_000 {
            early = early.max(err);
        } else if k >= 900_000 {
            late = late.max(err);
        }
    }
    // bounded oscillation, no secular drift: the last tenth is no worse
    // than the first tenth, and both are small (h² error).
    assert!(early < 1e-3, "early {early}");
    assert!(late < 1.5 * early, "early {early}, late {late}");
    // RK4 at a comparable cost does drift (it is not symplectic).
    let sys = Dynamics::new(&model);
    let mut z = y0;
    for _ in 0..250_000 {
        z = rk4(&sys, &z, 4.0 * h, 1);
    }
    let rk_err = ((energy(&model, &z) - e0) / e0).abs();
    assert!(rk_err > late, "RK4 drift {rk_err} vs Verlet {late}");
}

#[test]
fn dynamics_are_time_reversible() {
    let model = paper_model();
    let y0 = Phase {
        r: Vector2::new(250.0 * NM, 120.0 * NM),
        v: Vector2::new(-0.03, 0.08),
    };
    for (method, tol) in [
        (
            Method::Symplectic {
                substeps: 64,
                composition: Composition::Verlet,
            },
            1e-20,
        ),
        (
            Method::Symplectic {
                substeps: 16,
                composition: Composition::Yoshida4,
            },
            1e-20,
        ),
        (Method::Adaptive { rtol: 1e-12 }, 1e-16),
    ] {
        let p = Propagator::new(model, method, 3.0 * DT).unwrap();
        let mut y = p.phase(&y0).unwrap().end;
        y.v = -y.v;
        let mut back = p.phase(&y).unwrap().end;
        back.v = -back.v;
        assert!(
            (back.r - y0.r).norm() < f64::max(tol, 1e-7 * NM),
            "{method:?}: {:e}",
            (back.r - y0.r).norm()
        );
        assert!((back.v - y0.v).norm() < 1e-9 * y0.v.norm(), "{method:?}");
    }
}

#[test]
fn measured_convergence_orders() {
    // Max error over nine initial states (one state alone can hit a
    // cancellation), against DOP853 at rtol 1e-14; order = log2 of the
    // error ratio when the step is halved, in each method's asymptotic range.
    let model = paper_model();
    let t = DT;
    let starts: Vec<Phase<2>> = (0..9)
        .map(|i| {
            let a = f64::from(i) * 0.7;
            Phase {
                r: Vector2::new(300.0 * NM * a.cos(), 200.0 * NM * a.sin()),
                v: Vector2::new(0.05 * (2.0 * a).sin(), -0.05),
            }
        })
        .collect();
    let refp = Propagator::new(model, Method::Adaptive { rtol: 1e-14 }, t).unwrap();
    let exact: Vec<_> = starts
        .iter()
        .map(|y| refp.phase(y).unwrap().end.r)
        .collect();
    let sys = Dynamics::new(&model);
    // Fixed steps for the embedded pairs: infinite tolerance, step ratio pinned to 1.
    let fixed = StepControl {
        fac_min: 1.0,
        fac_max: 1.0,
        ..StepControl::default()
    };
    let loose = Tolerance {
        rtol: 1e30,
        atol_r: 1e30,
        atol_v: 1e30,
    };
    let rk = |y: &Phase<2>, n| rk4(&sys, y, t, n);
    let verlet = |y: &Phase<2>, n| symplectic(&model, y, t, n, Composition::Verlet).0;
    let y4 = |y: &Phase<2>, n| symplectic(&model, y, t, n, Composition::Yoshida4).0;
    let y6 = |y: &Phase<2>, n| symplectic(&model, y, t, n, Composition::Yoshida6).0;
    let dp5 = |y: &Phase<2>, n: u32| {
        dopri5(&sys, y, t, &loose, t / f64::from(n), &fixed)
            .unwrap()
            .0
    };
    let dp8 = |y: &Phase<2>, n: u32| {
        dop853(&sys, y, t, &loose, t / f64::from(n), &fixed)
            .unwrap()
            .0
    };
    type F<'a> = &'a dyn Fn(&Phase<2>, u32) -> Phase<2>;
    let cases: [(&str, F, u32, f64); 6] = [
        ("rk4", &rk, 128, 4.0),
        ("symplectic", &verlet, 64, 2.0),
        ("yoshida4", &y4, 32, 4.0),
        ("yoshida6", &y6, 64, 6.0),
        ("dopri5", &dp5, 64, 5.0),
        ("dop853", &dp8, 4, 8.0),
    ];
    for (name, f, n, expected) in cases {
        let err = |n: u32| {
            starts
                .iter()
                .zip(&exact)
                .map(|(y, x)| (f(y, n).r - x).norm())
                .fold(0.0, f64::max)
        };
        let p = (err(n) / err(2 * n)).log2();
        assert!(
            (p - expected).abs() < 0.3,
            "{name}: measured order {p:.2}, expected {expected}"
        );
    }
}

#[test]
fn hard_case_dt_of_many_periods() {
    // Δt = 50 periods of the stiff axis: adaptive stays on the reference,
    // the paper's single step is wildly off but finite.
    let model = paper_model();
    let wy = 2.0 * omega_x();
    let dt = 50.0 * 2.0 * std::f64::consts::PI / wy;
    let o = Vector2::new(-200.0 * NM, 100.0 * NM);
    let v0 = Vector2::new(0.02, -0.01);
    let refp = reference(model, dt).flow(&o, &v0).unwrap().0;
    let ad = Propagator::new(model, Method::default(), dt).unwrap();
    let (a, _, evals) = ad.flow(&o, &v0).unwrap();
    assert!(
        (a - refp).norm() < 0.05 * NM,
        "{} nm after {evals} evals",
        (a - refp).norm() / NM
    );
    let paper = Propagator::new(model, Method::PaperRk4, dt)
        .unwrap()
        .flow(&o, &v0)
        .unwrap()
        .0;
    assert!(paper.iter().all(|x| x.is_finite()));
    assert!((paper - refp).norm() > 1000.0 * NM);
}

#[test]
fn hard_case_far_outside_the_well_is_free_flight() {
    let model = paper_model();
    let v0 = Vector2::new(0.1, -0.05);
    for m in [
        Method::PaperRk4,
        Method::default(),
        Method::Dopri5 { rtol: 1e-8 },
    ] {
        let p = Propagator::new(model, m, DT).unwrap();
        for o in [
            Vector2::new(50e-6, 0.0),
            Vector2::new(1e3, -1e3),
            Vector2::new(1e300, 1e300),
        ] {
            let f = p.flow_jacobian(&o, &v0).unwrap();
            // exact up to the rounding of r0 = −offset and of r0 + d
            let err = (f.displacement - v0 * DT).norm();
            let bound = 4.0 * f64::EPSILON * o.norm() + 1e-12 * (v0 * DT).norm();
            if o.norm() < 1e6 {
                assert!(err <= bound, "{m:?} {o:?}: {err:e}");
            } else {
                // far beyond any optics bench the rounding of r0 swallows d
                assert!(f.displacement.iter().all(|x| x.is_finite()));
            }
            assert_eq!(f.velocity, v0);
            assert!(f.d_offset.iter().all(|x| *x == 0.0));
        }
    }
}

#[test]
fn hard_case_exactly_at_the_centre() {
    let model = paper_model();
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let f = p
        .flow_jacobian(&Vector2::zeros(), &Vector2::zeros())
        .unwrap();
    assert_eq!(f.displacement, Vector2::zeros());
    assert_eq!(f.velocity, Vector2::zeros());
    // Harmonic limit: ∂d/∂offset = I − cos(ω_i Δt) on the diagonal, to the
    // default tolerance (the sensitivities are error-controlled too).
    let wx = omega_x();
    for (i, w) in [wx, 2.0 * wx].iter().enumerate() {
        let e1 = (f.d_offset[(i, i)] - (1.0 - (w * DT).cos())).abs();
        let e2 = (f.d_velocity[(i, i)] - (w * DT).sin() / w).abs() / DT;
        assert!(e1 < 1e-5 && e2 < 1e-5, "axis {i}: {e1:e} {e2:e}");
    }
}

#[test]
fn hard_case_line_trap_follows_the_harmonic_solution() {
    // b/a = 1/100: the y axis oscillates 100× faster; Δt spans ~31 of its periods.
    let model = TrapModel::builder(DEPTH, [600e-9, 6e-9])
        .mass(MASS)
        .build()
        .unwrap();
    let k = model.well.stiffness();
    let (wx, wy) = ((k.x / MASS).sqrt(), (k.y / MASS).sqrt());
    let (x0, y0) = (1e-3 * 600e-9, 1e-3 * 6e-9);
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let end = p
        .phase(&Phase {
            r: Vector2::new(x0, y0),
            v: Vector2::zeros(),
        })
        .unwrap()
        .end;
    assert!((end.r.x - x0 * (wx * DT).cos()).abs() < 1e-5 * x0);
    // 31 fast periods at a picometre amplitude: absolute target 0.001 nm,
    // and the converged reference agrees with the harmonic solution to 1e-4.
    assert!((end.r.y - y0 * (wy * DT).cos()).abs() < 1e-3 * NM);
    let refp = reference(model, DT)
        .phase(&Phase {
            r: Vector2::new(x0, y0),
            v: Vector2::zeros(),
        })
        .unwrap()
        .end;
    assert!((refp.r.y - y0 * (wy * DT).cos()).abs() < 1e-4 * y0);
}

#[test]
fn hard_case_mass_over_drag_from_1000_dt_to_dt_over_1000() {
    // With drag and no noise the adaptive method is stable over the whole
    // range; it tends to the inertial solution when m/γ ≫ Δt and to the
    // overdamped one when m/γ ≪ Δt.
    let o = Vector2::new(-150.0 * NM, 80.0 * NM);
    let v0 = Vector2::zeros();
    let inertial = reference(paper_model(), DT).flow(&o, &v0).unwrap().0;
    let mut last = None;
    for e in -3..=3 {
        let tau = DT * 10f64.powi(e); // m/γ
        let gamma = MASS / tau;
        let eta = 1e-3;
        let radius = gamma / (6.0 * std::f64::consts::PI * eta);
        let model = TrapModel::builder(DEPTH, WAISTS)
            .mass(MASS)
            .stokes_drag(radius, eta)
            .build()
            .unwrap();
        let p = Propagator::new(model, Method::default(), DT).unwrap();
        let (d, _, _) = p.flow(&o, &v0).unwrap();
        assert!(d.iter().all(|x| x.is_finite()));
        if e == 3 {
            assert!(
                (d - inertial).norm() < 2e-3 * inertial.norm(),
                "m/γ = 1000 Δt"
            );
        }
        if e == -3 {
            let od = TrapModel::builder(DEPTH, WAISTS)
                .stokes_drag(radius, eta)
                .build()
                .unwrap();
            let (dod, _, _) = reference(od, DT).flow(&o, &v0).unwrap();
            assert!(
                (d - dod).norm() < 2e-2 * dod.norm(),
                "m/γ = Δt/1000: {d:?} vs {dod:?}"
            );
        }
        last = Some(d);
    }
    assert!(last.is_some());
    // The paper's single explicit step is unstable in the stiff limit.
    let gamma = MASS / (DT / 1000.0);
    let model = TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .stokes_drag(gamma / (6.0 * std::f64::consts::PI * 1e-3), 1e-3)
        .build()
        .unwrap();
    let (bad, _, _) = Propagator::new(model, Method::PaperRk4, DT)
        .unwrap()
        .flow(&o, &v0)
        .unwrap();
    assert!(bad.norm() > 1e3 * o.norm());
}

#[test]
fn hard_case_very_large_velocities() {
    // Launched from the bottom of the well the particle climbs out in a
    // fraction of Δt; energy conservation fixes its final speed:
    // v_end² = v0² − 2 P0/m.
    let model = paper_model();
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    for speed in [10.0, 1e3, 1e6] {
        let v0 = Vector2::new(speed, -0.5 * speed);
        let (d, v, _) = p.flow(&Vector2::zeros(), &v0).unwrap();
        assert!(d.iter().chain(v.iter()).all(|x| x.is_finite()));
        let expected = (v0.norm_squared() - 2.0 * DEPTH / MASS).sqrt();
        let err = (v.norm() - expected).abs() / expected;
        assert!(err < 1e-7, "speed {speed}: relative speed error {err:e}");
        let rel = (d - v0 * DT).norm() / (v0 * DT).norm();
        assert!(rel < 1.0 / (speed * speed), "speed {speed}: rel {rel}");
    }
}

#[test]
fn three_d_well_with_axial_waist() {
    let model = TrapModel::builder(DEPTH, [600e-9, 300e-9, 1500e-9])
        .mass(MASS)
        .build()
        .unwrap();
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let f = p
        .flow_jacobian(&Vector3::new(0.0, 0.0, -100.0 * NM), &Vector3::zeros())
        .unwrap();
    // on the axis the motion stays on the axis, harmonic-ish along z
    assert_eq!(f.displacement.x, 0.0);
    assert_eq!(f.displacement.y, 0.0);
    let wz = (model.well.stiffness().z / MASS).sqrt();
    let harmonic = -100.0 * NM * (1.0 - (wz * DT).cos());
    assert!((f.displacement.z - harmonic).abs() < 0.01 * harmonic.abs());
}

#[test]
fn method_and_interval_errors_are_typed() {
    let model = paper_model();
    let e = Propagator::new(model, Method::default(), 0.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "dt [s] = 0 is out of range: allowed finite and > 0"
    );
    let e = Method::from_name("euler", None, None).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("unknown method \"euler\": allowed \"paper-rk4\"")
    );
    let e = Method::from_name("rk4", None, Some(0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "substeps = 0 is out of range: allowed 1 ..= 10000000"
    );
    let e = Method::from_name("adaptive", Some(f64::NAN), None).unwrap_err();
    assert!(matches!(e, PhysicsError::Value(ref v) if v.field() == "rtol"));
    let damped = TrapModel::builder(DEPTH, WAISTS)
        .mass(MASS)
        .stokes_drag(0.5e-6, 1e-3)
        .build()
        .unwrap();
    let e = Propagator::new(
        damped,
        Method::from_name("symplectic", None, None).unwrap(),
        DT,
    )
    .unwrap_err();
    assert!(matches!(
        e,
        PhysicsError::Unsupported {
            method: "symplectic",
            ..
        }
    ));
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let e = p
        .flow(&Vector2::new(f64::NAN, 0.0), &Vector2::zeros())
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "offset [m] = NaN is out of range: allowed finite"
    );
    let e = p
        .flow(&Vector2::zeros(), &Vector2::new(0.0, f64::INFINITY))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "velocity [m/s] = inf is out of range: allowed finite"
    );
}

#[test]
fn hard_case_fast_particle_crossing_the_well_gets_the_analytic_time_advance() {
    // A particle at 100 m/s flies through the centre along x within one Δt.
    // Its speed is restored on exit and it leads free flight by
    // Δx = ∫ (−P(s)) ds / (m v²) = P0 a sqrt(π/ln2) / (m v²) to first order
    // in P0/(m v²) = 1e-4. The adaptive step must not hop over the well.
    let model = paper_model();
    let v = 100.0;
    let p = Propagator::new(model, Method::default(), DT).unwrap();
    let o = Vector2::new(20e-6, 0.0); // trap 20 µm ahead of the particle
    let (d, vend, _) = p.flow(&o, &Vector2::new(v, 0.0)).unwrap();
    let lead =
        DEPTH * WAISTS[0] * (std::f64::consts::PI / std::f64::consts::LN_2).sqrt() / (MASS * v * v);
    assert!((vend.x - v).abs() < 1e-9 * v);
    assert!(
        (d.x - v * DT - lead).abs() < 2e-3 * lead,
        "lead {} nm, expected {} nm",
        (d.x - v * DT) / NM,
        lead / NM
    );
}
