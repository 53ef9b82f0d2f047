//! Work-precision measurement on the paper problem, shared by the
//! `paper_table` and `bench_report` examples; the report's batch offsets and thermal-mode run,
//! shared with `tests/figures.rs`.
#![allow(dead_code)]

use bench_harness::span;
use nalgebra::Vector2;
use ot_physics::analysis::{
    autocorrelation, block_periodogram, fit_corner_aliased, fit_corner_lorentzian, mean_variance,
};
use ot_physics::langevin::{Scheme, ThermalRun, simulate};
use ot_physics::{BOLTZMANN, Method, Phase, PhysicsError, Propagator, TrapModel, paper};
use std::hint::black_box;

/// Start states and their converged displacements.
pub struct Problem {
    /// The model.
    pub model: TrapModel<2>,
    /// (offset m, v0 m/s) pairs.
    pub starts: Vec<(Vector2<f64>, Vector2<f64>)>,
    /// Reference displacements (m), DOP853 at rtol 1e-13.
    pub reference: Vec<Vector2<f64>>,
    /// Largest difference between rtol 1e-13 and 1e-14 references (m).
    pub reference_error: f64,
}

impl Problem {
    /// The paper problem on an `n × n` grid of offsets spanning ±1.5 µm,
    /// for v0 = 0 and v0 = (100, 100) nm/µs.
    pub fn paper(n: usize) -> Result<Self, PhysicsError> {
        let model = paper::model()?;
        let mut starts = Vec::new();
        for v in [Vector2::zeros(), Vector2::from(paper::V0_MOVING)] {
            for o in paper::offsets(n) {
                starts.push((o, v));
            }
        }
        let r13 = Propagator::new(model, Method::Adaptive { rtol: 1e-13 }, paper::DT)?;
        let r14 = Propagator::new(model, Method::Adaptive { rtol: 1e-14 }, paper::DT)?;
        let mut reference = Vec::with_capacity(starts.len());
        let mut reference_error: f64 = 0.0;
        for (o, v) in &starts {
            let a = r13.flow(o, v)?.0;
            let b = r14.flow(o, v)?.0;
            reference_error = reference_error.max((a - b).norm());
            reference.push(b);
        }
        Ok(Self {
            model,
            starts,
            reference,
            reference_error,
        })
    }
}

/// One point of a work-precision diagram.
#[derive(Debug, Clone)]
pub struct Row {
    /// Method family.
    pub method: String,
    /// Its setting (substeps or rtol).
    pub setting: String,
    /// Largest displacement error over the problem (nm).
    pub max_err_nm: f64,
    /// Mean displacement error (nm).
    pub mean_err_nm: f64,
    /// CPU time per trajectory (ns), best of repeated runs.
    pub ns_per_traj: f64,
    /// Force evaluations per trajectory (mean).
    pub evals_per_traj: f64,
}

/// CPU time of this thread per call of `f` over `n_calls` items (ns): blocks of ≥ `min_ms` ms,
/// minimum over 7 blocks (`bench_harness::best_block_cpu_s`). Thread CPU time (not wall time)
/// and the minimum keep other processes on a shared machine out of it.
pub fn time_per_call(n_calls: usize, min_ms: f64, f: impl FnMut()) -> f64 {
    bench_harness::best_block_cpu_s(7, min_ms * 1e-3, n_calls, f) * 1e9
}

/// Errors of `displacements` against the reference: (max, mean) in nm.
pub fn errors(p: &Problem, displacements: &[Vector2<f64>]) -> (f64, f64) {
    let mut max: f64 = 0.0;
    let mut sum = 0.0;
    for (d, r) in displacements.iter().zip(&p.reference) {
        let e = (d - r).norm() / 1e-9;
        max = max.max(e);
        sum += e;
    }
    (max, sum / displacements.len() as f64)
}

/// Measure one of our methods.
pub fn measure(
    p: &Problem,
    method: Method,
    setting: &str,
    min_ms: f64,
) -> Result<Row, PhysicsError> {
    let prop = Propagator::new(p.model, method, paper::DT)?;
    let mut disp = Vec::with_capacity(p.starts.len());
    let mut evals = 0u64;
    for (o, v) in &p.starts {
        let (d, _, n) = prop.flow(o, v)?;
        disp.push(d);
        evals += n;
    }
    let (max_err_nm, mean_err_nm) = errors(p, &disp);
    let ns = time_per_call(p.starts.len(), min_ms, || {
        for (o, v) in &p.starts {
            let _ = black_box(prop.flow(black_box(o), black_box(v)));
        }
    });
    Ok(Row {
        method: method.name().to_string(),
        setting: setting.to_string(),
        max_err_nm,
        mean_err_nm,
        ns_per_traj: ns,
        evals_per_traj: evals as f64 / p.starts.len() as f64,
    })
}

/// Measure one of our fixed-step methods through `flow_batch` (lockstep
/// lanes); the row's method name gets a ` batch` suffix.
pub fn measure_batch(
    p: &Problem,
    method: Method,
    setting: &str,
    min_ms: f64,
) -> Result<Row, PhysicsError> {
    let prop = Propagator::new(p.model, method, paper::DT)?;
    let offsets: Vec<Vector2<f64>> = p.starts.iter().map(|s| s.0).collect();
    let vels: Vec<Vector2<f64>> = p.starts.iter().map(|s| s.1).collect();
    let mut disp = vec![Vector2::zeros(); offsets.len()];
    let evals = prop.flow_batch(&offsets, &vels, &mut disp)?;
    let (max_err_nm, mean_err_nm) = errors(p, &disp);
    let ns = time_per_call(p.starts.len(), min_ms, || {
        let _ = black_box(prop.flow_batch(black_box(&offsets), &vels, &mut disp));
    });
    Ok(Row {
        method: format!("{} batch", method.name()),
        setting: setting.to_string(),
        max_err_nm,
        mean_err_nm,
        ns_per_traj: ns,
        evals_per_traj: evals as f64 / p.starts.len() as f64,
    })
}

/// The settings swept for each of our methods.
pub fn our_settings() -> Vec<(Method, String)> {
    use ot_physics::Composition::*;
    let mut v = vec![(Method::PaperRk4, "1 step".to_string())];
    for n in [2u32, 4, 8, 16, 32, 64, 128] {
        v.push((Method::Rk4 { substeps: n }, format!("n={n}")));
    }
    for n in [1u32, 2, 3, 4, 6, 8, 12] {
        v.push((Method::Rk8 { substeps: n }, format!("n={n}")));
    }
    for e in [4, 5, 6, 7, 8, 10, 12] {
        let rtol = 10f64.powi(-e);
        v.push((Method::Dopri5 { rtol }, format!("rtol=1e-{e}")));
    }
    for e in [4, 5, 6, 7, 8, 10, 12] {
        let rtol = 10f64.powi(-e);
        v.push((Method::Adaptive { rtol }, format!("rtol=1e-{e}")));
    }
    for n in [16u32, 64, 256, 1024] {
        v.push((
            Method::Symplectic {
                substeps: n,
                composition: Verlet,
            },
            format!("n={n}"),
        ));
    }
    for n in [4u32, 8, 16, 32, 64] {
        v.push((
            Method::Symplectic {
                substeps: n,
                composition: Yoshida4,
            },
            format!("n={n}"),
        ));
    }
    for n in [2u32, 4, 8, 16] {
        v.push((
            Method::Symplectic {
                substeps: n,
                composition: Yoshida6,
            },
            format!("n={n}"),
        ));
    }
    v
}

pub mod peer {
    //! The compiled peer: `ode_solvers`' Dop853, on the same problem in
    //! scaled units (nm, µs) so its scalar tolerances are meaningful.
    use super::{Problem, Row, errors, time_per_call};
    use nalgebra::Vector2;
    // ode_solvers pins its own nalgebra: use its re-exported vector type.
    use ode_solvers::{Dop853, Dopri5, OutputType, System, Vector4};
    use ot_physics::paper;
    use std::hint::black_box;

    struct Eq {
        /// ln2/w² in 1/nm².
        k: [f64; 2],
        /// 2 P0 / m in nm²/µs².
        c: f64,
    }

    impl System<f64, Vector4<f64>> for Eq {
        fn system(&self, _t: f64, y: &Vector4<f64>, dy: &mut Vector4<f64>) {
            let e = (-(self.k[0] * y[0] * y[0] + self.k[1] * y[1] * y[1])).exp();
            dy[0] = y[2];
            dy[1] = y[3];
            dy[2] = -self.c * self.k[0] * y[0] * e;
            dy[3] = -self.c * self.k[1] * y[1] * e;
        }
    }

    fn eq() -> Eq {
        let nm = 1e-9;
        let us = 1e-6;
        Eq {
            k: [
                std::f64::consts::LN_2 / (paper::WAISTS[0] / nm).powi(2),
                std::f64::consts::LN_2 / (paper::WAISTS[1] / nm).powi(2),
            ],
            // J/kg = m²/s² → nm²/µs²: × (1e9)² × (1e-6)²
            c: 2.0 * paper::DEPTH / paper::MASS * (us / nm).powi(2),
        }
    }

    /// Displacement (nm) and evaluations of one trajectory.
    fn solve(o: &Vector2<f64>, v: &Vector2<f64>, rtol: f64) -> Option<(Vector2<f64>, u32)> {
        let y0 = Vector4::new(-o.x * 1e9, -o.y * 1e9, v.x * 1e3, v.y * 1e3);
        let mut s = Dop853::new(eq(), 0.0, paper::DT * 1e6, 1.0, y0, rtol, rtol);
        s.set_output(OutputType::Sparse);
        let stats = s.integrate().ok()?;
        let y = s.y_out().last()?;
        Some((Vector2::new(y[0] - y0[0], y[1] - y0[1]), stats.num_eval))
    }

    /// Displacement (nm) and evaluations of one trajectory with the peer's
    /// Dopri5 (same tolerances and units as its Dop853).
    fn solve_dopri5(o: &Vector2<f64>, v: &Vector2<f64>, rtol: f64) -> Option<(Vector2<f64>, u32)> {
        let y0 = Vector4::new(-o.x * 1e9, -o.y * 1e9, v.x * 1e3, v.y * 1e3);
        let mut s = Dopri5::new(eq(), 0.0, paper::DT * 1e6, 1.0, y0, rtol, rtol);
        s.set_output(OutputType::Sparse);
        let stats = s.integrate().ok()?;
        let y = s.y_out().last()?;
        Some((Vector2::new(y[0] - y0[0], y[1] - y0[1]), stats.num_eval))
    }

    /// Measure the peer's Dopri5 at tolerance `rtol` (= atol, nm and nm/µs).
    pub fn measure_dopri5(p: &Problem, rtol: f64, min_ms: f64) -> Option<Row> {
        let mut disp = Vec::with_capacity(p.starts.len());
        let mut evals = 0u64;
        for (o, v) in &p.starts {
            let (d, n) = solve_dopri5(o, v, rtol)?;
            disp.push(d * 1e-9);
            evals += u64::from(n);
        }
        let (max_err_nm, mean_err_nm) = errors(p, &disp);
        let ns = time_per_call(p.starts.len(), min_ms, || {
            for (o, v) in &p.starts {
                let _ = black_box(solve_dopri5(black_box(o), black_box(v), rtol));
            }
        });
        Some(Row {
            method: "ode_solvers Dopri5".to_string(),
            setting: format!("tol={rtol:.0e}"),
            max_err_nm,
            mean_err_nm,
            ns_per_traj: ns,
            evals_per_traj: evals as f64 / p.starts.len() as f64,
        })
    }

    /// One pass over the problem (for instruction counting).
    pub fn measure_once(p: &Problem, rtol: f64) -> usize {
        p.starts
            .iter()
            .filter_map(|(o, v)| solve(o, v, rtol))
            .count()
    }

    /// Measure the peer at tolerance `rtol` (= atol, in nm and nm/µs).
    pub fn measure(p: &Problem, rtol: f64, min_ms: f64) -> Option<Row> {
        let mut disp = Vec::with_capacity(p.starts.len());
        let mut evals = 0u64;
        for (o, v) in &p.starts {
            let (d, n) = solve(o, v, rtol)?;
            disp.push(d * 1e-9);
            evals += u64::from(n);
        }
        let (max_err_nm, mean_err_nm) = errors(p, &disp);
        let ns = time_per_call(p.starts.len(), min_ms, || {
            for (o, v) in &p.starts {
                let _ = black_box(solve(black_box(o), black_box(v), rtol));
            }
        });
        Some(Row {
            method: "ode_solvers Dop853".to_string(),
            setting: format!("tol={rtol:.0e}"),
            max_err_nm,
            mean_err_nm,
            ns_per_traj: ns,
            evals_per_traj: evals as f64 / p.starts.len() as f64,
        })
    }
}

/// Cheapest row of `rows` (one method family) whose max error ≤ `target_nm`.
pub fn cheapest_within<'a>(rows: &'a [Row], method: &str, target_nm: f64) -> Option<&'a Row> {
    rows.iter()
        .filter(|r| r.method == method && r.max_err_nm <= target_nm)
        .min_by(|a, b| a.ns_per_traj.total_cmp(&b.ns_per_traj))
}

/// CPU time (ns) of one method family at exactly `target_nm` max error,
/// interpolated linearly in log(time)–log(error) between the two settings
/// that bracket it. `None` if no pair of settings brackets the target.
pub fn time_at_error(rows: &[Row], method: &str, target_nm: f64) -> Option<f64> {
    let mut pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.method == method && r.max_err_nm > 0.0)
        .map(|r| (r.max_err_nm.ln(), r.ns_per_traj.ln()))
        .collect();
    pts.sort_by(|a, b| b.0.total_cmp(&a.0));
    let t = target_nm.ln();
    pts.windows(2).find_map(|w| {
        let ((e0, c0), (e1, c1)) = (w[0], w[1]);
        (e0 >= t && t >= e1 && e0 > e1).then(|| (c0 + (c1 - c0) * (e0 - t) / (e0 - e1)).exp())
    })
}

/// `n` trap offsets from a fixed LCG, uniform in ±`paper::OFFSET_SPAN` in x and y (the
/// report's 10^6-flow batch).
pub fn batch_offsets(n: usize) -> Vec<Vector2<f64>> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * paper::OFFSET_SPAN
    };
    (0..n).map(|_| Vector2::new(next(), next())).collect()
}

/// Samples per block of the thermal run's periodogram.
pub const THERMAL_BLOCK: usize = 4096;

/// The thermal validation's figures (SI units): a 1 µm polystyrene bead in water at 20 °C,
/// κ = 0.1 pN/nm, 10 s at 78 125 Hz, seed 20261121.
pub struct Thermal {
    /// Trap stiffness κ (N/m).
    pub kappa: f64,
    /// The bead's mass (kg).
    pub mass: f64,
    /// Stokes drag γ (kg/s; NaN if the model has none).
    pub gamma: f64,
    /// kT (J).
    pub kt: f64,
    /// Measured variance of x (m²).
    pub var: f64,
    /// Expected corner frequency κ/(2πγ) (Hz).
    pub fc_true: f64,
    /// Corner frequency of the aliased (AR(1)) fit (Hz; NaN if the fit failed).
    pub fc_alias: f64,
    /// Corner frequency of the naive Lorentzian fit (Hz; NaN if the fit failed).
    pub fc_lor: f64,
    /// Largest deviation of the autocorrelation from exp(−κt/γ), lags 0–40.
    pub ac_err: f64,
    /// Periodogram blocks averaged.
    pub blocks: usize,
    /// Wall-clock seconds of `simulate`.
    pub simulate_s: f64,
}

/// Runs the thermal validation (BENCHMARKS.md "Thermal mode (harmonic limit)").
pub fn thermal() -> Result<Thermal, PhysicsError> {
    let (kappa, radius, eta, temp, waist, fs) = (1e-4, 0.5e-6, 1.002e-3, 293.15, 1e-6, 78_125.0);
    let mass = 1050.0 * 4.0 / 3.0 * std::f64::consts::PI * radius * radius * radius;
    let depth = kappa * waist * waist / (2.0 * std::f64::consts::LN_2);
    let model = TrapModel::builder(depth, [waist, waist])
        .mass(mass)
        .stokes_drag(radius, eta)
        .temperature(Some(temp))
        .build()?;
    let gamma = model.drag.unwrap_or(f64::NAN);
    let run = ThermalRun {
        duration: 10.0,
        sample_rate: fs,
        substeps: 1,
        scheme: Scheme::Auto,
        seed: 20261121,
    };
    let start = Phase {
        r: Vector2::zeros(),
        v: Vector2::zeros(),
    };
    let (xs, s) = span(|| simulate(&model, start, &run));
    let (xs, simulate_s) = (xs?, s.wall_s);
    let x: Vec<f64> = xs.iter().map(|p| p.x).collect();
    let (_, var) = mean_variance(&x);
    let (f, psd) = block_periodogram(&x, fs, THERMAL_BLOCK);
    let ac = autocorrelation(&x, 40);
    let ac_err = ac
        .iter()
        .enumerate()
        .map(|(k, c)| (c - (-kappa * k as f64 / (fs * gamma)).exp()).abs())
        .fold(0.0, f64::max);
    Ok(Thermal {
        kappa,
        mass,
        gamma,
        kt: BOLTZMANN * temp,
        var,
        fc_true: kappa / (2.0 * std::f64::consts::PI * gamma),
        fc_alias: fit_corner_aliased(&f, &psd, fs).unwrap_or(f64::NAN),
        fc_lor: fit_corner_lorentzian(&f, &psd).unwrap_or(f64::NAN),
        ac_err,
        blocks: x.len() / THERMAL_BLOCK,
        simulate_s,
    })
}
