//! The recording's channels, their schemas (ROS 2 `.msg` text, CDR encoding) and the typed
//! messages with their encoders and decoders.

use super::FORMAT_VERSION;
use crate::channels::cdr::{CdrError, CdrReader, CdrWriter};
use crate::vec3::Vec3;

/// The channels of a recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Channel {
    /// `/scene/description`, once at tick 0.
    Description,
    /// `/device/input`, every tick (an input of replay).
    DeviceInput,
    /// `/scene/switch`, on ticks where switches were set (an input of replay).
    Switch,
    /// `/world/state`, every tick.
    State,
    /// `/haptic/force`, every tick.
    Force,
    /// `/events`, on ticks with events.
    Events,
    /// `/loop/timing`, every tick (wall-clock measurements, not verified).
    Timing,
    /// `/foxglove/scene` (`foxglove.SceneUpdate`), at display rate.
    FoxgloveScene,
    /// `/foxglove/tf` (`foxglove.FrameTransform`), at display rate.
    FoxgloveTf,
    /// `/foxglove/log` (`foxglove.Log`), on ticks with events.
    FoxgloveLog,
}

impl Channel {
    /// Every channel, in registration order.
    pub const ALL: [Channel; 10] = [
        Channel::Description,
        Channel::DeviceInput,
        Channel::Switch,
        Channel::State,
        Channel::Force,
        Channel::Events,
        Channel::Timing,
        Channel::FoxgloveScene,
        Channel::FoxgloveTf,
        Channel::FoxgloveLog,
    ];

    /// MCAP topic.
    pub fn topic(self) -> &'static str {
        match self {
            Channel::Description => "/scene/description",
            Channel::DeviceInput => "/device/input",
            Channel::Switch => "/scene/switch",
            Channel::State => "/world/state",
            Channel::Force => "/haptic/force",
            Channel::Events => "/events",
            Channel::Timing => "/loop/timing",
            Channel::FoxgloveScene => "/foxglove/scene",
            Channel::FoxgloveTf => "/foxglove/tf",
            Channel::FoxgloveLog => "/foxglove/log",
        }
    }

    /// The channel with this topic.
    pub fn from_topic(topic: &str) -> Option<Channel> {
        Channel::ALL.into_iter().find(|c| c.topic() == topic)
    }

    /// True for outputs that replay recomputes and compares bit for bit.
    pub fn verified(self) -> bool {
        !matches!(
            self,
            Channel::Description | Channel::DeviceInput | Channel::Switch | Channel::Timing
        )
    }
}

/// Schema of `/device/input`.
pub const DEVICE_INPUT_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/DeviceInput",
    "# Device reading of one tick (device frame) and the real-time deadline flag.\n\
     uint64 tick\n\
     float64[3] position_m\n\
     uint32 buttons\n\
     bool deadline_missed\n\
     # the device's sequence number of this reading (information only)\n\
     uint64 seq\n\
     # ticks since the reading arrived (0: fresh; the watchdog ramps the force down from it)\n\
     uint32 age_ticks\n",
);

/// Schema of `/haptic/force`.
pub const FORCE_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/Force",
    "# Force of one tick: the scene's (world frame) and the one sent (device frame).\n\
     uint64 tick\n\
     float64[3] world_force_n\n\
     float64[3] device_force_n\n\
     float64 engagement\n\
     # bits: 1 clamped, 2 input invalid, 4 deadline missed, 8 stiffness over cap, 16 force invalid,\n\
     # 32 watchdog\n\
     uint8 status\n\
     # watchdog factor applied to the force (1: device samples fresh)\n\
     float64 watchdog\n\
     # local stiffness sent with the force, N/m, device frame, row-major 3x3\n\
     float64[9] device_stiffness_n_per_m\n",
);

/// Schema of `/events`.
pub const EVENTS_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/Events",
    "# Events raised during one tick, in order.\n\
     uint64 tick\n\
     string[] names\n\
     string[] details\n",
);

/// Schema of `/scene/switch`.
pub const SWITCH_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/Switch",
    "# Run-time switches set just before this tick's step (the teaching game's menu), in order.\n\
     uint64 tick\n\
     string[] names\n\
     # new values (on/off switches: 1 / 0)\n\
     float64[] values\n",
);

/// Schema of `/loop/timing`.
pub const TIMING_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/Timing",
    "# Wall-clock measurements of one tick (not reproducible, not verified by replay).\n\
     uint64 tick\n\
     int64 start_late_ns\n\
     uint64 compute_ns\n",
);

/// Schema of `/scene/description`.
pub const DESCRIPTION_SCHEMA: (&str, &str) = (
    "nanohaptics_msgs/msg/SceneDescription",
    "# The session: everything replay needs besides the per-tick inputs.\n\
     string format\n\
     string scene_name\n\
     string scene_kind\n\
     string scene_toml\n\
     string device_model\n\
     uint32 rate_hz\n\
     string mode\n\
     string script_name\n\
     string script_toml\n\
     string operator\n\
     string[] state_fields\n\
     # wall-clock start of the session, ns since the Unix epoch (log times are start + tick time)\n\
     uint64 start_time_ns\n\
     # how the device was connected: script, hand, replay, udp:HOST:PORT, python\n\
     string device_link\n\
     float64 device_max_force_n\n\
     float64 device_max_stiffness_n_per_m\n\
     float64 device_workspace_radius_m\n\
     string[] device_buttons\n",
);

/// Schema name and text of `/world/state` for a scene kind and its state fields.
pub fn state_schema(kind: &str, fields: &[String]) -> (String, String) {
    let mut camel = String::new();
    for part in kind.split('_') {
        let mut c = part.chars();
        if let Some(f) = c.next() {
            camel.extend(f.to_uppercase());
            camel.push_str(c.as_str());
        }
    }
    let mut text = String::from(
        "# World state after one tick; cursor in the world frame.\n\
         uint64 tick\n\
         float64[3] cursor_m\n\
         uint32 buttons\n",
    );
    for f in fields {
        text.push_str("float64 ");
        text.push_str(f);
        text.push('\n');
    }
    (format!("nanohaptics_msgs/msg/{camel}State"), text)
}

/// True when `name` is a valid ROS 2 field name (lower snake case, starts with a letter, no
/// double or trailing underscore) and not one of the fixed state fields.
pub fn valid_field_name(name: &str) -> bool {
    let b = name.as_bytes();
    !b.is_empty()
        && b[0].is_ascii_lowercase()
        && b.iter()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == b'_')
        && !name.contains("__")
        && !name.ends_with('_')
        && !["tick", "cursor_m", "buttons"].contains(&name)
}

/// `/device/input`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceInputMsg {
    /// Tick index.
    pub tick: u64,
    /// Stylus position, m, device frame (raw, possibly invalid).
    pub position_m: Vec3,
    /// Button bits (raw).
    pub buttons: u32,
    /// The real-time deadline of this tick was missed (zero force was sent).
    pub deadline_missed: bool,
    /// The device's sequence number of the reading.
    pub seq: u64,
    /// Ticks since the reading arrived (0: fresh).
    pub age_ticks: u32,
}

impl DeviceInputMsg {
    /// Encodes to CDR.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u64(self.tick)
            .f64s(&self.position_m)
            .u32(self.buttons)
            .bool(self.deadline_missed)
            .u64(self.seq)
            .u32(self.age_ticks);
        w.finish()
    }

    /// Decodes from CDR.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let m = DeviceInputMsg {
            tick: r.u64()?,
            position_m: r.vec3()?,
            buttons: r.u32()?,
            deadline_missed: r.bool()?,
            seq: r.u64()?,
            age_ticks: r.u32()?,
        };
        r.end()?;
        Ok(m)
    }
}

/// `/haptic/force`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceMsg {
    /// Tick index.
    pub tick: u64,
    /// Scene force, world frame, N.
    pub world_force_n: Vec3,
    /// Force sent, device frame, N.
    pub device_force_n: Vec3,
    /// Soft-engagement factor.
    pub engagement: f64,
    /// Status bits (see `haptic::status`).
    pub status: u8,
    /// Watchdog factor.
    pub watchdog: f64,
    /// Local stiffness sent, N/m, device frame, row-major 3×3.
    pub device_stiffness_n_per_m: [f64; 9],
}

impl ForceMsg {
    /// Encodes to CDR.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u64(self.tick)
            .f64s(&self.world_force_n)
            .f64s(&self.device_force_n)
            .f64(self.engagement)
            .u8(self.status)
            .f64(self.watchdog)
            .f64s(&self.device_stiffness_n_per_m);
        w.finish()
    }

    /// Decodes from CDR.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let m = ForceMsg {
            tick: r.u64()?,
            world_force_n: r.vec3()?,
            device_force_n: r.vec3()?,
            engagement: r.f64()?,
            status: r.u8()?,
            watchdog: r.f64()?,
            device_stiffness_n_per_m: {
                let mut k = [0.0; 9];
                for v in &mut k {
                    *v = r.f64()?;
                }
                k
            },
        };
        r.end()?;
        Ok(m)
    }
}

/// `/world/state`.
#[derive(Clone, Debug, PartialEq)]
pub struct StateMsg {
    /// Tick index.
    pub tick: u64,
    /// Cursor, world frame, m.
    pub cursor_m: Vec3,
    /// Buttons given to the scene.
    pub buttons: u32,
    /// The scene's state fields, in the order of the description's `state_fields`.
    pub values: Vec<f64>,
}

impl StateMsg {
    /// Encodes to CDR.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u64(self.tick)
            .f64s(&self.cursor_m)
            .u32(self.buttons)
            .f64s(&self.values);
        w.finish()
    }

    /// Decodes from CDR with `n` scene fields.
    pub fn decode(b: &[u8], n: usize) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let tick = r.u64()?;
        let cursor_m = r.vec3()?;
        let buttons = r.u32()?;
        let values = (0..n).map(|_| r.f64()).collect::<Result<Vec<_>, _>>()?;
        r.end()?;
        Ok(StateMsg {
            tick,
            cursor_m,
            buttons,
            values,
        })
    }
}

/// `/events`.
#[derive(Clone, Debug, PartialEq)]
pub struct EventsMsg {
    /// Tick index.
    pub tick: u64,
    /// Event names.
    pub names: Vec<String>,
    /// Event details (same length as `names`).
    pub details: Vec<String>,
}

impl EventsMsg {
    /// Encodes `events` of `tick` to CDR.
    pub fn encode(tick: u64, events: &[crate::scene::Event]) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u64(tick)
            .strings(events.iter().map(|e| e.name.as_str()))
            .strings(events.iter().map(|e| e.detail.as_str()));
        w.finish()
    }

    /// Decodes from CDR.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let m = EventsMsg {
            tick: r.u64()?,
            names: r.strings()?,
            details: r.strings()?,
        };
        r.end()?;
        Ok(m)
    }
}

/// `/scene/switch`.
#[derive(Clone, Debug, PartialEq)]
pub struct SwitchMsg {
    /// Tick index.
    pub tick: u64,
    /// The switches set before the tick's step, in order.
    pub switches: Vec<crate::scene::Switch>,
}

impl SwitchMsg {
    /// Encodes the `switches` of `tick` to CDR.
    pub fn encode(tick: u64, switches: &[crate::scene::Switch]) -> Vec<u8> {
        let values: Vec<f64> = switches.iter().map(|s| s.value).collect();
        let mut w = CdrWriter::new();
        w.u64(tick)
            .strings(switches.iter().map(|s| s.name.as_str()))
            .f64_seq(&values);
        w.finish()
    }

    /// Decodes from CDR; names and values must be of the same length.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let tick = r.u64()?;
        let names = r.strings()?;
        let values = r.f64_seq()?;
        r.end()?;
        if names.len() != values.len() {
            return Err(CdrError::Invalid(format!(
                "{} switch names but {} values",
                names.len(),
                values.len()
            )));
        }
        Ok(SwitchMsg {
            tick,
            switches: names
                .into_iter()
                .zip(values)
                .map(|(name, value)| crate::scene::Switch { name, value })
                .collect(),
        })
    }
}

/// `/loop/timing`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimingMsg {
    /// Tick index.
    pub tick: u64,
    /// Start lateness against the real-time schedule, ns (0 in batch mode).
    pub start_late_ns: i64,
    /// Work of the tick, ns.
    pub compute_ns: u64,
}

impl TimingMsg {
    /// Encodes to CDR.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u64(self.tick)
            .i64(self.start_late_ns)
            .u64(self.compute_ns);
        w.finish()
    }

    /// Decodes from CDR.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let m = TimingMsg {
            tick: r.u64()?,
            start_late_ns: r.i64()?,
            compute_ns: r.u64()?,
        };
        r.end()?;
        Ok(m)
    }
}

/// `/scene/description`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DescriptionMsg {
    /// [`FORMAT_VERSION`].
    pub format: String,
    /// Scene name.
    pub scene_name: String,
    /// Scene kind.
    pub scene_kind: String,
    /// The scene file's text.
    pub scene_toml: String,
    /// Device model used (may override the scene file's).
    pub device_model: String,
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// `batch` or `realtime`.
    pub mode: String,
    /// Script name (information only).
    pub script_name: String,
    /// Script text (information only: replay uses the logged inputs).
    pub script_toml: String,
    /// Operator (`rigid` or the hand parameters; information only).
    pub operator: String,
    /// Names of the scene's state fields.
    pub state_fields: Vec<String>,
    /// Wall-clock start of the session, ns since the Unix epoch (information; log times and
    /// Foxglove timestamps are `start_time_ns + tick · period`).
    pub start_time_ns: u64,
    /// How the device was connected (`script`, `hand`, `udp:HOST:PORT`, `python`).
    pub device_link: String,
    /// The device's maximum force, N.
    pub device_max_force_n: f64,
    /// The device's maximum stiffness, N/m.
    pub device_max_stiffness_n_per_m: f64,
    /// The device's workspace radius, m.
    pub device_workspace_radius_m: f64,
    /// The device's button names.
    pub device_buttons: Vec<String>,
}

impl DescriptionMsg {
    /// The description of a session of `loaded` (built from `scene_toml`) in `mode`, with the
    /// device connected by `link`, started at `start_time_ns`; no script (set `script_name`,
    /// `script_toml` and `operator` for a scripted session).
    pub fn new(
        scene_toml: &str,
        loaded: &crate::scene::file::LoadedScene,
        mode: &str,
        link: &str,
        start_time_ns: u64,
    ) -> Self {
        let specs = &loaded.config.specs;
        DescriptionMsg {
            format: FORMAT_VERSION.to_string(),
            scene_name: loaded.file.scene.name.clone(),
            scene_kind: loaded.scene.kind().to_string(),
            scene_toml: scene_toml.to_string(),
            device_model: specs.name.to_string(),
            rate_hz: loaded.config.rate_hz,
            mode: mode.to_string(),
            script_name: String::new(),
            script_toml: String::new(),
            operator: link.to_string(),
            state_fields: loaded.scene.state_fields(),
            start_time_ns,
            device_link: link.to_string(),
            device_max_force_n: specs.max_force_n,
            device_max_stiffness_n_per_m: specs.max_stiffness_n_per_m,
            device_workspace_radius_m: specs.workspace_radius_m,
            device_buttons: specs.button_names.iter().map(|b| b.to_string()).collect(),
        }
    }

    /// The device specifications this session ran with.
    pub fn device_specs(&self) -> crate::device::DeviceSpecs {
        crate::device::DeviceSpecs {
            name: self.device_model.clone().into(),
            max_force_n: self.device_max_force_n,
            max_stiffness_n_per_m: self.device_max_stiffness_n_per_m,
            workspace_radius_m: self.device_workspace_radius_m,
            button_names: self
                .device_buttons
                .iter()
                .map(|b| std::borrow::Cow::Owned(b.clone()))
                .collect::<Vec<_>>()
                .into(),
        }
    }
}

impl DescriptionMsg {
    /// Encodes to CDR.
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.string(&self.format)
            .string(&self.scene_name)
            .string(&self.scene_kind)
            .string(&self.scene_toml)
            .string(&self.device_model)
            .u32(self.rate_hz)
            .string(&self.mode)
            .string(&self.script_name)
            .string(&self.script_toml)
            .string(&self.operator)
            .strings(self.state_fields.iter().map(|s| s.as_str()))
            .u64(self.start_time_ns)
            .string(&self.device_link)
            .f64(self.device_max_force_n)
            .f64(self.device_max_stiffness_n_per_m)
            .f64(self.device_workspace_radius_m)
            .strings(self.device_buttons.iter().map(|s| s.as_str()));
        w.finish()
    }

    /// Decodes from CDR. A recording of another format version is refused with
    /// [`CdrError::Format`] naming the version it was recorded with.
    pub fn decode(b: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(b)?;
        let format = r.string()?;
        if format != FORMAT_VERSION {
            return Err(CdrError::Format(format));
        }
        let m = DescriptionMsg {
            format,
            scene_name: r.string()?,
            scene_kind: r.string()?,
            scene_toml: r.string()?,
            device_model: r.string()?,
            rate_hz: r.u32()?,
            mode: r.string()?,
            script_name: r.string()?,
            script_toml: r.string()?,
            operator: r.string()?,
            state_fields: r.strings()?,
            start_time_ns: r.u64()?,
            device_link: r.string()?,
            device_max_force_n: r.f64()?,
            device_max_stiffness_n_per_m: r.f64()?,
            device_workspace_radius_m: r.f64()?,
            device_buttons: r.strings()?,
        };
        r.end()?;
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_roundtrip() {
        let f = ForceMsg {
            tick: 9,
            world_force_n: [1.0, -0.0, f64::MIN_POSITIVE],
            device_force_n: [0.1, 0.2, 0.3],
            engagement: 0.5,
            status: 5,
            watchdog: 0.25,
            device_stiffness_n_per_m: [1.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0],
        };
        assert_eq!(ForceMsg::decode(&f.encode()), Ok(f));
        let i = DeviceInputMsg {
            tick: 1,
            position_m: [f64::NAN, 0.0, 1.0],
            buttons: 3,
            deadline_missed: true,
            seq: 77,
            age_ticks: 4,
        };
        let d = DeviceInputMsg::decode(&i.encode()).unwrap();
        assert!(d.position_m[0].is_nan() && d.buttons == 3 && d.deadline_missed);
        assert_eq!((d.seq, d.age_ticks), (77, 4));
        let s = StateMsg {
            tick: 2,
            cursor_m: [1.0, 2.0, 3.0],
            buttons: 1,
            values: vec![4.0, 5.0],
        };
        assert_eq!(StateMsg::decode(&s.encode(), 2), Ok(s.clone()));
        assert!(StateMsg::decode(&s.encode(), 3).is_err());
        assert!(StateMsg::decode(&s.encode(), 1).is_err());
    }

    #[test]
    fn state_schema_is_ros2_msg_text() {
        let (name, text) = state_schema("optical_tweezers", &["x_m".into(), "vx_m_per_s".into()]);
        assert_eq!(name, "nanohaptics_msgs/msg/OpticalTweezersState");
        assert!(text.ends_with("uint32 buttons\nfloat64 x_m\nfloat64 vx_m_per_s\n"));
        assert!(valid_field_name("penetration_m"));
        for bad in ["", "X", "a__b", "a_", "1a", "tick", "a-b"] {
            assert!(!valid_field_name(bad), "{bad}");
        }
    }
}
