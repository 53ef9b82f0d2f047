//! What one tick of the haptic loop produced, and its status bits.

use crate::device::Buttons;
use crate::event::Event;
use crate::switch::Switch;
use crate::vec3::Vec3;

/// Status bits of a tick (`TickResult::status`).
pub mod status {
    /// The force was scaled down to the device maximum.
    pub const CLAMPED: u8 = 1;
    /// The device input was invalid; zero force.
    pub const INPUT_INVALID: u8 = 2;
    /// The real-time deadline was missed; zero force.
    pub const DEADLINE_MISSED: u8 = 4;
    /// The scene rendered a stiffness above the cap; zero force.
    pub const STIFFNESS_OVER_CAP: u8 = 8;
    /// The scene returned a non-finite force; zero force.
    pub const FORCE_INVALID: u8 = 16;
    /// The device sample was stale beyond the grace time: the watchdog reduced the force.
    pub const WATCHDOG: u8 = 32;
    /// The passivity controller added damping: the rendering had returned more energy than
    /// it took, beyond the reserve.
    pub const PASSIVITY: u8 = 64;
    /// The force-rate limit held the change of force back.
    pub const RATE_LIMITED: u8 = 128;

    /// Every bit with its name, lowest first (the names used in reports and docs).
    pub const ALL: [(u8, &str); 8] = [
        (CLAMPED, "clamped"),
        (INPUT_INVALID, "input_invalid"),
        (DEADLINE_MISSED, "deadline_missed"),
        (STIFFNESS_OVER_CAP, "stiffness_over_cap"),
        (FORCE_INVALID, "force_invalid"),
        (WATCHDOG, "watchdog"),
        (PASSIVITY, "passivity"),
        (RATE_LIMITED, "rate_limited"),
    ];

    /// The names of the bits set in `status`, lowest bit first.
    pub fn names(status: u8) -> Vec<&'static str> {
        ALL.iter()
            .filter(|(bit, _)| status & bit != 0)
            .map(|(_, name)| *name)
            .collect()
    }
}

/// What one tick produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TickResult {
    /// Tick index.
    pub tick: u64,
    /// Cursor given to the scene, world frame, m.
    pub cursor_m: Vec3,
    /// Buttons given to the scene.
    pub buttons: Buttons,
    /// Force the scene returned, world frame, N.
    pub world_force_n: Vec3,
    /// Force sent to the device, device frame, N (finite, norm ≤ device maximum).
    pub device_force_n: Vec3,
    /// Soft-engagement factor applied, 0–1.
    pub engagement: f64,
    /// Watchdog factor applied, 0–1 (1 while device samples are fresh).
    pub watchdog: f64,
    /// Local stiffness sent with the force, N/m, device frame, row-major 3×3.
    pub device_stiffness_n_per_m: [f64; 9],
    /// Status bits, see [`status`].
    pub status: u8,
    /// Events of this tick: loop events, button events, scene events.
    pub events: Vec<Event>,
    /// Switches applied before this tick's step (an input of the tick; usually empty).
    pub switches: Vec<Switch>,
}

#[cfg(test)]
mod tests {
    use super::status;

    #[test]
    fn every_bit_is_named_once() {
        let all = status::ALL.iter().fold(0u8, |acc, (bit, _)| {
            assert_eq!(acc & bit, 0, "bit {bit} listed twice");
            acc | bit
        });
        assert_eq!(all, u8::MAX);
        assert_eq!(status::names(0), Vec::<&str>::new());
        assert_eq!(
            status::names(status::DEADLINE_MISSED | status::RATE_LIMITED),
            ["deadline_missed", "rate_limited"]
        );
    }
}
