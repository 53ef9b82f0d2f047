//! Approach–retract force–distance curves, measured by stepping a real [`World`].

use nalgebra::Vector3;

use crate::error::CurveError;
use crate::params::Params;
use crate::world::{Event, TipInput, World};
use world_form::{Limits, ValueError};

/// One vertical approach–retract sweep of the bare tip over the substrate.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSpec {
    /// Lateral cursor position (x, y) (m).
    pub xy_m: [f64; 2],
    /// Cursor gap where the sweep starts and ends (m): the gap between the cursor-held
    /// (undeflected) tip surface and the substrate's top surface (atom tops / plane).
    pub far_gap_m: f64,
    /// Cursor gap where the approach turns into the retraction (m); may be negative (press).
    pub near_gap_m: f64,
    /// Ticks per leg. Range [2, 10⁷].
    pub steps: usize,
    /// Tick length (s); the quasi-static laws do not depend on it. Range (0, 1].
    pub dt_s: f64,
}

/// A measured force–distance curve. Force is the z component sent to the device
/// (N, negative = pulled towards the substrate).
#[derive(Debug, Clone, PartialEq)]
pub struct ForceCurve {
    /// Cursor gap on approach (m), decreasing.
    pub approach_gap_m: Vec<f64>,
    /// Force z on approach (N).
    pub approach_force_n: Vec<f64>,
    /// Cursor gap on retraction (m), increasing.
    pub retract_gap_m: Vec<f64>,
    /// Force z on retraction (N).
    pub retract_force_n: Vec<f64>,
    /// Index into the approach arrays of the tick the tip snapped, if it did.
    pub snap_index: Option<usize>,
    /// Index into the retract arrays of the tick the tip pulled off, if it did.
    pub pull_off_index: Option<usize>,
    /// Energy dissipated over the loop, −∮F_z dz (J), trapezoid rule.
    pub hysteresis_j: f64,
}

/// Sweep a bare tip (no movable atoms, no loading zone, no house) down and up over the
/// substrate of `params` and record the device force (within `limits`, world units).
pub fn force_distance_curve(
    params: &Params,
    limits: &Limits,
    spec: &CurveSpec,
) -> Result<ForceCurve, CurveError> {
    let bad = |field: &'static str, value: f64, allowed: &str| {
        CurveError::OutOfRange(ValueError::out_of_range(field, value, allowed.to_string()))
    };
    if !spec.xy_m.iter().all(|v| v.is_finite()) {
        let v = if spec.xy_m[0].is_finite() {
            spec.xy_m[1]
        } else {
            spec.xy_m[0]
        };
        return Err(bad("xy_m", v, "finite metres"));
    }
    if !(spec.far_gap_m.is_finite() && spec.far_gap_m > 0.0 && spec.far_gap_m <= 1e-6) {
        return Err(bad("far_gap_m", spec.far_gap_m, "0 < value <= 1e-6 m"));
    }
    if !(spec.near_gap_m.is_finite() && spec.near_gap_m < spec.far_gap_m) {
        return Err(bad(
            "near_gap_m",
            spec.near_gap_m,
            &format!(
                "finite and < far_gap_m = {} m",
                world_form::numbers::fmt_num(spec.far_gap_m)
            ),
        ));
    }
    if !(2..=10_000_000).contains(&spec.steps) {
        return Err(bad("steps", spec.steps as f64, "2 <= steps <= 10^7"));
    }
    if !(spec.dt_s > 0.0 && spec.dt_s <= 1.0) {
        return Err(bad("dt_s", spec.dt_s, "0 < dt_s <= 1 s"));
    }
    let mut p = params.clone();
    p.loading_zone = None;
    p.initial_atoms_xy_m.clear();
    p.house = None;
    let top = p.substrate.atom_radius_m + p.tip.radius_m;
    let at = |gap: f64| Vector3::new(spec.xy_m[0], spec.xy_m[1], top + gap);
    let mut world = World::new(&p, limits, at(spec.far_gap_m))?;
    let n = spec.steps;
    let mut c = ForceCurve {
        approach_gap_m: Vec::with_capacity(n + 1),
        approach_force_n: Vec::with_capacity(n + 1),
        retract_gap_m: Vec::with_capacity(n + 1),
        retract_force_n: Vec::with_capacity(n + 1),
        snap_index: None,
        pull_off_index: None,
        hysteresis_j: 0.0,
    };
    for leg in 0..2 {
        for k in 0..=n {
            let s = k as f64 / n as f64;
            let gap = if leg == 0 {
                spec.far_gap_m + (spec.near_gap_m - spec.far_gap_m) * s
            } else {
                spec.near_gap_m + (spec.far_gap_m - spec.near_gap_m) * s
            };
            let r = world.step(
                &TipInput {
                    position_m: at(gap),
                },
                spec.dt_s,
            )?;
            let (gaps, forces) = if leg == 0 {
                (&mut c.approach_gap_m, &mut c.approach_force_n)
            } else {
                (&mut c.retract_gap_m, &mut c.retract_force_n)
            };
            gaps.push(gap);
            forces.push(r.force_n.z);
            for e in &r.events {
                match e {
                    Event::Snap { .. } if leg == 0 && c.snap_index.is_none() => {
                        c.snap_index = Some(k)
                    }
                    Event::PullOff { .. } if leg == 1 && c.pull_off_index.is_none() => {
                        c.pull_off_index = Some(k)
                    }
                    _ => {}
                }
            }
        }
    }
    let integral = |g: &[f64], f: &[f64]| -> f64 {
        g.windows(2)
            .zip(f.windows(2))
            .map(|(g, f)| 0.5 * (f[0] + f[1]) * (g[1] - g[0]))
            .sum()
    };
    c.hysteresis_j = -(integral(&c.approach_gap_m, &c.approach_force_n)
        + integral(&c.retract_gap_m, &c.retract_force_n));
    Ok(c)
}
