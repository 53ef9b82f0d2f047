//! The check's fixed sequence: what the simulator side does in each stage, how long, and what
//! the hand holding the device is asked to do.
//!
//! Times are from the welcome (the device's first sample is its time 0). The wall and the
//! brick's floor lie [`WALL_GAP_M`] below the stylus as it was at the end of the handshake,
//! facing +z of the device's frame, so a hand pushing down (−z) meets them.

use serde::Serialize;

/// One stage of the check.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Samples flow; answers carry no force.
    Handshake,
    /// A contact plane (the wall) below the stylus, answered over a slow link.
    Wall,
    /// A brick on the stylus, through a coupling, resting on a floor where the wall was.
    Brick,
    /// The brick, with a share of the answers dropped ([`LOSS`]).
    Loss,
    /// No answers at all: the check keeps receiving, the device keeps sending.
    Silence,
    /// Answers again, the force engaged softly from zero over [`ENGAGE_S`].
    Resume,
}

/// The stages in order, each with its length, s.
pub const STAGES: [(Stage, f64); 6] = [
    (Stage::Handshake, 0.5),
    (Stage::Wall, 1.5),
    (Stage::Brick, 1.5),
    (Stage::Loss, 1.0),
    (Stage::Silence, 0.5),
    (Stage::Resume, 1.0),
];

/// How long the check waits for the hello's repeat before it welcomes the first, s.
pub const HELLO_REPEAT_WAIT_S: f64 = 1.0;

/// How long the check listens after its bye, s.
pub const AFTER_BYE_S: f64 = 1.0;

/// How far below the stylus (its position at the end of the handshake) the wall and the
/// floor lie, m.
pub const WALL_GAP_M: f64 = 0.002;

/// The answers' delay, s: a slow link, over which only a device that
/// renders the local model at its own rate holds the wall (an answered force alone is felt
/// this late).
pub const LATENCY_S: f64 = 0.02;

/// Share of the answers dropped in [`Stage::Loss`].
pub const LOSS: f64 = 0.2;

/// The soft engagement after the silence: the force ramps from zero over this long, s (as the
/// simulator's `[loop]` engagement does after `device.resumed`).
pub const ENGAGE_S: f64 = 0.25;

/// How far below its start the check's own hand ([`hand_script`]) pushes the stylus, m: 6 mm
/// through the wall, which a loose (300 N/m) or firm (1000 N/m) grip does with a force well
/// under a Touch's, Falcon's, delta.3's or Inverse3's largest.
pub const HAND_PUSH_M: f64 = 0.008;

/// When the check's hand starts pushing and when it is down, s from the welcome.
pub const HAND_PUSH_S: (f64, f64) = (0.6, 1.0);

/// The script of a hand that does what the stages ask (`fake-device --check-hand`): still
/// through the handshake, then down [`HAND_PUSH_M`] over [`HAND_PUSH_S`], held there for a
/// minute (the check's bye ends it first).
pub fn hand_script() -> String {
    let push_mm = HAND_PUSH_M * 1e3;
    let (t1, t2) = HAND_PUSH_S;
    format!(
        "[script]\n\
         name = \"device-check's hand: still, then {push_mm} mm down and held\"\n\
         duration_s = 60.0\n\
         [[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, 0.0]\n\
         [[waypoint]]\nt_s = {t1:?}\nposition_mm = [0.0, 0.0, 0.0]\n\
         [[waypoint]]\nt_s = {t2:?}\nposition_mm = [0.0, 0.0, -{push_mm:?}]\n\
         [[waypoint]]\nt_s = 60.0\nposition_mm = [0.0, 0.0, -{push_mm:?}]\n"
    )
}

impl Stage {
    /// The stage's name in the report.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Handshake => "handshake",
            Stage::Wall => "wall",
            Stage::Brick => "brick",
            Stage::Loss => "loss",
            Stage::Silence => "silence",
            Stage::Resume => "resume",
        }
    }

    /// What the hand is asked to do, and what the check does, as the progress line says.
    pub fn prompt(self) -> &'static str {
        match self {
            Stage::Handshake => "hold the stylus still; answers carry no force, 20 ms late",
            Stage::Wall => {
                "push the stylus down gently (well under the device's maximum force) onto the \
                 wall 2 mm below it, and keep pushing to the end"
            }
            Stage::Brick => {
                "keep pushing: a brick on the stylus now rests on a floor where the wall was"
            }
            Stage::Loss => "keep pushing: 20 % of the answers are dropped",
            Stage::Silence => "keep pushing: no answers for 0.5 s",
            Stage::Resume => "keep pushing: answers again, the force engaged from zero over 0.25 s",
        }
    }

    /// Whether the check answers samples in this stage.
    pub fn answers(self) -> bool {
        self != Stage::Silence
    }

    /// When the stage starts and ends, s from the welcome.
    pub fn span_s(self) -> (f64, f64) {
        let mut t = 0.0;
        for (s, d) in STAGES {
            if s == self {
                return (t, t + d);
            }
            t += d;
        }
        (t, t)
    }
}

/// The whole sequence's length, s (the bye follows).
pub fn total_s() -> f64 {
    STAGES.iter().map(|s| s.1).sum()
}

/// The stage at `t_s` (s from the welcome); `None` after the last.
pub fn stage_at(t_s: f64) -> Option<Stage> {
    let mut t = 0.0;
    for (s, d) in STAGES {
        t += d;
        if t_s < t {
            return Some(s);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stages_follow_each_other_without_gaps() {
        assert_eq!(stage_at(0.0), Some(Stage::Handshake));
        assert_eq!(stage_at(0.5), Some(Stage::Wall));
        assert_eq!(Stage::Brick.span_s(), (2.0, 3.5));
        assert_eq!(stage_at(4.6), Some(Stage::Silence));
        assert_eq!(stage_at(total_s()), None);
        assert_eq!(total_s(), 6.0);
    }

    #[test]
    fn the_hand_script_pushes_6_mm_through_the_wall_after_the_handshake() {
        let specs = haptic_types::device::DeviceModel::Falcon.specs().clone();
        let s = crate::Script::from_toml(&hand_script(), &specs).unwrap();
        assert_eq!(s.position(0.5), [0.0; 3]);
        assert_eq!(s.position(1.0), [0.0, 0.0, -0.008]);
        assert_eq!(s.position(5.9), [0.0, 0.0, -0.008]);
        let wall_depth = -s.position(3.0)[2] - WALL_GAP_M;
        assert!((wall_depth - 0.006).abs() < 1e-15);
    }
}
