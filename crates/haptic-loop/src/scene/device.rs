//! A scene file's `[device]` table: the model the scene is tuned for and the overrides of the
//! button roles (`haptic_types::buttons`), and the roles in force for a device.

use haptic_engine::check::SceneError;
use haptic_types::{ButtonRoles, DeviceModel, DeviceSpecs, Role};
use serde::Deserialize;

/// `[device]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DeviceSection {
    /// Device model the scene is tuned for.
    pub model: DeviceModel,
    /// Overrides of the button roles: role name (`grip`, `turn_x`, `turn_y`, `turn_z`) → the
    /// device's button name (`[device] buttons = { grip = "a" }`); the rest of the mapping is
    /// the device's preset or the default by index (`haptic_types::buttons`).
    #[serde(default)]
    pub buttons: std::collections::BTreeMap<String, String>,
}

impl DeviceSection {
    /// The overrides as (role, button name), each role name checked.
    pub fn button_overrides(&self) -> Result<Vec<(Role, String)>, SceneError> {
        self.buttons
            .iter()
            .map(|(role, button)| {
                Role::from_name(&format!("device.buttons.{role}"), role)
                    .map(|r| (r, button.clone()))
                    .map_err(|e| buttons_error("device", e))
            })
            .collect()
    }

    /// The button roles in force for a device with `specs`: its preset or the default by
    /// index, with this section's overrides.
    pub fn roles_for(&self, specs: &DeviceSpecs) -> Result<ButtonRoles, SceneError> {
        ButtonRoles::resolve(specs, &self.button_overrides()?)
            .map_err(|e| buttons_error("device", e))
    }
}

/// A button error as a scene error naming the field under `[section]`.
fn buttons_error(section: &str, e: haptic_types::DeviceError) -> SceneError {
    match e {
        haptic_types::DeviceError::Buttons {
            field,
            value,
            allowed,
        } => SceneError::OutOfRange {
            field: if field.starts_with(section) {
                field
            } else {
                format!("{section}.{field}")
            },
            value,
            allowed,
        },
        other => SceneError::World {
            section: section.into(),
            field: Some("buttons".into()),
            message: other.to_string(),
        },
    }
}

/// The button roles in force for a scene file's `text` on a device with `specs` (a world's
/// adapter reads them so: its build sees the text and the loop configuration).
pub fn roles_in(text: &str, specs: &DeviceSpecs) -> Result<ButtonRoles, SceneError> {
    let device: DeviceSection = super::table::pick(text, "device")?.unwrap_or_default();
    device.roles_for(specs)
}

impl Default for DeviceSection {
    fn default() -> Self {
        DeviceSection {
            model: DeviceModel::Falcon,
            buttons: Default::default(),
        }
    }
}
