//! What a device is mechanically: moving mass, friction, encoder, force resolution, servo rate.

use serde::{Deserialize, Serialize};
use world_form::Limits;
use world_form::ValueError;
use world_form::value::in_range;

/// The mechanics of a haptic device at its end effector, one translational axis model applied
/// to each of x, y and z (a 3-DOF device linearised about the centre of its workspace).
///
/// Figures and their sources are in `docs/devices.md`; figures a manufacturer does not publish
/// (moving mass, friction, force resolution of the Falcon) are independent measurements or
/// estimates and say so there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mechanics {
    /// Model name as written on command lines (`falcon`, `touch`, `delta3`, `inverse3`).
    #[serde(skip)]
    pub name: &'static str,
    /// Apparent moving mass at the end effector, kg. Range `(0, 10]`.
    pub moving_mass_kg: f64,
    /// Viscous friction of the mechanism, N·s/m. Range `[0, 100]`.
    pub viscous_n_s_per_m: f64,
    /// Position resolution: the encoder reports whole multiples of this, m (0: ideal).
    /// Range `[0, 0.01]`.
    pub encoder_quantum_m: f64,
    /// Force resolution: each force component is rendered in whole multiples of this, N
    /// (0: ideal). Range `[0, 1]`.
    pub force_quantum_n: f64,
    /// The device's own servo rate, Hz: between two packets of the loop it renders the last
    /// command's local model `F0 − K (p − p0)` at this rate. Range `[100, 100000]`.
    pub servo_rate_hz: f64,
    /// Largest force (N) and largest stable stiffness at 1 kHz (N/m).
    pub limits: Limits,
    /// Radius of the reachable workspace around its centre, m.
    pub workspace_radius_m: f64,
}

/// A mechanics field out of range, or an unknown preset.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MechanicsError {
    /// A field (named in backticks) out of range, its allowed range with the unit.
    #[error("device {0}")]
    OutOfRange(ValueError),
    /// A preset name that is not known.
    #[error("unknown device model `{0}` (allowed: falcon, touch, delta3, inverse3)")]
    UnknownPreset(String),
}

/// The shipped presets, in the order of [`Mechanics::preset`]'s error message.
pub const PRESETS: [Mechanics; 4] = [
    Mechanics::FALCON,
    Mechanics::TOUCH,
    Mechanics::DELTA3,
    Mechanics::INVERSE3,
];

impl Mechanics {
    /// Novint Falcon: 400 dpi encoders (0.0635 mm), 8 N and 3000 N/m (CHAI3D's driver),
    /// 1 kHz; moving mass ≈ 0.15 kg and friction ≈ 0.2 N·s/m are independent estimates (the
    /// upper end of the 0.05–0.15 kg range issue 22 was reproduced with, the harder case),
    /// force resolution 8 N / 2¹¹ (a 12-bit signed command; not published).
    pub const FALCON: Mechanics = Mechanics {
        name: "falcon",
        moving_mass_kg: 0.15,
        viscous_n_s_per_m: 0.2,
        encoder_quantum_m: 0.0635e-3,
        force_quantum_n: 8.0 / 2048.0,
        servo_rate_hz: 1000.0,
        limits: Limits::FALCON,
        workspace_radius_m: 0.04,
    };
    /// 3D Systems Touch: apparent mass at the tip 45 g, > 450 dpi (0.055 mm), 3.3 N peak,
    /// backdrive friction 0.26 N (as ≈ 0.1 N·s/m viscous at the speeds of use), 1 kHz
    /// (OpenHaptics' servo loop); stiffness cap 400 N/m as [`Limits::TOUCH`].
    pub const TOUCH: Mechanics = Mechanics {
        name: "touch",
        moving_mass_kg: 0.045,
        viscous_n_s_per_m: 0.1,
        encoder_quantum_m: 0.055e-3,
        force_quantum_n: 3.3 / 2048.0,
        servo_rate_hz: 1000.0,
        limits: Limits::TOUCH,
        workspace_radius_m: 0.075,
    };
    /// Force Dimension delta.3: 20 N continuous, resolution < 0.02 mm, up to 4 kHz (Force
    /// Dimension's sheet); stiffness cap 5000 N/m as CHAI3D's driver renders it at a 1 kHz loop
    /// (the sheet's 14.5 N/mm is the device's own closed-loop figure, not a virtual wall's);
    /// moving mass ≈ 0.25 kg and friction ≈ 0.5 N·s/m estimated.
    pub const DELTA3: Mechanics = Mechanics {
        name: "delta3",
        moving_mass_kg: 0.25,
        viscous_n_s_per_m: 0.5,
        encoder_quantum_m: 0.02e-3,
        force_quantum_n: 20.0 / 4096.0,
        servo_rate_hz: 4000.0,
        limits: Limits {
            max_force_n: 20.0,
            max_stiffness_n_per_m: 5000.0,
        },
        workspace_radius_m: 0.13,
    };
    /// Haply Inverse3: servo up to 8 kHz (Haply's `Inverse3.h`; 4 kHz used), 10 N (a
    /// third-party CHAI3D driver's figure), 1000 N/m (the stiffness of Haply's own Python wall
    /// sample at 1 kHz); resolution ≈ 0.01 mm, moving mass ≈ 0.1 kg and friction estimated
    /// (not published).
    pub const INVERSE3: Mechanics = Mechanics {
        name: "inverse3",
        moving_mass_kg: 0.1,
        viscous_n_s_per_m: 0.2,
        encoder_quantum_m: 0.01e-3,
        force_quantum_n: 10.0 / 4096.0,
        servo_rate_hz: 4000.0,
        limits: Limits {
            max_force_n: 10.0,
            max_stiffness_n_per_m: 1000.0,
        },
        workspace_radius_m: 0.2,
    };

    /// The preset named `name` (`falcon`, `touch`, `delta3`, `inverse3`).
    pub fn preset(name: &str) -> Result<Mechanics, MechanicsError> {
        PRESETS
            .iter()
            .find(|m| m.name == name)
            .copied()
            .ok_or_else(|| MechanicsError::UnknownPreset(name.to_string()))
    }

    /// The same device with ideal sensing: no encoder counts, no force resolution.
    pub fn without_quantization(self) -> Mechanics {
        Mechanics {
            encoder_quantum_m: 0.0,
            force_quantum_n: 0.0,
            ..self
        }
    }

    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), MechanicsError> {
        let check = |field: &str, value: f64, ok: bool, allowed: &'static str| {
            in_range(format!("`{field}`"), value, ok, allowed).map_err(MechanicsError::OutOfRange)
        };
        let m = self.moving_mass_kg;
        check(
            "moving_mass_kg",
            m,
            m > 0.0 && m <= 10.0,
            "0 < moving_mass_kg ≤ 10 kg",
        )?;
        let b = self.viscous_n_s_per_m;
        check(
            "viscous_n_s_per_m",
            b,
            (0.0..=100.0).contains(&b),
            "0 ≤ viscous_n_s_per_m ≤ 100 N·s/m",
        )?;
        let q = self.encoder_quantum_m;
        check(
            "encoder_quantum_m",
            q,
            (0.0..=0.01).contains(&q),
            "0 ≤ encoder_quantum_m ≤ 0.01 m",
        )?;
        let f = self.force_quantum_n;
        check(
            "force_quantum_n",
            f,
            (0.0..=1.0).contains(&f),
            "0 ≤ force_quantum_n ≤ 1 N",
        )?;
        let s = self.servo_rate_hz;
        check(
            "servo_rate_hz",
            s,
            (100.0..=1e5).contains(&s),
            "100 ≤ servo_rate_hz ≤ 100000 Hz",
        )?;
        self.limits.validate().map_err(MechanicsError::OutOfRange)?;
        let r = self.workspace_radius_m;
        check(
            "workspace_radius_m",
            r,
            r > 0.0 && r <= 10.0,
            "0 < workspace_radius_m ≤ 10 m",
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn presets_are_valid_and_named() {
        for p in PRESETS {
            p.validate().unwrap();
            assert_eq!(Mechanics::preset(p.name).unwrap(), p);
        }
        assert_eq!(
            Mechanics::preset("omega7").unwrap_err().to_string(),
            "unknown device model `omega7` (allowed: falcon, touch, delta3, inverse3)"
        );
        let bad = Mechanics {
            moving_mass_kg: 0.0,
            ..Mechanics::FALCON
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "device `moving_mass_kg` = 0 is out of range: allowed 0 < moving_mass_kg ≤ 10 kg"
        );
    }
}
