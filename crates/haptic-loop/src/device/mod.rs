//! Haptic devices: the CHAI3D-like interface, device specifications, and the headless devices
//! (scripted, simulated operator, replay).
//!
//! A device reports a stylus position (m, device frame: origin at the workspace centre) and a
//! button bitmask, and accepts a force command (N, device frame). What a real device can render
//! is described by its [`DeviceSpecs`].

pub mod operator;
pub mod replay;
pub mod script;

use crate::vec3::Vec3;
use serde::{Deserialize, Serialize};

pub use operator::{OperatorParams, SimulatedOperator};
pub use replay::ReplayDevice;
pub use script::{Script, ScriptError, ScriptedDevice};

/// Specifications of a haptic device (what it can sense and render).
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceSpecs {
    /// Model name as written in scene files and recordings.
    pub name: &'static str,
    /// Largest force the device renders, N (the force vector is scaled down to this norm).
    pub max_force_n: f64,
    /// Largest stable stiffness at a 1 kHz servo rate, N/m.
    pub max_stiffness_n_per_m: f64,
    /// Radius of the sphere, centred on the device origin, that the stylus can reach, m.
    pub workspace_radius_m: f64,
    /// Button names, bit `i` of [`Buttons`] is `button_names[i]`.
    pub button_names: &'static [&'static str],
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
    name: "falcon",
    max_force_n: 8.0,
    max_stiffness_n_per_m: 3000.0,
    workspace_radius_m: 0.04,
    button_names: &["centre", "plus", "minus", "forward"],
};

/// Touch / Omni class specifications (conservative end of the published ranges).
pub const TOUCH: DeviceSpecs = DeviceSpecs {
    name: "touch",
    max_force_n: 3.3,
    max_stiffness_n_per_m: 400.0,
    workspace_radius_m: 0.075,
    button_names: &["button1", "button2"],
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
        self.specs().name
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
                device: self.name,
                name: name.to_string(),
                allowed: self.button_names.join(", "),
            })
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
        device: &'static str,
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
}

/// The generic haptic device (after CHAI3D's `cGenericHapticDevice`).
///
/// The loop calls [`HapticDevice::sample`] once per tick, in tick order, then
/// [`HapticDevice::set_force`] with the force to render until the next tick.
pub trait HapticDevice {
    /// The device's specifications.
    fn specs(&self) -> &DeviceSpecs;
    /// Reads position (m) and buttons for tick `time`.
    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError>;
    /// Commands the force (N, device frame) rendered until the next tick.
    fn set_force(&mut self, force_n: Vec3);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falcon_specs_match_the_issue() {
        let s = DeviceModel::Falcon.specs();
        assert_eq!(s.max_force_n, 8.0);
        assert_eq!(s.max_stiffness_n_per_m, 3000.0);
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
