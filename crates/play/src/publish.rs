//! What the pages see and hear: a sink on the tick thread that hands each tick's data to the
//! publisher thread (an unbounded channel: the tick never waits), and the publisher, which
//! builds the frames (about 60 per second) and the sound ticks and queues both for every page.
//!
//! **Sound.** The page synthesises the sound itself, in an AudioWorklet (`synth.js`, a port of
//! [`render::audio::StreamSynth`] run at the page's own sample rate). The publisher sends it,
//! as soon as the tick thread hands them over, what that synthesis consumes of each tick: the
//! tick's sounds (the recording's `brick.impact`, `nano.snap`, `nano.pull_off` events through
//! [`haptic_loop::sound::sound_events`], the mapping `render --audio` uses, each with its index
//! in the session's list of sounds) and its `nearest_m` (the proximity tone), with the tick's
//! wall time, in a binary [`SoundTicks`] message. The tick thread hands its ticks over every
//! [`SOUND_BLOCK_TICKS`] ticks (every [`PLAY_SOUND_BLOCK_TICKS`] in `play`, whose page's lead
//! is sized from the ticks' lateness, a block's length included), and at once for a tick with
//! a sound ([`SOUND_EVENTS`]) and the tick after it (whose distance the tone needs to finish
//! the sound's tick). The page's
//! samples are therefore those of `nanohaptics render REC --audio OUT.wav --proximity` at the
//! page's sample rate (the browser test compares them), except where that track needed its
//! anti-clipping scale (live, samples beyond the ceiling are limited instead). The frames also
//! carry each sound with its tick, for captions and checks.

use crate::protocol::{
    EventAt, Frame, FrameView, ServerMsg, SoundAt, SoundKind, SoundOn, SoundTick, SoundTicks,
};
use crate::server::Shared;
use haptic_engine::HapticLoop;
use haptic_engine::pacing::TickStats;
use haptic_engine::sink::{SessionInfo, Sink, SinkError, TickView};
use haptic_loop::session::{SessionArrays, now_unix_ns};
use haptic_types::Primitive;
use render::audio::Sound;
use std::collections::VecDeque;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender};
use tungstenite::Message;

/// Ticks between two frames (16 ticks: 62.5 frames/s at 1 kHz).
pub const FRAME_EVERY_TICKS: u64 = 16;
/// Ticks the tick thread hands over at once when nothing sounds (5 ms at 1 kHz): the most a
/// [`SoundTicks`] message holds, short of a frame's.
pub const SOUND_BLOCK_TICKS: u64 = 5;
/// The same for `play` (one page or a few): 2 ticks. The page's worklet plays a lead behind
/// its clock that must cover the lateness of a block's first tick, so a block of 5 ticks adds
/// 3 ms to every sound's latency over 2; a block of 1 (1000 messages a second) let the page's
/// main thread fall behind by a quarter of a second and more on this 2-core machine under load
/// (BENCHMARKS.md, play).
pub const PLAY_SOUND_BLOCK_TICKS: u64 = 2;

/// The events that make a sound (those [`haptic_loop::sound::sound_events`] reads): a tick
/// with one is handed to the publisher at once.
pub const SOUND_EVENTS: &[&str] = &["brick.impact", "nano.snap", "nano.pull_off"];

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
    /// Several of the above in order: the tick thread hands its ticks over every
    /// [`SOUND_BLOCK_TICKS`] ticks, on a frame, and at once around a tick with a sound,
    /// instead of waking the publisher every tick.
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
    /// The last tick had a sound: hand this one over at once too.
    flush_next: bool,
    /// Ticks handed over at once when nothing sounds.
    block_ticks: u64,
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
            flush_next: false,
            block_ticks: SOUND_BLOCK_TICKS,
            input_latency_ms: Vec::new(),
        }
    }

    /// Hands the ticks over every `ticks` ticks when nothing sounds (at least 1).
    pub fn with_block_ticks(mut self, ticks: u64) -> Self {
        self.block_ticks = ticks.max(1);
        self
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
        // A tick with a sound goes at once, and so does the next one (the proximity tone needs
        // its distance to finish the sound's tick).
        let sounds = r
            .events
            .iter()
            .any(|e| SOUND_EVENTS.contains(&e.name.as_str()));
        let flush = frame.is_some()
            || sounds
            || self.flush_next
            || r.tick % self.block_ticks == self.block_ticks - 1;
        self.flush_next = sounds;
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
    /// Binary sound-tick messages sent.
    pub sound_messages: u64,
    /// Ticks the sound-tick messages carried.
    pub sound_ticks: u64,
    /// Sounds (impacts, snaps, pull-offs) placed.
    pub sounds: u64,
    /// Events published.
    pub events: u64,
}

/// The page's name of a sound (`thud`, `clack`, `tap`, `snap`, `pull_off`) and its peak
/// amplitude (0–1 of full scale).
pub fn sound_name(s: &Sound) -> (&'static str, f64) {
    let (kind, amplitude) = SoundKind::of(s);
    (kind.name(), amplitude)
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

/// Where the publisher's messages go: a live session's pages ([`Shared`]), or a replay's
/// list of frames ([`crate::replay`]).
pub trait Outlet: Send + Sync {
    /// Sends `m` to every page.
    fn broadcast(&self, m: &Message);
    /// Sends `m` to page `page` only.
    fn send_to(&self, page: u64, m: Message);
    /// A live switch was applied: the value a page that connects later is told.
    fn switched(&self, name: &str, value: f64);
}

impl Outlet for Shared {
    fn broadcast(&self, m: &Message) {
        Shared::broadcast(self, m);
    }
    fn send_to(&self, page: u64, m: Message) {
        Shared::send_to(self, page, m);
    }
    fn switched(&self, name: &str, value: f64) {
        refresh_hello(self, name, value);
    }
}

/// The publisher thread's loop: runs until the session's `Finish` (or the channel closes).
/// `proximity_on_distance_m`: the distance below which the proximity tone sounds, m (`None`:
/// no tone), sent to the pages with the ticks.
pub fn run_publisher(
    rx: Receiver<ToPublisher>,
    shared: Arc<Shared>,
    rate_hz: u32,
    state_fields: Vec<String>,
    proximity_on_distance_m: Option<f64>,
) -> PublishSummary {
    crate::background::lower_priority();
    publish(rx, shared, rate_hz, state_fields, proximity_on_distance_m)
}

/// [`run_publisher`]'s loop on this thread, into `out`.
pub fn publish(
    rx: Receiver<ToPublisher>,
    out: Arc<dyn Outlet>,
    rate_hz: u32,
    state_fields: Vec<String>,
    proximity_on_distance_m: Option<f64>,
) -> PublishSummary {
    let mut p = Publisher {
        shared: out,
        dt: 1.0 / f64::from(rate_hz.max(1)),
        state_fields,
        sum: PublishSummary::default(),
        scratch: SessionArrays::new(rate_hz, Vec::new()),
        events: Vec::new(),
        sounds: Vec::new(),
        ticks: SoundTicks {
            first_tick: 0,
            tone_on_distance_m: proximity_on_distance_m,
            ticks: Vec::new(),
            sounds: Vec::new(),
        },
    };
    let mut queue: VecDeque<ToPublisher> = VecDeque::new();
    loop {
        let m = match queue.pop_front() {
            Some(m) => m,
            None => {
                // All that was handed over is done: its sound goes out now.
                p.send_ticks();
                match rx.recv() {
                    Ok(m) => m,
                    Err(_) => break,
                }
            }
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
                events,
                nearest_m,
                frame,
            } => {
                p.tick(tick, wall_ms, nearest_m);
                p.events(tick, events);
                if let Some(f) = frame {
                    p.frame(tick, wall_ms, *f);
                }
            }
            ToPublisher::Switched { tick, name, value } => {
                p.shared.switched(&name, value);
                let m = ServerMsg::Switched { tick, name, value };
                p.shared.broadcast(&Message::text(m.to_json()));
            }
            ToPublisher::Refused { page, message } => {
                let m = ServerMsg::Error {
                    field: "switch.value".into(),
                    message,
                };
                p.shared.send_to(page, Message::text(m.to_json()));
            }
            ToPublisher::Finish { ticks } => {
                p.finish(ticks);
                break;
            }
        }
    }
    p.sum
}

/// The publisher's state between messages: the ticks not yet sent to the pages' synthesis,
/// and the events and sounds since the last frame.
struct Publisher {
    shared: Arc<dyn Outlet>,
    dt: f64,
    state_fields: Vec<String>,
    sum: PublishSummary,
    scratch: SessionArrays,
    events: Vec<EventAt>,
    sounds: Vec<SoundAt>,
    ticks: SoundTicks,
}

impl Publisher {
    /// Sends the ticks not yet sent to the pages' synthesis.
    fn send_ticks(&mut self) {
        let ticks = &mut self.ticks;
        if ticks.ticks.is_empty() {
            return;
        }
        self.shared.broadcast(&Message::binary(ticks.encode()));
        self.sum.sound_messages += 1;
        self.sum.sound_ticks += ticks.ticks.len() as u64;
        ticks.first_tick += ticks.ticks.len() as u64;
        ticks.ticks.clear();
        ticks.sounds.clear();
    }

    /// Tick `tick`'s input to the synthesis.
    fn tick(&mut self, tick: u64, wall_ms: f64, nearest_m: f64) {
        let t = &self.ticks;
        if t.ticks.is_empty() || t.first_tick + t.ticks.len() as u64 != tick {
            // Ticks are consecutive; a message starts at the first tick it holds.
            self.send_ticks();
            self.ticks.first_tick = tick;
        }
        self.ticks.ticks.push(SoundTick { wall_ms, nearest_m });
    }

    /// Tick `tick`'s events, and the sounds they start.
    fn events(&mut self, tick: u64, evs: Vec<(String, String)>) {
        if evs.is_empty() {
            return;
        }
        self.scratch.events.clear();
        for (name, detail) in evs {
            self.sum.events += 1;
            self.events
                .push(EventAt(tick, name.clone(), detail.clone()));
            self.scratch.events.push((tick, name, detail));
        }
        // The mapping of `render --audio`; an event whose detail it cannot read makes no
        // sound (the recording keeps it; `render --audio` names it).
        if let Ok(list) = haptic_loop::sound::sound_events(&self.scratch) {
            for s in list {
                let (kind, amplitude) = SoundKind::of(&s.sound);
                self.sounds
                    .push(SoundAt(tick, kind.name().to_string(), amplitude));
                self.ticks.sounds.push(SoundOn {
                    tick,
                    index: u32::try_from(self.sum.sounds).unwrap_or(u32::MAX),
                    kind,
                    amplitude,
                });
                self.sum.sounds += 1;
            }
        }
    }

    /// The world drawn at tick `tick`, with the events and sounds since the last frame.
    fn frame(&mut self, tick: u64, wall_ms: f64, f: FrameData) {
        // The sound first: the frame takes a while to write.
        self.send_ticks();
        let msg = ServerMsg::Frame(Frame {
            tick,
            time_s: tick as f64 * self.dt,
            view: Some(FrameView {
                wall_ms,
                prims: f.prims,
                state: self.state_fields.iter().cloned().zip(f.state).collect(),
                cursor_m: f.cursor_m,
                world_force_n: f.world_force_n,
                device_force_n: f.device_force_n,
                status: f.status,
            }),
            events: std::mem::take(&mut self.events),
            sounds: std::mem::take(&mut self.sounds),
        });
        self.shared.broadcast(&Message::text(msg.to_json()));
        self.sum.frames += 1;
    }

    /// The session's end after `n` ticks: the last sound, and the last events and sounds in a
    /// last frame without drawing.
    fn finish(&mut self, n: u64) {
        self.send_ticks();
        let msg = ServerMsg::Frame(Frame {
            tick: n.saturating_sub(1),
            time_s: n as f64 * self.dt,
            view: None,
            events: std::mem::take(&mut self.events),
            sounds: std::mem::take(&mut self.sounds),
        });
        self.shared.broadcast(&Message::text(msg.to_json()));
    }
}
