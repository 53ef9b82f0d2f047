//! Server → page: the JSON messages ([`ServerMsg`]) and their parts.

use super::lesson::{LessonView, QuestionView};
use haptic_engine::runner::EndReason;
use haptic_types::primitive::{Ball, Primitive, Rgba};
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;

/// A message from the server to a page (JSON text, tagged by `type`).
///
/// The wire form is `{"type": "<name>", ...fields}`; the names are [`ServerMsg::TYPES`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ServerMsg {
    /// What is played: sent to every page when the scene is known, and first to each page
    /// that connects later.
    Hello(Hello),
    /// The session waits for a bridged device's hello: sent first to a page that connects
    /// before the scene is known.
    Waiting {
        /// What the session waits for, in words (`the device's hello`).
        #[serde(rename = "for")]
        waiting_for: String,
    },
    /// The answer to a page's `start`: whether it is the hand or watches.
    Role {
        /// The page's role.
        role: Role,
    },
    /// What the world looks like, about 60 times a second, and the events and sounds since
    /// the last frame.
    Frame(Frame),
    /// A menu switch applied before tick `tick` (sent to every page).
    Switched {
        /// The tick the switch applied to (it applies before the tick's step).
        tick: u64,
        /// The switch's name as the scene names it.
        name: String,
        /// Its value, in the switch's unit.
        value: f64,
    },
    /// A page message refused (sent to the page that sent it; the session goes on).
    Error {
        /// The field the error is about (`input.pos[2]`, `switch.value`; `type` for the
        /// message as a whole).
        field: String,
        /// What was wrong and what is allowed, in words.
        message: String,
    },
    /// The session is over: its figures and where to download its recording (sent to every
    /// page, and to each page that connects later).
    End(EndReport),
    /// Where the student is in the lesson (`play --lesson`): sent to every page on every move,
    /// and to a page that connects later.
    Lesson(Box<LessonView>),
}

impl ServerMsg {
    /// The `type` of every server message, in the order of the enum's variants.
    pub const TYPES: &'static [&'static str] = &[
        "hello", "waiting", "role", "frame", "switched", "error", "end", "lesson",
    ];

    /// The message's `type` on the wire.
    pub fn type_name(&self) -> &'static str {
        match self {
            ServerMsg::Hello(_) => "hello",
            ServerMsg::Waiting { .. } => "waiting",
            ServerMsg::Role { .. } => "role",
            ServerMsg::Frame(_) => "frame",
            ServerMsg::Switched { .. } => "switched",
            ServerMsg::Error { .. } => "error",
            ServerMsg::End(_) => "end",
            ServerMsg::Lesson(_) => "lesson",
        }
    }

    /// One example of every server message, in [`ServerMsg::TYPES`] order (for tests, docs
    /// and programs that check what they read).
    pub fn examples() -> Vec<ServerMsg> {
        let msgs = vec![
            ServerMsg::Hello(example_hello()),
            ServerMsg::Waiting {
                waiting_for: "the device's hello".into(),
            },
            ServerMsg::Role { role: Role::Hand },
            ServerMsg::Frame(Frame {
                tick: 32,
                time_s: 0.032,
                view: Some(FrameView {
                    wall_ms: 1_764_000_000_000.5,
                    prims: vec![Primitive::Sphere(Ball {
                        center_m: [0.0, 0.0, 0.1],
                        radius_m: 0.01,
                        color: Rgba([1.0, 0.5, 0.0, 1.0]),
                    })],
                    state: [("score".to_string(), 25.0)].into_iter().collect(),
                    cursor_m: [0.0, 0.0, 0.1],
                    world_force_n: [0.0, 0.0, 1.5],
                    device_force_n: [0.0, 0.0, 1.5],
                    status: 1,
                }),
                events: vec![EventAt(20, "brick.grabbed".into(), "0".into())],
                sounds: vec![SoundAt(21, "thud".into(), 0.25)],
            }),
            ServerMsg::Switched {
                tick: 700,
                name: "friction".into(),
                value: 0.2,
            },
            ServerMsg::Error {
                field: "input.pos[2]".into(),
                message: "out of range".into(),
            },
            ServerMsg::End(EndReport {
                end: EndReason::Stopped,
                ticks: 2000,
                seconds: 2.0,
                missed_deadlines: 0,
                tick_work: TickWorkMs {
                    p50_ms: 0.01,
                    p99_ms: 0.05,
                    max_ms: 0.2,
                },
                state: [("score".to_string(), 25.0)].into_iter().collect(),
                peak_device_force_n: 2.5,
                events: 4,
                input_latency_ms: LatencyMs::of(&[1.0, 2.0]),
                recording: "/recording.mcap".into(),
                recording_file: Some("play.mcap".into()),
                recording_bytes: Some(4096),
            }),
            ServerMsg::Lesson(Box::new(example_lesson())),
        ];
        // A new variant stops this match from compiling: give it an example above and its
        // `type` in `ServerMsg::TYPES` (and a row in docs/play.md's table).
        for m in &msgs {
            match m {
                ServerMsg::Hello(_)
                | ServerMsg::Waiting { .. }
                | ServerMsg::Role { .. }
                | ServerMsg::Frame(_)
                | ServerMsg::Switched { .. }
                | ServerMsg::Error { .. }
                | ServerMsg::End(_)
                | ServerMsg::Lesson(_) => {}
            }
        }
        msgs
    }

    /// The message as the JSON text sent to a page (numbers as `serde_json` writes them: an
    /// `f64` always with a fraction or exponent, `1.0`; a non-finite one as `null`).
    pub fn to_json(&self) -> String {
        // Only maps with non-string keys fail to serialise, and these types have none.
        serde_json::to_string(self).unwrap_or_else(|_| {
            r#"{"type":"error","field":"type","message":"the server could not write a message"}"#
                .to_string()
        })
    }
}

/// A page's role in the session.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// The page is the hand: its inputs drive the session.
    Hand,
    /// The page watches and listens (another page or a bridged device is the hand).
    View,
}

/// The `hello` message: the scene, the device, the view's mapping, the menu, the state
/// fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// The scene's name as its file gives it (the page's title).
    pub scene: String,
    /// The scene kind (`brickworld`, `nanoworld`, `wall`, …).
    pub kind: String,
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// The device's name (`falcon`, or the bridged device's).
    pub device: String,
    /// Radius of the device workspace, m (device frame).
    pub workspace_radius_m: f64,
    /// The device's largest force, N (the force gauge's full scale).
    pub max_force_n: f64,
    /// The device's buttons by name, button 0 first (button `i` is bit `i` of an `input`'s
    /// `buttons`).
    pub buttons: Vec<String>,
    /// Whether a page is the hand (false: a bridged device is, the pages watch).
    pub page_is_hand: bool,
    /// Display metres per world metre (the drawing's scale: a shape's metres times this).
    pub display_scale: f64,
    /// Device workspace to world.
    pub mapping: Mapping,
    /// The scene's menu of switches with their values now.
    pub switches: Vec<SwitchInfo>,
    /// The names of the scene's state fields (the keys of a frame's `state`).
    pub state_fields: Vec<String>,
    /// The session's planned length, s (`null`: until the player or the program ends it).
    pub seconds: Option<f64>,
}

/// Device workspace to world: `world_m = origin_m + workspace_scale × device_m`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mapping {
    /// World point under the device origin, m.
    pub origin_m: [f64; 3],
    /// World metres per device metre.
    pub workspace_scale: f64,
}

/// A switch of the scene's menu.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SwitchInfo {
    /// Name, with its unit as suffix (`gravity_m_per_s2`).
    pub name: String,
    /// Smallest allowed value (inclusive), in the switch's unit.
    pub min: f64,
    /// Largest allowed value (inclusive), in the switch's unit.
    pub max: f64,
    /// A boolean switch: 0 (off) or 1 (on) only.
    pub boolean: bool,
    /// What it changes, in words.
    pub doc: String,
    /// Its value now (`null`: the scene does not say).
    pub value: Option<f64>,
}

/// The `frame` message: the world drawn at tick `tick` and what happened since the last
/// frame. The session's last frame has no drawing ([`Frame::view`] is `None`): it carries the
/// last events and sounds only.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// The tick drawn (the last tick, for the last frame).
    pub tick: u64,
    /// Session time of the tick, s (`tick / rate_hz`; the session's length for the last frame).
    pub time_s: f64,
    /// The drawing, the state and the forces (absent from the last frame).
    #[serde(flatten)]
    pub view: Option<FrameView>,
    /// The events since the last frame, in tick order.
    pub events: Vec<EventAt>,
    /// The sounds since the last frame, in tick order.
    pub sounds: Vec<SoundAt>,
}

/// What a frame shows: its fields sit beside [`Frame`]'s in the same JSON object.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameView {
    /// When the tick's force was sent, by the server's clock, ms since the Unix epoch.
    pub wall_ms: f64,
    /// The shapes to draw, world frame, in the scene's order (the first is the ground).
    pub prims: Vec<Primitive>,
    /// The scene's state after the tick: each of the hello's `state_fields` with its value
    /// (units in the field's name; a non-finite value is `null`).
    #[serde(deserialize_with = "null_as_nan")]
    pub state: BTreeMap<String, f64>,
    /// The haptic cursor, world frame, m.
    pub cursor_m: [f64; 3],
    /// The world's force on the hand, world frame, N.
    pub world_force_n: [f64; 3],
    /// The force sent to the device, device frame, N.
    pub device_force_n: [f64; 3],
    /// The tick's status bits (`haptic_types::tick::status`: 1 clamped, 2 input invalid,
    /// 4 deadline missed, …).
    pub status: u8,
}

/// An event at its tick, on the wire `[tick, name, detail]`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventAt(
    /// The tick.
    pub u64,
    /// The event's name (`brick.grabbed`, `nano.snap`, …).
    pub String,
    /// Its detail as the recording writes it.
    pub String,
);

/// A sound at its tick, on the wire `[tick, name, amplitude]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SoundAt(
    /// The tick.
    pub u64,
    /// The sound (`thud`, `clack`, `tap`, `snap`, `pull_off`).
    pub String,
    /// Its amplitude, 0–1 of full scale.
    pub f64,
);

/// The `end` message: the session's figures and where to download its recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EndReport {
    /// How the session ended.
    pub end: EndReason,
    /// Ticks run.
    pub ticks: u64,
    /// Session time, s (`ticks / rate_hz`).
    pub seconds: f64,
    /// Ticks that missed their real-time deadline.
    pub missed_deadlines: u64,
    /// The tick's work (the step and the sinks), ms.
    pub tick_work: TickWorkMs,
    /// The scene's state after the last tick, as in a frame (units in each name; a
    /// non-finite value is `null`).
    #[serde(deserialize_with = "null_as_nan")]
    pub state: BTreeMap<String, f64>,
    /// Largest force sent to the device, N.
    pub peak_device_force_n: f64,
    /// Events in the session.
    pub events: u64,
    /// A page input to the force of the first tick that used it, ms (`null`: a bridged
    /// device was the hand, or no input arrived).
    pub input_latency_ms: Option<LatencyMs>,
    /// Where to download the recording (`/recording.mcap`).
    pub recording: String,
    /// The recording's file name (the download's name).
    pub recording_file: Option<String>,
    /// The recording's size, bytes (`null`: not known).
    pub recording_bytes: Option<u64>,
}

/// A tick's work: median, 99th percentile and largest, ms.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TickWorkMs {
    /// Median, ms.
    pub p50_ms: f64,
    /// 99th percentile, ms.
    pub p99_ms: f64,
    /// Largest, ms.
    pub max_ms: f64,
}

/// Latency figures, ms.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatencyMs {
    /// Samples.
    pub n: usize,
    /// Median, ms.
    pub p50: f64,
    /// 99th percentile (nearest rank), ms.
    pub p99: f64,
    /// Largest, ms.
    pub max: f64,
}

impl LatencyMs {
    /// Figures of `v` (`None` when empty).
    pub fn of(v: &[f64]) -> Option<Self> {
        if v.is_empty() {
            return None;
        }
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        Some(LatencyMs {
            n: s.len(),
            p50: world_form::numbers::percentile(&s, 0.5)?,
            p99: world_form::numbers::percentile(&s, 0.99)?,
            max: world_form::numbers::percentile(&s, 1.0)?,
        })
    }
}

/// A state map whose non-finite values were written as `null` (JSON has no NaN): `null`
/// reads back as NaN.
fn null_as_nan<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<String, f64>, D::Error> {
    let m = BTreeMap::<String, Option<f64>>::deserialize(d)?;
    Ok(m.into_iter()
        .map(|(k, v)| (k, v.unwrap_or(f64::NAN)))
        .collect())
}

// Page → server.

/// The example `hello` of [`ServerMsg::examples`].
fn example_hello() -> Hello {
    Hello {
        scene: "wall".into(),
        kind: "wall".into(),
        rate_hz: 1000,
        device: "falcon".into(),
        workspace_radius_m: 0.04,
        max_force_n: 8.0,
        buttons: vec!["centre".into(), "plus".into()],
        page_is_hand: true,
        display_scale: 10.0,
        mapping: Mapping {
            origin_m: [0.0, -0.05, 0.2],
            workspace_scale: 20.0,
        },
        switches: vec![SwitchInfo {
            name: "friction".into(),
            min: 0.0,
            max: 10.0,
            boolean: false,
            doc: "friction coefficient of every contact".into(),
            value: Some(0.6),
        }],
        state_fields: vec!["score".into()],
        seconds: None,
    }
}

/// The example `lesson` of [`ServerMsg::examples`].
fn example_lesson() -> LessonView {
    LessonView {
        title: "Sticky atoms".into(),
        place: "before".into(),
        step: Some(1),
        steps: 3,
        step_id: "float".into(),
        step_title: "A brick without gravity".into(),
        task: "Gravity is off. Throw a brick.".into(),
        question: Some(QuestionView {
            prompt: "What will the brick do?".into(),
            choices: vec!["Fall".into(), "Fly on".into()],
            max_chars: 2000,
        }),
        score: None,
        words: "Step 2 of 3, A brick without gravity. Before you start: What will the brick do?"
            .into(),
    }
}
