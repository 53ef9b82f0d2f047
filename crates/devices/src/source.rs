//! The device sources a session can be driven by, registered in one place: adding a device is
//! one new file implementing [`HapticDevice`](haptic_types::device::HapticDevice) and one arm here.

use crate::bridge::{BridgeConfig, UdpDevice};
use crate::operator::SimulatedOperator;
use crate::script::Script;
use crate::script::{OperatorParams, ScriptedDevice};
use haptic_types::device::{DeviceError, DeviceModel, HapticDevice};

/// Which device drives a session.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceSource {
    /// The script played exactly by a rigid stylus of this model.
    Script(DeviceModel),
    /// A simulated hand of this model following the script, pushed by the rendered force.
    Hand(DeviceModel, OperatorParams),
    /// A device in another process over the UDP bridge (it announces its own specifications).
    Udp(BridgeConfig),
}

impl DeviceSource {
    /// The operator as written in the recording's description.
    pub fn describe(&self) -> String {
        match self {
            DeviceSource::Script(_) => "rigid".into(),
            DeviceSource::Hand(_, p) => format!(
                "hand ({} kg, {} N/m, {} N·s/m)",
                p.mass_kg, p.stiffness_n_per_m, p.damping_n_s_per_m
            ),
            DeviceSource::Udp(_) => "person (bridged device)".into(),
        }
    }

    /// How the device is connected, as written in the recording's description.
    pub fn link_name(&self) -> String {
        match self {
            DeviceSource::Script(_) => "script".into(),
            DeviceSource::Hand(..) => "hand".into(),
            DeviceSource::Udp(c) => format!("udp:{}", c.bind),
        }
    }
}

/// Builds the device of `source` (`script` is required by the script and hand sources).
pub fn open_device(
    source: &DeviceSource,
    script: Option<&Script>,
) -> Result<Box<dyn HapticDevice>, DeviceError> {
    let need = || {
        script
            .cloned()
            .ok_or(DeviceError::Link("no script for a scripted device".into()))
    };
    Ok(match source {
        DeviceSource::Script(m) => Box::new(ScriptedDevice::new(need()?, m.specs().clone())),
        DeviceSource::Hand(m, p) => {
            Box::new(SimulatedOperator::new(need()?, m.specs().clone(), *p))
        }
        DeviceSource::Udp(c) => Box::new(UdpDevice::new(c.clone())),
    })
}
