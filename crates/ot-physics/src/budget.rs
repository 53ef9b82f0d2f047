//! The error budget of a tick map: the cheapest fixed-step method whose
//! displacement stays within a stated distance (m) of converged dynamics,
//! chosen once per (model, Δt, tolerance) and reported.
//!
//! Fixed-step maps are what the envelope and the inverse solver want: their
//! Jacobian is the exact derivative of the map they solve, four offsets run in
//! lockstep, and the cost per flow is known in advance. The error is measured,
//! not estimated: the candidate is compared with [`converged`] on a lattice of
//! probe offsets covering the searched region (3 waists around the free
//! drift) for a spread of start velocities up to `v_max`, and accepted only
//! within half the tolerance (a safety factor of 2 for the space between
//! probes).

use crate::error::{PhysicsError, Result, ValueError, positive};
use crate::integrate::{Method, Propagator};
use crate::model::TrapModel;
use nalgebra::Vector2;

/// Relative tolerance of the converged reference (DOP853).
pub const CONVERGED_RTOL: f64 = 1e-12;

/// Safety factor between the measured probe error and the tolerance.
pub const SAFETY: f64 = 2.0;

/// Probe lattice points per axis.
const PROBES_PER_AXIS: usize = 9;

/// Half-width of the probed region beyond the drift path, in waists.
const PROBE_MARGIN_WAISTS: f64 = 3.0;

/// The largest substep count tried.
const MAX_SUBSTEPS: u32 = 512;

/// The converged reference of a model's tick: DOP853 at
/// [`CONVERGED_RTOL`] (within ~1e-14 m on the hard cases).
pub fn converged<const D: usize>(model: TrapModel<D>, dt: f64) -> Result<Propagator<D>> {
    Propagator::new(
        model,
        Method::Adaptive {
            rtol: CONVERGED_RTOL,
        },
        dt,
    )
}

/// What [`choose_tick_map`] chose, and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapChoice {
    /// The chosen fixed-step method.
    pub method: Method,
    /// Largest displacement error measured at the probes (m).
    pub error_m: f64,
    /// The tolerance asked for (m).
    pub tol_m: f64,
    /// Force evaluations per flow of the chosen map (without Jacobian).
    pub evals_per_flow: u64,
    /// Probe flows compared (offsets × velocities).
    pub probes: usize,
    /// Largest start speed probed (m/s).
    pub v_max: f64,
}

/// The choice in words, its numbers to three significant digits by
/// [`fmt_sig`](world_form::fmt_sig). Only printed: the scenes record the choice as a typed
/// event (its fields), not this text.
impl std::fmt::Display for MapChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = match self.method {
            Method::Rk4 { substeps } | Method::Rk8 { substeps } => substeps,
            _ => 1,
        };
        let num = |x: f64| world_form::fmt_sig(x, 3);
        write!(
            f,
            "tick map {}×{n}: {} m from converged dynamics at {} probes (budget {} m, \
             speeds ≤ {} m/s), {} force evaluations per flow",
            self.method.name(),
            num(self.error_m),
            self.probes,
            num(self.tol_m),
            num(self.v_max),
            self.evals_per_flow
        )
    }
}

fn candidates() -> Vec<(u64, Method)> {
    let mut c: Vec<(u64, Method)> = Vec::new();
    for n in 1..=MAX_SUBSTEPS {
        c.push((4 * u64::from(n), Method::Rk4 { substeps: n }));
        if n <= MAX_SUBSTEPS / 3 {
            c.push((12 * u64::from(n), Method::Rk8 { substeps: n }));
        }
    }
    // cheapest first; RK4 before RK8 at equal cost (stable order)
    c.sort_by_key(|(e, m)| (*e, u8::from(matches!(m, Method::Rk8 { .. }))));
    c
}

/// Checks the largest start speed `v_max` (m/s) of the probes: finite and ≥ 0.
fn start_speed(v_max: f64) -> Result<f64> {
    if v_max.is_finite() && v_max >= 0.0 {
        Ok(v_max)
    } else {
        Err(PhysicsError::Value(ValueError::out_of_range(
            "v_max [m/s]",
            v_max,
            "finite and >= 0",
        )))
    }
}

/// The probe set: for each start velocity (0, `v_max` along x, along y and
/// along the anti-diagonal), a lattice of offsets over the region within 3
/// waists of the free drift path.
fn probes(model: &TrapModel<2>, dt: f64, v_max: f64) -> Vec<(Vector2<f64>, Vector2<f64>)> {
    let w = model.well.waists();
    let s = std::f64::consts::FRAC_1_SQRT_2 * v_max;
    let vels = [
        Vector2::zeros(),
        Vector2::new(v_max, 0.0),
        Vector2::new(0.0, v_max),
        Vector2::new(-s, s),
    ];
    let mut out = Vec::new();
    for v in vels {
        let (a, b) = (Vector2::zeros(), v * dt);
        let lo = a.inf(&b) - w * PROBE_MARGIN_WAISTS;
        let hi = a.sup(&b) + w * PROBE_MARGIN_WAISTS;
        let k = (PROBES_PER_AXIS - 1) as f64;
        for i in 0..PROBES_PER_AXIS {
            for j in 0..PROBES_PER_AXIS {
                let t = Vector2::new(i as f64 / k, j as f64 / k);
                out.push((lo + (hi - lo).component_mul(&t), v));
            }
        }
        if v_max == 0.0 {
            break;
        }
    }
    out
}

/// Measure a given fixed-step `method`'s displacement error (m) against
/// converged dynamics at the same probes [`choose_tick_map`] uses (start
/// speeds up to `v_max`, m/s), and report it as a [`MapChoice`] with
/// `tol_m` = the measured error (a map fixed by hand has no budget).
pub fn measure(model: TrapModel<2>, method: Method, dt: f64, v_max: f64) -> Result<MapChoice> {
    let v_max = start_speed(v_max)?;
    let reference = converged(model, dt)?;
    let p = Propagator::new(model, method, dt)?;
    let probes = probes(&model, dt, v_max);
    let mut worst: f64 = 0.0;
    let mut evals = 0;
    for (o, v) in &probes {
        let (d, _, e) = p.flow(o, v)?;
        evals = e;
        worst = worst.max((d - reference.flow(o, v)?.0).norm());
    }
    Ok(MapChoice {
        method,
        error_m: worst,
        tol_m: worst,
        evals_per_flow: evals,
        probes: probes.len(),
        v_max,
    })
}

/// Choose the cheapest fixed-step tick map (RK4 or DOP853's 8th-order
/// formula, `n` equal substeps) whose displacement is within `tol_m` (m) of
/// converged dynamics for start speeds up to `v_max` (m/s), measured at
/// probe offsets with a safety factor of [`SAFETY`]. Returns the propagator
/// and the report of the choice. Fails with a typed error when `tol_m` is
/// not finite and > 0, `v_max` not finite and ≥ 0, or no candidate up to
/// 512 substeps meets the budget.
pub fn choose_tick_map(
    model: TrapModel<2>,
    dt: f64,
    tol_m: f64,
    v_max: f64,
) -> Result<(Propagator<2>, MapChoice)> {
    let tol_m = positive("tick map tolerance [m]", tol_m)?;
    let v_max = start_speed(v_max)?;
    let reference = converged(model, dt)?;
    let probes = probes(&model, dt, v_max);
    let mut exact = Vec::with_capacity(probes.len());
    for (o, v) in &probes {
        exact.push(reference.flow(o, v)?.0);
    }
    'next: for (evals, method) in candidates() {
        let p = Propagator::new(model, method, dt)?;
        let mut worst: f64 = 0.0;
        for ((o, v), e) in probes.iter().zip(&exact) {
            worst = worst.max((p.flow(o, v)?.0 - e).norm());
            if worst * SAFETY > tol_m {
                continue 'next;
            }
        }
        return Ok((
            p,
            MapChoice {
                method,
                error_m: worst,
                tol_m,
                evals_per_flow: evals,
                probes: probes.len(),
                v_max,
            },
        ));
    }
    Err(PhysicsError::Value(ValueError::out_of_range(
        "tick map tolerance [m]",
        tol_m,
        "reachable by RK4 or RK8 with at most 512 substeps for this model and dt",
    )))
}
