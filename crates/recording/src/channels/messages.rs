//! The recording's channels and their messages, each declared once (see [`super::declare`]):
//! the struct, its CDR encoder and decoder, its ROS 2 `.msg` schema text, its per-tick columns
//! and its constructor from a tick all come from the declaration below.

use super::FORMAT_VERSION;
use super::cdr::{CdrError, CdrField, CdrReader, CdrWriter};
use super::declare::{ColumnData, ColumnField, recording_channels};
use haptic_types::vec3::Vec3;
use haptic_types::{DeviceSample, DeviceSpecs, Event, Switch, TickResult};

recording_channels! {
    channel Description = "/scene/description", Input, "once, tick 0",
    message DescriptionMsg(Clone, Debug, PartialEq, serde::Serialize)
        = "nanohaptics_msgs/msg/SceneDescription",
        "The session: everything replay needs besides the per-tick inputs."
    {
        /// The format version (`FORMAT_VERSION`, `nanohaptics-recording/3`; a reader refuses any
        /// other).
        #[check = check_format]
        format: String,
        /// Scene name.
        scene_name: String,
        /// Scene kind (`wall`, `nanoworld`, `brickworld`, `optical_tweezers`, …).
        scene_kind: String,
        /// The whole scene file: replay rebuilds the world from it.
        scene_toml: String,
        /// Device model used (`falcon`, `touch`, or the name a bridged device announced).
        device_model: String,
        /// Tick rate, Hz.
        rate_hz: u32,
        /// `batch`, `realtime` or `stepped`.
        mode: String,
        /// Script name (information only).
        script_name: String,
        /// Script text (information only: replay uses the logged inputs).
        script_toml: String,
        /// Operator: `rigid`, the simulated hand's parameters, `person` or `python` (information
        /// only).
        operator: String,
        /// Names of the scene's state fields, each with its unit.
        state_fields: Vec<String>,
        /// Wall-clock start of the session, ns since the Unix epoch (information; log times and
        /// Foxglove timestamps are `start_time_ns + tick · period`).
        #[msg = "wall-clock start of the session, ns since the Unix epoch (log times are start + tick time)"]
        start_time_ns: u64,
        /// How the device was connected: `script`, `hand`, `replay`, `udp:HOST:PORT`, `python`.
        #[msg = "how the device was connected: script, hand, replay, udp:HOST:PORT, python"]
        device_link: String,
        /// The device's maximum force, N (replay rebuilds the loop with the device's
        /// specifications).
        device_max_force_n: f64,
        /// The device's maximum stiffness, N/m.
        device_max_stiffness_n_per_m: f64,
        /// The device's workspace radius, m.
        device_workspace_radius_m: f64,
        /// The device's button names.
        device_buttons: Vec<String>,
    }

    channel DeviceInput = "/device/input", Input, "every tick",
    message DeviceInputMsg(Clone, Copy, Debug, PartialEq) = "nanohaptics_msgs/msg/DeviceInput",
        "Device reading of one tick (device frame) and the real-time deadline flag.",
        from(tick: u64, sample: &DeviceSample, deadline_missed: bool)
    {
        /// Tick index.
        tick: u64 => tick = tick,
        /// Stylus position, device frame, m (raw, possibly invalid).
        position_m: Vec3 => device_position_m = sample.position_m,
        /// Button bits (raw): bit i = button i of the device (Falcon: centre, plus, minus,
        /// forward).
        buttons: u32 => device_buttons = sample.buttons.0,
        /// The real-time deadline of this tick was missed (zero force was sent).
        deadline_missed: bool => deadline_missed = deadline_missed,
        /// The device's sequence number of the reading (information only).
        #[msg = "the device's sequence number of this reading (information only)"]
        seq: u64 => device_seq = sample.seq,
        /// Age of the reading, ticks since it arrived (0: fresh; the watchdog ramps the force
        /// down from it).
        #[msg = "ticks since the reading arrived (0: fresh; the watchdog ramps the force down from it)"]
        age_ticks: u32 => device_age_ticks = sample.age_ticks,
    }

    channel Switch = "/scene/switch", Input, "ticks with switches",
    message SwitchMsg(Clone, Debug, PartialEq) = "nanohaptics_msgs/msg/Switch",
        "Run-time switches set just before this tick's step (the teaching game's menu), in order.",
        from(tick: u64, switches: &[Switch]),
        validate = same_lengths
    {
        /// Tick index.
        tick: u64 = tick,
        /// Names of the switches set before the tick's step, in order.
        names: Vec<String> = switches.iter().map(|s| s.name.clone()).collect(),
        /// Their new values, in the switch's unit (on/off switches: 1 / 0); same length as
        /// `names`.
        #[msg = "new values (on/off switches: 1 / 0)"]
        values: Vec<f64> = switches.iter().map(|s| s.value).collect(),
    }

    channel State = "/world/state", Verified, "every tick",
    message StateMsg(Clone, Debug, PartialEq) = "nanohaptics_msgs/msg/<Kind>State",
        "World state after one tick; cursor in the world frame.",
        from(r: &TickResult, values: &[f64]),
        decode = custom
    {
        /// Tick index.
        tick: u64 = r.tick,
        /// Cursor, world frame, m (held at the last valid input when the input is invalid).
        cursor_m: Vec3 => cursor_m = r.cursor_m,
        /// Buttons given to the scene (bits).
        buttons: u32 = r.buttons.0,
        /// The scene's state fields, one `float64` each, named with its unit, in the order of
        /// the description's `state_fields`.
        values: StateValues => state = StateValues(values.to_vec()),
    }

    channel Force = "/haptic/force", Verified, "every tick",
    message ForceMsg(Clone, Copy, Debug, PartialEq) = "nanohaptics_msgs/msg/Force",
        "Force of one tick: the scene's (world frame) and the one sent (device frame).",
        from(r: &TickResult)
    {
        /// Tick index.
        tick: u64 = r.tick,
        /// Force of the scene on the cursor, world frame, N.
        world_force_n: Vec3 => world_force_n = r.world_force_n,
        /// Force sent, device frame, N (finite, norm ≤ the device's maximum).
        device_force_n: Vec3 => device_force_n = r.device_force_n,
        /// Soft-engagement factor, 0–1.
        engagement: f64 => engagement = r.engagement,
        /// Status bits (`haptic::status`): 1 clamped, 2 input invalid, 4 deadline missed, 8
        /// scene stiffness over the cap, 16 scene force not finite, 32 watchdog (stale device
        /// samples reduced the force), 64 the passivity controller added damping, 128 the
        /// force-rate limit held the change back.
        #[msg = "bits: 1 clamped, 2 input invalid, 4 deadline missed, 8 stiffness over cap, 16 force invalid,"]
        #[msg = "32 watchdog, 64 passivity controller, 128 force-rate limit"]
        status: u8 => status = r.status,
        /// Watchdog factor applied to the force, 0–1 (1: device samples fresh).
        #[msg = "watchdog factor applied to the force (1: device samples fresh)"]
        watchdog: f64 => watchdog = r.watchdog,
        /// Local stiffness sent with the force, N/m, device frame, row-major 3×3 (k a aᵀ for a
        /// wall, k I for a proxy spring), scaled by mapping, engagement, watchdog and clamp.
        #[msg = "local stiffness sent with the force, N/m, device frame, row-major 3x3"]
        device_stiffness_n_per_m: [f64; 9] => device_stiffness_n_per_m
            = r.device_stiffness_n_per_m,
    }

    channel Events = "/events", Verified, "ticks with events",
    message EventsMsg(Clone, Debug, PartialEq) = "nanohaptics_msgs/msg/Events",
        "Events raised during one tick, in order.",
        from(tick: u64, events: &[Event])
    {
        /// Tick index.
        tick: u64 = tick,
        /// Event names (`button.down`, `wall.contact_begin`, `force.clamped`, …).
        names: Vec<String> = events.iter().map(|e| e.name.clone()).collect(),
        /// Event details, same length as `names` (JSON with a `type` tag and named fields, or
        /// words; may be empty).
        details: Vec<String> = events.iter().map(|e| e.detail.clone()).collect(),
    }

    channel Timing = "/loop/timing", Unverified, "every tick",
    message TimingMsg(Clone, Copy, Debug, PartialEq) = "nanohaptics_msgs/msg/Timing",
        "Wall-clock measurements of one tick (not reproducible, not verified by replay).",
        from(tick: u64, start_late_ns: i64, compute_ns: u64)
    {
        /// Tick index.
        tick: u64 = tick,
        /// Start lateness against the real-time schedule, ns (0 in batch mode).
        start_late_ns: i64 => start_late_ns = start_late_ns,
        /// Work of the tick up to the hand-off of its messages, ns (wall clock).
        compute_ns: u64 => compute_ns = compute_ns,
    }

    protobuf FoxgloveScene = "/foxglove/scene", Verified,
        "display rate (`[display] rate_hz`, default 50 Hz)", "foxglove.SceneUpdate";
    protobuf FoxgloveTf = "/foxglove/tf", Verified,
        "display rate (`world` → `cursor`)", "foxglove.FrameTransform";
    protobuf FoxgloveLog = "/foxglove/log", Verified,
        "ticks with events (one per event)", "foxglove.Log";
}

impl Channel {
    /// The channel with this topic.
    pub fn from_topic(topic: &str) -> Option<Channel> {
        Channel::ALL.into_iter().find(|c| c.topic() == topic)
    }

    /// True for outputs that replay recomputes and compares bit for bit.
    pub fn verified(self) -> bool {
        self.role() == super::declare::Role::Verified
    }
}

/// A description of another format version is refused before the rest is read (its layout
/// may differ).
fn check_format(format: &str) -> Result<(), CdrError> {
    if format == FORMAT_VERSION {
        Ok(())
    } else {
        Err(CdrError::Format(format.to_string()))
    }
}

/// Switch names and values come in pairs.
fn same_lengths(m: &SwitchMsg) -> Result<(), CdrError> {
    if m.names.len() == m.values.len() {
        Ok(())
    } else {
        Err(CdrError::Invalid(format!(
            "{} switch names but {} values",
            m.names.len(),
            m.values.len()
        )))
    }
}

impl SwitchMsg {
    /// The switches, in order.
    pub fn switches(&self) -> Vec<Switch> {
        self.names
            .iter()
            .zip(&self.values)
            .map(|(name, &value)| Switch {
                name: name.clone(),
                value,
            })
            .collect()
    }
}

/// The scene's state fields of one tick (one `float64` each in `/world/state`, after the fixed
/// fields; their names and count are the description's `state_fields`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StateValues(pub Vec<f64>);

impl std::ops::Deref for StateValues {
    type Target = Vec<f64>;
    fn deref(&self) -> &Vec<f64> {
        &self.0
    }
}

impl CdrField for StateValues {
    /// Empty: the fields are named by the scene and appended by [`state_schema`].
    const MSG_TYPE: &'static str = "";
    fn put(&self, w: &mut CdrWriter) {
        w.f64s(&self.0);
    }
    /// Reads `float64` values up to the end of the message.
    fn get(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        let mut v = Vec::new();
        while r.remaining() > 0 {
            v.push(r.f64()?);
        }
        Ok(StateValues(v))
    }
}

impl ColumnField for StateValues {
    type Column = Vec<f64>;
    fn push_to(&self, col: &mut Vec<f64>) {
        col.extend_from_slice(&self.0);
    }
    fn reserve(col: &mut Vec<f64>, rows: usize, width: usize) {
        col.reserve(rows.saturating_mul(width));
    }
    fn data(col: &Vec<f64>) -> ColumnData<'_> {
        ColumnData::Table(col)
    }
}

impl StateMsg {
    /// Decodes from CDR with `n` scene fields (the description's `state_fields`).
    pub fn decode(b: &[u8], n: usize) -> Result<Self, CdrError> {
        let m = Self::decode_message(b)?;
        if m.values.len() != n {
            return Err(CdrError::Invalid(format!(
                "{} state values, the description names {n} state fields",
                m.values.len()
            )));
        }
        Ok(m)
    }
}

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
    let mut text = StateMsg::schema_text();
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

impl DescriptionMsg {
    /// The device specifications this session ran with.
    pub fn device_specs(&self) -> DeviceSpecs {
        DeviceSpecs {
            name: self.device_model.clone().into(),
            limits: world_form::Limits {
                max_force_n: self.device_max_force_n,
                max_stiffness_n_per_m: self.device_max_stiffness_n_per_m,
            },
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
            values: StateValues(vec![4.0, 5.0]),
        };
        assert_eq!(StateMsg::decode(&s.encode(), 2), Ok(s.clone()));
        assert!(StateMsg::decode(&s.encode(), 3).is_err());
        let sw = SwitchMsg::from_tick(
            7,
            &[Switch {
                name: "gravity_m_per_s2".into(),
                value: 0.0,
            }],
        );
        let b = sw.encode();
        // header, tick, one name (u32 count, u32 length, 17 bytes with NUL), pad to 4, the
        // values (u32 count, then one f64 already 8-aligned)
        assert_eq!(b.len(), 4 + 8 + 4 + 4 + 17 + 3 + 4 + 8);
        let back = SwitchMsg::decode(&b).unwrap();
        assert_eq!(back, sw);
        assert_eq!(back.switches()[0].name, "gravity_m_per_s2");
        assert!(StateMsg::decode(&s.encode(), 1).is_err());
    }

    /// The schema texts as they were written out by hand before the declarations (format 3),
    /// copied here once: the declarations must give exactly these bytes.
    const OLD_SCHEMAS: [(&str, &str); 6] = [
        (
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
        ),
        (
            "nanohaptics_msgs/msg/Force",
            "# Force of one tick: the scene's (world frame) and the one sent (device frame).\n\
             uint64 tick\n\
             float64[3] world_force_n\n\
             float64[3] device_force_n\n\
             float64 engagement\n\
             # bits: 1 clamped, 2 input invalid, 4 deadline missed, 8 stiffness over cap, 16 force invalid,\n\
             # 32 watchdog, 64 passivity controller, 128 force-rate limit\n\
             uint8 status\n\
             # watchdog factor applied to the force (1: device samples fresh)\n\
             float64 watchdog\n\
             # local stiffness sent with the force, N/m, device frame, row-major 3x3\n\
             float64[9] device_stiffness_n_per_m\n",
        ),
        (
            "nanohaptics_msgs/msg/Events",
            "# Events raised during one tick, in order.\n\
             uint64 tick\n\
             string[] names\n\
             string[] details\n",
        ),
        (
            "nanohaptics_msgs/msg/Switch",
            "# Run-time switches set just before this tick's step (the teaching game's menu), in order.\n\
             uint64 tick\n\
             string[] names\n\
             # new values (on/off switches: 1 / 0)\n\
             float64[] values\n",
        ),
        (
            "nanohaptics_msgs/msg/Timing",
            "# Wall-clock measurements of one tick (not reproducible, not verified by replay).\n\
             uint64 tick\n\
             int64 start_late_ns\n\
             uint64 compute_ns\n",
        ),
        (
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
        ),
    ];

    #[test]
    fn declared_schemas_are_the_old_texts_byte_for_byte() {
        let ros2: Vec<(&str, String)> = Channel::ALL
            .into_iter()
            .filter(|c| *c != Channel::State)
            .filter_map(Channel::ros2_schema)
            .collect();
        assert_eq!(ros2.len(), OLD_SCHEMAS.len());
        for (name, text) in OLD_SCHEMAS {
            let got = ros2
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, t)| t.as_str());
            assert_eq!(got, Some(text), "{name}");
        }
        // The state's fixed part, then one line per scene field.
        let (name, text) = state_schema("wall", &["penetration_m".into(), "in_contact".into()]);
        assert_eq!(name, "nanohaptics_msgs/msg/WallState");
        assert_eq!(
            text,
            "# World state after one tick; cursor in the world frame.\n\
             uint64 tick\n\
             float64[3] cursor_m\n\
             uint32 buttons\n\
             float64 penetration_m\n\
             float64 in_contact\n"
        );
    }

    #[test]
    fn channels_keep_their_topics_order_and_roles() {
        let topics: Vec<&str> = Channel::ALL.into_iter().map(Channel::topic).collect();
        assert_eq!(
            topics,
            [
                "/scene/description",
                "/device/input",
                "/scene/switch",
                "/world/state",
                "/haptic/force",
                "/events",
                "/loop/timing",
                "/foxglove/scene",
                "/foxglove/tf",
                "/foxglove/log"
            ]
        );
        let verified: Vec<bool> = Channel::ALL.into_iter().map(Channel::verified).collect();
        assert_eq!(
            verified,
            [
                false, false, false, true, true, true, false, true, true, true
            ]
        );
        assert_eq!(Channel::from_topic("/haptic/force"), Some(Channel::Force));
        assert_eq!(Channel::from_topic("/haptic/forces"), None);
    }

    #[test]
    fn columns_are_the_session_arrays_names() {
        let names: Vec<&str> = TickColumns::INFO.iter().map(|c| c.name).collect();
        assert_eq!(
            names,
            [
                "tick",
                "device_position_m",
                "device_buttons",
                "deadline_missed",
                "device_seq",
                "device_age_ticks",
                "cursor_m",
                "state",
                "world_force_n",
                "device_force_n",
                "engagement",
                "status",
                "watchdog",
                "device_stiffness_n_per_m",
                "start_late_ns",
                "compute_ns"
            ]
        );
        assert_eq!(
            TickColumns::INFO[13].doc.lines().next(),
            Some(
                " Local stiffness sent with the force, N/m, device frame, row-major 3×3 (k a aᵀ for a"
            )
        );
    }

    #[test]
    fn decoders_refuse_what_does_not_fit() {
        let s = SwitchMsg {
            tick: 3,
            names: vec!["gravity_m_per_s2".into()],
            values: vec![0.0, 1.0],
        };
        assert_eq!(
            SwitchMsg::decode(&s.encode()),
            Err(CdrError::Invalid("1 switch names but 2 values".into()))
        );
        let mut d = DescriptionMsg::decode_message(&[0, 1, 0, 0]).unwrap_err();
        assert_eq!(
            d,
            CdrError::Eof {
                at: 4,
                what: "uint32"
            }
        );
        let mut w = CdrWriter::new();
        w.string("nanohaptics-recording/2");
        d = DescriptionMsg::decode(&w.finish()).unwrap_err();
        assert_eq!(d, CdrError::Format("nanohaptics-recording/2".into()));
        // docs/recording-format.md quotes this message whole
        assert_eq!(
            d.to_string(),
            "recorded with format nanohaptics-recording/2; this build reads \
             nanohaptics-recording/3 (re-record the session, or replay it with the build that \
             wrote it)"
        );
        let st = StateMsg {
            tick: 2,
            cursor_m: [1.0, 2.0, 3.0],
            buttons: 1,
            values: StateValues(vec![4.0]),
        };
        assert_eq!(
            StateMsg::decode(&st.encode(), 2),
            Err(CdrError::Invalid(
                "1 state values, the description names 2 state fields".into()
            ))
        );
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
