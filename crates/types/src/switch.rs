//! Run-time switches: what the teaching game's menu changes during a session (gravity,
//! restitution, friction, inertia and brick mass in the macro world; pair strengths, atom mass,
//! gravity and inertia in the nano world).
//!
//! A scene lists the switches it offers ([`SwitchSpec`]); a switch is set by name to a number
//! (a boolean switch takes 0 = off or 1 = on). A script schedules switches at given times
//! (`[[switch]]`), the loop applies them before the tick's step, and the recording keeps them
//! as an input of the tick (`/scene/switch`), so that replay applies them on the same tick.

use serde::Serialize;

/// One switch a scene offers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwitchSpec {
    /// Name as written in scripts, with its unit as suffix (`gravity_m_per_s2`).
    pub name: &'static str,
    /// An earlier name still accepted (`gravity_m_s2`, before the one unit spelling); the
    /// switch is applied and recorded under [`SwitchSpec::name`].
    pub old_name: Option<&'static str>,
    /// Smallest allowed value (inclusive).
    pub min: f64,
    /// Largest allowed value (inclusive).
    pub max: f64,
    /// A boolean switch: 0 (off) or 1 (on) only.
    pub boolean: bool,
    /// What it changes, in words (for errors and docs).
    pub doc: &'static str,
}

impl SwitchSpec {
    /// A numeric switch in `[min, max]`.
    pub const fn number(name: &'static str, min: f64, max: f64, doc: &'static str) -> Self {
        SwitchSpec {
            name,
            old_name: None,
            min,
            max,
            boolean: false,
            doc,
        }
    }

    /// A boolean switch (0 = off, 1 = on).
    pub const fn on_off(name: &'static str, doc: &'static str) -> Self {
        SwitchSpec {
            name,
            old_name: None,
            min: 0.0,
            max: 1.0,
            boolean: true,
            doc,
        }
    }

    /// The same switch, also accepted under `old` (a name scripts used before; the switch is
    /// still applied and recorded under its own name).
    pub const fn or_old_name(self, old: &'static str) -> Self {
        SwitchSpec {
            old_name: Some(old),
            ..self
        }
    }

    /// Whether `name` names this switch (its name or its old name).
    pub fn is_named(&self, name: &str) -> bool {
        self.name == name || self.old_name == Some(name)
    }

    /// The allowed values in words.
    pub fn allowed(&self) -> String {
        if self.boolean {
            "true / false (1 / 0)".to_string()
        } else {
            format!("{} ≤ value ≤ {}", self.min, self.max)
        }
    }

    fn admits(&self, v: f64) -> bool {
        if self.boolean {
            v == 0.0 || v == 1.0
        } else {
            v.is_finite() && v >= self.min && v <= self.max
        }
    }
}

/// A switch set to a value: an input of the tick it applies to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Switch {
    /// The switch's name (one of the scene's [`SwitchSpec`]s).
    pub name: String,
    /// Its new value (booleans: 0 or 1).
    pub value: f64,
}

/// A switch the scene does not offer, or a value outside its range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SwitchError {
    /// No switch of that name in this scene.
    #[error("the {kind} scene has no switch `{name}` (its switches: {allowed})")]
    Unknown {
        /// Scene kind.
        kind: String,
        /// The name asked for.
        name: String,
        /// The names it has, comma-separated (`none` when it has none).
        allowed: String,
    },
    /// A value outside the switch's range (its field is `` switch `name` ``).
    #[error(transparent)]
    OutOfRange(crate::ValueError),
    /// The world refused a value its range admits (a combination it cannot hold).
    #[error("switch `{name}` = {}: {message}", world_form::fmt_num(*value))]
    Refused {
        /// The switch.
        name: String,
        /// The value given.
        value: f64,
        /// The world's reason.
        message: String,
    },
}

/// The detail of the `switch.set` event: `{"name":"gravity_m_per_s2","value":0.0}` (JSON; the
/// value's shortest round-trip decimal form).
pub fn event_detail(s: &Switch) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| format!("{{\"name\":\"{}\"}}", s.name))
}

/// Checks `name = value` against the switches `specs` of a scene of kind `kind`; `name` may be
/// a switch's old name. Returns the switch, whose [`SwitchSpec::name`] is the one to apply and
/// record.
pub fn check(
    kind: &str,
    specs: &[SwitchSpec],
    name: &str,
    value: f64,
) -> Result<SwitchSpec, SwitchError> {
    let Some(spec) = specs.iter().find(|s| s.is_named(name)) else {
        let names: Vec<&str> = specs.iter().map(|s| s.name).collect();
        return Err(SwitchError::Unknown {
            kind: kind.to_string(),
            name: name.to_string(),
            allowed: if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            },
        });
    };
    if !spec.admits(value) {
        return Err(SwitchError::OutOfRange(crate::ValueError::out_of_range(
            format!("switch `{name}`"),
            value,
            spec.allowed(),
        )));
    }
    Ok(*spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPECS: [SwitchSpec; 2] = [
        SwitchSpec::number("gravity_m_per_s2", 0.0, 100.0, "gravity").or_old_name("gravity_m_s2"),
        SwitchSpec::on_off("inertia", "inertial force"),
    ];

    #[test]
    fn unknown_names_and_out_of_range_values_are_named() {
        assert_eq!(
            check("brickworld", &SPECS, "gravity", 1.0)
                .unwrap_err()
                .to_string(),
            "the brickworld scene has no switch `gravity` (its switches: gravity_m_per_s2, inertia)"
        );
        assert_eq!(
            check("wall", &[], "gravity", 1.0).unwrap_err().to_string(),
            "the wall scene has no switch `gravity` (its switches: none)"
        );
        assert_eq!(
            check("brickworld", &SPECS, "gravity_m_per_s2", 101.0)
                .unwrap_err()
                .to_string(),
            "switch `gravity_m_per_s2` = 101 is out of range: allowed 0 ≤ value ≤ 100"
        );
        assert_eq!(
            check("brickworld", &SPECS, "inertia", 0.5)
                .unwrap_err()
                .to_string(),
            "switch `inertia` = 0.5 is out of range: allowed true / false (1 / 0)"
        );
        assert!(check("brickworld", &SPECS, "gravity_m_per_s2", f64::NAN).is_err());
        assert!(check("brickworld", &SPECS, "gravity_m_per_s2", 0.0).is_ok());
        assert!(check("brickworld", &SPECS, "inertia", 1.0).is_ok());
        // The old spelling still names the switch, which answers with its new name.
        let spec = check("brickworld", &SPECS, "gravity_m_s2", 0.0).unwrap();
        assert_eq!(spec.name, "gravity_m_per_s2");
        assert_eq!(
            check("brickworld", &SPECS, "gravity_m_s2", 101.0)
                .unwrap_err()
                .to_string(),
            "switch `gravity_m_s2` = 101 is out of range: allowed 0 ≤ value ≤ 100"
        );
    }
}
