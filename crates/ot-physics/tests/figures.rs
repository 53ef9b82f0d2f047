//! BENCHMARKS.md's ot-physics figures, held by the report's own computation
//! (`examples/bench_report.rs` through `examples/common/mod.rs`): the problem (882 starts, the
//! reference's own error), every row of the work-precision table but its times (max and mean
//! error to the printed 3 significant digits, evaluations per trajectory to 0.1; ours, the batch
//! call and the compiled peer; not scipy, run in Python), the default settings' row, the
//! paper's one-step figures, the `flow_batch` check, and the thermal-mode table (same seed).
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

#[path = "../examples/common/mod.rs"]
mod common;

use common::{Problem, batch_offsets, measure, measure_batch, our_settings, peer, thermal};
use nalgebra::Vector2;
use ot_physics::{Method, Propagator, paper};

/// The work-precision table as printed (method, setting, max error nm, mean error nm, force
/// evaluations per trajectory), BENCHMARKS.md "Work-precision table".
const TABLE: &[(&str, &str, &str, &str, &str)] = &[
    ("paper-rk4", "1 step", "3.62e2", "1.68e1", "4.0"),
    ("rk4", "n=2", "6.27e1", "4.05e0", "8.0"),
    ("rk4", "n=4", "4.57e0", "2.56e-1", "16.0"),
    ("rk4", "n=8", "2.14e-1", "1.36e-2", "32.0"),
    ("rk4", "n=16", "1.13e-2", "7.27e-4", "64.0"),
    ("rk4", "n=32", "6.43e-4", "4.14e-5", "128.0"),
    ("rk4", "n=64", "3.78e-5", "2.45e-6", "256.0"),
    ("rk4", "n=128", "2.30e-6", "1.49e-7", "512.0"),
    ("rk8", "n=1", "2.44e1", "8.94e-1", "12.0"),
    ("rk8", "n=2", "6.64e-1", "1.61e-2", "24.0"),
    ("rk8", "n=3", "3.06e-2", "6.17e-4", "36.0"),
    ("rk8", "n=4", "3.75e-3", "1.16e-4", "48.0"),
    ("rk8", "n=6", "2.22e-4", "4.29e-6", "72.0"),
    ("rk8", "n=8", "1.55e-5", "3.72e-7", "96.0"),
    ("rk8", "n=12", "4.42e-7", "1.33e-8", "144.0"),
    ("dopri5", "rtol=1e-4", "9.12e-2", "6.15e-3", "14.3"),
    ("dopri5", "rtol=1e-5", "6.07e-3", "7.46e-4", "19.2"),
    ("dopri5", "rtol=1e-6", "4.33e-4", "7.41e-5", "26.7"),
    ("dopri5", "rtol=1e-7", "4.82e-5", "8.28e-6", "38.0"),
    ("dopri5", "rtol=1e-8", "4.89e-6", "9.72e-7", "55.5"),
    ("dopri5", "rtol=1e-10", "8.39e-8", "1.26e-8", "127.9"),
    ("dopri5", "rtol=1e-12", "5.63e-10", "1.41e-10", "310.0"),
    ("adaptive", "rtol=1e-4", "5.40e-2", "1.66e-3", "32.3"),
    ("adaptive", "rtol=1e-5", "1.99e-2", "2.56e-4", "43.9"),
    ("adaptive", "rtol=1e-6", "2.71e-3", "3.68e-5", "44.7"),
    ("adaptive", "rtol=1e-7", "9.42e-5", "2.98e-6", "50.4"),
    ("adaptive", "rtol=1e-8", "9.34e-6", "3.19e-7", "59.3"),
    ("adaptive", "rtol=1e-10", "1.02e-7", "5.39e-9", "82.9"),
    ("adaptive", "rtol=1e-12", "9.66e-10", "6.63e-11", "120.7"),
    ("symplectic", "n=16", "1.13e0", "1.27e-1", "17.0"),
    ("symplectic", "n=64", "7.03e-2", "7.94e-3", "65.0"),
    ("symplectic", "n=256", "4.39e-3", "4.96e-4", "257.0"),
    ("symplectic", "n=1024", "2.75e-4", "3.10e-5", "1025.0"),
    ("yoshida4", "n=4", "1.38e1", "9.96e-1", "13.0"),
    ("yoshida4", "n=8", "9.47e-1", "7.70e-2", "25.0"),
    ("yoshida4", "n=16", "6.56e-2", "5.61e-3", "49.0"),
    ("yoshida4", "n=32", "4.22e-3", "3.64e-4", "97.0"),
    ("yoshida4", "n=64", "2.66e-4", "2.29e-5", "193.0"),
    ("yoshida6", "n=2", "3.88e2", "1.77e1", "19.0"),
    ("yoshida6", "n=4", "9.74e0", "6.96e-1", "37.0"),
    ("yoshida6", "n=8", "7.55e-1", "3.39e-2", "73.0"),
    ("yoshida6", "n=16", "1.54e-2", "6.06e-4", "145.0"),
    ("rk8 batch", "n=2", "6.64e-1", "1.61e-2", "24.0"),
    ("rk8 batch", "n=3", "3.06e-2", "6.17e-4", "36.0"),
    ("rk8 batch", "n=4", "3.75e-3", "1.16e-4", "48.0"),
    ("rk8 batch", "n=6", "2.22e-4", "4.29e-6", "72.0"),
    ("rk8 batch", "n=8", "1.55e-5", "3.72e-7", "96.0"),
    ("rk8 batch", "n=12", "4.42e-7", "1.33e-8", "144.0"),
    (
        "ode_solvers Dop853",
        "tol=1e-3",
        "4.11e-1",
        "5.94e-3",
        "38.3",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-4",
        "4.21e-2",
        "1.07e-3",
        "40.5",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-5",
        "2.94e-3",
        "1.32e-4",
        "45.2",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-6",
        "2.47e-4",
        "1.36e-5",
        "52.3",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-7",
        "2.31e-5",
        "1.15e-6",
        "59.0",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-8",
        "2.23e-6",
        "1.15e-7",
        "67.0",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-10",
        "2.60e-8",
        "1.47e-9",
        "92.1",
    ),
    (
        "ode_solvers Dop853",
        "tol=1e-12",
        "4.34e-10",
        "1.80e-11",
        "131.4",
    ),
];

fn printed(r: &common::Row) -> (String, String, String, String, String) {
    (
        r.method.clone(),
        r.setting.clone(),
        format!("{:.2e}", r.max_err_nm),
        format!("{:.2e}", r.mean_err_nm),
        format!("{:.1}", r.evals_per_traj),
    )
}

/// The problem, the work-precision table, the default settings, the paper's one-step model and
/// the `flow_batch` check. (Each row's timing loop runs its 7 blocks of one pass: `min_ms` 0.)
#[test]
fn work_precision_figures() {
    let p = Problem::paper(21).unwrap();
    assert_eq!(p.starts.len(), 882);
    // "differs from rtol 1e-13 by 1.0e-10 nm"
    assert_eq!(format!("{:.1e}", p.reference_error / 1e-9), "1.0e-10");

    let mut rows = Vec::new();
    for (m, s) in our_settings() {
        rows.push(measure(&p, m, &s, 0.0).unwrap());
    }
    for n in [2u32, 3, 4, 6, 8, 12] {
        rows.push(measure_batch(&p, Method::Rk8 { substeps: n }, &format!("n={n}"), 0.0).unwrap());
    }
    for e in [3, 4, 5, 6, 7, 8, 10, 12] {
        rows.push(peer::measure(&p, 10f64.powi(-e), 0.0).unwrap());
    }
    let got: Vec<_> = rows.iter().map(printed).collect();
    let want: Vec<_> = TABLE
        .iter()
        .map(|r| {
            (
                r.0.to_string(),
                r.1.to_string(),
                r.2.to_string(),
                r.3.to_string(),
                r.4.to_string(),
            )
        })
        .collect();
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g, w);
    }
    assert_eq!(got.len(), want.len());

    // the paper's difference equation: "off by up to 362 nm (mean 16.8 nm)"
    let one = &rows[0];
    assert_eq!(one.method, "paper-rk4");
    assert_eq!(
        (
            format!("{:.0}", one.max_err_nm),
            format!("{:.1}", one.mean_err_nm)
        ),
        ("362".to_string(), "16.8".to_string())
    );

    // default settings: "max 2.05e-6 nm, mean 1.07e-7 nm, … 64.7 evaluations per trajectory"
    let d = measure(&p, Method::default(), "default", 0.0).unwrap();
    assert_eq!(
        (
            format!("{:.2e}", d.max_err_nm),
            format!("{:.2e}", d.mean_err_nm),
            format!("{:.1}", d.evals_per_traj)
        ),
        (
            "2.05e-6".to_string(),
            "1.07e-7".to_string(),
            "64.7".to_string()
        )
    );

    // `flow_batch` with rk8 (4 substeps, the cheapest batch row within 0.01 nm): "max error
    // 5.8e-3 nm on a 2000-flow check" — every 500th of the report's 10^6 LCG offsets (the
    // batch call's results are bit-identical to one flow per call, so the 2000 alone)
    let cheapest = rows
        .iter()
        .filter(|r| r.method == "rk8 batch" && r.max_err_nm <= 0.01)
        .min_by(|a, b| a.evals_per_traj.total_cmp(&b.evals_per_traj))
        .unwrap();
    assert_eq!(cheapest.setting, "n=4");
    let offsets = batch_offsets(1_000_000);
    let checked: Vec<Vector2<f64>> = offsets.iter().step_by(500).copied().collect();
    assert_eq!(checked.len(), 2000);
    let v = [Vector2::from(paper::V0_MOVING)];
    let mut out = vec![Vector2::zeros(); checked.len()];
    let prop = Propagator::new(p.model, Method::Rk8 { substeps: 4 }, paper::DT).unwrap();
    prop.flow_batch(&checked, &v, &mut out).unwrap();
    let reference = Propagator::new(p.model, Method::Adaptive { rtol: 1e-13 }, paper::DT).unwrap();
    let mut max_err: f64 = 0.0;
    for (o, d) in checked.iter().zip(&out) {
        let r = reference.flow(o, &v[0]).unwrap().0;
        assert_eq!(
            prop.flow(o, &v[0]).unwrap().0,
            *d,
            "batch = one flow per call"
        );
        max_err = max_err.max((d - r).norm() / 1e-9);
    }
    assert_eq!(format!("{max_err:.1e}"), "5.8e-3");
}

/// BENCHMARKS.md "Thermal mode (harmonic limit)", the report's run (seed 20261121): the bead's
/// mass and m/γ, the expected figures, variance +0.48 %, the aliased corner fit −0.50 %, the
/// naive Lorentzian +41.91 %, the autocorrelation's largest deviation 0.0091, 190 blocks.
#[test]
fn thermal_figures() {
    let t = thermal().unwrap();
    let got = [
        format!("{:.3e}", t.mass),
        format!("{:.0}", t.mass / t.gamma * 1e9),
        format!("{:.3}", t.kt / t.kappa * 1e18),
        format!("{:.3}", t.var * 1e18),
        format!("{:+.2}", 100.0 * (t.var / (t.kt / t.kappa) - 1.0)),
        format!("{:.1}", t.fc_true),
        format!("{:.1}", t.fc_alias),
        format!("{:+.2}", 100.0 * (t.fc_alias / t.fc_true - 1.0)),
        format!("{:.1}", t.fc_lor),
        format!("{:+.2}", 100.0 * (t.fc_lor / t.fc_true - 1.0)),
        format!("{:.4}", t.ac_err),
        format!("{}", t.blocks),
    ];
    assert_eq!(
        got,
        [
            "5.498e-16",
            "58",
            "40.474",
            "40.669",
            "+0.48",
            "1685.3",
            "1676.9",
            "-0.50",
            "2391.7",
            "+41.91",
            "0.0091",
            "190"
        ]
    );
}
