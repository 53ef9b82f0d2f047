//! Haptic devices as the loop sees them: the CHAI3D-like interface ([`HapticDevice`]), device
//! specifications, samples and force commands. The devices themselves (scripts, the simulated
//! hand, the UDP bridge) live in `haptic-devices`.
//!
//! A device reports a stylus position (m, device frame: origin at the workspace centre) and a
//! button bitmask, and accepts a force command (N, device frame). What a real device can render
//! is described by its [`DeviceSpecs`].

use crate::value::{ValueError, out_of_range};
use crate::vec3::Vec3;
use serde::{Deserialize, Serialize};
use world_form::{Limits, fmt_num};

use std::borrow::Cow;

/// Specifications of a haptic device (what it can sense and render).
///
/// The shipped models are constants ([`FALCON`], [`TOUCH`]); a device bridged from another
/// process announces its own at run time (see `docs/device-bridge.md`), hence the owned-or-static
/// strings.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceSpecs {
    /// Model name as written in scene files and recordings.
    pub name: Cow<'static, str>,
    /// What the device renders: largest force, N (the force vector is scaled down to this
    /// norm), and largest stable stiffness at a 1 kHz servo rate, N/m.
    pub limits: Limits,
    /// Radius of the sphere, centred on the device origin, that the stylus can reach, m.
    pub workspace_radius_m: f64,
    /// Button names, bit `i` of [`Buttons`] is `button_names[i]` (at most 32).
    pub button_names: Cow<'static, [Cow<'static, str>]>,
}

/// The device models this crate ships specifications for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeviceModel {
    /// Novint Falcon: 3-DOF, 8 N, 3000 N/m, ~4 cm workspace radius, four buttons.
    Falcon,
    /// 3D Systems Touch / SensAble Phantom Omni class: 3.3 N peak, 400–700 N/m (the lower end is
    /// used), 0.075–0.10 m workspace (0.075 m used), two stylus buttons.
    Touch,
}

/// Novint Falcon specifications.
pub const FALCON: DeviceSpecs = DeviceSpecs {
    name: Cow::Borrowed("falcon"),
    limits: Limits::FALCON,
    workspace_radius_m: 0.04,
    button_names: Cow::Borrowed(&[
        Cow::Borrowed("centre"),
        Cow::Borrowed("plus"),
        Cow::Borrowed("minus"),
        Cow::Borrowed("forward"),
    ]),
};

/// Touch / Omni class specifications (conservative end of the published ranges).
pub const TOUCH: DeviceSpecs = DeviceSpecs {
    name: Cow::Borrowed("touch"),
    limits: Limits::TOUCH,
    workspace_radius_m: 0.075,
    button_names: Cow::Borrowed(&[Cow::Borrowed("button1"), Cow::Borrowed("button2")]),
};

impl DeviceModel {
    /// Specifications of this model.
    pub fn specs(self) -> &'static DeviceSpecs {
        match self {
            DeviceModel::Falcon => &FALCON,
            DeviceModel::Touch => &TOUCH,
        }
    }

    /// Model name as written in scene files ("falcon", "touch").
    pub fn name(self) -> &'static str {
        match self {
            DeviceModel::Falcon => "falcon",
            DeviceModel::Touch => "touch",
        }
    }

    /// Parses a model name; the error lists the allowed names.
    pub fn from_name(name: &str) -> Result<Self, DeviceError> {
        match name {
            "falcon" => Ok(DeviceModel::Falcon),
            "touch" => Ok(DeviceModel::Touch),
            other => Err(DeviceError::UnknownModel(other.to_string())),
        }
    }
}

impl DeviceSpecs {
    /// Bit index of a named button, or an error naming the allowed buttons.
    pub fn button_index(&self, name: &str) -> Result<u32, DeviceError> {
        self.button_names
            .iter()
            .position(|b| *b == name)
            .map(|i| i as u32)
            .ok_or_else(|| DeviceError::UnknownButton {
                device: self.name.to_string(),
                name: name.to_string(),
                allowed: self.button_names.join(", "),
            })
    }

    /// Button names as plain string slices.
    pub fn button_strs(&self) -> Vec<&str> {
        self.button_names.iter().map(|b| b.as_ref()).collect()
    }

    /// Checks specifications announced by a device (e.g. over the bridge): every number finite
    /// and in range, at most 32 buttons, names of 1–32 printable ASCII characters.
    pub fn validate(&self) -> Result<(), DeviceError> {
        // Lower bounds a haptic device meets by far (1 mN, 1 mN/m): below them the squares of
        // the force are subnormal and clamping to the limit loses its precision.
        let range = |field: &'static str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && v >= lo && v <= hi {
                Ok(())
            } else {
                Err(DeviceError::Spec(ValueError::out_of_range(
                    format!("`{field}`"),
                    v,
                    format!("{} ≤ {field} ≤ {}", fmt_num(lo), fmt_num(hi)),
                )))
            }
        };
        range("max_force_n", self.limits.max_force_n, 1e-3, 1e3)?;
        range(
            "max_stiffness_n_per_m",
            self.limits.max_stiffness_n_per_m,
            1e-3,
            1e6,
        )?;
        range("workspace_radius_m", self.workspace_radius_m, 1e-4, 10.0)?;
        let name_ok = |s: &str| {
            (1..=32).contains(&s.len()) && s.bytes().all(|b| b.is_ascii_graphic() || b == b' ')
        };
        if !name_ok(&self.name) {
            return Err(DeviceError::BadSpec {
                field: "name",
                value: format!("\"{}\"", self.name.escape_default()),
                allowed: "1–32 printable ASCII characters".into(),
            });
        }
        if self.button_names.len() > 32 {
            return Err(DeviceError::BadSpec {
                field: "button_names",
                value: format!("{} buttons", self.button_names.len()),
                allowed: "at most 32 buttons".into(),
            });
        }
        if let Some(b) = self.button_names.iter().find(|b| !name_ok(b)) {
            return Err(DeviceError::BadSpec {
                field: "button_names",
                value: format!("\"{}\"", b.escape_default()),
                allowed: "1–32 printable ASCII characters per name".into(),
            });
        }
        // A role is bound to a button by its name: two buttons of one name would make the
        // binding ambiguous.
        let names = &self.button_names;
        if let Some((i, b)) = (names.iter().enumerate()).find(|(i, b)| names[..*i].contains(b)) {
            let first = names.iter().position(|x| x == b).unwrap_or(0);
            return Err(DeviceError::BadSpec {
                field: "button_names",
                value: format!("\"{}\" (buttons {first} and {i})", b.escape_default()),
                allowed: "distinct names (a role is bound to a button by its name)".into(),
            });
        }
        Ok(())
    }

    /// Bitmask of the buttons this device has.
    pub fn button_mask(&self) -> u32 {
        if self.button_names.len() >= 32 {
            u32::MAX
        } else {
            (1u32 << self.button_names.len()) - 1
        }
    }
}

/// Button state: bit `i` set means button `i` of the device's [`DeviceSpecs::button_names`] is
/// pressed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Buttons(pub u32);

impl Buttons {
    /// True when button `index` is pressed.
    pub fn pressed(self, index: u32) -> bool {
        index < 32 && self.0 & (1 << index) != 0
    }

    /// Returns a copy with button `index` set to `down`.
    pub fn with(self, index: u32, down: bool) -> Self {
        if index >= 32 {
            return self;
        }
        if down {
            Buttons(self.0 | (1 << index))
        } else {
            Buttons(self.0 & !(1 << index))
        }
    }
}

/// One reading of the device.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceSample {
    /// Stylus position, m, device frame.
    pub position_m: Vec3,
    /// Button state.
    pub buttons: Buttons,
    /// The device's own sequence number of this reading (0 for headless devices, which number
    /// nothing). Information only: the physics never reads it.
    pub seq: u64,
    /// Ticks since this reading arrived: 0 for a fresh reading; n > 0 when no new reading came
    /// for n ticks and the last one is repeated (a bridged device whose packets stopped). The
    /// loop's watchdog ramps the force down from it, so it is an input of the tick and recorded.
    pub age_ticks: u32,
}

impl DeviceSample {
    /// A fresh reading (age 0, sequence number 0).
    pub fn new(position_m: Vec3, buttons: Buttons) -> Self {
        DeviceSample {
            position_m,
            buttons,
            seq: 0,
            age_ticks: 0,
        }
    }
}

/// What the loop commands the device until the next tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForceCommand {
    /// The tick this command answers.
    pub tick: u64,
    /// The device's sequence number of the reading this command answers.
    pub seq: u64,
    /// Force, N, device frame (finite, norm ≤ the device maximum).
    pub force_n: Vec3,
    /// Local stiffness of the rendered force field, N/m, device frame, row-major 3×3
    /// (`F(p + dp) ≈ F(p) − K dp`), already scaled by engagement, watchdog and clamp, so a
    /// driver may render between packets at its own rate.
    pub stiffness_n_per_m: [f64; 9],
    /// Status bits of the tick (see `haptic::status`).
    pub status: u8,
}

/// The time of a tick as the devices see it (tick index is time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickTime {
    /// Tick index from the start of the session.
    pub index: u64,
    /// `index / rate_hz`, s (computed by one correctly rounded division).
    pub time_s: f64,
    /// Tick length, s.
    pub dt_s: f64,
}

impl TickTime {
    /// Time of tick `index` at `rate_hz` ticks per second.
    pub fn new(index: u64, rate_hz: u32) -> Self {
        TickTime {
            index,
            time_s: index as f64 / f64::from(rate_hz),
            dt_s: 1.0 / f64::from(rate_hz),
        }
    }
}

/// Errors of devices.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DeviceError {
    /// A device model name that is not known.
    #[error("unknown device model `{0}` (allowed: falcon, touch)")]
    UnknownModel(String),
    /// A button name that this device does not have.
    #[error("device `{device}` has no button `{name}` (allowed: {allowed})")]
    UnknownButton {
        /// Device model name.
        device: String,
        /// The name asked for.
        name: String,
        /// The device's button names.
        allowed: String,
    },
    /// The device was sampled out of order (headless devices advance one tick at a time).
    #[error("device sampled at tick {got} but the next tick is {expected}")]
    OutOfOrder {
        /// Tick asked for.
        got: u64,
        /// Tick the device expected.
        expected: u64,
    },
    /// A replay device ran past the end of its recording.
    #[error("the recording has no device input for tick {0}")]
    EndOfRecording(u64),
    /// A number in the specifications announced by a device out of range.
    #[error("device specs: {0}")]
    Spec(ValueError),
    /// A name or a count in the specifications announced by a device out of range.
    #[error("device specs: {}", out_of_range(&format!("`{field}`"), value, allowed))]
    BadSpec {
        /// Field name.
        field: &'static str,
        /// The value announced.
        value: String,
        /// The allowed range.
        allowed: String,
    },
    /// A button role or a role's button out of range (a scene's `[device] buttons`, the
    /// command line's `--buttons`, a script's `role`).
    #[error("{}", out_of_range(&format!("`{field}`"), value, allowed))]
    Buttons {
        /// Where it was written, e.g. `buttons.grip` or `--buttons`.
        field: String,
        /// The value given.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// The device ended the session (a bridged device said goodbye): not an error of the run.
    #[error("the device ended the session")]
    Ended,
    /// The device's transport failed (socket error, device gone for good).
    #[error("device link: {0}")]
    Link(String),
}

/// A headless device is sampled one tick after another: `time` must be tick `next`.
pub fn in_order(time: TickTime, next: u64) -> Result<(), DeviceError> {
    if time.index == next {
        Ok(())
    } else {
        Err(DeviceError::OutOfOrder {
            got: time.index,
            expected: next,
        })
    }
}

/// The generic haptic device (after CHAI3D's `cGenericHapticDevice`).
///
/// The runner calls [`HapticDevice::open`] once, then per tick [`HapticDevice::sample`] (in
/// tick order) and [`HapticDevice::set_force`] with the command to render until the next tick,
/// and [`HapticDevice::close`] at the end (also after an error).
pub trait HapticDevice {
    /// The device's specifications (a bridged device's are known after `open`).
    fn specs(&self) -> &DeviceSpecs;
    /// Connects to the device (waits for a bridged device's hello). Headless devices: nothing.
    fn open(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }
    /// Reads position (m) and buttons for tick `time`.
    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError>;
    /// Commands the force (N, device frame) and local stiffness rendered until the next tick.
    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError>;
    /// Releases the device (a bridged device is told the session ended; zero force).
    fn close(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }
    /// Counters of the device's link (packets received, dropped, ...); empty for headless
    /// devices.
    fn link_counters(&self) -> Vec<(&'static str, u64)> {
        Vec::new()
    }
    /// Whether the device renders the local model between answers (bridge protocol 2): the
    /// runner then hands it each tick's model with [`HapticDevice::set_local_model`] before
    /// [`HapticDevice::set_force`].
    fn wants_local_model(&self) -> bool {
        false
    }
    /// The bridge protocol version whose local model the device renders (2, or 3 with the
    /// bond of `crate::local::Bond`, a spring that breaks); asked only when
    /// [`HapticDevice::wants_local_model`].
    fn local_model_version(&self) -> u8 {
        2
    }
    /// The local model that goes with the next [`HapticDevice::set_force`] (protocol-2 devices
    /// only; others ignore it).
    fn set_local_model(&mut self, _model: crate::local::LocalModel) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falcon_specs_match_the_issue() {
        let s = DeviceModel::Falcon.specs();
        assert_eq!(s.limits, Limits::FALCON);
        assert_eq!(s.limits.max_force_n, 8.0);
        assert_eq!(s.limits.max_stiffness_n_per_m, 3000.0);
        assert_eq!(s.workspace_radius_m, 0.04);
        assert_eq!(s.button_index("centre"), Ok(0));
        assert_eq!(s.button_index("forward"), Ok(3));
        assert_eq!(s.button_mask(), 0b1111);
        assert_eq!(
            s.button_index("trigger").unwrap_err().to_string(),
            "device `falcon` has no button `trigger` (allowed: centre, plus, minus, forward)"
        );
    }

    #[test]
    fn tick_time_is_exact_on_whole_milliseconds() {
        assert_eq!(TickTime::new(500, 1000).time_s, 0.5);
        assert_eq!(TickTime::new(1234, 1000).time_s, 1.234);
        assert_eq!(
            DeviceModel::from_name("phantom").unwrap_err().to_string(),
            "unknown device model `phantom` (allowed: falcon, touch)"
        );
    }

    #[test]
    fn buttons_set_and_clear() {
        let b = Buttons(0).with(2, true).with(0, true).with(2, false);
        assert_eq!(b, Buttons(1));
        assert!(b.pressed(0) && !b.pressed(2) && !b.pressed(40));
    }
}
