//! Scene files: TOML under `scenes/`, parsed with unknown fields refused and validated with
//! errors that name the field and the allowed range.
//!
//! ```toml
//! [scene]
//! name = "stiff wall"
//! kind = "wall"                        # which world: "wall", "nanoworld", "brickworld", "optical_tweezers"
//! default_script = "wall-press.script.toml"   # relative to the scene file
//!
//! [device]
//! model = "falcon"                     # "falcon" | "touch"
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

use super::Scene;
use super::brick::{BrickScene, BrickSection};
use super::nano::{NanoScene, NanoSection};
use super::optical::{OpticalScene, OtParams};
use super::wall::{WallParams, WallScene};
use crate::device::{DeviceModel, DeviceSpecs};
use crate::haptic::{LoopConfig, Mapping};
use crate::textpos::{Position, field_position, position};
use serde::Deserialize;

/// Errors in a scene file.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SceneError {
    /// Not valid TOML for a scene (unknown field, wrong type, missing field, ...).
    #[error("scene: {message}")]
    Syntax {
        /// What the TOML reader found wrong and what it expected.
        message: String,
        /// Byte offset in the text where it went wrong, when known.
        offset: Option<usize>,
    },
    /// A world refused its parameters.
    #[error("scene: {section}: {message}")]
    World {
        /// The scene table the world reads, e.g. `nanoworld.params`.
        section: String,
        /// The offending field's dotted path inside `section`, when the world names one.
        field: Option<String>,
        /// The world's own message (names the field and the allowed range).
        message: String,
    },
    /// A number out of its allowed range.
    #[error("scene: `{field}` = {value} is out of range (allowed: {allowed})")]
    OutOfRange {
        /// Field path, e.g. `mapping.force_scale`.
        field: String,
        /// The value found, as written.
        value: String,
        /// The allowed range in words.
        allowed: String,
    },
    /// `scene.kind` names no known world, or its table is missing.
    #[error("scene: `scene.kind` = \"{kind}\" {problem}")]
    Kind {
        /// The kind found.
        kind: String,
        /// What is wrong.
        problem: String,
    },
    /// The file could not be read.
    #[error("scene: cannot read {path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// OS error.
        message: String,
    },
}

impl SceneError {
    /// Where in the scene's `text` the error is: the TOML reader's position, or the named
    /// field's value (`None` when neither is known).
    pub fn position(&self, text: &str) -> Option<Position> {
        match self {
            SceneError::Syntax { offset, .. } => offset.map(|o| position(text, o)),
            SceneError::OutOfRange { field, .. } => field_position(text, field),
            SceneError::Kind { .. } => field_position(text, "scene.kind"),
            SceneError::World { section, field, .. } => field
                .as_ref()
                .and_then(|f| field_position(text, &format!("{section}.{f}")))
                .or_else(|| field_position(text, section)),
            SceneError::Io { .. } => None,
        }
    }
}

/// Builds an out-of-range error.
pub fn out_of_range(field: &str, value: impl ToString, allowed: impl Into<String>) -> SceneError {
    SceneError::OutOfRange {
        field: field.to_string(),
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

/// Formats a bound for an error message: plain in 1e-3..1e6, scientific outside (`1e-6`).
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Checks `lo ≤ value ≤ hi` (and finite).
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), SceneError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(out_of_range(
            field,
            value,
            format!("{} ≤ {field} ≤ {}", fmt_num(lo), fmt_num(hi)),
        ))
    }
}

/// Checks `0 < value ≤ hi` (and finite).
pub fn check_positive(field: &str, value: f64, hi: f64) -> Result<(), SceneError> {
    if value.is_finite() && value > 0.0 && value <= hi {
        Ok(())
    } else {
        Err(out_of_range(
            field,
            value,
            format!("0 < {field} ≤ {}", fmt_num(hi)),
        ))
    }
}

/// `[scene]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneHeader {
    /// Display name.
    pub name: String,
    /// World kind: `wall`.
    pub kind: String,
    /// Default script, relative to the scene file.
    #[serde(default)]
    pub default_script: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
}

/// `[device]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct DeviceSection {
    /// Device model the scene is tuned for.
    pub model: DeviceModel,
}

impl Default for DeviceSection {
    fn default() -> Self {
        DeviceSection {
            model: DeviceModel::Falcon,
        }
    }
}

/// `[mapping]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct MappingSection {
    /// World metres per device metre (e.g. 1e-4: 1 mm of stylus = 100 nm). Allowed: 1e-12–1e3.
    pub workspace_scale: f64,
    /// Device newtons per world newton. Allowed: 1e-6–1e18.
    pub force_scale: f64,
    /// World point under the device origin, m.
    pub origin_m: [f64; 3],
}

impl Default for MappingSection {
    fn default() -> Self {
        MappingSection {
            workspace_scale: 1.0,
            force_scale: 1.0,
            origin_m: [0.0; 3],
        }
    }
}

/// `[loop]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct LoopSection {
    /// Tick rate, Hz. Allowed: 100–10 000 and a whole number of nanoseconds per tick.
    pub rate_hz: u32,
    /// Soft-engagement ramp at start (and after invalid input), s. Allowed: 0–10.
    pub engage_s: f64,
    /// How long a bridged device's last sample is used at full force, s. Allowed: 0–0.1.
    pub watchdog_grace_s: f64,
    /// Time after the last sample at which the force has ramped to zero, s. Allowed: more than
    /// `watchdog_grace_s` plus one tick, at most 1.
    pub watchdog_timeout_s: f64,
}

impl Default for LoopSection {
    fn default() -> Self {
        LoopSection {
            rate_hz: 1000,
            engage_s: 0.25,
            watchdog_grace_s: 0.003,
            watchdog_timeout_s: 0.010,
        }
    }
}

/// `[display]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct DisplaySection {
    /// Rate of the Foxglove channels, Hz; must divide the tick rate. Allowed: 1–tick rate.
    pub rate_hz: u32,
    /// Display metres per world metre in the Foxglove channels (1e6: 1 µm shows as 1 m).
    pub scale: f64,
}

impl Default for DisplaySection {
    fn default() -> Self {
        DisplaySection {
            rate_hz: 50,
            scale: 1.0,
        }
    }
}

/// A whole scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[scene]`.
    pub scene: SceneHeader,
    /// `[device]`.
    #[serde(default)]
    pub device: DeviceSection,
    /// `[mapping]`.
    #[serde(default)]
    pub mapping: MappingSection,
    /// `[loop]`.
    #[serde(default, rename = "loop")]
    pub loop_: LoopSection,
    /// `[display]`.
    #[serde(default)]
    pub display: DisplaySection,
    /// `[wall]`: parameters of the wall scene.
    #[serde(default)]
    pub wall: Option<WallParams>,
    /// `[nanoworld]`: the nano world (crate `nanoworld`).
    #[serde(default)]
    pub nanoworld: Option<NanoSection>,
    /// `[brickworld]`: the macro world (crate `brickworld`).
    #[serde(default)]
    pub brickworld: Option<BrickSection>,
    /// `[optical_tweezers]`: the optical-tweezers steering scene (crates `ot-physics`,
    /// `ot-envelope`).
    #[serde(default)]
    pub optical_tweezers: Option<OtParams>,
}

/// The world kinds this build knows.
pub const KINDS: &[&str] = &["wall", "nanoworld", "brickworld", "optical_tweezers"];

impl SceneFile {
    /// Parses a scene file's text (no validation of ranges yet).
    pub fn parse(text: &str) -> Result<SceneFile, SceneError> {
        toml::from_str(text).map_err(|e: toml::de::Error| SceneError::Syntax {
            message: e.message().trim().to_string(),
            offset: e.span().map(|s| s.start),
        })
    }

    /// Builds the loop configuration for device `model`, checking every common field.
    pub fn loop_config(&self, model: DeviceModel) -> Result<LoopConfig, SceneError> {
        self.loop_config_for(model.specs().clone())
    }

    /// Builds the loop configuration for a device with `specs` (e.g. announced by a bridged
    /// device), checking every common field.
    pub fn loop_config_for(&self, specs: DeviceSpecs) -> Result<LoopConfig, SceneError> {
        let m = &self.mapping;
        check_range("mapping.workspace_scale", m.workspace_scale, 1e-12, 1e3)?;
        check_range("mapping.force_scale", m.force_scale, 1e-6, 1e18)?;
        for (k, c) in m.origin_m.iter().enumerate() {
            check_range(&format!("mapping.origin_m[{k}]"), *c, -1e3, 1e3)?;
        }
        let l = &self.loop_;
        // Up to 20 kHz (the optical-tweezers tick runs at 10 kHz with room to spare); the
        // period stays exact in whole nanoseconds.
        if !(100..=20_000).contains(&l.rate_hz) || 1_000_000_000 % l.rate_hz != 0 {
            return Err(out_of_range(
                "loop.rate_hz",
                l.rate_hz,
                "100 ≤ rate_hz ≤ 20000 with 10^9 / rate_hz a whole number",
            ));
        }
        check_range("loop.engage_s", l.engage_s, 0.0, 10.0)?;
        check_range("loop.watchdog_grace_s", l.watchdog_grace_s, 0.0, 0.1)?;
        // A stale tick of age a runs (a + 0.5) periods after the last sample: the grace covers
        // the ages whose tick is within watchdog_grace_s, and the force is zero from the first
        // age whose tick is within watchdog_timeout_s of the last sample.
        let rate = f64::from(l.rate_hz);
        let grace_ticks = (l.watchdog_grace_s * rate - 0.5).floor().max(0.0);
        let min_timeout = (grace_ticks + 1.5) / rate;
        check_range(
            "loop.watchdog_timeout_s",
            l.watchdog_timeout_s,
            min_timeout,
            1.0,
        )?;
        let timeout_ticks = (l.watchdog_timeout_s * rate - 0.5)
            .floor()
            .max(grace_ticks + 1.0);
        let d = &self.display;
        if d.rate_hz == 0 || d.rate_hz > l.rate_hz || l.rate_hz % d.rate_hz != 0 {
            return Err(out_of_range(
                "display.rate_hz",
                d.rate_hz,
                format!("a divisor of loop.rate_hz = {}", l.rate_hz),
            ));
        }
        check_range("display.scale", d.scale, 1e-3, 1e12)?;
        Ok(LoopConfig {
            rate_hz: l.rate_hz,
            engage_ticks: (l.engage_s * f64::from(l.rate_hz)).round() as u64,
            display_every: l.rate_hz / d.rate_hz,
            display_scale: d.scale,
            mapping: Mapping {
                workspace_scale: m.workspace_scale,
                force_scale: m.force_scale,
                origin_m: m.origin_m,
            },
            specs,
            watchdog_grace_ticks: grace_ticks as u32,
            watchdog_timeout_ticks: timeout_ticks as u32,
        })
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
    let config = file.loop_config_for(specs)?;
    let cap = config.world_stiffness_cap_n_per_m();
    let dt = 1.0 / f64::from(config.rate_hz);
    let missing = |kind: &str| SceneError::Kind {
        kind: kind.to_string(),
        problem: format!("needs a `[{kind}]` table"),
    };
    let scene: Box<dyn Scene> = match file.scene.kind.as_str() {
        "wall" => {
            let p = file.wall.clone().ok_or_else(|| missing("wall"))?;
            Box::new(WallScene::new(p, cap, dt)?)
        }
        "nanoworld" => {
            let p = file.nanoworld.clone().ok_or_else(|| missing("nanoworld"))?;
            let fmax = config.specs.max_force_n / config.mapping.force_scale;
            Box::new(NanoScene::new(p, cap, fmax, dt)?)
        }
        "optical_tweezers" => {
            let p = file
                .optical_tweezers
                .clone()
                .ok_or_else(|| missing("optical_tweezers"))?;
            Box::new(OpticalScene::new(p, cap)?)
        }
        "brickworld" => {
            let p = file
                .brickworld
                .clone()
                .ok_or_else(|| missing("brickworld"))?;
            let fmax = config.specs.max_force_n / config.mapping.force_scale;
            Box::new(BrickScene::new(
                p,
                cap,
                fmax,
                dt,
                &config.specs.button_strs(),
            )?)
        }
        other => {
            return Err(SceneError::Kind {
                kind: other.to_string(),
                problem: format!("is not a known world (allowed: {})", KINDS.join(", ")),
            });
        }
    };
    Ok(LoadedScene {
        file,
        config,
        scene,
    })
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
        assert_eq!(t.config.specs.max_force_n, 3.3);
    }

    #[test]
    fn bad_fields_are_named() {
        assert_eq!(
            err(&format!("{WALL}[loop]\nrate_hz = 999\n")),
            "scene: `loop.rate_hz` = 999 is out of range (allowed: 100 ≤ rate_hz ≤ 20000 with \
             10^9 / rate_hz a whole number)"
        );
        assert_eq!(
            err(&format!("{WALL}[loop]\nrate_hz = 25000\n")),
            "scene: `loop.rate_hz` = 25000 is out of range (allowed: 100 ≤ rate_hz ≤ 20000 with \
             10^9 / rate_hz a whole number)"
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
            "scene: `mapping.force_scale` = -1 is out of range (allowed: 1e-6 ≤ \
             mapping.force_scale ≤ 1e18)"
        );
        assert_eq!(
            err(&format!("{WALL}[loop]\nwatchdog_timeout_s = 0.001\n")),
            "scene: `loop.watchdog_timeout_s` = 0.001 is out of range (allowed: 0.0035 ≤ \
             loop.watchdog_timeout_s ≤ 1)"
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
            "scene: `display.rate_hz` = 30 is out of range (allowed: a divisor of loop.rate_hz = \
             1000)"
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
            "scene: `wall.normal` = [0, 0, 0] is out of range (allowed: a non-zero finite vector)"
        );
    }
}
