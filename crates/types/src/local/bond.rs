//! Bridge protocol 3's primitive: a spring that breaks.
//!
//! A [`Bond`] is the anchored contact of an adhesive world (the nano world's snap-to-contact),
//! felt as `k (a − p)` until the stylus has pulled it past its breaking stretch, and as nothing
//! beyond. Protocol 2 sends it as the residual's linear spring, which a device behind a link
//! extrapolates past the pull-off for a round trip: the hand feels a pull the world no longer
//! gives (issue 40: up to +29 % of the peak force at 10 ms).
//!
//! ```
//! use haptic_types::local::Bond;
//! // A bond anchored at the origin on a surface facing +z, 100 N/m, breaking at 2 mm.
//! let b = Bond { anchor_m: [0.0; 3], normal: [0.0, 0.0, 1.0], stiffness_n_per_m: 100.0, break_m: 0.002 };
//! assert!((b.force([0.0, 0.0, 0.0015])[2] + 0.15).abs() < 1e-12); // holds: 0.15 N down
//! assert_eq!(b.force([0.0, 0.0, 0.0025]), [0.0; 3]); // broken
//! // Pressing into the surface does not break it: only the pull and the shear count.
//! assert!(b.force([0.0, 0.0, -0.0025])[2] > 0.0);
//! ```

use super::{LocalModel, range};
use crate::vec3::{self, Vec3};
use world_form::fmt_num;

/// A spring that breaks: `F = k (a − p)` while the bond's stretch `s(p) < break_m`, 0 from
/// there. The stretch counts the pull away from the surface and the shear, not a press into
/// it: with `d = p − a`, `s = |d − min(0, n·d) n|` (the nano world's pull on a bond).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Bond {
    /// Where the spring holds the stylus, m.
    pub anchor_m: Vec3,
    /// Unit normal of the surface the stylus is bonded to, pointing to the stylus's side.
    pub normal: Vec3,
    /// The spring's stiffness, N/m (0 ≤ k ≤ the device's largest stiffness).
    pub stiffness_n_per_m: f64,
    /// The stretch at which it breaks, m (> 0): the pull-off force over the stiffness.
    pub break_m: f64,
}

impl Bond {
    /// The bond's stretch at `p`, m.
    pub fn stretch_m(&self, p: Vec3) -> f64 {
        let d = vec3::sub(p, self.anchor_m);
        let along = vec3::dot(d, self.normal);
        vec3::norm(vec3::sub(d, vec3::scale(self.normal, along.min(0.0))))
    }

    /// Whether the bond holds at `p`.
    pub fn holds(&self, p: Vec3) -> bool {
        self.stretch_m(p) < self.break_m
    }

    /// The bond's pull at `p`, N.
    pub fn force(&self, p: Vec3) -> Vec3 {
        if self.holds(p) {
            vec3::scale(vec3::sub(self.anchor_m, p), self.stiffness_n_per_m)
        } else {
            [0.0; 3]
        }
    }
}

/// Checks protocol 3's part of a model: a finite bond with a unit normal, a stiffness within
/// the device's cap and a breaking stretch in `(0, 1]` m.
pub(super) fn check(m: &LocalModel, max_stiffness_n_per_m: f64) -> Result<(), String> {
    if let Some(b) = &m.bond {
        let n = vec3::norm(b.normal);
        if !vec3::is_finite(b.anchor_m) || !vec3::is_finite(b.normal) || (n - 1.0).abs() > 1e-6 {
            return Err(
                "bond: the anchor must be finite and the normal a finite unit vector".into(),
            );
        }
        if !(0.0..=max_stiffness_n_per_m).contains(&b.stiffness_n_per_m) {
            return Err(range(
                "bond.stiffness_n_per_m",
                b.stiffness_n_per_m,
                format!("0 ≤ k ≤ {} N/m", fmt_num(max_stiffness_n_per_m)),
            ));
        }
        if !(b.break_m > 0.0 && b.break_m <= 1.0) {
            return Err(range("bond.break_m", b.break_m, "0 < s ≤ 1 m"));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bond() -> Bond {
        Bond {
            anchor_m: [0.0; 3],
            normal: [0.0, 0.0, 1.0],
            stiffness_n_per_m: 100.0,
            break_m: 0.002,
        }
    }

    /// The stretch is the nano world's pull: the pull along the normal and the shear, never a
    /// press into the surface; the bond breaks at its stretch, not before.
    #[test]
    fn a_bond_breaks_at_its_stretch_in_pull_or_shear_never_in_press() {
        let b = bond();
        assert_eq!(b.stretch_m([0.0, 0.0, 0.001]), 0.001);
        assert_eq!(b.stretch_m([0.0, 0.0, -0.005]), 0.0);
        assert!((b.stretch_m([0.0015, 0.0, -0.005]) - 0.0015).abs() < 1e-18);
        assert!(b.holds([0.0, 0.0, 0.001_999]));
        assert!(!b.holds([0.0, 0.0, 0.002]));
        assert!(!b.holds([0.002, 0.0, -0.01]));
        assert_eq!(b.force([0.0, 0.0, 0.001]), [0.0, 0.0, -0.1]);
        assert_eq!(b.force([0.0, 0.003, 0.0]), [0.0; 3]);
    }

    /// Protocol 3's part is checked by field and range.
    #[test]
    fn a_bad_bond_is_refused_by_name() {
        let mut m = LocalModel {
            bond: Some(Bond {
                break_m: 0.0,
                ..bond()
            }),
            ..LocalModel::default()
        };
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "bond.break_m = 0 is out of range: allowed 0 < s ≤ 1 m"
        );
        m.bond = Some(Bond {
            stiffness_n_per_m: 2000.0,
            ..bond()
        });
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "bond.stiffness_n_per_m = 2000 is out of range: allowed 0 ≤ k ≤ 1000 N/m"
        );
        m.bond = Some(bond());
        assert_eq!(m.check(1000.0), Ok(()));
    }
}
