//! Scripted sessions: cursor paths that stand in for a hand on the device.

use nalgebra::Vector3;
use thiserror::Error;
use world_form::{ValueError, fmt_sig};

use crate::law::PairKind;
use crate::world::{TipInput, World};

/// Why a house script cannot be planned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScriptError {
    /// The world has no loading zone to fetch atoms from.
    #[error("loading_zone is missing: the house script fetches atoms from it")]
    NoLoadingZone,
    /// The world has no house blueprint.
    #[error("house is missing: nothing to build")]
    NoHouse,
    /// A slot has no atom (initial or earlier slot) directly below it at bonding distance.
    #[error(
        "house.slots_m[{slot}] has no support: allowed slots sit 2*atoms.radius_m (+ contact gap) above an initial atom or an earlier slot"
    )]
    Unsupported {
        /// Slot index.
        slot: usize,
    },
    /// `step_m` is not a positive finite length.
    #[error(transparent)]
    BadStep(ValueError),
    /// `step_m` is so small that the script would exceed [`MAX_SCRIPT_SAMPLES`].
    #[error("{error}")]
    TooManySamples {
        /// The step asked for (m) and the range this house allows.
        error: ValueError,
        /// The path's length, m.
        path_m: f64,
        /// The smallest step this path allows, m.
        min_step_m: f64,
    },
}

/// The most cursor samples a planned script may hold (10^7 samples, 240 MB: about 2.8 hours
/// of a 1 kHz session).
pub const MAX_SCRIPT_SAMPLES: usize = 10_000_000;

/// How many samples [`polyline`] makes for `points` at `step_m` (without making them).
pub fn polyline_len(points: &[Vector3<f64>], step_m: f64) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    1.0 + points
        .windows(2)
        .map(|w| ((w[1] - w[0]).norm() / step_m).ceil().max(1.0))
        .sum::<f64>()
}

/// Cursor positions visiting `points` in order along straight lines, at most `step_m`
/// apart (the first point included once).
pub fn polyline(points: &[Vector3<f64>], step_m: f64) -> Vec<TipInput> {
    let mut out = Vec::new();
    let Some(first) = points.first() else {
        return out;
    };
    out.push(TipInput { position_m: *first });
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let n = ((d.norm() / step_m).ceil() as usize).max(1);
        for k in 1..=n {
            out.push(TipInput {
                position_m: w[0] + d * (k as f64 / n as f64),
            });
        }
    }
    out
}

/// Plan the house: for each blueprint slot in order, fetch an atom from the loading zone
/// (descend onto it from above until it jumps onto the tip), carry it above the slot at a
/// safe height, descend until it snaps onto the atom below the slot, and retract until
/// the tip–atom bond breaks (the atom stays: transfer). Returns the waypoints (m), starting
/// and ending at the current cursor. Uses the world's own laws for every distance.
pub fn house_waypoints(world: &World) -> Result<Vec<Vector3<f64>>, ScriptError> {
    let p = world.params();
    let zone = p.loading_zone.as_ref().ok_or(ScriptError::NoLoadingZone)?;
    let house = p.house.as_ref().ok_or(ScriptError::NoHouse)?;
    let laws = world.laws();
    let (rt, ra) = (p.tip.radius_m, p.atoms.radius_m);
    let cg = laws.get(PairKind::AtomAtom).contact_gap_m;
    let hang = rt + ra + laws.get(PairKind::TipAtom).contact_gap_m;
    let bond = 2.0 * ra + cg;
    let mut supports: Vec<Vector3<f64>> = world.atoms().iter().map(|a| a.position_m()).collect();
    for (k, s) in house.slots_m.iter().enumerate() {
        let s = Vector3::new(s[0], s[1], s[2]);
        let below = s - Vector3::z() * bond;
        if !supports.iter().any(|q| (q - below).norm() <= 1e-6 * bond) {
            return Err(ScriptError::Unsupported { slot: k });
        }
        supports.push(s);
    }
    // Safe height: above everything by the largest reach, plus room to pull off.
    let mut reach: f64 = 0.0;
    let mut pull: f64 = 0.0;
    for kind in PairKind::ALL {
        let l = laws.get(kind);
        let r = if l.cutoff_gap_m.is_finite() {
            l.cutoff_gap_m
        } else {
            20.0 * l.snap_gap_m
        };
        reach = reach.max(r);
        pull = pull.max(l.pull_off_n / l.stiffness_n_per_m);
    }
    let top = supports.iter().map(|q| q.z).fold(f64::MIN, f64::max);
    let safe = top + ra + hang + 2.0 * reach + 1.5 * pull;
    let spawn = world.rest_position(zone.spawn_xy_m);
    let start = world.cursor_m();
    let mut pts = vec![start];
    let ta_snap = laws.get(PairKind::TipAtom).snap_gap_m;
    let aa_snap = laws.get(PairKind::AtomAtom).snap_gap_m;
    for s in &house.slots_m {
        let above = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        pts.push(above(spawn.x, spawn.y, safe));
        pts.push(above(spawn.x, spawn.y, spawn.z + rt + ra + 0.5 * ta_snap));
        pts.push(above(spawn.x, spawn.y, safe));
        pts.push(above(s[0], s[1], safe));
        pts.push(above(s[0], s[1], s[2] + hang + 0.5 * aa_snap));
        pts.push(above(s[0], s[1], safe));
    }
    pts.push(start);
    Ok(pts)
}

/// The house script as cursor inputs at most `step_m` (m) apart.
pub fn house_script(world: &World, step_m: f64) -> Result<Vec<TipInput>, ScriptError> {
    if !(step_m.is_finite() && step_m > 0.0 && step_m <= 1e-6) {
        return Err(ScriptError::BadStep(ValueError::out_of_range(
            "step_m",
            step_m,
            "0 < step_m <= 1e-6 m",
        )));
    }
    let pts = house_waypoints(world)?;
    if polyline_len(&pts, step_m) > MAX_SCRIPT_SAMPLES as f64 {
        let path_m: f64 = pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        // Each segment rounds up to whole steps: leave room for one extra sample per segment.
        let min_step_m = path_m / (MAX_SCRIPT_SAMPLES - pts.len()) as f64;
        return Err(ScriptError::TooManySamples {
            error: ValueError::out_of_range(
                "step_m",
                step_m,
                format!(
                    "{} <= step_m <= 1e-6 m for this house (its path is {} m long; at most \
                     {MAX_SCRIPT_SAMPLES} samples)",
                    fmt_sig(min_step_m, 6),
                    fmt_sig(path_m, 6)
                ),
            ),
            path_m,
            min_step_m,
        });
    }
    Ok(polyline(&pts, step_m))
}
