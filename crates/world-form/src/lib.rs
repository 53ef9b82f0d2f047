//! # world-form — the bottom of the workspace: device limits, numbers, strict arrays
//!
//! Every world (optical tweezers, bricks, atoms, the calibration wall) is built from its SI
//! `Params` and the [`Limits`] of the device it renders to, and steps with
//! `step(&Input) -> StepReport` (force N, stiffness felt N/m, typed events). That form is a
//! convention each world keeps (`docs/extending.md`), not a trait here; this crate holds the
//! small pieces every world and most other crates need, each defined once, and depends on no
//! workspace crate:
//!
//! * [`Limits`]: what a device can render (largest force, N; largest stable stiffness, N/m),
//!   the shipped device models' figures ([`Limits::FALCON`], [`Limits::TOUCH`]), its one range
//!   check ([`Limits::validate`], [`LimitsError`]) and its mapping into a world's units
//!   ([`Limits::in_world`]). Used by every world, `haptic-types`' device specifications, the
//!   recording's session header and the engine.
//! * [`numbers`]: the one way a number is written in a message ([`fmt_num`]) and the one
//!   percentile (nearest rank), used by errors, reports, pacing statistics and benchmarks.
//! * [`exact`]: fixed-length arrays read strictly from scene files and Python dicts (a
//!   `[f64; 3]` given four numbers is an error, not silently cut).
//!
//! What it is not: no device I/O, buttons or workspace (those are `haptic-types`' device
//! specifications and `haptic-devices`' sources), no physics, no world of its own, no loop.
//!
//! ```
//! use world_form::Limits;
//! assert_eq!(Limits::FALCON.max_force_n, 8.0);
//! let bad = Limits { max_force_n: f64::NAN, ..Limits::FALCON };
//! assert_eq!(
//!     bad.validate().unwrap_err().to_string(),
//!     "`max_force_n` = NaN is out of range: allowed 0 < max_force_n ≤ 100000 N"
//! );
//! ```

pub mod exact;
pub mod numbers;
pub mod value;

pub use numbers::{fmt_num, fmt_sig};
pub use value::ValueError;

use serde::{Deserialize, Serialize};

/// What a haptic device can render, expressed where a world uses it (CHAI3D's
/// `cHapticDeviceInfo`: `m_maxLinearForce`, `m_maxLinearStiffness`).
///
/// A world scales its force down to `max_force_n` and never renders a spring stiffer than
/// `max_stiffness_n_per_m`. The haptic loop hands each world the device's limits mapped into
/// the world's frame and units (divided by the force scale of the mapping).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Largest force magnitude the device renders, N.
    pub max_force_n: f64,
    /// Largest stiffness the device renders stably at a 1 kHz servo rate, N/m.
    #[serde(alias = "max_stiffness_n_m")]
    pub max_stiffness_n_per_m: f64,
}

/// Largest force a [`Limits`] may state, N.
pub const MAX_FORCE_LIMIT_N: f64 = 1e5;
/// Largest stiffness a [`Limits`] may state, N/m.
pub const MAX_STIFFNESS_LIMIT_N_PER_M: f64 = 1e7;

/// A limit that is not finite, not positive or beyond the largest allowed value: a
/// [`ValueError`] naming the field (`` `max_force_n` ``) and its range with the unit.
pub type LimitsError = ValueError;

impl Limits {
    /// Novint Falcon: 8 N, 3000 N/m — the figures of CHAI3D's Falcon driver
    /// (`CFalconDevice.cpp`: `m_maxLinearForce = 8.0`, `m_maxLinearStiffness = 3000.0`).
    /// Novint's brochure says "over 2 lbf" (8.9 N) peak; 8 N is what CHAI3D renders, and the one
    /// figure used everywhere here.
    pub const FALCON: Limits = Limits {
        max_force_n: 8.0,
        max_stiffness_n_per_m: 3000.0,
    };

    /// 3D Systems Touch (SensAble Phantom Omni class): 3.3 N peak force, 400 N/m (the low end
    /// of the published 400–700 N/m).
    pub const TOUCH: Limits = Limits {
        max_force_n: 3.3,
        max_stiffness_n_per_m: 400.0,
    };

    /// Checks both limits are finite, positive and at most [`MAX_FORCE_LIMIT_N`] /
    /// [`MAX_STIFFNESS_LIMIT_N_PER_M`].
    pub fn validate(&self) -> Result<(), LimitsError> {
        check("max_force_n", self.max_force_n, MAX_FORCE_LIMIT_N, "N")?;
        check(
            "max_stiffness_n_per_m",
            self.max_stiffness_n_per_m,
            MAX_STIFFNESS_LIMIT_N_PER_M,
            "N/m",
        )
    }

    /// What the device can render expressed in a world the device maps onto: one world newton
    /// is `force_scale` device newtons and one device metre is `workspace_scale` world metres
    /// (both > 0). Forces divide by `force_scale`; stiffnesses by
    /// `force_scale · workspace_scale` (a world spring `k` is felt as `k · force_scale ·
    /// workspace_scale` on the device).
    pub fn in_world(&self, force_scale: f64, workspace_scale: f64) -> Limits {
        Limits {
            max_force_n: self.max_force_n / force_scale,
            max_stiffness_n_per_m: self.max_stiffness_n_per_m / (force_scale * workspace_scale),
        }
    }
}

fn check(field: &'static str, value: f64, max: f64, unit: &'static str) -> Result<(), LimitsError> {
    if value.is_finite() && value > 0.0 && value <= max {
        Ok(())
    } else {
        Err(ValueError::out_of_range(
            format!("`{field}`"),
            value,
            format!("0 < {field} ≤ {} {unit}", fmt_num(max)),
        ))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn each_bad_limit_is_named_with_its_range() {
        let e = Limits {
            max_stiffness_n_per_m: 0.0,
            ..Limits::FALCON
        }
        .validate()
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "`max_stiffness_n_per_m` = 0 is out of range: allowed 0 < max_stiffness_n_per_m ≤ 1e7 \
             N/m"
        );
        let e = Limits {
            max_force_n: 2e5,
            ..Limits::TOUCH
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.field(), "`max_force_n`");
        assert!(Limits::FALCON.validate().is_ok());
        assert!(Limits::TOUCH.validate().is_ok());
    }

    #[test]
    fn limits_in_a_world_follow_the_mapping() {
        // The optical-tweezers scene: 1 mm of stylus = 1 µm, 1 µN of world force = 1 N felt.
        let l = Limits::FALCON.in_world(1e6, 1e-3);
        assert_eq!(l.max_force_n, 8e-6);
        assert_eq!(l.max_stiffness_n_per_m, 3.0);
    }

    #[test]
    fn the_old_unit_spelling_still_loads() {
        let l: Limits = toml::from_str("max_force_n = 9.0\nmax_stiffness_n_m = 3000.0").unwrap();
        assert_eq!(l.max_stiffness_n_per_m, 3000.0);
        let err = toml::from_str::<Limits>("max_force_n = 9.0\nstiffness = 1.0").unwrap_err();
        assert!(
            err.to_string().contains("unknown field `stiffness`"),
            "{err}"
        );
    }
}
