//! Scripts (TOML waypoints with times and button events) and the scripted device.
//!
//! Between two waypoints the stylus follows a minimum-jerk profile
//! `p(τ) = p0 + (p1 − p0)(10τ³ − 15τ⁴ + 6τ⁵)`, the classic model of a human reaching movement
//! (Flash & Hogan 1985): position, velocity and acceleration are continuous, the velocity is zero
//! at every waypoint, and the path stays on the segment between the waypoints (so a script whose
//! waypoints are inside the workspace sphere never leaves it).
//!
//! ```toml
//! [script]
//! name = "press the wall"
//! duration_s = 3.0            # optional; default: the last waypoint or button time
//! operator = "hand"           # optional: "hand" (default) or "rigid", when the caller leaves it
//!
//! [operator]                  # optional: parameters of the simulated operator's hand
//! mass_kg = 0.3
//!
//! [[waypoint]]
//! t_s = 0.0
//! position_mm = [0.0, 0.0, 10.0]
//!
//! [[button]]
//! t_s = 1.0
//! role = "grip"               # a role (grip, turn_x, turn_y, turn_z), played by whichever
//! down = true                 # button the device maps to it; or `name = "centre"`, a button
//!                             # of the device by its own name
//!
//! [[switch]]                  # optional: the teaching game's menu, at a time
//! t_s = 2.0
//! name = "gravity_m_per_s2"       # one of the scene's switches (docs/haptic-loop.md)
//! value = 0.0                 # a number, or true / false for on/off switches
//! ```

use haptic_types::device::{
    Buttons, DeviceError, DeviceSample, DeviceSpecs, ForceCommand, HapticDevice, TickTime,
};
use haptic_types::vec3::{self, Vec3};
use haptic_types::{ButtonRoles, Role};
use serde::{Deserialize, Serialize};
use world_form::{ValueError, fmt_num};

/// Errors in a script file; each names the field and the allowed range.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ScriptError {
    /// A value that cannot be read (an `--operator` override that is not `key=value`, ...).
    #[error("script: {0}")]
    Parse(String),
    /// The text is not valid TOML for a script (unknown field, wrong type, ...).
    #[error("script: {message}")]
    Syntax {
        /// What the TOML reader found wrong and what it expected.
        message: String,
        /// Byte offset in the text where it went wrong, when known.
        offset: Option<usize>,
    },
    /// A script needs at least one waypoint.
    #[error("script: `waypoint` must list at least one waypoint")]
    NoWaypoints,
    /// A number outside its allowed range; the field path in backticks, e.g.
    /// `` `waypoint[2].t_s` ``.
    #[error("script: {0}")]
    OutOfRange(ValueError),
    /// A switch the scene does not have, or a value outside its range.
    #[error("script: `{field}`: {source}")]
    Switch {
        /// Field path, e.g. `switch[0].name`.
        field: String,
        /// What the scene allows.
        source: haptic_types::switch::SwitchError,
    },
    /// A button event's role out of range, or an event with both or neither of `name` and
    /// `role` (the error names the field).
    #[error("script: {0}")]
    Role(DeviceError),
    /// A button the device does not have.
    #[error("script: `{field}`: {source}")]
    Button {
        /// Field path, e.g. `button[0].name`.
        field: String,
        /// The device error naming the allowed buttons.
        source: DeviceError,
    },
}

impl ScriptError {
    /// Where in the script's `text` the error is: the TOML reader's position, or the named
    /// field's value (`None` when neither is known).
    pub fn position(&self, text: &str) -> Option<haptic_types::textpos::Position> {
        use haptic_types::textpos::{field_position, position};
        match self {
            ScriptError::Syntax { offset, .. } => offset.map(|o| position(text, o)),
            ScriptError::OutOfRange(e) => field_position(text, e.field().trim_matches('`')),
            ScriptError::Button { field, .. } | ScriptError::Switch { field, .. } => {
                field_position(text, field)
            }
            ScriptError::NoWaypoints => field_position(text, "script"),
            ScriptError::Role(DeviceError::Buttons { field, .. }) => field_position(text, field),
            ScriptError::Role(_) => None,
            ScriptError::Parse(_) => None,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptFile {
    script: ScriptHeader,
    #[serde(default)]
    operator: Option<OperatorParams>,
    #[serde(default)]
    waypoint: Vec<WaypointFile>,
    #[serde(default)]
    button: Vec<ButtonFile>,
    #[serde(default)]
    switch: Vec<SwitchFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ScriptHeader {
    name: String,
    #[serde(default)]
    duration_s: Option<f64>,
    #[serde(default)]
    operator: OperatorKind,
}

/// How a script wants to be played when the caller does not choose (`[script] operator`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OperatorKind {
    /// Through the simulated hand (parameters from `[operator]` or the defaults).
    #[default]
    Hand,
    /// Exactly, by a rigid stylus (e.g. a path that must be followed to a fraction of an atom).
    Rigid,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WaypointFile {
    t_s: f64,
    #[serde(deserialize_with = "world_form::exact::array")]
    position_mm: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ButtonFile {
    t_s: f64,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    role: Option<String>,
    down: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SwitchFile {
    t_s: f64,
    name: String,
    value: SwitchValue,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum SwitchValue {
    Bool(bool),
    Number(f64),
}

/// A scheduled switch: at `t_s` the scene's switch `name` takes `value` (applied before the
/// first tick whose time is ≥ `t_s`, like button events).
#[derive(Clone, Debug, PartialEq)]
pub struct SwitchEvent {
    /// Time, s.
    pub t_s: f64,
    /// The switch (checked against the scene when the session starts).
    pub name: String,
    /// Its value (booleans as 0 / 1).
    pub value: f64,
    /// Its index in the file's `[[switch]]` list (errors name `switch[index]`).
    pub index: usize,
}

/// A waypoint: the stylus is at `position_m` at time `t_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Time from the start of the session, s.
    pub t_s: f64,
    /// Stylus position, m, device frame.
    pub position_m: Vec3,
}

/// A button event: at `t_s` the button with bit `index` goes down (`down = true`) or up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ButtonEvent {
    /// Time, s.
    pub t_s: f64,
    /// Bit index of the button in the device's button list.
    pub index: u32,
    /// New state.
    pub down: bool,
}

/// A validated script for one device.
#[derive(Clone, Debug, PartialEq)]
pub struct Script {
    /// Script name.
    pub name: String,
    /// Session length the script asks for, s.
    pub duration_s: f64,
    /// Waypoints in strictly increasing time.
    pub waypoints: Vec<Waypoint>,
    /// Button events in non-decreasing time (file order kept on equal times).
    pub buttons: Vec<ButtonEvent>,
    /// Switch events in non-decreasing time (file order kept on equal times).
    pub switches: Vec<SwitchEvent>,
    /// Operator hand parameters given by the script, if any.
    pub operator: Option<OperatorParams>,
    /// How the script wants to be played by default.
    pub operator_kind: OperatorKind,
}

fn check(field: String, value: f64, ok: bool, allowed: &str) -> Result<(), ScriptError> {
    if ok {
        Ok(())
    } else {
        Err(ScriptError::OutOfRange(ValueError::out_of_range(
            format!("`{field}`"),
            value,
            allowed.to_string(),
        )))
    }
}

/// `field` = `t_s` checked: finite, within 0 … [`MAX_SCRIPT_S`].
fn check_time(field: String, t_s: f64) -> Result<(), ScriptError> {
    check(
        field,
        t_s,
        t_s.is_finite() && (0.0..=MAX_SCRIPT_S).contains(&t_s),
        &format!("0 ≤ t_s ≤ {MAX_SCRIPT_S}"),
    )
}

/// The `[[waypoint]]`s: times increasing, positions finite and inside the workspace.
fn waypoints(file: &[WaypointFile], specs: &DeviceSpecs) -> Result<Vec<Waypoint>, ScriptError> {
    let r_mm = specs.workspace_radius_m * 1e3;
    let mut waypoints = Vec::with_capacity(file.len());
    let mut last_t = f64::NEG_INFINITY;
    for (i, w) in file.iter().enumerate() {
        let field = format!("waypoint[{i}].t_s");
        check_time(field.clone(), w.t_s)?;
        check(
            field,
            w.t_s,
            w.t_s > last_t,
            &format!("greater than the previous waypoint's t_s = {last_t}"),
        )?;
        last_t = w.t_s;
        for (k, c) in w.position_mm.iter().enumerate() {
            check(
                format!("waypoint[{i}].position_mm[{k}]"),
                *c,
                c.is_finite(),
                "a finite number",
            )?;
        }
        let p = vec3::scale(w.position_mm, 1e-3);
        let dist_mm = vec3::norm(w.position_mm);
        check(
            format!("waypoint[{i}].position_mm (distance from the device origin, mm)"),
            dist_mm,
            vec3::norm(p) <= specs.workspace_radius_m,
            &format!("≤ {r_mm} mm, the {} workspace radius", specs.name),
        )?;
        waypoints.push(Waypoint {
            t_s: w.t_s,
            position_m: p,
        });
    }
    Ok(waypoints)
}

/// The `[[button]]` events, by time: each a button the device has, by its name or by the role
/// it plays in `roles`. An event for a role no button of the device plays is left out (the
/// device cannot press it; the script still runs).
fn buttons(
    file: &[ButtonFile],
    specs: &DeviceSpecs,
    roles: &ButtonRoles,
) -> Result<Vec<ButtonEvent>, ScriptError> {
    let mut buttons = Vec::with_capacity(file.len());
    for (i, b) in file.iter().enumerate() {
        check_time(format!("button[{i}].t_s"), b.t_s)?;
        let index = match (&b.name, &b.role) {
            (Some(name), None) => {
                specs
                    .button_index(name)
                    .map_err(|source| ScriptError::Button {
                        field: format!("button[{i}].name"),
                        source,
                    })?
            }
            (None, Some(role)) => {
                let field = format!("button[{i}].role");
                let role = Role::from_name(&field, role).map_err(ScriptError::Role)?;
                match roles.bit(role) {
                    Some(bit) => bit,
                    None => continue,
                }
            }
            _ => {
                return Err(ScriptError::Role(DeviceError::Buttons {
                    field: format!("button[{i}]"),
                    value: "both or neither of `name` and `role`".into(),
                    allowed: "exactly one: `role` (grip, turn_x, turn_y, turn_z) or `name` \
                              (a button of the device)"
                        .into(),
                }));
            }
        };
        buttons.push(ButtonEvent {
            t_s: b.t_s,
            index,
            down: b.down,
        });
    }
    buttons.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    Ok(buttons)
}

/// The `[[switch]]` events, by time, each value finite (the scene checks names and ranges).
fn switches(file: &[SwitchFile]) -> Result<Vec<SwitchEvent>, ScriptError> {
    let mut switches = Vec::with_capacity(file.len());
    for (i, w) in file.iter().enumerate() {
        check_time(format!("switch[{i}].t_s"), w.t_s)?;
        let value = match w.value {
            SwitchValue::Bool(b) => f64::from(u8::from(b)),
            SwitchValue::Number(v) => v,
        };
        check(
            format!("switch[{i}].value"),
            value,
            value.is_finite(),
            "a finite number",
        )?;
        switches.push(SwitchEvent {
            t_s: w.t_s,
            name: w.name.clone(),
            value,
            index: i,
        });
    }
    switches.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    Ok(switches)
}

/// Longest script accepted, s (one hour).
pub const MAX_SCRIPT_S: f64 = 3600.0;

impl Script {
    /// Parses and validates a script for a device with specs `specs`, its buttons by their
    /// preset's roles or the default by index (no overrides).
    pub fn from_toml(text: &str, specs: &DeviceSpecs) -> Result<Script, ScriptError> {
        let roles = ButtonRoles::resolve(specs, &[]).map_err(ScriptError::Role)?;
        Script::from_toml_with(text, specs, &roles)
    }

    /// Parses and validates a script for a device with specs `specs` whose buttons play the
    /// roles `roles` (the mapping in force, overrides included).
    pub fn from_toml_with(
        text: &str,
        specs: &DeviceSpecs,
        roles: &ButtonRoles,
    ) -> Result<Script, ScriptError> {
        let file: ScriptFile =
            toml::from_str(text).map_err(|e: toml::de::Error| ScriptError::Syntax {
                message: e.message().trim().to_string(),
                offset: e.span().map(|s| s.start),
            })?;
        if file.waypoint.is_empty() {
            return Err(ScriptError::NoWaypoints);
        }
        let waypoints = waypoints(&file.waypoint, specs)?;
        let buttons = buttons(&file.button, specs, roles)?;
        let switches = switches(&file.switch)?;
        let natural = buttons
            .iter()
            .map(|b| b.t_s)
            .chain(switches.iter().map(|s| s.t_s))
            .fold(waypoints[waypoints.len() - 1].t_s, f64::max);
        let duration_s = match file.script.duration_s {
            Some(d) => {
                check(
                    "script.duration_s".to_string(),
                    d,
                    d.is_finite() && d > 0.0 && d <= MAX_SCRIPT_S,
                    &format!("0 < duration_s ≤ {MAX_SCRIPT_S}"),
                )?;
                d
            }
            None => natural.max(0.0),
        };
        if let Some(op) = &file.operator {
            op.validate().map_err(|e| match e {
                ScriptError::OutOfRange(e) => ScriptError::OutOfRange(
                    e.map_field(|f| format!("`operator.{}`", f.trim_matches('`'))),
                ),
                other => other,
            })?;
        }
        Ok(Script {
            name: file.script.name,
            duration_s,
            waypoints,
            buttons,
            switches,
            operator: file.operator,
            operator_kind: file.script.operator,
        })
    }

    fn segment(&self, t: f64) -> Option<(usize, f64)> {
        // Index i of the segment [w_i, w_{i+1}] holding t, and τ in [0, 1].
        let w = &self.waypoints;
        if t <= w[0].t_s || w.len() == 1 {
            return None;
        }
        let i = w.partition_point(|p| p.t_s <= t);
        if i >= w.len() {
            return None;
        }
        let (a, b) = (w[i - 1], w[i]);
        Some((i - 1, (t - a.t_s) / (b.t_s - a.t_s)))
    }

    /// Intended stylus position at time `t_s`, m (held at the first waypoint before it and at the
    /// last after it).
    pub fn position(&self, t_s: f64) -> Vec3 {
        match self.segment(t_s) {
            None => {
                let w = &self.waypoints;
                if t_s <= w[0].t_s {
                    w[0].position_m
                } else {
                    w[w.len() - 1].position_m
                }
            }
            Some((i, tau)) => {
                let (a, b) = (self.waypoints[i], self.waypoints[i + 1]);
                let s = tau * tau * tau * (10.0 + tau * (-15.0 + 6.0 * tau));
                vec3::add(
                    a.position_m,
                    vec3::scale(vec3::sub(b.position_m, a.position_m), s),
                )
            }
        }
    }

    /// Intended stylus velocity at time `t_s`, m/s.
    pub fn velocity(&self, t_s: f64) -> Vec3 {
        match self.segment(t_s) {
            None => [0.0; 3],
            Some((i, tau)) => {
                let (a, b) = (self.waypoints[i], self.waypoints[i + 1]);
                let ds = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / (b.t_s - a.t_s);
                vec3::scale(vec3::sub(b.position_m, a.position_m), ds)
            }
        }
    }

    /// Button state at time `t_s`: every event with `t ≤ t_s` applied in order.
    pub fn buttons(&self, t_s: f64) -> Buttons {
        self.buttons
            .iter()
            .take_while(|e| e.t_s <= t_s)
            .fold(Buttons(0), |b, e| b.with(e.index, e.down))
    }
}

/// A device that plays a script exactly (a perfectly rigid hand: forces do not move it).
#[derive(Clone, Debug)]
pub struct ScriptedDevice {
    script: Script,
    specs: DeviceSpecs,
    last_force_n: Vec3,
}

impl ScriptedDevice {
    /// A scripted device with specs `specs` (the script must have been validated for them).
    pub fn new(script: Script, specs: DeviceSpecs) -> Self {
        ScriptedDevice {
            script,
            specs,
            last_force_n: [0.0; 3],
        }
    }

    /// The last commanded force, N.
    pub fn last_force_n(&self) -> Vec3 {
        self.last_force_n
    }
}

impl HapticDevice for ScriptedDevice {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError> {
        Ok(DeviceSample::new(
            self.script.position(time.time_s),
            self.script.buttons(time.time_s),
        ))
    }

    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError> {
        self.last_force_n = cmd.force_n;
        Ok(())
    }
}

/// Parameters of the simulated hand.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OperatorParams {
    /// Effective mass of hand and stylus, kg. Allowed: 0.01–10.
    pub mass_kg: f64,
    /// Stiffness pulling the hand toward the intent, N/m. Allowed: 1–10 000.
    pub stiffness_n_per_m: f64,
    /// Damping relative to the intended velocity, N·s/m. Allowed: 0–1000.
    pub damping_n_s_per_m: f64,
    /// Felt force that halves the operator's intended speed, N (0: off, a passive hand).
    /// Allowed: 0–100.
    pub yield_force_n: f64,
}

impl Default for OperatorParams {
    fn default() -> Self {
        OperatorParams {
            mass_kg: 0.3,
            stiffness_n_per_m: 300.0,
            damping_n_s_per_m: 12.0,
            yield_force_n: 0.0,
        }
    }
}

impl OperatorParams {
    /// Checks every field against its allowed range.
    pub fn validate(&self) -> Result<(), ScriptError> {
        let fields = [
            ("mass_kg", self.mass_kg, 0.01, 10.0),
            ("stiffness_n_per_m", self.stiffness_n_per_m, 1.0, 1.0e4),
            ("damping_n_s_per_m", self.damping_n_s_per_m, 0.0, 1.0e3),
            ("yield_force_n", self.yield_force_n, 0.0, 100.0),
        ];
        for (field, value, lo, hi) in fields {
            if !(value.is_finite() && value >= lo && value <= hi) {
                return Err(ScriptError::OutOfRange(ValueError::out_of_range(
                    format!("`{field}`"),
                    value,
                    format!("{} ≤ {field} ≤ {}", fmt_num(lo), fmt_num(hi)),
                )));
            }
        }
        Ok(())
    }

    /// Parses `key=value,key=value` overrides (keys are the field names) on top of `self`.
    pub fn with_overrides(mut self, spec: &str) -> Result<Self, ScriptError> {
        for part in spec.split(',').filter(|p| !p.trim().is_empty()) {
            let (key, value) = part.split_once('=').ok_or_else(|| {
                ScriptError::Parse(format!("operator: expected key=value, got `{part}`"))
            })?;
            let v: f64 = value.trim().parse().map_err(|_| {
                ScriptError::Parse(format!("operator: `{}` is not a number", value.trim()))
            })?;
            match key.trim() {
                "mass_kg" => self.mass_kg = v,
                "stiffness_n_per_m" => self.stiffness_n_per_m = v,
                "damping_n_s_per_m" => self.damping_n_s_per_m = v,
                "yield_force_n" => self.yield_force_n = v,
                other => {
                    return Err(ScriptError::Parse(format!(
                        "operator: unknown key `{other}` (allowed: mass_kg, stiffness_n_per_m, \
                         damping_n_s_per_m, yield_force_n)"
                    )));
                }
            }
        }
        self.validate()?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::device::FALCON;

    const S: &str = r#"
[script]
name = "t"
[[waypoint]]
t_s = 0.0
position_mm = [0.0, 0.0, 0.0]
[[waypoint]]
t_s = 2.0
position_mm = [20.0, 0.0, -10.0]
[[button]]
t_s = 1.0
name = "centre"
down = true
[[button]]
t_s = 1.5
name = "centre"
down = false
"#;

    #[test]
    fn min_jerk_midpoint_and_ends() {
        let s = Script::from_toml(S, &FALCON).unwrap();
        assert_eq!(s.duration_s, 2.0);
        assert_eq!(s.position(0.0), [0.0, 0.0, 0.0]);
        assert_eq!(s.position(2.0), [0.02, 0.0, -0.01]);
        assert_eq!(s.position(5.0), [0.02, 0.0, -0.01]);
        let mid = s.position(1.0);
        assert!((mid[0] - 0.01).abs() < 1e-15 && (mid[2] + 0.005).abs() < 1e-15);
        // Peak velocity of a minimum-jerk move: 1.875 · distance / duration, at the midpoint.
        assert!((s.velocity(1.0)[0] - 1.875 * 0.02 / 2.0).abs() < 1e-15);
        assert_eq!(s.velocity(0.0), [0.0; 3]);
        // Velocity is the derivative of position (central difference, O(h²)).
        let h = 1e-5;
        for t in [0.3, 0.77, 1.4] {
            let fd = (s.position(t + h)[0] - s.position(t - h)[0]) / (2.0 * h);
            assert!((fd - s.velocity(t)[0]).abs() < 1e-9, "t = {t}");
        }
    }

    #[test]
    fn button_events_apply_in_time() {
        let s = Script::from_toml(S, &FALCON).unwrap();
        assert_eq!(s.buttons(0.999), Buttons(0));
        assert_eq!(s.buttons(1.0), Buttons(1));
        assert_eq!(s.buttons(1.5), Buttons(0));
    }

    #[test]
    fn errors_name_the_field() {
        let bad = S.replace("[20.0, 0.0, -10.0]", "[50.0, 0.0, 0.0]");
        assert_eq!(
            Script::from_toml(&bad, &FALCON).unwrap_err().to_string(),
            "script: `waypoint[1].position_mm (distance from the device origin, mm)` = 50 is out \
             of range: allowed ≤ 40 mm, the falcon workspace radius"
        );
        let bad = S.replace("t_s = 2.0", "t_s = 0.0");
        assert_eq!(
            Script::from_toml(&bad, &FALCON).unwrap_err().to_string(),
            "script: `waypoint[1].t_s` = 0 is out of range: allowed greater than the previous \
             waypoint's t_s = 0"
        );
        let bad = S.replacen("name = \"centre\"", "name = \"trigger\"", 1);
        assert_eq!(
            Script::from_toml(&bad, &FALCON).unwrap_err().to_string(),
            "script: `button[0].name`: device `falcon` has no button `trigger` (allowed: centre, \
             plus, minus, forward)"
        );
        let bad = S.replace("[script]", "[script]\nspeed = 3");
        assert!(matches!(
            Script::from_toml(&bad, &FALCON),
            Err(ScriptError::Syntax { message: m, .. }) if m.contains("unknown field `speed`")
        ));
        let bad = S.replace(
            "position_mm = [0.0, 0.0, 0.0]",
            "position_mm = [nan, 0.0, 0.0]",
        );
        assert_eq!(
            Script::from_toml(&bad, &FALCON).unwrap_err().to_string(),
            "script: `waypoint[0].position_mm[0]` = NaN is out of range: allowed a finite number"
        );
    }
}
