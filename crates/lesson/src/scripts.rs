//! The hand motions of the lesson, as script texts (device frame, mm): the same motion is
//! played in both worlds where the lesson compares them.
//!
//! Device → world: brick world `origin (0, −0.05, 0.2) m + 20 · p`, nano world
//! `origin (4.05, 4.05, 3.5) nm + 1.5e-7 · p` (the built-in scenes' mappings).

use std::fmt::Write;

/// A script under construction.
pub struct ScriptText {
    text: String,
}

impl ScriptText {
    /// A script called `name`, played by a rigid stylus (the same operator everywhere).
    pub fn new(name: &str) -> Self {
        ScriptText {
            text: format!("[script]\nname = \"{name}\"\noperator = \"rigid\"\n"),
        }
    }

    /// The stylus at `mm` (device frame) at `t_s`.
    pub fn at(mut self, t_s: f64, mm: [f64; 3]) -> Self {
        let _ = write!(
            self.text,
            "\n[[waypoint]]\nt_s = {t_s:?}\nposition_mm = [{:?}, {:?}, {:?}]\n",
            mm[0], mm[1], mm[2]
        );
        self
    }

    /// Button `name` goes down (`down`) or up at `t_s`.
    pub fn button(mut self, t_s: f64, name: &str, down: bool) -> Self {
        let _ = write!(
            self.text,
            "\n[[button]]\nt_s = {t_s:?}\nname = \"{name}\"\ndown = {down}\n"
        );
        self
    }

    /// Switch `name` takes `value` at `t_s`.
    pub fn switch(mut self, t_s: f64, name: &str, value: f64) -> Self {
        let _ = write!(
            self.text,
            "\n[[switch]]\nt_s = {t_s:?}\nname = \"{name}\"\nvalue = {value:?}\n"
        );
        self
    }

    /// The script's TOML text.
    pub fn text(self) -> String {
        self.text
    }
}

/// Where the brick world's loading-zone brick is grabbed (device mm): the house script's first
/// pick-up, above the brick at (−0.45, 0, 0.03) m.
pub const BRICK_PICK_MM: [f64; 3] = [-22.5, 2.5, -6.8];
/// Carry height of the brick world's house script, device mm.
pub const BRICK_CARRY_Z_MM: f64 = 7.5;

/// Lifting a brick and holding it still: grab, lift in 0.6 s, hold 0.8 s, carry 22.5 mm
/// (0.45 m in the world) sideways in 0.9 s, hold 0.5 s. Times of the phases are returned with
/// the text: (grab, lift end, carry start, carry end).
pub fn brick_lift(switches: &[(&str, f64)]) -> (String, [f64; 4]) {
    let [x, y, z] = BRICK_PICK_MM;
    let mut s = ScriptText::new("lesson: lift and carry a brick")
        .at(0.0, [x, y, BRICK_CARRY_Z_MM])
        .at(0.6, [x, y, z])
        .at(0.7, [x, y, z])
        .button(0.65, "centre", true)
        .at(1.3, [x, y, BRICK_CARRY_Z_MM])
        .at(2.1, [x, y, BRICK_CARRY_Z_MM])
        .at(3.0, [0.0, y, BRICK_CARRY_Z_MM])
        .at(3.5, [0.0, y, BRICK_CARRY_Z_MM]);
    for (n, v) in switches {
        s = s.switch(0.0, n, *v);
    }
    (s.text(), [0.65, 1.3, 2.1, 3.0])
}

/// Throwing a brick: grab it, lift, swing 30 mm sideways in `swing_s` and let go at the middle
/// of the swing (the fastest point of a minimum-jerk move), then hold still. Returns the text
/// and the release time.
pub fn brick_throw(swing_s: f64) -> (String, f64) {
    let [x, y, z] = BRICK_PICK_MM;
    let t0 = 2.0;
    let release = t0 + 0.5 * swing_s;
    let s = ScriptText::new("lesson: throw a brick")
        .at(0.0, [x, y, BRICK_CARRY_Z_MM])
        .at(0.6, [x, y, z])
        .at(0.7, [x, y, z])
        .button(0.65, "centre", true)
        .at(1.3, [x, y, BRICK_CARRY_Z_MM])
        .at(t0, [x, y, BRICK_CARRY_Z_MM])
        .at(t0 + swing_s, [x + 30.0, y, BRICK_CARRY_Z_MM])
        .button(release, "centre", false)
        .at(t0 + swing_s + 2.0, [x + 30.0, y, BRICK_CARRY_Z_MM]);
    (s.text(), release)
}

/// Above the loading-zone atom of the nano world, device mm (the house script's pick-up).
pub const NANO_PICK_XY_MM: [f64; 2] = [-14.0, -14.0];
/// Carry height of the nano house script, device mm.
pub const NANO_CARRY_Z_MM: f64 = 26.08088022903977;
/// Depth of the nano house script's pick-up descent, device mm.
pub const NANO_PICK_Z_MM: f64 = -18.419119770960236;

/// The same throw in the nano world: pick up the loading-zone atom, lift, swing 30 mm sideways
/// in `swing_s` (the hand's motion of [`brick_throw`]; there is no release: atoms stick), hold.
pub fn atom_throw(swing_s: f64, switches: &[(&str, f64)]) -> String {
    let [x, y] = NANO_PICK_XY_MM;
    let t0 = 2.0;
    let mut s = ScriptText::new("lesson: try to throw an atom")
        .at(0.0, [x, y, NANO_CARRY_Z_MM])
        .at(0.557, [x, y, NANO_PICK_Z_MM])
        .at(1.113, [x, y, NANO_CARRY_Z_MM])
        .at(t0, [x, y, NANO_CARRY_Z_MM])
        .at(t0 + swing_s, [x + 30.0, y, NANO_CARRY_Z_MM])
        .at(t0 + swing_s + 0.5, [x + 30.0, y, NANO_CARRY_Z_MM]);
    for (n, v) in switches {
        s = s.switch(0.0, n, *v);
    }
    s.text()
}

/// Approach and retract over one substrate atom, away from every movable atom: the tip comes
/// down from 1.5 nm above the atom's top in 2 s, pushes 0.25 nm past contact, and goes back up
/// to 3 nm in 2 s. Substrate atom at (3.9, 3.9, 0) nm: device x = y = −1 mm.
pub fn approach_retract(switches: &[(&str, f64)]) -> String {
    // World z (nm) of the tip centre → device mm: (z − 3.5) / 0.15.
    let dev = |z_nm: f64| (z_nm - 3.5) / 0.15;
    let (top, low, high) = (0.45 + 1.5, 0.45 - 0.25, 0.45 + 3.0);
    let mut s = ScriptText::new("lesson: approach and retract")
        .at(0.0, [-1.0, -1.0, dev(top)])
        .at(2.0, [-1.0, -1.0, dev(low)])
        .at(2.2, [-1.0, -1.0, dev(low)])
        .at(4.2, [-1.0, -1.0, dev(high)]);
    for (n, v) in switches {
        s = s.switch(0.0, n, *v);
    }
    s.text()
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_devices::Script;
    use haptic_types::device::FALCON;

    #[test]
    fn every_lesson_script_is_a_valid_falcon_script() {
        let texts = [
            brick_lift(&[("gravity_m_per_s2", 0.0)]).0,
            brick_throw(0.3).0,
            atom_throw(0.3, &[("atom_mass_kg", 1e-3)]),
            approach_retract(&[("adhesion_scale", 0.5)]),
        ];
        for t in texts {
            let s = Script::from_toml(&t, &FALCON).unwrap_or_else(|e| panic!("{e}\n{t}"));
            assert!(s.duration_s > 2.5, "{}", s.duration_s);
        }
        let (t, release) = brick_throw(0.3);
        let s = Script::from_toml(&t, &FALCON).unwrap();
        assert_eq!(s.buttons.len(), 2);
        assert_eq!(s.buttons[1].t_s, release);
        // The release is at the swing's middle: the fastest point, 1.875 × 30 mm / 0.3 s.
        let v = s.velocity(release);
        assert!((v[0] - 1.875 * 0.030 / 0.3).abs() < 1e-12);
    }
}
