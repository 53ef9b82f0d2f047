//! The one way a device is named and opened.
//!
//! A person names a device in one form wherever they name it: `nanohaptics run --device`,
//! `play --device`, `fake-device` (the simulator it plays against), and Python's `device=`.
//! [`DeviceSource::parse`] reads that form: a model in this process (`falcon`, `touch`), or a
//! device in another process over the UDP bridge (`udp:HOST:PORT`, or `udp:PORT` on
//! loopback). [`Driver`] adds how a local model is moved (a script played by a rigid stylus
//! or by a simulated hand), and [`open_device`] builds it: adding a device is one new file
//! implementing [`HapticDevice`] and one arm here.
//!
//! ```
//! use haptic_devices::source::DeviceSource;
//! use haptic_types::device::DeviceModel;
//! assert_eq!(DeviceSource::parse("touch").unwrap(), DeviceSource::Model(DeviceModel::Touch));
//! let DeviceSource::Udp(b) = DeviceSource::parse("udp:9870").unwrap() else { panic!() };
//! assert_eq!(b.bind.to_string(), "127.0.0.1:9870");
//! assert_eq!(
//!     DeviceSource::parse("phantom").unwrap_err().to_string(),
//!     "device `phantom` is not known: allowed falcon, touch, udp:HOST:PORT or udp:PORT"
//! );
//! ```

use crate::bridge::{BridgeConfig, UdpDevice};
use crate::operator::SimulatedOperator;
use crate::script::Script;
use crate::script::{OperatorKind, OperatorParams, ScriptedDevice};
use haptic_types::device::{DeviceError, DeviceModel, HapticDevice};

/// The forms a device name may take, as errors list them.
pub const DEVICE_FORMS: &str = "falcon, touch, udp:HOST:PORT or udp:PORT";

/// A device name that is not one of [`DEVICE_FORMS`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DeviceNameError {
    /// Neither a model nor a bridge address.
    #[error("device `{0}` is not known: allowed {DEVICE_FORMS}")]
    Unknown(String),
    /// `udp:` followed by something that is not a port or an address and port.
    #[error("{0}")]
    Address(String),
}

/// A device as a person names it: a model in this process, or a device in another process.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceSource {
    /// A model in this process, moved by the session's script ([`Driver`]).
    Model(DeviceModel),
    /// A device in another process over the UDP bridge (it announces its own specifications).
    Udp(BridgeConfig),
}

impl DeviceSource {
    /// Parses a device name: `falcon`, `touch`, `udp:HOST:PORT`, or `udp:PORT` (loopback).
    pub fn parse(name: &str) -> Result<Self, DeviceNameError> {
        if name.starts_with("udp:") {
            return BridgeConfig::parse(name)
                .map(DeviceSource::Udp)
                .map_err(|e| match e {
                    DeviceError::Link(m) => DeviceNameError::Address(m),
                    e => DeviceNameError::Address(e.to_string()),
                });
        }
        DeviceModel::from_name(name)
            .map(DeviceSource::Model)
            .map_err(|_| DeviceNameError::Unknown(name.to_string()))
    }

    /// The bridge address of a bridged device (`None` for a model).
    pub fn bridge(&self) -> Option<&BridgeConfig> {
        match self {
            DeviceSource::Udp(b) => Some(b),
            DeviceSource::Model(_) => None,
        }
    }

    /// The name as [`parse`](Self::parse) reads it (`touch`, `udp:127.0.0.1:9870`).
    pub fn name(&self) -> String {
        match self {
            DeviceSource::Model(m) => m.name().to_string(),
            DeviceSource::Udp(b) => format!("udp:{}", b.bind),
        }
    }
}

/// How a session's script drives its device model: the one choice `nanohaptics run`
/// (`--operator`), the wheel and the checks make; [`Driver::of_script`] resolves it.
#[derive(Clone, Debug, PartialEq)]
pub enum OperatorChoice {
    /// The stylus follows the script exactly (forces do not move it).
    Rigid,
    /// A simulated hand follows the script and is pushed by the rendered force.
    Hand(OperatorParams),
    /// As the script says (`[script] operator`): a hand with its `[operator]` parameters (or
    /// the defaults), or a rigid stylus.
    ScriptHand,
}

/// What drives a session: a model moved by a script (rigidly or through a simulated hand), or
/// a bridged device. Made from the device named ([`DeviceSource`]) and, for a model, how its
/// script holds it ([`OperatorChoice`]); a live page session's hand is the page itself
/// (`nanohaptics-play`'s `Hand`), which drives the same engine step.
#[derive(Clone, Debug, PartialEq)]
pub enum Driver {
    /// The script played exactly by a rigid stylus of this model.
    Script(DeviceModel),
    /// A simulated hand of this model following the script, pushed by the rendered force.
    Hand(DeviceModel, OperatorParams),
    /// A device in another process over the UDP bridge (it announces its own specifications).
    Udp(BridgeConfig),
}

impl Driver {
    /// The driver of `model` played by `script` as `choice` says (a hand's parameters are
    /// checked).
    pub fn of_script(
        model: DeviceModel,
        choice: &OperatorChoice,
        script: &Script,
    ) -> Result<Driver, crate::ScriptError> {
        Ok(match choice {
            OperatorChoice::Rigid => Driver::Script(model),
            OperatorChoice::Hand(p) => {
                p.validate()?;
                Driver::Hand(model, *p)
            }
            OperatorChoice::ScriptHand if script.operator_kind == OperatorKind::Rigid => {
                Driver::Script(model)
            }
            OperatorChoice::ScriptHand => Driver::Hand(model, script.operator.unwrap_or_default()),
        })
    }

    /// The operator as written in the recording's description.
    pub fn describe(&self) -> String {
        match self {
            Driver::Script(_) => "rigid".into(),
            Driver::Hand(_, p) => format!(
                "hand ({} kg, {} N/m, {} N·s/m)",
                p.mass_kg, p.stiffness_n_per_m, p.damping_n_s_per_m
            ),
            Driver::Udp(_) => "person (bridged device)".into(),
        }
    }

    /// How the device is connected, as written in the recording's description.
    pub fn link_name(&self) -> String {
        match self {
            Driver::Script(_) => "script".into(),
            Driver::Hand(..) => "hand".into(),
            Driver::Udp(c) => format!("udp:{}", c.bind),
        }
    }
}

/// Builds the device of `driver` (`script` is required by the script and hand drivers).
pub fn open_device(
    driver: &Driver,
    script: Option<&Script>,
) -> Result<Box<dyn HapticDevice>, DeviceError> {
    let need = || {
        script
            .cloned()
            .ok_or(DeviceError::Link("no script for a scripted device".into()))
    };
    Ok(match driver {
        Driver::Script(m) => Box::new(ScriptedDevice::new(need()?, m.specs().clone())),
        Driver::Hand(m, p) => Box::new(SimulatedOperator::new(need()?, m.specs().clone(), *p)),
        Driver::Udp(c) => Box::new(UdpDevice::new(c.clone())),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_form_parses_and_names_itself_back() {
        for name in ["falcon", "touch", "udp:127.0.0.1:9870", "udp:[::1]:7000"] {
            assert_eq!(DeviceSource::parse(name).unwrap().name(), name);
        }
        assert_eq!(
            DeviceSource::parse("udp:7000").unwrap().name(),
            "udp:127.0.0.1:7000"
        );
    }

    #[test]
    fn a_bad_name_lists_the_forms_and_a_bad_address_says_why() {
        assert_eq!(
            DeviceSource::parse("Falcon").unwrap_err().to_string(),
            "device `Falcon` is not known: allowed falcon, touch, udp:HOST:PORT or udp:PORT"
        );
        assert_eq!(
            DeviceSource::parse("udp:host").unwrap_err().to_string(),
            "device `udp:host`: `host` is not an IP address and port (e.g. 127.0.0.1:9870)"
        );
    }
}
