//! Buttons by role: the worlds bind their actions to *roles* (grip, turn about x, y or z), and
//! each device maps its own buttons to them (issue 41).
//!
//! The mapping in force for a device is [`ButtonRoles::resolve`]d from its button names:
//!
//! 1. a device whose button list is exactly a preset's ([`BUTTON_PRESETS`]: the Falcon's four,
//!    the Touch's two, the delta.3's two, the Inverse3's VerseGrip three) takes the preset's
//!    roles;
//! 2. any other device takes the default by index ([`ROLES_BY_INDEX`]): button 0 grips,
//!    button 1 turns about z, button 2 about x, button 3 about y (a device with fewer buttons
//!    has no button for the later roles; buttons after the fourth play none);
//! 3. then the overrides (a scene's `[device] buttons = { grip = "a" }`, the command line's
//!    `--buttons grip=a,turn_z=b`) bind each named role to the named button, which then plays
//!    no other role.
//!
//! The rule reads nothing but the button names and the overrides (both recorded: the names in
//! the recording's description, the overrides in its scene text), so a replay maps the buttons
//! as the session did.

use crate::device::{Buttons, DeviceError, DeviceSpecs};

/// What a button does in the worlds, whatever the device calls it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Role {
    /// Grab and hold (the brick world carries a brick, the optical tweezers hold a bead).
    Grip,
    /// Turn the held brick a quarter turn about the world's x axis.
    TurnX,
    /// Turn the held brick a quarter turn about the world's y axis.
    TurnY,
    /// Turn the held brick a quarter turn about the world's z axis.
    TurnZ,
}

impl Role {
    /// Every role, in the order of the welcome's role bytes.
    pub const ALL: [Role; 4] = [Role::Grip, Role::TurnX, Role::TurnY, Role::TurnZ];

    /// The role's name in scene files, scripts and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Role::Grip => "grip",
            Role::TurnX => "turn_x",
            Role::TurnY => "turn_y",
            Role::TurnZ => "turn_z",
        }
    }

    /// The role named `name`; `field` names where it was written (for the error).
    pub fn from_name(field: &str, name: &str) -> Result<Role, DeviceError> {
        Role::ALL
            .into_iter()
            .find(|r| r.name() == name)
            .ok_or_else(|| DeviceError::Buttons {
                field: field.to_string(),
                value: format!("\"{}\"", name.escape_default()),
                allowed: "a role: grip, turn_x, turn_y, turn_z".into(),
            })
    }

    fn index(self) -> usize {
        match self {
            Role::Grip => 0,
            Role::TurnX => 1,
            Role::TurnY => 2,
            Role::TurnZ => 3,
        }
    }
}

/// A device preset's buttons, in bit order, each with the role it plays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ButtonPreset {
    /// The preset's device name (`falcon`, `touch`, `delta3`, `inverse3`).
    pub device: &'static str,
    /// Its buttons in bit order: name and role.
    pub buttons: &'static [(&'static str, Role)],
}

/// The presets' buttons. The Falcon's grip has four buttons (centre grips, plus / minus /
/// forward turn about x / y / z); the Touch's stylus two (OpenHaptics' buttons 1 and 2: grip,
/// turn about z); the delta.3 the Force Dimension SDK's buttons 0 and 1 (grip, turn about z);
/// the Inverse3 the VerseGrip's `a`, `b`, `c` (the wheel's Haply adapter's names: grip, turn
/// about z, turn about x).
pub const BUTTON_PRESETS: [ButtonPreset; 4] = [
    ButtonPreset {
        device: "falcon",
        buttons: &[
            ("centre", Role::Grip),
            ("plus", Role::TurnX),
            ("minus", Role::TurnY),
            ("forward", Role::TurnZ),
        ],
    },
    ButtonPreset {
        device: "touch",
        buttons: &[("button1", Role::Grip), ("button2", Role::TurnZ)],
    },
    ButtonPreset {
        device: "delta3",
        buttons: &[("button0", Role::Grip), ("button1", Role::TurnZ)],
    },
    ButtonPreset {
        device: "inverse3",
        buttons: &[("a", Role::Grip), ("b", Role::TurnZ), ("c", Role::TurnX)],
    },
];

/// The preset named `device`, if any.
pub fn button_preset(device: &str) -> Option<&'static ButtonPreset> {
    BUTTON_PRESETS.iter().find(|p| p.device == device)
}

/// The roles of a device the simulator does not know, by button index: button 0 grips,
/// button 1 turns about z, button 2 about x, button 3 about y.
pub const ROLES_BY_INDEX: [Role; 4] = [Role::Grip, Role::TurnZ, Role::TurnX, Role::TurnY];

/// Where the mapping in force came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoleSource {
    /// The device's buttons are a preset's (its device name).
    Preset(&'static str),
    /// The default by index.
    ByIndex,
}

/// Which button (bit) plays each role on one device.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ButtonRoles {
    bits: [Option<u32>; 4],
    source: RoleSource,
    overridden: bool,
}

impl ButtonRoles {
    /// The mapping in force for `specs`' buttons with `overrides` (role, button name) applied;
    /// an override naming a button the device does not have is an error naming the allowed
    /// buttons.
    pub fn resolve(specs: &DeviceSpecs, overrides: &[(Role, String)]) -> Result<Self, DeviceError> {
        let names = specs.button_strs();
        let preset = BUTTON_PRESETS
            .iter()
            .find(|p| p.buttons.iter().map(|b| b.0).eq(names.iter().copied()));
        let mut bits = [None; 4];
        let source = match preset {
            Some(p) => {
                for (i, (_, role)) in p.buttons.iter().enumerate() {
                    bits[role.index()] = Some(i as u32);
                }
                RoleSource::Preset(p.device)
            }
            None => {
                for (i, role) in ROLES_BY_INDEX.iter().enumerate().take(names.len()) {
                    bits[role.index()] = Some(i as u32);
                }
                RoleSource::ByIndex
            }
        };
        for (role, button) in overrides {
            let bit =
                names
                    .iter()
                    .position(|b| b == button)
                    .ok_or_else(|| DeviceError::Buttons {
                        field: format!("buttons.{}", role.name()),
                        value: format!("\"{}\"", button.escape_default()),
                        allowed: if names.is_empty() {
                            format!("none: device `{}` has no buttons", specs.name)
                        } else {
                            format!("a button of device `{}`: {}", specs.name, names.join(", "))
                        },
                    })? as u32;
            for b in &mut bits {
                if *b == Some(bit) {
                    *b = None;
                }
            }
            bits[role.index()] = Some(bit);
        }
        Ok(ButtonRoles {
            bits,
            source,
            overridden: !overrides.is_empty(),
        })
    }

    /// The button bit that plays `role` (`None`: no button does).
    pub fn bit(&self, role: Role) -> Option<u32> {
        self.bits[role.index()]
    }

    /// Whether the button playing `role` is pressed in `buttons`.
    pub fn pressed(&self, role: Role, buttons: Buttons) -> bool {
        self.bit(role).is_some_and(|b| buttons.pressed(b))
    }

    /// Where the mapping came from (before overrides).
    pub fn source(&self) -> RoleSource {
        self.source
    }

    /// The welcome's four role bytes: the button index of grip, turn_x, turn_y, turn_z, 255
    /// where no button plays the role.
    pub fn wire(&self) -> [u8; 4] {
        self.bits
            .map(|b| b.and_then(|b| u8::try_from(b).ok()).unwrap_or(u8::MAX))
    }

    /// The mapping as people read it: `grip = centre, turn_x = plus, turn_y = minus, turn_z =
    /// forward (the falcon preset)`; `names` are the device's button names.
    pub fn describe(&self, names: &[&str]) -> String {
        let roles: Vec<String> = Role::ALL
            .into_iter()
            .map(|r| {
                let b = self
                    .bit(r)
                    .and_then(|b| names.get(b as usize).copied())
                    .unwrap_or("none");
                format!("{} = {b}", r.name())
            })
            .collect();
        let from = match self.source {
            RoleSource::Preset(d) => format!("the {d} preset"),
            RoleSource::ByIndex => "the default by index".to_string(),
        };
        let over = if self.overridden { ", overridden" } else { "" };
        format!("{} ({from}{over})", roles.join(", "))
    }
}

/// Parses the command line's `--buttons grip=a,turn_z=b` into (role, button name) overrides.
pub fn parse_overrides(text: &str) -> Result<Vec<(Role, String)>, DeviceError> {
    let mut out: Vec<(Role, String)> = Vec::new();
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let Some((role, button)) = part.split_once('=') else {
            return Err(DeviceError::Buttons {
                field: "--buttons".into(),
                value: format!("\"{}\"", part.escape_default()),
                allowed: "ROLE=BUTTON pairs separated by commas, e.g. grip=a,turn_z=b".into(),
            });
        };
        let role = Role::from_name("--buttons", role.trim())?;
        if out.iter().any(|(r, _)| *r == role) {
            return Err(DeviceError::Buttons {
                field: "--buttons".into(),
                value: format!("\"{}\"", role.name()),
                allowed: "each role once".into(),
            });
        }
        out.push((role, button.trim().to_string()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::device::{FALCON, TOUCH};
    use std::borrow::Cow;

    fn device(name: &'static str, buttons: &[&'static str]) -> DeviceSpecs {
        DeviceSpecs {
            name: Cow::Borrowed(name),
            button_names: buttons
                .iter()
                .map(|b| Cow::Borrowed(*b))
                .collect::<Vec<_>>()
                .into(),
            ..FALCON
        }
    }

    #[test]
    fn presets_map_their_own_buttons_and_others_go_by_index() {
        let f = ButtonRoles::resolve(&FALCON, &[]).unwrap();
        assert_eq!(f.wire(), [0, 1, 2, 3]);
        assert_eq!(
            f.describe(&FALCON.button_strs()),
            "grip = centre, turn_x = plus, turn_y = minus, turn_z = forward (the falcon preset)"
        );
        let t = ButtonRoles::resolve(&TOUCH, &[]).unwrap();
        assert_eq!(t.wire(), [0, 255, 255, 1]);
        assert_eq!(t.source(), RoleSource::Preset("touch"));
        // The Haply adapter's default names are the Inverse3 preset's; any name goes by index.
        let h = ButtonRoles::resolve(&device("haply", &["a", "b", "c"]), &[]).unwrap();
        assert_eq!(
            (h.wire(), h.source()),
            ([0, 2, 255, 1], RoleSource::Preset("inverse3"))
        );
        let u = ButtonRoles::resolve(&device("lab", &["x", "y", "z", "w", "v"]), &[]).unwrap();
        assert_eq!((u.wire(), u.source()), ([0, 2, 3, 1], RoleSource::ByIndex));
        assert!(u.pressed(Role::Grip, Buttons(1)) && !u.pressed(Role::Grip, Buttons(16)));
        let none = ButtonRoles::resolve(&device("bare", &[]), &[]).unwrap();
        assert_eq!(none.wire(), [255; 4]);
        assert_eq!(
            none.describe(&[]),
            "grip = none, turn_x = none, turn_y = none, turn_z = none (the default by index)"
        );
    }

    #[test]
    fn overrides_bind_a_role_to_a_named_button_and_are_checked() {
        let o = parse_overrides("grip=forward, turn_z=centre").unwrap();
        let f = ButtonRoles::resolve(&FALCON, &o).unwrap();
        assert_eq!(f.wire(), [3, 1, 2, 0]);
        assert!(
            f.describe(&FALCON.button_strs())
                .ends_with("(the falcon preset, overridden)")
        );
        let o = parse_overrides("grip=button2").unwrap();
        // button2 plays grip and no longer turn_z.
        assert_eq!(
            ButtonRoles::resolve(&TOUCH, &o).unwrap().wire(),
            [1, 255, 255, 255]
        );
        assert_eq!(
            ButtonRoles::resolve(&TOUCH, &parse_overrides("grip=a").unwrap())
                .unwrap_err()
                .to_string(),
            "`buttons.grip` = \"a\" is out of range: allowed a button of device `touch`: \
             button1, button2"
        );
        assert_eq!(
            parse_overrides("hold=a").unwrap_err().to_string(),
            "`--buttons` = \"hold\" is out of range: allowed a role: grip, turn_x, turn_y, turn_z"
        );
        assert_eq!(
            parse_overrides("grip").unwrap_err().to_string(),
            "`--buttons` = \"grip\" is out of range: allowed ROLE=BUTTON pairs separated by \
             commas, e.g. grip=a,turn_z=b"
        );
        assert!(parse_overrides("grip=a,grip=b").is_err());
    }
}
