//! A scripted operator whose hand holds a modelled device: the closed loop of issue 22.
//!
//! The script is the operator's *intent*; a [`crate::Plant`] is the device (moving
//! mass, friction, encoder counts, force resolution, the command held at the device's servo
//! rate) gripped by a hand ([`crate::Grip`]) that follows the intent. Each tick the
//! loop reads the encoder, and the force it answers is held until the next tick. Unlike the
//! rigid [`super::ScriptedDevice`] or the massless [`super::SimulatedOperator`], this device can
//! show a rendering's instability: a buzz, a limit cycle, energy pumped into the hand.

use crate::script::Script;
use crate::{Grip, Hold, Mechanics, Plant};
use haptic_types::device::{
    DeviceError, DeviceSample, DeviceSpecs, ForceCommand, HapticDevice, TickTime, in_order,
};
use haptic_types::vec3::Vec3;
use std::borrow::Cow;

/// A scripted hand holding a modelled device.
#[derive(Clone, Debug)]
pub struct ModelledDevice {
    script: Script,
    specs: DeviceSpecs,
    plant: Plant,
    hold: Hold,
    reading_m: Vec3,
    next_tick: u64,
}

impl ModelledDevice {
    /// The device `mech` held with `grip`, following `script`; the buttons are those of
    /// `buttons_of` (a script names its buttons for the device it was written for), the limits
    /// and workspace those of `mech`.
    pub fn new(script: Script, mech: Mechanics, grip: Grip, buttons_of: &DeviceSpecs) -> Self {
        let start = script.position(0.0);
        let plant = Plant::new(mech, grip, start);
        ModelledDevice {
            specs: specs_of(&mech, buttons_of),
            reading_m: plant.reading_m(),
            plant,
            script,
            hold: Hold::constant([0.0; 3]),
            next_tick: 0,
        }
    }

    /// The device and hand.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }
}

/// Device specifications for a modelled preset: its name, limits and workspace, and its own
/// buttons (`haptic_types::buttons::BUTTON_PRESETS`; none for a device that is not a preset).
pub fn preset_specs(mech: &Mechanics) -> DeviceSpecs {
    let buttons: Vec<Cow<'static, str>> = haptic_types::buttons::button_preset(mech.name)
        .map(|p| p.buttons.iter().map(|b| Cow::Borrowed(b.0)).collect())
        .unwrap_or_default();
    DeviceSpecs {
        name: Cow::Borrowed(mech.name),
        limits: mech.limits,
        workspace_radius_m: mech.workspace_radius_m,
        button_names: Cow::Owned(buttons),
    }
}

/// Device specifications for a modelled device: its name, limits and workspace, and the
/// buttons of `buttons_of`.
pub fn specs_of(mech: &Mechanics, buttons_of: &DeviceSpecs) -> DeviceSpecs {
    DeviceSpecs {
        name: Cow::Borrowed(mech.name),
        limits: mech.limits,
        workspace_radius_m: mech.workspace_radius_m,
        button_names: buttons_of.button_names.clone(),
    }
}

impl HapticDevice for ModelledDevice {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError> {
        in_order(time, self.next_tick)?;
        if time.index > 0 {
            let t0 = time.time_s - time.dt_s;
            let script = &self.script;
            self.plant.advance(
                time.dt_s,
                |t| (script.position(t0 + t), script.velocity(t0 + t)),
                &self.hold,
            );
        }
        self.next_tick += 1;
        self.reading_m = self.plant.reading_m();
        Ok(DeviceSample::new(
            self.reading_m,
            self.script.buttons(time.time_s),
        ))
    }

    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError> {
        self.hold = Hold {
            force_n: cmd.force_n,
            stiffness_n_per_m: cmd.stiffness_n_per_m,
            p0_m: self.reading_m,
        };
        Ok(())
    }
}
