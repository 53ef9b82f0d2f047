//! The hand: a spring-damper from the stylus to the operator's intended path.

use serde::{Deserialize, Serialize};
use world_form::ValueError;
use world_form::value::in_range;

/// How firmly a hand holds the stylus: the impedance of the arm around its intended path
/// (`F = k (x_intent − x) + b (v_intent − v)`), plus the part of the hand's mass that moves with
/// the stylus.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grip {
    /// Stiffness of the hand to its intended path, N/m. Range `(0, 10000]`.
    pub stiffness_n_per_m: f64,
    /// Damping of the hand to its intended velocity, N·s/m. Range `[0, 200]`.
    pub damping_n_s_per_m: f64,
    /// Mass of the fingers that moves with the stylus, kg (added to the device's moving mass).
    /// Range `[0, 2]`.
    #[serde(default)]
    pub mass_kg: f64,
}

/// A grip given out of range or in a form that does not parse.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GripError {
    /// A number out of range (`` `k` ``, `` `b` `` or `` `m` ``), its range with the unit.
    #[error("grip {0}")]
    OutOfRange(ValueError),
    /// Text that is neither `loose`, `firm` nor `k=…,b=…[,m=…]`.
    #[error(
        "grip `{0}` is not understood (allowed: loose, firm, or k=N/m,b=N·s/m[,m=kg], e.g. k=500,b=4)"
    )]
    Syntax(String),
}

impl Grip {
    /// A loose grip: 300 N/m, 2 N·s/m (the lower end of arm impedances measured for a light
    /// pinch grasp; the setting under which the carried brick buzzed in issue 22).
    pub const LOOSE: Grip = Grip {
        stiffness_n_per_m: 300.0,
        damping_n_s_per_m: 2.0,
        mass_kg: 0.0,
    };
    /// A firm grip: 1000 N/m, 8 N·s/m.
    pub const FIRM: Grip = Grip {
        stiffness_n_per_m: 1000.0,
        damping_n_s_per_m: 8.0,
        mass_kg: 0.0,
    };

    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), GripError> {
        let check = |field: &str, value: f64, ok: bool, allowed: &'static str| {
            in_range(format!("`{field}`"), value, ok, allowed).map_err(GripError::OutOfRange)
        };
        let k = self.stiffness_n_per_m;
        check("k", k, k > 0.0 && k <= 1e4, "0 < k ≤ 10000 N/m")?;
        let b = self.damping_n_s_per_m;
        check("b", b, (0.0..=200.0).contains(&b), "0 ≤ b ≤ 200 N·s/m")?;
        let m = self.mass_kg;
        check("m", m, (0.0..=2.0).contains(&m), "0 ≤ m ≤ 2 kg")
    }

    /// Parses `loose`, `firm` or `k=…,b=…[,m=…]` (N/m, N·s/m, kg; `b` and `m` default to 0).
    ///
    /// ```
    /// use haptic_devices::Grip;
    /// assert_eq!(Grip::parse("firm").unwrap(), Grip::FIRM);
    /// let g = Grip::parse("k=500,b=4").unwrap();
    /// assert_eq!((g.stiffness_n_per_m, g.damping_n_s_per_m), (500.0, 4.0));
    /// assert_eq!(
    ///     Grip::parse("k=0,b=4").unwrap_err().to_string(),
    ///     "grip `k` = 0 is out of range: allowed 0 < k ≤ 10000 N/m"
    /// );
    /// ```
    pub fn parse(text: &str) -> Result<Grip, GripError> {
        match text.trim() {
            "loose" => return Ok(Grip::LOOSE),
            "firm" => return Ok(Grip::FIRM),
            _ => {}
        }
        let syntax = || GripError::Syntax(text.to_string());
        let (mut k, mut b, mut m) = (None, 0.0, 0.0);
        for part in text.split(',') {
            let (key, value) = part.split_once('=').ok_or_else(syntax)?;
            let v: f64 = value.trim().parse().map_err(|_| syntax())?;
            match key.trim() {
                "k" => k = Some(v),
                "b" => b = v,
                "m" => m = v,
                _ => return Err(syntax()),
            }
        }
        let g = Grip {
            stiffness_n_per_m: k.ok_or_else(syntax)?,
            damping_n_s_per_m: b,
            mass_kg: m,
        };
        g.validate()?;
        Ok(g)
    }

    /// The grip as it is written on a command line: `loose`, `firm` or `k=…,b=…,m=…`.
    pub fn label(&self) -> String {
        if *self == Grip::LOOSE {
            "loose".into()
        } else if *self == Grip::FIRM {
            "firm".into()
        } else {
            format!(
                "k={},b={},m={}",
                self.stiffness_n_per_m, self.damping_n_s_per_m, self.mass_kg
            )
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn grips_parse_and_refuse_with_the_field_named() {
        assert_eq!(Grip::parse("loose").unwrap(), Grip::LOOSE);
        let g = Grip::parse("k=800, b=5, m=0.1").unwrap();
        assert_eq!(g.mass_kg, 0.1);
        assert_eq!(Grip::parse(&g.label()).unwrap(), g);
        assert_eq!(
            Grip::parse("b=-1,k=300").unwrap_err().to_string(),
            "grip `b` = -1 is out of range: allowed 0 ≤ b ≤ 200 N·s/m"
        );
        assert_eq!(
            Grip::parse("k=NaN").unwrap_err().to_string(),
            "grip `k` = NaN is out of range: allowed 0 < k ≤ 10000 N/m"
        );
        assert!(matches!(Grip::parse("tight"), Err(GripError::Syntax(_))));
        assert!(matches!(Grip::parse("b=3"), Err(GripError::Syntax(_))));
        assert!(matches!(Grip::parse("k=3,q=1"), Err(GripError::Syntax(_))));
    }
}
