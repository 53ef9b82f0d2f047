//! The loop's configuration: the `[mapping]`, `[loop]` and `[display]` tables of a scene file,
//! checked, and what the haptic loop makes of them ([`LoopConfig`]).

use crate::check::{SceneError, check_range, out_of_range};
use haptic_types::DeviceSpecs;
use haptic_types::vec3::{self, Vec3};
use serde::Deserialize;
use world_form::Limits;
use world_form::fmt_num;

/// `[mapping]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct MappingSection {
    /// World metres per device metre (e.g. 1e-4: 1 mm of stylus = 100 nm). Allowed: 1e-12–1e3.
    pub workspace_scale: f64,
    /// Device newtons per world newton. Allowed: 1e-6–1e18.
    pub force_scale: f64,
    /// World point under the device origin, m.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub origin_m: [f64; 3],
    /// Fit the mapping to a device softer than the one the scene is written for (`[device]
    /// model`): `force_scale` times the ratio of the two devices' largest stiffnesses, so every
    /// spring, damper and force of the world reaches the device in the same proportion of its
    /// range (as CHAI3D scales materials to the connected device). The world's physics does
    /// not change. `false`: the mapping is used as written, and a world spring the device
    /// cannot render is refused.
    pub fit_device: bool,
}

impl Default for MappingSection {
    fn default() -> Self {
        MappingSection {
            workspace_scale: 1.0,
            force_scale: 1.0,
            origin_m: [0.0; 3],
            fit_device: true,
        }
    }
}

/// How the mapping was fitted to a softer device than the scene was written for.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DeviceFit {
    /// The device the scene is written for (`[device] model`).
    pub written_for: String,
    /// Its largest stiffness, N/m.
    pub written_for_stiffness_n_per_m: f64,
    /// The scene file's `force_scale`.
    pub scene_force_scale: f64,
    /// The factor applied (< 1): the connected device's largest stiffness over the other's.
    pub factor: f64,
}

impl DeviceFit {
    /// The fit for a device with `specs` running a scene written for `written_for` with
    /// `force_scale`: `None` when the device is as stiff or stiffer.
    pub fn of(specs: &DeviceSpecs, written_for: &DeviceSpecs, force_scale: f64) -> Option<Self> {
        let k = specs.limits.max_stiffness_n_per_m;
        let k0 = written_for.limits.max_stiffness_n_per_m;
        (k < k0).then(|| DeviceFit {
            written_for: written_for.name.to_string(),
            written_for_stiffness_n_per_m: k0,
            scene_force_scale: force_scale,
            factor: k / k0,
        })
    }

    /// What the recording's `device.fit` event says: the scene's `force_scale`, the fitted one
    /// and why.
    pub fn describe(&self, device: &str, device_stiffness_n_per_m: f64) -> String {
        use world_form::numbers::fmt_num;
        format!(
            "mapping.force_scale {} → {} (×{}): {device} renders up to {} N/m, the scene is written for {} ({} N/m); every world stiffness, damping and force reaches the device ×{} (set mapping.fit_device = false to refuse instead)",
            fmt_num(self.scene_force_scale),
            fmt_num(self.scene_force_scale * self.factor),
            fmt_num(self.factor),
            fmt_num(device_stiffness_n_per_m),
            self.written_for,
            fmt_num(self.written_for_stiffness_n_per_m),
            fmt_num(self.factor),
        )
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
    /// The passivity observer and controller at the device port (Hannaford and Ryu 2002): on
    /// by default.
    pub passivity: bool,
    /// Energy the rendering may return to the hand beyond what it took, J (device side): the
    /// observer's reserve. Allowed: 0–10.
    pub passivity_reserve_j: f64,
    /// The force-rate limit at the device port (OpenHaptics' impulse limit): on by default.
    pub force_rate_limit: bool,
    /// Largest change of the device force, N/s; default the device's largest stiffness times
    /// 1 m/s (a Falcon: 3000 N/s, 3 N per 1 ms tick). Allowed: 1–10⁹.
    pub max_force_rate_n_per_s: Option<f64>,
}

impl Default for LoopSection {
    fn default() -> Self {
        LoopSection {
            rate_hz: 1000,
            engage_s: 0.25,
            watchdog_grace_s: 0.003,
            watchdog_timeout_s: 0.010,
            passivity: true,
            passivity_reserve_j: DEFAULT_PASSIVITY_RESERVE_J,
            force_rate_limit: true,
            max_force_rate_n_per_s: None,
        }
    }
}

/// Default [`LoopSection::passivity_reserve_j`], J: 20 mJ, more than a brick lowered 1 m
/// at the default brick-world mapping returns (2.45 J × 0.125 / 20 = 15 mJ), far less than a
/// buzz at a Falcon's 8 N puts in per second (0.1–1 J).
pub const DEFAULT_PASSIVITY_RESERVE_J: f64 = 0.02;

/// The safety layer at the device port ([`crate::haptic::HapticLoop`] applies it after the
/// clamp): which parts are on and their settings, as the loop uses them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Safety {
    /// The passivity observer's reserve, J, or `None` when the observer is off.
    pub passivity_reserve_j: Option<f64>,
    /// The largest force change per second, N/s, or `None` when the limit is off.
    pub max_force_rate_n_per_s: Option<f64>,
}

impl Safety {
    /// Nothing on: the force leaves the clamp unchanged.
    pub const OFF: Safety = Safety {
        passivity_reserve_j: None,
        max_force_rate_n_per_s: None,
    };

    /// The settings in words, for the recording's first tick (`safety.config`).
    pub fn describe(&self, max_stiffness_n_per_m: f64) -> String {
        let po = match self.passivity_reserve_j {
            Some(r) => format!("passivity observer on (reserve {r} J)"),
            None => "passivity observer off".into(),
        };
        let rate = match self.max_force_rate_n_per_s {
            Some(r) => format!("force-rate limit on ({r} N/s)"),
            None => "force-rate limit off".into(),
        };
        format!("{po}; {rate}; stiffness cap {max_stiffness_n_per_m} N/m")
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

/// Device ↔ world mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Mapping {
    /// World metres per device metre.
    pub workspace_scale: f64,
    /// Device newtons per world newton.
    pub force_scale: f64,
    /// World point under the device origin, m.
    pub origin_m: Vec3,
}

impl Mapping {
    /// World position (m) of device position `p_m` (m).
    pub fn to_world(&self, p_m: Vec3) -> Vec3 {
        vec3::add(self.origin_m, vec3::scale(p_m, self.workspace_scale))
    }
}

/// Everything the loop needs besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopConfig {
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// Length of the soft-engagement ramp, ticks (0: none).
    pub engage_ticks: u64,
    /// Foxglove display channels are written every this many ticks.
    pub display_every: u32,
    /// Display metres per world metre (Foxglove channels only).
    pub display_scale: f64,
    /// Device ↔ world mapping.
    pub mapping: Mapping,
    /// The device's specifications.
    pub specs: DeviceSpecs,
    /// Ticks a stale device sample is tolerated at full force.
    pub watchdog_grace_ticks: u32,
    /// Ticks after the last fresh sample at which the force has ramped to zero (> grace).
    pub watchdog_timeout_ticks: u32,
    /// The safety layer at the device port.
    pub safety: Safety,
    /// How the mapping was fitted to a softer device (`None`: used as written).
    pub device_fit: Option<DeviceFit>,
}

impl LoopConfig {
    /// Builds the loop configuration from the `[mapping]`, `[loop]` and `[display]` tables for a
    /// device with `specs`, checking every field.
    pub fn new(
        m: &MappingSection,
        l: &LoopSection,
        d: &DisplaySection,
        specs: DeviceSpecs,
        written_for: &DeviceSpecs,
    ) -> Result<LoopConfig, SceneError> {
        check_range("mapping.workspace_scale", m.workspace_scale, 1e-12, 1e3)?;
        check_range("mapping.force_scale", m.force_scale, 1e-6, 1e18)?;
        for (k, c) in m.origin_m.iter().enumerate() {
            check_range(&format!("mapping.origin_m[{k}]"), *c, -1e3, 1e3)?;
        }
        // Up to 20 kHz (the optical-tweezers tick runs at 10 kHz with room to spare); the
        // period stays exact in whole nanoseconds.
        if !(100..=20_000).contains(&l.rate_hz) || 1_000_000_000 % l.rate_hz != 0 {
            return Err(out_of_range(
                "loop.rate_hz",
                f64::from(l.rate_hz),
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
        if d.rate_hz == 0 || d.rate_hz > l.rate_hz || l.rate_hz % d.rate_hz != 0 {
            return Err(out_of_range(
                "display.rate_hz",
                f64::from(d.rate_hz),
                format!(
                    "a divisor of loop.rate_hz = {}",
                    fmt_num(f64::from(l.rate_hz))
                ),
            ));
        }
        check_range("display.scale", d.scale, 1e-3, 1e12)?;
        check_range("loop.passivity_reserve_j", l.passivity_reserve_j, 0.0, 10.0)?;
        let rate_default = specs.limits.max_stiffness_n_per_m * 1.0;
        let rate = l.max_force_rate_n_per_s.unwrap_or(rate_default);
        check_range("loop.max_force_rate_n_per_s", rate, 1.0, 1e9)?;
        let safety = Safety {
            passivity_reserve_j: l.passivity.then_some(l.passivity_reserve_j),
            max_force_rate_n_per_s: l.force_rate_limit.then_some(rate),
        };
        let device_fit = m
            .fit_device
            .then(|| DeviceFit::of(&specs, written_for, m.force_scale))
            .flatten();
        let force_scale = device_fit
            .as_ref()
            .map_or(m.force_scale, |f| m.force_scale * f.factor);
        Ok(LoopConfig {
            rate_hz: l.rate_hz,
            engage_ticks: (l.engage_s * f64::from(l.rate_hz)).round() as u64,
            display_every: l.rate_hz / d.rate_hz,
            display_scale: d.scale,
            mapping: Mapping {
                workspace_scale: m.workspace_scale,
                force_scale,
                origin_m: m.origin_m,
            },
            specs,
            watchdog_grace_ticks: grace_ticks as u32,
            watchdog_timeout_ticks: timeout_ticks as u32,
            safety,
            device_fit,
        })
    }

    /// Tick length, s.
    pub fn dt_s(&self) -> f64 {
        1.0 / f64::from(self.rate_hz)
    }

    /// Tick length, ns (exact: validated to be whole).
    pub fn period_ns(&self) -> u64 {
        1_000_000_000 / u64::from(self.rate_hz)
    }

    /// The device's largest force expressed in the world, N (`max_force_n / force_scale`).
    pub fn world_max_force_n(&self) -> f64 {
        self.specs.limits.max_force_n / self.mapping.force_scale
    }

    /// The largest world-frame stiffness that renders within the device's stiffness limit, N/m.
    pub fn world_stiffness_cap_n_per_m(&self) -> f64 {
        self.specs.limits.max_stiffness_n_per_m
            / (self.mapping.force_scale * self.mapping.workspace_scale)
    }

    /// The device's limits mapped to the world, the [`Limits`] every world is built with:
    /// [`LoopConfig::world_max_force_n`] (N) and [`LoopConfig::world_stiffness_cap_n_per_m`]
    /// (N/m), i.e. `Limits::in_world(force_scale, workspace_scale)` of the device's limits: a
    /// stiffness maps by `force_scale · workspace_scale`, a force by `force_scale` alone.
    pub fn world_limits(&self) -> Limits {
        Limits {
            max_force_n: self.world_max_force_n(),
            max_stiffness_n_per_m: self.world_stiffness_cap_n_per_m(),
        }
    }
}
