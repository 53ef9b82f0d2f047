//! Scene files: TOML under `scenes/`, parsed with unknown fields refused and validated with
//! errors that name the field and the allowed range.
//!
//! The common tables (`[scene]`, `[device]`, `[mapping]`, `[loop]`, `[display]`) are read here;
//! a world's own table (`[wall]`, `[brickworld]`, …) is read by that world's adapter, found in
//! [`super::registry`] by `scene.kind`. Adding a world does not touch this file.
//!
//! ```toml
//! [scene]
//! name = "stiff wall"
//! kind = "wall"                        # which world: "wall", "nanoworld", "brickworld", "optical_tweezers"
//! default_script = "wall-press.script.toml"   # relative to the scene file
//!
//! [device]
//! model = "falcon"                     # "falcon" | "touch"
//! buttons = { grip = "plus" }          # optional: a role's button, overriding the device's
//!                                      # preset or the default by index (docs/devices.md)
//!
//! [mapping]
//! workspace_scale = 1.0                # world metres per device metre
//! force_scale = 1.0                    # device newtons per world newton
//! origin_m = [0.0, 0.0, 0.0]           # world point under the device origin
//!
//! [loop]
//! rate_hz = 1000                       # tick rate, 100..=20000 Hz; 10^9 / rate_hz whole ns
//! engage_s = 0.25                      # soft-engagement ramp at start
//! watchdog_grace_s = 0.003             # a bridged device's sample may be this late at full force
//! watchdog_timeout_s = 0.010           # ... and the force is zero this long after the last one
//!
//! [display]
//! rate_hz = 50                         # Foxglove channels; must divide the tick rate
//! scale = 1.0                          # display metres per world metre (Foxglove only)
//!
//! [wall]                               # the world's own table, named after `kind`
//! ...
//! ```

pub use super::device::DeviceSection;
use super::registry;
use super::table;
use haptic_engine::check::SceneError;
use haptic_engine::header::SessionHeader;
use haptic_engine::loop_config::{DisplaySection, LoopConfig, LoopSection, MappingSection};
use haptic_engine::scene::Scene;
use haptic_types::DeviceModel;
use haptic_types::DeviceSpecs;
use serde::Deserialize;

/// `[scene]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneHeader {
    /// Display name.
    pub name: String,
    /// World kind, one of [`registry::kinds`]: `wall`, `nanoworld`, `brickworld`,
    /// `optical_tweezers`.
    pub kind: String,
    /// Default script, relative to the scene file.
    #[serde(default)]
    pub default_script: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
}

/// The tables every scene file shares (the world's own table is read by its adapter).
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
struct Common {
    scene: Option<SceneHeader>,
    #[serde(default)]
    device: DeviceSection,
    #[serde(default)]
    mapping: MappingSection,
    #[serde(default, rename = "loop")]
    loop_: LoopSection,
    #[serde(default)]
    display: DisplaySection,
}

/// The names of the common tables.
const COMMON: [&str; 5] = ["scene", "device", "mapping", "loop", "display"];

/// A whole scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneFile {
    /// `[scene]`.
    pub scene: SceneHeader,
    /// `[device]`.
    pub device: DeviceSection,
    /// `[mapping]`.
    pub mapping: MappingSection,
    /// `[loop]`.
    pub loop_: LoopSection,
    /// `[display]`.
    pub display: DisplaySection,
    /// The file's text, from which the world's table is read (with its positions).
    text: String,
}

impl SceneFile {
    /// Parses a scene file's text: the common tables, and every world table present is checked
    /// by its world for unknown fields and types (no validation of ranges yet).
    pub fn parse(text: &str) -> Result<SceneFile, SceneError> {
        let kinds = registry::kinds();
        let allowed: Vec<&str> = COMMON
            .iter()
            .copied()
            .chain(kinds.iter().copied())
            .collect();
        table::check_keys(text, &allowed)?;
        let common: Common = table::parse(text)?;
        let scene = common.scene.ok_or_else(|| SceneError::Syntax {
            message: "missing field `scene`".into(),
            offset: None,
        })?;
        for world in registry::WORLDS {
            (world.check)(text)?;
        }
        Ok(SceneFile {
            scene,
            device: common.device,
            mapping: common.mapping,
            loop_: common.loop_,
            display: common.display,
            text: text.to_string(),
        })
    }

    /// The text the file was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The world's own table (`[<scene.kind>]`) as the world's parameter type `T`; `None` when
    /// the file has no such table.
    pub fn world<T: serde::de::DeserializeOwned>(&self) -> Result<Option<T>, SceneError> {
        table::pick(&self.text, &self.scene.kind)
    }

    /// Builds the loop configuration for device `model`, checking every common field.
    pub fn loop_config(&self, model: DeviceModel) -> Result<LoopConfig, SceneError> {
        self.loop_config_for(model.specs().clone())
    }

    /// Builds the loop configuration for a device with `specs` (e.g. announced by a bridged
    /// device), checking every common field.
    pub fn loop_config_for(&self, specs: DeviceSpecs) -> Result<LoopConfig, SceneError> {
        LoopConfig::new(
            &self.mapping,
            &self.loop_,
            &self.display,
            specs,
            self.device.model.specs(),
        )
    }
}

/// A scene ready to run: its file, the loop configuration and the world.
pub struct LoadedScene {
    /// The parsed file.
    pub file: SceneFile,
    /// The loop configuration (device, mapping, rates).
    pub config: LoopConfig,
    /// The world.
    pub scene: Box<dyn Scene>,
}

/// Parses, validates and builds a scene; `device` overrides the file's `[device] model`.
pub fn load_scene(text: &str, device: Option<DeviceModel>) -> Result<LoadedScene, SceneError> {
    let file = SceneFile::parse(text)?;
    let model = device.unwrap_or(file.device.model);
    let specs = model.specs().clone();
    build(file, specs)
}

/// Parses, validates and builds a scene for a device with `specs` (a bridged device announces
/// its own; the file's `[device] model` is then ignored).
pub fn load_scene_for(text: &str, specs: DeviceSpecs) -> Result<LoadedScene, SceneError> {
    build(SceneFile::parse(text)?, specs)
}

fn build(file: SceneFile, specs: DeviceSpecs) -> Result<LoadedScene, SceneError> {
    file.device.roles_for(&specs)?;
    let config = file.loop_config_for(specs)?;
    let kind = file.scene.kind.as_str();
    let world = registry::find(kind).ok_or_else(|| SceneError::Kind {
        kind: kind.to_string(),
        problem: format!(
            "is not a known world (allowed: {})",
            registry::kinds().join(", ")
        ),
    })?;
    let scene = (world.build)(&file.text, &config)?;
    Ok(LoadedScene {
        file,
        config,
        scene,
    })
}

impl LoadedScene {
    /// The header of a session of this scene (built from `scene_toml`) in `mode`, with the
    /// device connected by `link`, started at `start_time_ns` (ns since the Unix epoch); no
    /// script (set `script_name`, `script_toml` and `operator` for a scripted session).
    pub fn header(
        &self,
        scene_toml: &str,
        mode: &str,
        link: &str,
        start_time_ns: u64,
    ) -> SessionHeader {
        SessionHeader {
            scene_name: self.file.scene.name.clone(),
            scene_kind: self.scene.kind().to_string(),
            scene_toml: scene_toml.to_string(),
            rate_hz: self.config.rate_hz,
            mode: mode.to_string(),
            script_name: String::new(),
            script_toml: String::new(),
            operator: link.to_string(),
            state_fields: self.scene.state_fields(),
            start_time_ns,
            device_link: link.to_string(),
            device: self.config.specs.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WALL: &str = r#"
[scene]
name = "w"
kind = "wall"
[wall]
normal = [0.0, 0.0, 1.0]
stiffness_n_per_m = 2000.0
"#;

    fn err(text: &str) -> String {
        match load_scene(text, None) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn defaults_are_falcon_at_1khz() {
        let s = load_scene(WALL, None).unwrap();
        assert_eq!(s.config.rate_hz, 1000);
        assert_eq!(s.config.engage_ticks, 250);
        assert_eq!(s.config.display_every, 20);
        assert_eq!(s.config.specs.name, "falcon");
        let t = load_scene(WALL, Some(DeviceModel::Touch)).unwrap();
        assert_eq!(t.config.specs.limits.max_force_n, 3.3);
    }

    #[test]
    fn bad_fields_are_named() {
        assert_eq!(
            err(&format!("{WALL}[loop]\nrate_hz = 999\n")),
            "scene: `loop.rate_hz` = 999 is out of range: allowed 100 ≤ rate_hz ≤ 20000 with \
             10^9 / rate_hz a whole number"
        );
        assert_eq!(
            err(&format!("{WALL}[loop]\nrate_hz = 25000\n")),
            "scene: `loop.rate_hz` = 25000 is out of range: allowed 100 ≤ rate_hz ≤ 20000 with \
             10^9 / rate_hz a whole number"
        );
        assert_eq!(
            load_scene(&format!("{WALL}[loop]\nrate_hz = 10000\n"), None)
                .unwrap()
                .config
                .period_ns(),
            100_000
        );
        assert_eq!(
            err(&format!("{WALL}[mapping]\nforce_scale = -1.0\n")),
            "scene: `mapping.force_scale` = -1 is out of range: allowed 1e-6 ≤ \
             mapping.force_scale ≤ 1e18"
        );
        assert_eq!(
            err(&format!("{WALL}[loop]\nwatchdog_timeout_s = 0.001\n")),
            "scene: `loop.watchdog_timeout_s` = 0.001 is out of range: allowed 0.0035 ≤ \
             loop.watchdog_timeout_s ≤ 1"
        );
        let s = load_scene(&format!("{WALL}[loop]\nrate_hz = 10000\n"), None).unwrap();
        // At 10 kHz: full force through age 29 (2.95 ms), zero from age 99 (9.95 ms).
        assert_eq!(
            (
                s.config.watchdog_grace_ticks,
                s.config.watchdog_timeout_ticks
            ),
            (29, 99)
        );
        assert_eq!(
            err(&format!("{WALL}[display]\nrate_hz = 30\n")),
            "scene: `display.rate_hz` = 30 is out of range: allowed a divisor of loop.rate_hz = \
             1000"
        );
        assert_eq!(
            err(&WALL.replace("kind = \"wall\"", "kind = \"moon\"")),
            "scene: `scene.kind` = \"moon\" is not a known world (allowed: wall, nanoworld, brickworld, optical_tweezers)"
        );
        assert!(
            err(&format!("{WALL}[device]\nmodel = \"phantom\"\n"))
                .contains("unknown variant `phantom`")
        );
        assert!(
            err(&WALL.replace("[wall]", "[wall]\ncolour = 1")).contains("unknown field `colour`")
        );
        assert_eq!(
            err(&WALL.replace("[0.0, 0.0, 1.0]", "[0.0, 0.0, 0.0]")),
            "scene: `wall.normal` = [0, 0, 0] is out of range: allowed a non-zero finite vector"
        );
    }
}
