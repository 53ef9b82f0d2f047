//! World parameters (what never changes during a step), deserializable from a TOML table.
//!
//! Every field is SI and says its unit in its name where a human types it. [`Params::validate`]
//! checks every field against its range and returns a [`ParamError`] naming the field.
//! Run-time switches (gravity, restitution, friction, inertia, brick mass) are changed through
//! the validated setters on [`crate::World`], which reuse the same range checks.

use rapier3d_f64::math::{Rotation, Vector};
use serde::{Deserialize, Serialize};
use world_form::{Limits, fmt_num};

use crate::error::ParamError;

/// The world frame is right-handed with `z` up; the ground is the plane `z = 0`.
/// Gravity (when on) points along `-z`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    /// Physics and haptic time step in s. The haptic loop runs at `1 / dt_s` (1 kHz by default).
    /// Range `[1e-4, 1e-2]`.
    pub dt_s: f64,
    /// Magnitude of gravity in m/s² (0 switches gravity off). Range `[0, 100]`.
    #[serde(alias = "gravity_m_s2")]
    pub gravity_m_per_s2: f64,
    /// Coefficient of restitution of every contact (0 = no bounce). Range `[0, 1]`.
    pub restitution: f64,
    /// Coulomb friction coefficient of every contact (0 = frictionless). Range `[0, 10]`.
    pub friction: f64,
    /// How the carried brick's inertia reaches the hand: `"coupling"` (the default: the brick
    /// is a rigid body joined to the hand by a spring-damper the device can hold, so weight,
    /// inertia and contacts arrive through it), `"paper"` (the paper's `F = −M a` from a
    /// stencil of sampled positions; unstable on a real device, see `docs/brickworld.md`) or
    /// `"off"` (weight only). `true` / `false` are read as `"coupling"` / `"off"`.
    pub inertia: Inertia,
    /// The virtual coupling of a carried brick (used when `inertia = "coupling"`).
    pub coupling: Coupling,
    /// A rigidly carried brick (`inertia = "paper"` or `"off"`) leaves the hand with the grip
    /// point's velocity, estimated from its sampled positions by adaptive windowing (FOAW,
    /// [`crate::AdaptiveWindow`]): its band, m, one encoder count mapped to the world (the
    /// default: a Falcon's 0.0635 mm at ×20; 0 for exact positions). Range `[0, 0.1]`. (A
    /// coupled brick leaves with its own velocity: nothing is estimated.)
    pub release_velocity_band_m: f64,
    /// Longest window of that estimate, ticks. Range `[1, 200]`.
    pub release_velocity_max_window: usize,
    /// How the cursor acceleration for the paper's inertial force is estimated.
    pub accel_estimator: AccelEstimator,
    /// Mass of one brick in kg. Range `[1e-3, 100]`.
    pub brick_mass_kg: f64,
    /// Half-extents of a brick along its local x, y, z axes in m. Each in `[1e-3, 1]`.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub brick_half_extents_m: [f64; 3],
    /// Stiffness of the proxy spring `F = -k d n` in N/m. Range `(0, device max stiffness]`.
    #[serde(alias = "proxy_stiffness_n_m")]
    pub proxy_stiffness_n_per_m: f64,
    /// Radius of the cursor sphere (the god-object) in m. Range `[1e-4, 0.1]`.
    pub proxy_radius_m: f64,
    /// A brick can be grabbed when the cursor sphere is within this gap of its surface, in m.
    /// Range `[0, 0.1]`.
    pub grab_distance_m: f64,
    /// A release faster than this is reported as a throw, in m/s. Range `[0, 100]`.
    #[serde(alias = "throw_min_speed_m_s")]
    pub throw_min_speed_m_per_s: f64,
    /// Cursor inputs must satisfy `|x|, |y|, |z| <= workspace_half_extent_m` (m). Range `(0, 100]`.
    pub workspace_half_extent_m: f64,
    /// Largest number of bricks the world may hold. Range `[0, 10000]`.
    pub max_bricks: usize,
    /// Rigid-body solver iterations per step (rapier substeps). Range `[1, 64]`.
    pub solver_iterations: usize,
    /// Natural frequency of rapier's soft contact constraints, Hz (rapier's default, 30 Hz, is
    /// tuned for 60 Hz games and lets a 10-brick stack settle 31 mm). Range `[1, 1000]`.
    pub contact_frequency_hz: f64,
    /// Whether resting bricks may fall asleep (stop being simulated until disturbed).
    pub sleeping: bool,
    /// The loading zone that supplies bricks; `None` (the default: no `[loading_zone]` table)
    /// disables spawning. [`LoadingZone::default`] is a 30 cm × 60 cm zone left of the origin.
    pub loading_zone: Option<LoadingZone>,
    /// The house to build; empty slots means no task.
    pub blueprint: Blueprint,
    /// Bricks present at the start.
    pub bricks: Vec<BrickPlacement>,
    /// Fixed boxes (tables, ramps, walls) besides the ground.
    pub obstacles: Vec<Obstacle>,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            dt_s: 1e-3,
            gravity_m_per_s2: 9.81,
            restitution: 0.2,
            friction: 0.6,
            inertia: Inertia::Coupling,
            coupling: Coupling::default(),
            release_velocity_band_m: 0.001_27,
            release_velocity_max_window: 25,
            accel_estimator: AccelEstimator::Paper,
            brick_mass_kg: 0.5,
            brick_half_extents_m: [0.1, 0.05, 0.03],
            proxy_stiffness_n_per_m: 1000.0,
            proxy_radius_m: 0.005,
            grab_distance_m: 0.005,
            throw_min_speed_m_per_s: 0.2,
            workspace_half_extent_m: 2.0,
            max_bricks: 200,
            solver_iterations: 4,
            contact_frequency_hz: 500.0,
            sleeping: true,
            loading_zone: None,
            blueprint: Blueprint::default(),
            bricks: Vec::new(),
            obstacles: Vec::new(),
        }
    }
}

/// How the carried brick's inertia reaches the hand (the `inertia` switch: 0 is `Off`, 1 the
/// scene's chosen method).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Inertia {
    /// Weight only: the brick is carried rigidly (kinematic) and no inertial force is felt.
    Off,
    /// The paper's method: the brick is carried rigidly and `F = −M a` is computed from the
    /// grip point's sampled positions ([`Params::accel_estimator`]). Displays `M` times the
    /// mapping's force and workspace scales at the device; unstable there above a fraction of
    /// the device's own mass (measured in `docs/brickworld.md`).
    Paper,
    /// Virtual coupling (Colgate 1995): the brick is a rigid body joined to the hand by a
    /// spring-damper no stiffer than the device allows; weight, inertia and contacts are felt
    /// through it alone.
    Coupling,
}

impl Inertia {
    /// The name as written in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Inertia::Off => "off",
            Inertia::Paper => "paper",
            Inertia::Coupling => "coupling",
        }
    }
}

impl<'de> Deserialize<'de> for Inertia {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Inertia;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"coupling\", \"paper\", \"off\", true or false")
            }
            fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Inertia, E> {
                Ok(if v { Inertia::Coupling } else { Inertia::Off })
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Inertia, E> {
                match v {
                    "coupling" => Ok(Inertia::Coupling),
                    "paper" => Ok(Inertia::Paper),
                    "off" => Ok(Inertia::Off),
                    other => Err(E::invalid_value(serde::de::Unexpected::Str(other), &self)),
                }
            }
        }
        d.deserialize_any(V)
    }
}

/// The virtual coupling that carries a brick (`[coupling]`): a spring-damper between the
/// hand's grip point and the brick, integrated implicitly with the brick's mass, so it is
/// stable for any brick mass and no contact reaches the hand stiffer than the spring.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Coupling {
    /// Spring stiffness as a fraction of the device's largest stable stiffness (in world units,
    /// [`Limits::max_stiffness_n_per_m`]). Range `(0, 1]`.
    pub stiffness_fraction: f64,
    /// Damping ratio of the coupling with the carried brick's mass, `b = 2 ζ √(k M)`; the
    /// damper acts through a series spring `(max_fraction − stiffness_fraction) k_max`, so its
    /// force never jumps. Range `[0, 2]`.
    pub damping_ratio: f64,
    /// The coupling's stiffness at high frequency (its spring plus the damper's series spring),
    /// as a fraction of the device's largest stable stiffness: what a fast jolt meets. Range
    /// `(stiffness_fraction, 1]`; below 1 it leaves the device a stability margin of
    /// `1 / max_fraction` against its rated stiffness.
    pub max_fraction: f64,
}

impl Default for Coupling {
    fn default() -> Self {
        Coupling {
            stiffness_fraction: 0.3,
            max_fraction: 0.6,
            damping_ratio: 0.9,
        }
    }
}

/// Estimator of the cursor acceleration used for the inertial force `F = -M a`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum AccelEstimator {
    /// The paper's stencil over the last five samples, `a = (B4 - 2 B2 + B0) / (2 dt)²`
    /// (the paper omits the `(2 dt)²` scale). Exact for quadratic motion, 2 ticks of lag,
    /// noise gain `sqrt(6) / (4 dt²)` times the position noise.
    Paper,
    /// Least-squares quadratic fit (Savitzky–Golay) over the last `window` samples; the
    /// acceleration is twice the fitted quadratic coefficient. Exact for quadratic motion,
    /// `(window - 1) / 2` ticks of lag, far less noise. `window` in `[5, 201]`.
    SavitzkyGolay {
        /// Number of samples in the fit (ticks).
        window: usize,
    },
}

/// The loading zone: an axis-aligned rectangle on the ground. When the cursor enters it (from
/// outside), a brick appears at `spawn_m` if that spot is clear.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingZone {
    /// Lower corner (x, y) of the zone in m.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub min_m: [f64; 2],
    /// Upper corner (x, y) of the zone in m; must exceed `min_m` on both axes.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub max_m: [f64; 2],
    /// Height of the zone above the ground in m (the cursor must be below it). Range `(0, 10]`.
    pub height_m: f64,
    /// Where the spawned brick's centre appears (x, y) in m; it rests flat on the ground.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub spawn_m: [f64; 2],
}

impl Default for LoadingZone {
    fn default() -> Self {
        Self {
            min_m: [-0.6, -0.3],
            max_m: [-0.3, 0.3],
            height_m: 0.5,
            spawn_m: [-0.45, 0.0],
        }
    }
}

/// Pose of a brick: centre in m and orientation as a rotation vector in degrees
/// (axis times angle; `[0, 0, 90]` is a quarter turn about z).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrickPlacement {
    /// Centre of the brick in the world frame, m.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub center_m: [f64; 3],
    /// Rotation vector (axis · angle) in degrees.
    #[serde(default)]
    #[serde(deserialize_with = "world_form::exact::array")]
    pub rotation_deg: [f64; 3],
}

impl BrickPlacement {
    /// The orientation (rotation vector in degrees) as a unit quaternion.
    pub fn rotation(&self) -> Rotation {
        let v = Vector::from_array(self.rotation_deg) * (std::f64::consts::PI / 180.0);
        Rotation::from_scaled_axis(v)
    }
}

/// Properties of one brick that may differ from the world's ([`crate::World::add_brick_with`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BrickProps {
    /// Initial linear velocity, m/s. Each component in `[-100, 100]`.
    #[serde(alias = "velocity_m_s")]
    #[serde(deserialize_with = "world_form::exact::array")]
    pub velocity_m_per_s: [f64; 3],
    /// Mass, kg in `[1e-3, 100]`; `None`: [`Params::brick_mass_kg`].
    pub mass_kg: Option<f64>,
    /// Friction coefficient in `[0, 10]`; `None`: [`Params::friction`]. A contact uses the
    /// mean of its two bodies' coefficients (rapier's rule).
    pub friction: Option<f64>,
    /// Coefficient of restitution in `[0, 1]`; `None`: [`Params::restitution`]. A contact uses
    /// the mean of its two bodies' coefficients.
    pub restitution: Option<f64>,
}

/// A fixed box (table, ramp, wall).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Centre in the world frame, m.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub center_m: [f64; 3],
    /// Half-extents along the box's local axes, m. Each in `[1e-3, 100]`.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub half_extents_m: [f64; 3],
    /// Rotation vector (axis · angle) in degrees.
    #[serde(default)]
    #[serde(deserialize_with = "world_form::exact::array")]
    pub rotation_deg: [f64; 3],
}

/// The house to build: brick slots and the tolerances that decide whether a slot is filled.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Blueprint {
    /// Target brick poses.
    pub slots: Vec<BrickPlacement>,
    /// A slot is filled by a brick whose centre is within this distance, m. Range `(0, 1]`.
    pub position_tolerance_m: f64,
    /// ... and whose orientation is within this angle (up to the box's symmetries), degrees.
    /// Range `(0, 90]`.
    pub angle_tolerance_deg: f64,
}

impl Default for Blueprint {
    fn default() -> Self {
        Self {
            slots: Vec::new(),
            position_tolerance_m: 0.01,
            angle_tolerance_deg: 5.0,
        }
    }
}

/// Lower bound of a range check.
#[derive(Clone, Copy)]
pub(crate) enum Lo {
    /// `[lo, ...`
    Closed(f64),
    /// `(lo, ...`
    Open(f64),
}

/// Checks `value` lies in `lo .. hi]` (upper bound closed); NaN always fails.
pub(crate) fn range(field: &str, value: f64, lo: Lo, hi: f64) -> Result<(), ParamError> {
    let (ok_lo, lo_txt) = match lo {
        Lo::Closed(l) => (value >= l, format!("[{}", fmt_num(l))),
        Lo::Open(l) => (value > l, format!("({}", fmt_num(l))),
    };
    if ok_lo && value <= hi {
        Ok(())
    } else {
        Err(ParamError::out_of_range(
            field,
            value,
            format!("{lo_txt}, {}]", fmt_num(hi)),
        ))
    }
}

fn count(field: &str, value: usize, lo: usize, hi: usize) -> Result<(), ParamError> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(ParamError::out_of_range(
            field,
            value as f64,
            format!("[{lo}, {hi}]"),
        ))
    }
}

/// Checks `value` lies in `[-limit, limit]`; NaN always fails.
fn plus_minus(field: &str, value: f64, limit: f64) -> Result<(), ParamError> {
    range(field, value, Lo::Closed(-limit), limit)
}

/// Checks every component `field[i]` of `v` lies in `[-limit, limit]`.
pub(crate) fn finite3(field: &str, v: &[f64; 3], limit: f64) -> Result<(), ParamError> {
    for (i, x) in v.iter().enumerate() {
        plus_minus(&format!("{field}[{i}]"), *x, limit)?;
    }
    Ok(())
}

/// Checks a placement `field`: its centre in ±100 m, its rotation in ±3600°.
pub(crate) fn placement(field: &str, p: &BrickPlacement) -> Result<(), ParamError> {
    finite3(&format!("{field}.center_m"), &p.center_m, 100.0)?;
    finite3(&format!("{field}.rotation_deg"), &p.rotation_deg, 3600.0)
}

impl Params {
    /// Parses a TOML table and validates it.
    pub fn from_toml(text: &str) -> Result<Params, ParamsFromTomlError> {
        let p: Params =
            toml::from_str(text).map_err(|e| ParamsFromTomlError::Toml(e.to_string()))?;
        p.validate()?;
        Ok(p)
    }

    /// Checks every field against its documented range (device-independent part).
    pub fn validate(&self) -> Result<(), ParamError> {
        self.validate_dynamics()?;
        if let Some(z) = &self.loading_zone {
            validate_loading_zone(z)?;
        }
        self.validate_layout()
    }

    /// The tick, gravity, contacts, coupling, estimators, brick and proxy, solver.
    fn validate_dynamics(&self) -> Result<(), ParamError> {
        range("dt_s", self.dt_s, Lo::Closed(1e-4), 1e-2)?;
        range(
            "gravity_m_per_s2",
            self.gravity_m_per_s2,
            Lo::Closed(0.0),
            100.0,
        )?;
        range("restitution", self.restitution, Lo::Closed(0.0), 1.0)?;
        range("friction", self.friction, Lo::Closed(0.0), 10.0)?;
        let c = &self.coupling;
        range(
            "coupling.stiffness_fraction",
            c.stiffness_fraction,
            Lo::Open(0.0),
            1.0,
        )?;
        range(
            "coupling.max_fraction",
            c.max_fraction,
            Lo::Open(c.stiffness_fraction),
            1.0,
        )?;
        range(
            "coupling.damping_ratio",
            c.damping_ratio,
            Lo::Closed(0.0),
            2.0,
        )?;
        range(
            "release_velocity_band_m",
            self.release_velocity_band_m,
            Lo::Closed(0.0),
            0.1,
        )?;
        count(
            "release_velocity_max_window",
            self.release_velocity_max_window,
            1,
            200,
        )?;
        if let AccelEstimator::SavitzkyGolay { window } = self.accel_estimator {
            count("accel_estimator.savitzky_golay.window", window, 5, 201)?;
        }
        range("brick_mass_kg", self.brick_mass_kg, Lo::Closed(1e-3), 100.0)?;
        for (i, h) in self.brick_half_extents_m.iter().enumerate() {
            range(
                &format!("brick_half_extents_m[{i}]"),
                *h,
                Lo::Closed(1e-3),
                1.0,
            )?;
        }
        range(
            "proxy_stiffness_n_per_m",
            self.proxy_stiffness_n_per_m,
            Lo::Open(0.0),
            1e7,
        )?;
        range("proxy_radius_m", self.proxy_radius_m, Lo::Closed(1e-4), 0.1)?;
        range(
            "grab_distance_m",
            self.grab_distance_m,
            Lo::Closed(0.0),
            0.1,
        )?;
        range(
            "throw_min_speed_m_per_s",
            self.throw_min_speed_m_per_s,
            Lo::Closed(0.0),
            100.0,
        )?;
        range(
            "workspace_half_extent_m",
            self.workspace_half_extent_m,
            Lo::Open(0.0),
            100.0,
        )?;
        count("max_bricks", self.max_bricks, 0, 10_000)?;
        count("solver_iterations", self.solver_iterations, 1, 64)?;
        range(
            "contact_frequency_hz",
            self.contact_frequency_hz,
            Lo::Closed(1.0),
            1000.0,
        )?;
        Ok(())
    }

    /// The blueprint, the bricks placed at the start and the obstacles.
    fn validate_layout(&self) -> Result<(), ParamError> {
        for (i, s) in self.blueprint.slots.iter().enumerate() {
            placement(&format!("blueprint.slots[{i}]"), s)?;
        }
        range(
            "blueprint.position_tolerance_m",
            self.blueprint.position_tolerance_m,
            Lo::Open(0.0),
            1.0,
        )?;
        range(
            "blueprint.angle_tolerance_deg",
            self.blueprint.angle_tolerance_deg,
            Lo::Open(0.0),
            90.0,
        )?;
        count("bricks", self.bricks.len(), 0, self.max_bricks)?;
        for (i, b) in self.bricks.iter().enumerate() {
            placement(&format!("bricks[{i}]"), b)?;
        }
        for (i, o) in self.obstacles.iter().enumerate() {
            finite3(&format!("obstacles[{i}].center_m"), &o.center_m, 100.0)?;
            finite3(
                &format!("obstacles[{i}].rotation_deg"),
                &o.rotation_deg,
                3600.0,
            )?;
            for (k, h) in o.half_extents_m.iter().enumerate() {
                range(
                    &format!("obstacles[{i}].half_extents_m[{k}]"),
                    *h,
                    Lo::Closed(1e-3),
                    100.0,
                )?;
            }
        }
        Ok(())
    }

    /// Checks the parameters that depend on the device: the limits themselves (named
    /// `device.max_force_n` / `device.max_stiffness_n_per_m`) and the proxy stiffness, which
    /// must not exceed [`Limits::max_stiffness_n_per_m`].
    pub fn validate_for_device(&self, limits: &Limits) -> Result<(), ParamError> {
        limits.validate().map_err(|e| {
            ParamError::Value(e.map_field(|f| format!("`device.{}`", f.trim_matches('`'))))
        })?;
        range(
            "proxy_stiffness_n_per_m",
            self.proxy_stiffness_n_per_m,
            Lo::Open(0.0),
            limits.max_stiffness_n_per_m,
        )
    }
}

/// The loading zone: its corners ordered and within ±100 m, its spawn point, its height.
fn validate_loading_zone(z: &LoadingZone) -> Result<(), ParamError> {
    for i in 0..2 {
        plus_minus(&format!("loading_zone.min_m[{i}]"), z.min_m[i], 100.0)?;
        plus_minus(&format!("loading_zone.max_m[{i}]"), z.max_m[i], 100.0)?;
        if z.min_m[i] >= z.max_m[i] {
            return Err(ParamError::Inconsistent {
                field: format!("loading_zone.max_m[{i}]"),
                reason: format!("must exceed loading_zone.min_m[{i}] = {}", z.min_m[i]),
            });
        }
        plus_minus(&format!("loading_zone.spawn_m[{i}]"), z.spawn_m[i], 100.0)?;
    }
    range("loading_zone.height_m", z.height_m, Lo::Open(0.0), 10.0)?;
    Ok(())
}

/// Failure to read parameters from TOML text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamsFromTomlError {
    /// The text is not valid TOML for [`Params`] (unknown field, wrong type, ...).
    #[error("invalid brickworld parameters: {0}")]
    Toml(String),
    /// The table parsed but a value is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
}
