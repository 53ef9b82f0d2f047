//! What the pages see and hear: a sink on the tick thread that hands each tick's data to the
//! publisher thread (an unbounded channel: the tick never waits), and the publisher, which
//! builds the frames (about 60 per second), streams the sound and queues both for every page.
//!
//! **Sound.** The publisher feeds each tick's sounds (the recording's `brick.impact`,
//! `nano.snap`, `nano.pull_off` events through [`haptic_loop::sound::sound_events`], the mapping
//! `render --audio` uses) and its `nearest_m` (the proximity tone) to a
//! [`render::audio::StreamSynth`] and sends the samples as they complete, in blocks of 5 ms.
//! The samples a page receives are therefore those of `nanohaptics render REC --audio OUT.wav
//! --proximity` for the session's recording, sample for sample, unless that track needed its
//! anti-clipping scale (the summary's `sound_samples_limited` counts the live samples limited
//! instead). The frames also carry each sound with its tick, for captions and checks.

use crate::protocol::{
    EventAt, Frame, FrameView, SOUND_BLOCK_HEADER_BYTES, ServerMsg, Shape, SoundAt,
};
use crate::server::Shared;
use haptic_loop::HapticLoop;
use haptic_loop::pacing::TickStats;
use haptic_loop::session::{SessionArrays, now_unix_ns};
use haptic_loop::sink::{SessionInfo, Sink, SinkError, TickView};
use haptic_types::Primitive;
use render::audio::{Impact, Sound, StreamSynth};
use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender};
use tungstenite::Message;

/// Ticks between two frames (16 ticks: 62.5 frames/s at 1 kHz).
pub const FRAME_EVERY_TICKS: u64 = 16;
/// Ticks between two sound blocks (5 ms at 1 kHz).
pub const SOUND_BLOCK_TICKS: u64 = 5;
/// Sample rate of the live sound, Hz (the default of `render --audio`).
pub const SAMPLE_RATE_HZ: u32 = render::audio::SAMPLE_RATE_HZ;

/// A frame's drawing and state.
pub struct FrameData {
    prims: Vec<Primitive>,
    state: Vec<f64>,
    cursor_m: [f64; 3],
    world_force_n: [f64; 3],
    device_force_n: [f64; 3],
    status: u8,
}

/// What the tick thread and the live hook hand to the publisher.
pub enum ToPublisher {
    /// One tick.
    Tick {
        /// Tick index.
        tick: u64,
        /// Wall time the tick's force was sent, ms since the Unix epoch.
        wall_ms: f64,
        /// Its events (name, detail).
        events: Vec<(String, String)>,
        /// Distance to the nearest object after the tick, m (NaN: the scene has none).
        nearest_m: f64,
        /// The frame, every [`FRAME_EVERY_TICKS`] ticks.
        frame: Option<Box<FrameData>>,
    },
    /// A live switch applied before tick `tick`.
    Switched {
        /// The tick.
        tick: u64,
        /// Name.
        name: String,
        /// Value.
        value: f64,
    },
    /// A live switch the world refused.
    Refused {
        /// The page that asked.
        page: u64,
        /// Why.
        message: String,
    },
    /// Several of the above in order: the tick thread hands its ticks over once per sound
    /// block (or frame) instead of waking the publisher every tick.
    Batch(Vec<ToPublisher>),
    /// The session ended after `ticks` ticks.
    Finish {
        /// Ticks run.
        ticks: u64,
    },
}

/// The sink on the tick thread.
pub struct PlaySink {
    tx: Sender<ToPublisher>,
    shared: Arc<Shared>,
    nearest: Option<usize>,
    state: Vec<f64>,
    last_seq: u64,
    pending: Vec<ToPublisher>,
    /// Input-to-force latencies, ms (page event to the force of the first tick that used it).
    pub input_latency_ms: Vec<f64>,
}

impl PlaySink {
    /// A sink sending to `tx`.
    pub fn new(tx: Sender<ToPublisher>, shared: Arc<Shared>) -> Self {
        PlaySink {
            tx,
            shared,
            nearest: None,
            state: Vec::new(),
            last_seq: 0,
            pending: Vec::with_capacity(SOUND_BLOCK_TICKS as usize),
            input_latency_ms: Vec::new(),
        }
    }
}

fn unix_ms() -> f64 {
    now_unix_ns() as f64 * 1e-6
}

impl Sink for PlaySink {
    fn name(&self) -> &'static str {
        "play"
    }

    fn start(&mut self, _info: &SessionInfo<'_>, lp: &HapticLoop) -> Result<(), SinkError> {
        self.nearest = lp
            .scene()
            .state_fields()
            .iter()
            .position(|f| f == "nearest_m");
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let r = t.result;
        let wall_ms = unix_ms();
        let seq = t.sample.seq;
        if seq != self.last_seq {
            self.last_seq = seq;
            let (latest, _) = self.shared.input.latest();
            if latest.count == seq && self.input_latency_ms.len() < 1 << 20 {
                self.input_latency_ms.push(wall_ms - latest.t_ms);
            }
        }
        self.state.clear();
        t.lp.scene().state(&mut self.state);
        let nearest_m = self
            .nearest
            .and_then(|k| self.state.get(k).copied())
            .unwrap_or(f64::NAN);
        let frame = (r.tick % FRAME_EVERY_TICKS == 0).then(|| {
            let mut prims = Vec::with_capacity(64);
            t.lp.scene().draw(&mut prims);
            Box::new(FrameData {
                prims,
                state: self.state.clone(),
                cursor_m: r.cursor_m,
                world_force_n: r.world_force_n,
                device_force_n: r.device_force_n,
                status: r.status,
            })
        });
        let events = r
            .events
            .iter()
            .map(|e| (e.name.clone(), e.detail.clone()))
            .collect();
        let flush = frame.is_some() || r.tick % SOUND_BLOCK_TICKS == SOUND_BLOCK_TICKS - 1;
        self.pending.push(ToPublisher::Tick {
            tick: r.tick,
            wall_ms,
            events,
            nearest_m,
            frame,
        });
        if flush {
            // A closed channel means the publisher is gone: the session goes on without pages.
            let _ = self
                .tx
                .send(ToPublisher::Batch(std::mem::take(&mut self.pending)));
        }
        Ok(())
    }

    fn finish(
        &mut self,
        stats: &TickStats,
        _link: &[(&'static str, u64)],
    ) -> Result<(), SinkError> {
        if !self.pending.is_empty() {
            let _ = self
                .tx
                .send(ToPublisher::Batch(std::mem::take(&mut self.pending)));
        }
        let _ = self.tx.send(ToPublisher::Finish { ticks: stats.ticks });
        Ok(())
    }
}

/// What the publisher did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PublishSummary {
    /// Frames sent.
    pub frames: u64,
    /// Sound samples streamed.
    pub sound_samples: u64,
    /// Live samples limited to the ceiling (0: the stream equals `render --audio`).
    pub sound_samples_limited: u64,
    /// Sounds (impacts, snaps, pull-offs) placed.
    pub sounds: u64,
    /// Events published.
    pub events: u64,
}

/// The page's name of a sound.
pub fn sound_name(s: &Sound) -> (&'static str, f64) {
    match *s {
        Sound::Impact { kind, amplitude } => (
            match kind {
                Impact::BrickGround => "thud",
                Impact::BrickBrick => "clack",
                Impact::Cursor => "tap",
            },
            amplitude,
        ),
        Sound::Snap { amplitude } => ("snap", amplitude),
        Sound::PullOff { amplitude } => ("pull_off", amplitude),
    }
}

/// Keeps the `hello` a page gets on connecting up to date with switch `name` = `value`, so a
/// page that joins after a switch (or reloads) shows its value now.
fn refresh_hello(shared: &Shared, name: &str, value: f64) {
    let Ok(mut h) = shared.hello.lock() else {
        return;
    };
    let Some(mut hello) = h
        .as_deref()
        .and_then(|t| serde_json::from_str::<ServerMsg>(t).ok())
    else {
        return;
    };
    if let ServerMsg::Hello(ref mut hi) = hello
        && let Some(sw) = hi.switches.iter_mut().find(|s| s.name == name)
    {
        sw.value = Some(value);
        *h = Some(hello.to_json());
    }
}

/// The publisher thread's loop: runs until the session's `Finish` (or the channel closes).
pub fn run_publisher(
    rx: Receiver<ToPublisher>,
    shared: Arc<Shared>,
    rate_hz: u32,
    state_fields: Vec<String>,
    proximity_on_distance_m: Option<f64>,
) -> PublishSummary {
    let dt = 1.0 / f64::from(rate_hz.max(1));
    let mut sum = PublishSummary::default();
    let mut synth = StreamSynth::new(SAMPLE_RATE_HZ, dt, proximity_on_distance_m).ok();
    let sr = f64::from(SAMPLE_RATE_HZ);
    let mut scratch = SessionArrays::new(rate_hz, Vec::new());
    let mut pcm: Vec<f32> = Vec::new();
    let mut pcm_first: u64 = 0;
    let mut tick_wall: VecDeque<(u64, f64)> = VecDeque::new();
    let mut events: Vec<EventAt> = Vec::new();
    let mut sounds: Vec<SoundAt> = Vec::new();
    let send_pcm = |pcm: &mut Vec<f32>, first: &mut u64, walls: &mut VecDeque<(u64, f64)>| {
        if pcm.is_empty() {
            return;
        }
        let tick = (*first as f64 / sr / dt).floor() as u64;
        while walls.len() > 1 && walls[0].0 < tick {
            walls.pop_front();
        }
        let wall = walls.front().map_or(0.0, |w| w.1);
        let mut b = Vec::with_capacity(SOUND_BLOCK_HEADER_BYTES + 4 * pcm.len());
        b.extend_from_slice(&first.to_le_bytes());
        b.extend_from_slice(&wall.to_le_bytes());
        for s in pcm.iter() {
            b.extend_from_slice(&s.to_le_bytes());
        }
        shared.broadcast(&Message::binary(b));
        *first += pcm.len() as u64;
        pcm.clear();
    };
    crate::background::lower_priority();
    let mut queue: VecDeque<ToPublisher> = VecDeque::new();
    loop {
        let m = match queue.pop_front() {
            Some(m) => m,
            None => match rx.recv() {
                Ok(m) => m,
                Err(_) => break,
            },
        };
        match m {
            ToPublisher::Batch(list) => {
                for (k, x) in list.into_iter().enumerate() {
                    queue.insert(k, x);
                }
            }
            ToPublisher::Tick {
                tick,
                wall_ms,
                events: evs,
                nearest_m,
                frame,
            } => {
                tick_wall.push_back((tick, wall_ms));
                if !evs.is_empty() {
                    scratch.events.clear();
                    for (name, detail) in evs {
                        sum.events += 1;
                        events.push(EventAt(tick, name.clone(), detail.clone()));
                        scratch.events.push((tick, name, detail));
                    }
                    // The mapping of `render --audio`; an event whose detail it cannot read
                    // makes no sound (the recording keeps it; `render --audio` names it).
                    if let Ok(list) = haptic_loop::sound::sound_events(&scratch) {
                        for s in list {
                            sum.sounds += 1;
                            let (name, amplitude) = sound_name(&s.sound);
                            sounds.push(SoundAt(tick, name.to_string(), amplitude));
                            if let Some(sy) = synth.as_mut() {
                                sy.push(&s);
                            }
                        }
                    }
                }
                if let Some(sy) = synth.as_mut() {
                    sy.tick(nearest_m, &mut pcm);
                }
                if tick % SOUND_BLOCK_TICKS == SOUND_BLOCK_TICKS - 1 {
                    send_pcm(&mut pcm, &mut pcm_first, &mut tick_wall);
                }
                if let Some(f) = frame {
                    let msg = ServerMsg::Frame(Frame {
                        tick,
                        time_s: tick as f64 * dt,
                        view: Some(FrameView {
                            wall_ms,
                            prims: f.prims.iter().map(Shape::from).collect(),
                            state: state_fields.iter().cloned().zip(f.state).collect(),
                            cursor_m: f.cursor_m,
                            world_force_n: f.world_force_n,
                            device_force_n: f.device_force_n,
                            status: f.status,
                        }),
                        events: std::mem::take(&mut events),
                        sounds: std::mem::take(&mut sounds),
                    });
                    shared.broadcast(&Message::text(msg.to_json()));
                    sum.frames += 1;
                }
            }
            ToPublisher::Switched { tick, name, value } => {
                refresh_hello(&shared, &name, value);
                let m = ServerMsg::Switched { tick, name, value };
                shared.broadcast(&Message::text(m.to_json()));
            }
            ToPublisher::Refused { page, message } => {
                let m = ServerMsg::Error {
                    field: "switch.value".into(),
                    message,
                };
                shared.send_to(page, Message::text(m.to_json()));
            }
            ToPublisher::Finish { ticks } => {
                if let Some(sy) = synth.as_mut() {
                    sy.finish(ticks as f64 * dt, &mut pcm);
                }
                send_pcm(&mut pcm, &mut pcm_first, &mut tick_wall);
                // The last events and sounds, in a last frame without drawing.
                let msg = ServerMsg::Frame(Frame {
                    tick: ticks.saturating_sub(1),
                    time_s: ticks as f64 * dt,
                    view: None,
                    events: std::mem::take(&mut events),
                    sounds: std::mem::take(&mut sounds),
                });
                shared.broadcast(&Message::text(msg.to_json()));
                break;
            }
        }
    }
    if let Some(sy) = synth.as_ref() {
        sum.sound_samples = sy.emitted() as u64;
        sum.sound_samples_limited = sy.limited();
    }
    sum
}
