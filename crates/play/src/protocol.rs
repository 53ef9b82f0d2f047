//! The page ↔ server protocol over the WebSocket (`/ws`): one type per direction.
//!
//! - **Server → page**: [`ServerMsg`], JSON text messages tagged by `type` (`hello`, `waiting`,
//!   `role`, `frame`, `switched`, `error`, `end`), written by [`ServerMsg::to_json`] (the one
//!   place a server message becomes text), and binary sound ticks ([`SoundTicks`]).
//! - **Page → server**: [`PageMsg`], JSON text messages tagged by `type` (`start`, `input`,
//!   `switch`, `end`), read by [`parse`], which checks every field: a bad one gets a typed
//!   [`ProtocolError`] naming the field and its allowed range (sent back to the page as an
//!   `error` message; the session goes on).
//!
//! Both types serialise and deserialise, so another program (a test, a classroom server
//! watching several sessions) can speak the protocol with the same types. The table of every
//! message, its fields with units and when it is sent is in `docs/play.md`; a test
//! (`tests/protocol_doc.rs`) keeps that table and these types in step.
//!
//! **Binary sound ticks** (server → page): what the page's sound synthesis needs of each tick
//! (its wall time, the distance to the nearest object for the proximity tone, and the sounds
//! that start on it), sent as soon as the publisher has them; the page synthesises the sound
//! itself (`synth.js`, an AudioWorklet port of [`render::audio::StreamSynth`]). The layout is
//! [`SoundTicks::encode`]'s.

use haptic_engine::runner::EndReason;
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;

/// Bytes of a [`SoundTicks`] message's header: the first tick (u64), the proximity tone's
/// on-distance (f64, m; NaN: no tone), the number of ticks (u32) and of sounds (u32).
pub const SOUND_TICKS_HEADER_BYTES: usize = 24;
/// Bytes per tick of a [`SoundTicks`] message: its wall time (f64, ms since the Unix epoch)
/// and its distance to the nearest object (f64, m; NaN: nothing near or no such state).
pub const SOUND_TICK_BYTES: usize = 16;
/// Bytes per sound of a [`SoundTicks`] message: its tick (u64), its index in the session's
/// list of sounds (u32), its kind (u32, [`SoundKind`]) and its peak amplitude (f64).
pub const SOUND_ON_BYTES: usize = 24;

/// The timbre of a sound on the wire (the `kind` of a [`SoundOn`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoundKind {
    /// 0: a brick on the ground (`thud`).
    Thud = 0,
    /// 1: a brick on a brick (`clack`).
    Clack = 1,
    /// 2: the hand on a brick or the ground (`tap`).
    Tap = 2,
    /// 3: snap-to-contact (`snap`).
    Snap = 3,
    /// 4: pull-off (`pull_off`).
    PullOff = 4,
}

impl SoundKind {
    /// The kind with wire code `code`, if any.
    pub fn from_code(code: u32) -> Option<SoundKind> {
        Some(match code {
            0 => SoundKind::Thud,
            1 => SoundKind::Clack,
            2 => SoundKind::Tap,
            3 => SoundKind::Snap,
            4 => SoundKind::PullOff,
            _ => return None,
        })
    }

    /// The kind of a synthesised sound and its peak amplitude (0–1 of full scale).
    pub fn of(s: &render::audio::Sound) -> (SoundKind, f64) {
        use render::audio::{Impact, Sound};
        match *s {
            Sound::Impact { kind, amplitude } => (
                match kind {
                    Impact::BrickGround => SoundKind::Thud,
                    Impact::BrickBrick => SoundKind::Clack,
                    Impact::Cursor => SoundKind::Tap,
                },
                amplitude,
            ),
            Sound::Snap { amplitude } => (SoundKind::Snap, amplitude),
            Sound::PullOff { amplitude } => (SoundKind::PullOff, amplitude),
        }
    }

    /// The synthesised sound of this kind at peak amplitude `amplitude`.
    pub fn sound(self, amplitude: f64) -> render::audio::Sound {
        use render::audio::{Impact, Sound};
        let impact = |kind| Sound::Impact { kind, amplitude };
        match self {
            SoundKind::Thud => impact(Impact::BrickGround),
            SoundKind::Clack => impact(Impact::BrickBrick),
            SoundKind::Tap => impact(Impact::Cursor),
            SoundKind::Snap => Sound::Snap { amplitude },
            SoundKind::PullOff => Sound::PullOff { amplitude },
        }
    }

    /// The page's name of the sound (a frame's `sounds`).
    pub fn name(self) -> &'static str {
        match self {
            SoundKind::Thud => "thud",
            SoundKind::Clack => "clack",
            SoundKind::Tap => "tap",
            SoundKind::Snap => "snap",
            SoundKind::PullOff => "pull_off",
        }
    }
}

/// One tick's input to the sound synthesis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundTick {
    /// When the tick's force was sent, by the server's clock, ms since the Unix epoch.
    pub wall_ms: f64,
    /// Distance to the nearest object after the tick, m (NaN: none).
    pub nearest_m: f64,
}

/// A sound that starts on a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundOn {
    /// The tick it starts on (its onset is `tick / rate_hz` s).
    pub tick: u64,
    /// Its place in the session's list of sounds, from 0 (it seeds the noise of impacts).
    pub index: u32,
    /// Its timbre.
    pub kind: SoundKind,
    /// Its peak amplitude, 0–1 of full scale.
    pub amplitude: f64,
}

/// The binary sound message: consecutive ticks `first_tick ..` with what the synthesis needs
/// of each, and the sounds that start on them, in order.
///
/// Wire layout, all little-endian: [`SOUND_TICKS_HEADER_BYTES`] of header (`first_tick` u64,
/// `tone_on_distance_m` f64 with NaN for none, the number of ticks u32, the number of sounds
/// u32), then [`SOUND_TICK_BYTES`] per tick (`wall_ms` f64, `nearest_m` f64), then
/// [`SOUND_ON_BYTES`] per sound (`tick` u64, `index` u32, `kind` u32, `amplitude` f64).
#[derive(Clone, Debug, PartialEq)]
pub struct SoundTicks {
    /// The first tick's index.
    pub first_tick: u64,
    /// Distance below which the proximity tone sounds, m (`None`: no tone in this scene).
    pub tone_on_distance_m: Option<f64>,
    /// Ticks `first_tick`, `first_tick + 1`, ….
    pub ticks: Vec<SoundTick>,
    /// The sounds starting on those ticks, in the session's order.
    pub sounds: Vec<SoundOn>,
}

/// Why bytes are not a [`SoundTicks`] message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("sound ticks message: {0}")]
pub struct SoundTicksError(String);

impl SoundTicks {
    /// The message's bytes (the layout above).
    pub fn encode(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(
            SOUND_TICKS_HEADER_BYTES
                + SOUND_TICK_BYTES * self.ticks.len()
                + SOUND_ON_BYTES * self.sounds.len(),
        );
        b.extend_from_slice(&self.first_tick.to_le_bytes());
        b.extend_from_slice(&self.tone_on_distance_m.unwrap_or(f64::NAN).to_le_bytes());
        b.extend_from_slice(&(self.ticks.len() as u32).to_le_bytes());
        b.extend_from_slice(&(self.sounds.len() as u32).to_le_bytes());
        for t in &self.ticks {
            b.extend_from_slice(&t.wall_ms.to_le_bytes());
            b.extend_from_slice(&t.nearest_m.to_le_bytes());
        }
        for s in &self.sounds {
            b.extend_from_slice(&s.tick.to_le_bytes());
            b.extend_from_slice(&s.index.to_le_bytes());
            b.extend_from_slice(&(s.kind as u32).to_le_bytes());
            b.extend_from_slice(&s.amplitude.to_le_bytes());
        }
        b
    }

    /// Reads a message; wrong lengths and unknown kinds are errors.
    pub fn decode(b: &[u8]) -> Result<SoundTicks, SoundTicksError> {
        fn u64_at(b: &[u8], at: usize) -> Option<u64> {
            Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
        }
        fn u32_at(b: &[u8], at: usize) -> Option<u32> {
            Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
        }
        let f64_at = |at| u64_at(b, at).map(f64::from_bits);
        let short = || SoundTicksError(format!("{} bytes is too short", b.len()));
        let first_tick = u64_at(b, 0).ok_or_else(short)?;
        let on = f64_at(8).ok_or_else(short)?;
        let nt = u32_at(b, 16).ok_or_else(short)? as usize;
        let ns = u32_at(b, 20).ok_or_else(short)? as usize;
        let want = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * nt + SOUND_ON_BYTES * ns;
        if b.len() != want {
            return Err(SoundTicksError(format!(
                "{} bytes for {nt} ticks and {ns} sounds (allowed: {want})",
                b.len()
            )));
        }
        let mut ticks = Vec::with_capacity(nt);
        for i in 0..nt {
            let at = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * i;
            ticks.push(SoundTick {
                wall_ms: f64_at(at).ok_or_else(short)?,
                nearest_m: f64_at(at + 8).ok_or_else(short)?,
            });
        }
        let mut sounds = Vec::with_capacity(ns);
        for i in 0..ns {
            let at = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * nt + SOUND_ON_BYTES * i;
            let code = u32_at(b, at + 12).ok_or_else(short)?;
            sounds.push(SoundOn {
                tick: u64_at(b, at).ok_or_else(short)?,
                index: u32_at(b, at + 8).ok_or_else(short)?,
                kind: SoundKind::from_code(code)
                    .ok_or_else(|| SoundTicksError(format!("sound kind {code} (allowed: 0–4)")))?,
                amplitude: f64_at(at + 16).ok_or_else(short)?,
            });
        }
        Ok(SoundTicks {
            first_tick,
            tone_on_distance_m: (!on.is_nan()).then_some(on),
            ticks,
            sounds,
        })
    }
}

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
}

impl ServerMsg {
    /// The `type` of every server message, in the order of the enum's variants.
    pub const TYPES: &'static [&'static str] = &[
        "hello", "waiting", "role", "frame", "switched", "error", "end",
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
        }
    }

    /// One example of every server message, in [`ServerMsg::TYPES`] order (for tests, docs
    /// and programs that check what they read).
    pub fn examples() -> Vec<ServerMsg> {
        let msgs = vec![
            ServerMsg::Hello(Hello {
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
            }),
            ServerMsg::Waiting {
                waiting_for: "the device's hello".into(),
            },
            ServerMsg::Role { role: Role::Hand },
            ServerMsg::Frame(Frame {
                tick: 32,
                time_s: 0.032,
                view: Some(FrameView {
                    wall_ms: 1_764_000_000_000.5,
                    prims: vec![Shape::Sphere {
                        center_m: [0.0, 0.0, 0.1],
                        radius_m: 0.01,
                        color: [1.0, 0.5, 0.0, 1.0],
                    }],
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
                | ServerMsg::End(_) => {}
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
    pub prims: Vec<Shape>,
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

/// A shape as the page draws it: world frame, metres, tagged by `k`, with short keys (a
/// frame carries dozens of them 60 times a second). Made from a scene's
/// [`haptic_types::primitive::Primitive`] by [`Shape::from`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "k", rename_all = "snake_case")]
pub enum Shape {
    /// A shaded sphere.
    Sphere {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Radius, m.
        #[serde(rename = "r")]
        radius_m: f64,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// The haptic cursor: a see-through sphere with an outline.
    Cursor {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Radius, m.
        #[serde(rename = "r")]
        radius_m: f64,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A shaded box (drawn dashed and see-through when its alpha is below 0.5).
    Box {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Half extents along the box axes, m.
        #[serde(rename = "h")]
        half_extents_m: [f64; 3],
        /// Orientation, unit quaternion `[x, y, z, w]`.
        #[serde(rename = "q")]
        rotation: [f64; 4],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A blueprint slot: the dashed edges of a box where a brick should go.
    Slot {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Half extents along the box axes, m.
        #[serde(rename = "h")]
        half_extents_m: [f64; 3],
        /// Orientation, unit quaternion `[x, y, z, w]`.
        #[serde(rename = "q")]
        rotation: [f64; 4],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// An ellipse in a plane of constant z (the page draws it as a disc of radius `ax[0]`).
    Ellipse {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Semi-axes along x and y, m.
        #[serde(rename = "ax")]
        semi_axes_m: [f64; 2],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A polyline, dashed, over the ground.
    #[serde(rename = "line")]
    Line {
        /// Vertices, m.
        #[serde(rename = "p")]
        points_m: Vec<[f64; 3]>,
        /// Join the last vertex to the first.
        closed: bool,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// An arrow (a force drawn at the scene's m/N scale), drawn over the solids.
    Arrow {
        /// Tail, m.
        #[serde(rename = "a")]
        from_m: [f64; 3],
        /// Head, m.
        #[serde(rename = "b")]
        to_m: [f64; 3],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A text label (the first one is also the page's task line).
    Label {
        /// Anchor, m.
        #[serde(rename = "c")]
        position_m: [f64; 3],
        /// Text.
        text: String,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
}

impl From<&haptic_types::primitive::Primitive> for Shape {
    fn from(p: &haptic_types::primitive::Primitive) -> Self {
        use haptic_types::primitive::Primitive as P;
        match p {
            P::Sphere {
                center_m,
                radius_m,
                color,
            } => Shape::Sphere {
                center_m: *center_m,
                radius_m: *radius_m,
                color: color.0,
            },
            P::Cursor {
                center_m,
                radius_m,
                color,
            } => Shape::Cursor {
                center_m: *center_m,
                radius_m: *radius_m,
                color: color.0,
            },
            P::Box {
                center_m,
                half_extents_m,
                rotation,
                color,
            } => Shape::Box {
                center_m: *center_m,
                half_extents_m: *half_extents_m,
                rotation: *rotation,
                color: color.0,
            },
            P::Slot {
                center_m,
                half_extents_m,
                rotation,
                color,
            } => Shape::Slot {
                center_m: *center_m,
                half_extents_m: *half_extents_m,
                rotation: *rotation,
                color: color.0,
            },
            P::Ellipse {
                center_m,
                semi_axes_m,
                color,
            } => Shape::Ellipse {
                center_m: *center_m,
                semi_axes_m: *semi_axes_m,
                color: color.0,
            },
            P::Polyline {
                points_m,
                closed,
                color,
            } => Shape::Line {
                points_m: points_m.clone(),
                closed: *closed,
                color: color.0,
            },
            P::Arrow {
                from_m,
                to_m,
                color,
            } => Shape::Arrow {
                from_m: *from_m,
                to_m: *to_m,
                color: color.0,
            },
            P::Label {
                position_m,
                text,
                color,
            } => Shape::Label {
                position_m: *position_m,
                text: text.clone(),
                color: color.0,
            },
        }
    }
}

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

/// Largest page message accepted, bytes.
pub const MAX_MESSAGE_BYTES: usize = 4096;

/// A page message that cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProtocolError {
    /// Not a JSON object.
    #[error("page message is not a JSON object: {0}")]
    NotJson(String),
    /// Longer than [`MAX_MESSAGE_BYTES`].
    #[error("page message of {0} bytes is too long (allowed: at most {MAX_MESSAGE_BYTES} bytes)")]
    TooLong(usize),
    /// A binary frame (the page sends text only).
    #[error("page message is binary (allowed: JSON text)")]
    Binary,
    /// An unknown `type`.
    #[error("page message `type` = {0} is unknown (allowed: start, input, switch, end)")]
    UnknownType(String),
    /// A field missing or of the wrong type.
    #[error("page message field `{field}` is {got} (expected: {expected})")]
    Field {
        /// The field, e.g. `input.pos[2]`.
        field: String,
        /// What it was (`missing`, `a string`).
        got: String,
        /// What it must be.
        expected: &'static str,
    },
    /// A number out of its range.
    #[error("page message field `{field}` = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// The field.
        field: String,
        /// The value given.
        value: String,
        /// The allowed range.
        allowed: String,
    },
}

impl ProtocolError {
    /// The field the error is about (`type` for the message as a whole).
    pub fn field(&self) -> &str {
        match self {
            ProtocolError::Field { field, .. } | ProtocolError::OutOfRange { field, .. } => field,
            _ => "type",
        }
    }
}

/// The hand as the page sent it (the fields of an `input` message).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PageInput {
    /// The page's sequence number of the input.
    pub seq: u64,
    /// A point of the unit ball (right, away, up in the device frame).
    pub pos: [f64; 3],
    /// Button bits (bit `i`: the device's button `i`).
    pub buttons: u32,
    /// When the input happened by the page's clock, ms since the Unix epoch (information only:
    /// the input-to-force latency).
    pub t_ms: f64,
}

/// A message from a page to the server (JSON text, tagged by `type`), as [`parse`] read and
/// checked it.
///
/// The wire form is `{"type": "<name>", ...fields}`; the names are [`PageMsg::TYPES`].
/// [`PageMsg::to_json`] writes one (for tests and programs that play the page's part);
/// the server reads them with [`parse`] only, never with serde, so every field is checked.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum PageMsg {
    /// The player pressed Start.
    Start,
    /// The hand.
    Input(PageInput),
    /// A menu switch (name and value still to check against the scene's switches).
    Switch {
        /// Switch name.
        name: String,
        /// Its value.
        value: f64,
    },
    /// The player ends the session.
    End,
}

impl PageMsg {
    /// The `type` of every page message, in the order of the enum's variants.
    pub const TYPES: &'static [&'static str] = &["start", "input", "switch", "end"];

    /// The message's `type` on the wire.
    pub fn type_name(&self) -> &'static str {
        match self {
            PageMsg::Start => "start",
            PageMsg::Input(_) => "input",
            PageMsg::Switch { .. } => "switch",
            PageMsg::End => "end",
        }
    }

    /// One example of every page message, in [`PageMsg::TYPES`] order (for tests, docs and
    /// programs that play the page's part).
    pub fn examples() -> Vec<PageMsg> {
        let msgs = vec![
            PageMsg::Start,
            PageMsg::Input(PageInput {
                seq: 7,
                pos: [0.6, 0.0, -0.8],
                buttons: 9,
                t_ms: 1_764_000_000_000.5,
            }),
            PageMsg::Switch {
                name: "friction".into(),
                value: 0.5,
            },
            PageMsg::End,
        ];
        // A new variant stops this match from compiling: give it an example above and its
        // `type` in `PageMsg::TYPES` (and a row in docs/play.md's table).
        for m in &msgs {
            match m {
                PageMsg::Start | PageMsg::Input(_) | PageMsg::Switch { .. } | PageMsg::End => {}
            }
        }
        msgs
    }

    /// The message as a page sends it (JSON text).
    pub fn to_json(&self) -> String {
        // A non-finite number is written as `null`, which [`parse`] refuses, as it should.
        serde_json::to_string(self).unwrap_or_default()
    }
}

fn kind(v: Option<&Value>) -> String {
    match v {
        None => "missing".into(),
        Some(Value::Null) => "null".into(),
        Some(Value::Bool(_)) => "a boolean".into(),
        Some(Value::Number(n)) => format!("the number {n}"),
        Some(Value::String(_)) => "a string".into(),
        Some(Value::Array(a)) => format!("a list of {}", a.len()),
        Some(Value::Object(_)) => "an object".into(),
    }
}

fn number(obj: &Value, key: &str, field: &str) -> Result<f64, ProtocolError> {
    let v = obj.get(key);
    v.and_then(Value::as_f64)
        .ok_or_else(|| ProtocolError::Field {
            field: field.into(),
            got: kind(v),
            expected: "a number",
        })
}

/// Largest integer a page's JavaScript number holds exactly.
const MAX_SAFE_INTEGER: u64 = (1 << 53) - 1;

/// Parses and checks a page message; `button_mask` has a bit for each button of the device.
pub fn parse(text: &str, button_mask: u32) -> Result<PageMsg, ProtocolError> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Err(ProtocolError::TooLong(text.len()));
    }
    let v: Value = serde_json::from_str(text).map_err(|e| ProtocolError::NotJson(e.to_string()))?;
    if !v.is_object() {
        return Err(ProtocolError::NotJson(format!("got {}", kind(Some(&v)))));
    }
    let t = match v.get("type") {
        Some(Value::String(s)) => s.as_str(),
        other => {
            return Err(ProtocolError::Field {
                field: "type".into(),
                got: kind(other),
                expected: "one of start, input, switch, end",
            });
        }
    };
    match t {
        "start" => Ok(PageMsg::Start),
        "end" => Ok(PageMsg::End),
        "switch" => parse_switch(&v),
        "input" => parse_input(&v, button_mask),
        other => Err(ProtocolError::UnknownType(format!(
            "\"{}\"",
            other.escape_default()
        ))),
    }
}

/// A `switch` message: a name of 1–64 characters and a number.
fn parse_switch(v: &Value) -> Result<PageMsg, ProtocolError> {
    let name = match v.get("name") {
        Some(Value::String(s)) if (1..=64).contains(&s.len()) => s.clone(),
        other => {
            return Err(ProtocolError::Field {
                field: "switch.name".into(),
                got: kind(other),
                expected: "a switch name of 1–64 characters",
            });
        }
    };
    let value = number(v, "value", "switch.value")?;
    Ok(PageMsg::Switch { name, value })
}

/// An `input` message: its sequence number, position, buttons and page time.
fn parse_input(v: &Value, button_mask: u32) -> Result<PageMsg, ProtocolError> {
    let seq = input_seq(v)?;
    let pos = input_pos(v)?;
    let buttons = input_buttons(v, button_mask)?;
    let t_ms = number(v, "t_ms", "input.t_ms")?;
    if !(0.0..1e14).contains(&t_ms) {
        return Err(ProtocolError::OutOfRange {
            field: "input.t_ms".into(),
            value: t_ms.to_string(),
            allowed: "0 ≤ t_ms < 1e14 (ms since the Unix epoch)".into(),
        });
    }
    Ok(PageMsg::Input(PageInput {
        seq,
        pos,
        buttons,
        t_ms,
    }))
}

/// `input.seq`: an integer a page's JavaScript number holds exactly.
fn input_seq(v: &Value) -> Result<u64, ProtocolError> {
    match v.get("seq") {
        Some(Value::Number(n)) if n.as_u64().is_some_and(|s| s <= MAX_SAFE_INTEGER) => {
            Ok(n.as_u64().unwrap_or(0))
        }
        Some(Value::Number(n)) => Err(ProtocolError::OutOfRange {
            field: "input.seq".into(),
            value: n.to_string(),
            allowed: format!("an integer 0 ≤ seq ≤ {MAX_SAFE_INTEGER}"),
        }),
        other => Err(ProtocolError::Field {
            field: "input.seq".into(),
            got: kind(other),
            expected: "an integer",
        }),
    }
}

/// `input.pos`: a point of the unit ball (the device workspace, normalised).
fn input_pos(v: &Value) -> Result<[f64; 3], ProtocolError> {
    let arr = match v.get("pos") {
        Some(Value::Array(a)) if a.len() == 3 => a,
        other => {
            return Err(ProtocolError::Field {
                field: "input.pos".into(),
                got: kind(other),
                expected: "a list of 3 numbers",
            });
        }
    };
    let mut pos = [0.0; 3];
    for (i, x) in arr.iter().enumerate() {
        let field = format!("input.pos[{i}]");
        let n = x.as_f64().ok_or_else(|| ProtocolError::Field {
            field: field.clone(),
            got: kind(Some(x)),
            expected: "a number",
        })?;
        if !(-1.0..=1.0).contains(&n) {
            return Err(ProtocolError::OutOfRange {
                field,
                value: n.to_string(),
                allowed: "-1 ≤ value ≤ 1".into(),
            });
        }
        pos[i] = n;
    }
    let r2 = pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2];
    if r2 > 1.0 {
        return Err(ProtocolError::OutOfRange {
            field: "input.pos".into(),
            value: format!("[{}, {}, {}] (norm {})", pos[0], pos[1], pos[2], r2.sqrt()),
            allowed: "a point of the unit ball, norm ≤ 1".into(),
        });
    }
    Ok(pos)
}

/// `input.buttons`: an integer whose bits are among the device's buttons (`button_mask`).
fn input_buttons(v: &Value, button_mask: u32) -> Result<u32, ProtocolError> {
    match v.get("buttons") {
        Some(Value::Number(n)) if n.as_u64().is_some_and(|b| b & !u64::from(button_mask) == 0) => {
            Ok(n.as_u64().unwrap_or(0) as u32)
        }
        Some(Value::Number(n)) => Err(ProtocolError::OutOfRange {
            field: "input.buttons".into(),
            value: n.to_string(),
            allowed: format!("an integer whose bits are the device's buttons, 0–{button_mask}"),
        }),
        other => Err(ProtocolError::Field {
            field: "input.buttons".into(),
            got: kind(other),
            expected: "an integer",
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text, 0b1111).unwrap_err().to_string()
    }

    #[test]
    fn good_messages_parse() {
        assert_eq!(parse(r#"{"type":"start"}"#, 1), Ok(PageMsg::Start));
        assert_eq!(parse(r#"{"type":"end"}"#, 1), Ok(PageMsg::End));
        assert_eq!(
            parse(r#"{"type":"switch","name":"friction","value":0.5}"#, 1),
            Ok(PageMsg::Switch {
                name: "friction".into(),
                value: 0.5
            })
        );
        assert_eq!(
            parse(
                r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
                0b1111
            ),
            Ok(PageMsg::Input(PageInput {
                seq: 7,
                pos: [0.6, 0.0, -0.8],
                buttons: 9,
                t_ms: 1_764_000_000_000.5
            }))
        );
    }

    #[test]
    fn bad_messages_name_the_field_and_range() {
        assert!(err("nope").starts_with("page message is not a JSON object: expected"));
        assert_eq!(
            err("[1]"),
            "page message is not a JSON object: got a list of 1"
        );
        assert_eq!(
            err(r#"{"kind":"input"}"#),
            "page message field `type` is missing (expected: one of start, input, switch, end)"
        );
        assert_eq!(
            err(r#"{"type":"jump"}"#),
            "page message `type` = \"jump\" is unknown (allowed: start, input, switch, end)"
        );
        let input = |rest: &str| format!(r#"{{"type":"input","seq":1,{rest}}}"#);
        assert_eq!(
            err(&input(r#""pos":[0,0,1.5],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos[2]` = 1.5 is out of range: allowed -1 ≤ value ≤ 1"
        );
        assert_eq!(
            err(&input(r#""pos":[0.8,0.8,0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos` = [0.8, 0.8, 0] (norm 1.1313708498984762) is out of \
             range: allowed a point of the unit ball, norm ≤ 1"
        );
        assert_eq!(
            err(&input(r#""pos":[0,"a",0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos[1]` is a string (expected: a number)"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos` is a list of 2 (expected: a list of 3 numbers)"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":16,"t_ms":0"#)),
            "page message field `input.buttons` = 16 is out of range: allowed an integer whose \
             bits are the device's buttons, 0–15"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":-1,"t_ms":0"#)),
            "page message field `input.buttons` = -1 is out of range: allowed an integer whose \
             bits are the device's buttons, 0–15"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":0"#)),
            "page message field `input.t_ms` is missing (expected: a number)"
        );
        assert_eq!(
            err(r#"{"type":"input","seq":-3,"pos":[0,0,0],"buttons":0,"t_ms":0}"#),
            "page message field `input.seq` = -3 is out of range: allowed an integer 0 ≤ seq ≤ \
             9007199254740991"
        );
        assert_eq!(
            err(r#"{"type":"switch","name":"friction","value":"lots"}"#),
            "page message field `switch.value` is a string (expected: a number)"
        );
        assert_eq!(
            err(r#"{"type":"switch","value":1}"#),
            "page message field `switch.name` is missing (expected: a switch name of 1–64 characters)"
        );
        let long = format!(r#"{{"type":"start","pad":"{}"}}"#, "x".repeat(5000));
        assert_eq!(
            err(&long),
            "page message of 5025 bytes is too long (allowed: at most 4096 bytes)"
        );
        // JSON has no NaN or infinity: `1e999` overflows and is refused as not a number.
        assert!(parse(&input(r#""pos":[1e999,0,0],"buttons":0,"t_ms":0"#), 1).is_err());
        assert_eq!(
            ProtocolError::OutOfRange {
                field: "input.pos[2]".into(),
                value: "2".into(),
                allowed: String::new()
            }
            .field(),
            "input.pos[2]"
        );
    }

    #[test]
    fn every_server_message_is_tagged_by_its_type_and_reads_back() {
        let msgs = ServerMsg::examples();
        let names: Vec<&str> = msgs.iter().map(ServerMsg::type_name).collect();
        assert_eq!(names, ServerMsg::TYPES);
        for m in &msgs {
            let text = m.to_json();
            let v: Value = serde_json::from_str(&text).unwrap();
            assert_eq!(v["type"], m.type_name(), "{text}");
            assert!(text.starts_with(&format!(r#"{{"type":"{}""#, m.type_name())));
            let back: ServerMsg = serde_json::from_str(&text).unwrap();
            assert_eq!(&back, m, "{text}");
        }
    }

    #[test]
    fn the_wire_form_of_small_messages() {
        let msgs = ServerMsg::examples();
        assert_eq!(
            msgs[1].to_json(),
            r#"{"type":"waiting","for":"the device's hello"}"#
        );
        assert_eq!(msgs[2].to_json(), r#"{"type":"role","role":"hand"}"#);
        assert_eq!(
            ServerMsg::Role { role: Role::View }.to_json(),
            r#"{"type":"role","role":"view"}"#
        );
        assert_eq!(
            msgs[4].to_json(),
            r#"{"type":"switched","tick":700,"name":"friction","value":0.2}"#
        );
        assert_eq!(
            msgs[5].to_json(),
            r#"{"type":"error","field":"input.pos[2]","message":"out of range"}"#
        );
    }

    #[test]
    fn a_frame_and_the_last_frame_on_the_wire() {
        let msgs = ServerMsg::examples();
        assert_eq!(
            msgs[3].to_json(),
            concat!(
                r#"{"type":"frame","tick":32,"time_s":0.032,"wall_ms":1764000000000.5,"#,
                r#""prims":[{"k":"sphere","c":[0.0,0.0,0.1],"r":0.01,"col":[1.0,0.5,0.0,1.0]}],"#,
                r#""state":{"score":25.0},"cursor_m":[0.0,0.0,0.1],"world_force_n":[0.0,0.0,1.5],"#,
                r#""device_force_n":[0.0,0.0,1.5],"status":1,"#,
                r#""events":[[20,"brick.grabbed","0"]],"sounds":[[21,"thud",0.25]]}"#
            )
        );
        // The session's last frame: no drawing, the last events and sounds.
        let last = ServerMsg::Frame(Frame {
            tick: 1999,
            time_s: 2.0,
            view: None,
            events: Vec::new(),
            sounds: vec![SoundAt(1998, "snap".into(), 1.0)],
        });
        let text = last.to_json();
        assert_eq!(
            text,
            r#"{"type":"frame","tick":1999,"time_s":2.0,"events":[],"sounds":[[1998,"snap",1.0]]}"#
        );
        assert_eq!(serde_json::from_str::<ServerMsg>(&text).unwrap(), last);
        // JSON has no NaN: a non-finite state value is written `null` and reads back as NaN.
        let mut f = match &msgs[3] {
            ServerMsg::Frame(f) => f.clone(),
            _ => unreachable!(),
        };
        if let Some(v) = f.view.as_mut() {
            v.state.insert("nearest_m".into(), f64::NAN);
        }
        let text = ServerMsg::Frame(f).to_json();
        assert!(
            text.contains(r#""state":{"nearest_m":null,"score":25.0}"#),
            "{text}"
        );
        let Ok(ServerMsg::Frame(back)) = serde_json::from_str::<ServerMsg>(&text) else {
            panic!("{text}")
        };
        assert!(back.view.unwrap().state["nearest_m"].is_nan());
    }

    #[test]
    fn an_end_on_the_wire() {
        let msgs = ServerMsg::examples();
        assert_eq!(
            msgs[6].to_json(),
            concat!(
                r#"{"type":"end","end":"stopped","ticks":2000,"seconds":2.0,"missed_deadlines":0,"#,
                r#""tick_work":{"p50_ms":0.01,"p99_ms":0.05,"max_ms":0.2},"state":{"score":25.0},"#,
                r#""peak_device_force_n":2.5,"events":4,"#,
                r#""input_latency_ms":{"n":2,"p50":1.0,"p99":2.0,"max":2.0},"#,
                r#""recording":"/recording.mcap","recording_file":"play.mcap","recording_bytes":4096}"#
            )
        );
        for (e, word) in [
            (EndReason::Completed, "completed"),
            (EndReason::Stopped, "stopped"),
            (EndReason::DeviceEnded, "device_ended"),
        ] {
            assert_eq!(e.name(), word);
            assert_eq!(serde_json::to_value(e).unwrap(), word);
        }
    }

    #[test]
    fn every_shape_keeps_its_short_keys() {
        use haptic_types::primitive::{Primitive, Rgba};
        let col = Rgba([0.5, 0.25, 1.0, 1.0]);
        let c = [0.25, -0.5, 1.0];
        let q = [0.0, 0.0, 0.0, 1.0];
        let cases = [
            (
                Primitive::Sphere {
                    center_m: c,
                    radius_m: 0.5,
                    color: col,
                },
                r#"{"k":"sphere","c":[0.25,-0.5,1.0],"r":0.5,"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Cursor {
                    center_m: c,
                    radius_m: 0.5,
                    color: col,
                },
                r#"{"k":"cursor","c":[0.25,-0.5,1.0],"r":0.5,"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Box {
                    center_m: c,
                    half_extents_m: [1.0, 2.0, 3.0],
                    rotation: q,
                    color: col,
                },
                r#"{"k":"box","c":[0.25,-0.5,1.0],"h":[1.0,2.0,3.0],"q":[0.0,0.0,0.0,1.0],"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Slot {
                    center_m: c,
                    half_extents_m: [1.0, 2.0, 3.0],
                    rotation: q,
                    color: col,
                },
                r#"{"k":"slot","c":[0.25,-0.5,1.0],"h":[1.0,2.0,3.0],"q":[0.0,0.0,0.0,1.0],"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Ellipse {
                    center_m: c,
                    semi_axes_m: [0.5, 0.25],
                    color: col,
                },
                r#"{"k":"ellipse","c":[0.25,-0.5,1.0],"ax":[0.5,0.25],"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Polyline {
                    points_m: vec![c, [0.0; 3]],
                    closed: true,
                    color: col,
                },
                r#"{"k":"line","p":[[0.25,-0.5,1.0],[0.0,0.0,0.0]],"closed":true,"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Arrow {
                    from_m: c,
                    to_m: [0.0; 3],
                    color: col,
                },
                r#"{"k":"arrow","a":[0.25,-0.5,1.0],"b":[0.0,0.0,0.0],"col":[0.5,0.25,1.0,1.0]}"#,
            ),
            (
                Primitive::Label {
                    position_m: c,
                    text: "blueprint 1/4".into(),
                    color: col,
                },
                r#"{"k":"label","c":[0.25,-0.5,1.0],"text":"blueprint 1/4","col":[0.5,0.25,1.0,1.0]}"#,
            ),
        ];
        for (p, want) in cases {
            let shape = Shape::from(&p);
            assert_eq!(serde_json::to_string(&shape).unwrap(), want);
            assert_eq!(serde_json::from_str::<Shape>(want).unwrap(), shape);
        }
    }

    #[test]
    fn every_page_message_reads_back_through_the_checked_parser() {
        let msgs = PageMsg::examples();
        let names: Vec<&str> = msgs.iter().map(PageMsg::type_name).collect();
        assert_eq!(names, PageMsg::TYPES);
        for m in &msgs {
            let text = m.to_json();
            assert_eq!(parse(&text, 0b1111).as_ref(), Ok(m), "{text}");
        }
        assert_eq!(
            msgs[1].to_json(),
            r#"{"type":"input","seq":7,"pos":[0.6,0.0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#
        );
    }

    #[test]
    fn no_input_panics() {
        // Every prefix of good and bad messages, and odd bytes: errors, never a panic.
        let samples = [
            r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
            r#"{"type":"switch","name":"friction","value":0.5}"#,
            "{\"type\":\"\u{0}\"}",
            r#"{"type":"input","seq":1e300,"pos":[null,{},[]],"buttons":1.5,"t_ms":-1}"#,
        ];
        for s in samples {
            for i in 0..=s.len() {
                if s.is_char_boundary(i) {
                    let _ = parse(&s[..i], 0b11);
                }
            }
        }
    }
}
