//! MCAP recording: per-tick message encoding, a writer thread that never stalls a tick, and a
//! reader that gives clear errors on corrupt or truncated files.
//!
//! Layout and schemas: `docs/recording-format.md`.

pub mod foxglove_out;
pub mod parse;
pub mod reader;
pub mod replay_device;
pub mod sink;
pub mod writer;

pub use crate::channels::messages::Channel;
use crate::channels::messages::{
    DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, SwitchMsg, TimingMsg,
};
use crate::device::DeviceSample;
use crate::haptic::{HapticLoop, TickResult};
use crate::scene::Primitive;
pub use reader::{Integrity, Recording, RecordingError, read_recording, read_recording_file};
pub use replay_device::ReplayDevice;
pub use writer::{Recorder, RecorderSetup, WriteSummary};

/// One encoded message of a tick.
#[derive(Clone, Debug, PartialEq)]
pub struct OutMsg {
    /// Its channel.
    pub channel: Channel,
    /// Encoded bytes (CDR or protobuf, per channel).
    pub data: Vec<u8>,
}

/// All messages of one tick, in channel order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TickMessages {
    /// Tick index.
    pub tick: u64,
    /// Log time, ns since the Unix epoch (`start + tick · period`).
    pub log_time_ns: u64,
    /// The messages, in the order they are written.
    pub msgs: Vec<OutMsg>,
}

/// Encodes the messages of each tick (the same code for recording and for replay, so replay
/// compares exactly what was written).
#[derive(Debug)]
pub struct TickEncoder {
    start_ns: u64,
    period_ns: u64,
    display_every: u64,
    display_scale: f64,
    state: Vec<f64>,
    prims: Vec<Primitive>,
}

impl TickEncoder {
    /// An encoder for the loop `l` of a session that started at `start_ns` (ns since the Unix
    /// epoch; log times are `start_ns + tick · period`).
    pub fn new(l: &HapticLoop, start_ns: u64) -> Self {
        let c = l.config();
        TickEncoder {
            start_ns,
            period_ns: c.period_ns(),
            display_every: u64::from(c.display_every),
            display_scale: c.display_scale,
            state: Vec::new(),
            prims: Vec::new(),
        }
    }

    /// Log time of tick `tick`, ns since the Unix epoch.
    pub fn log_time_ns(&self, tick: u64) -> u64 {
        self.start_ns
            .saturating_add(tick.saturating_mul(self.period_ns))
    }

    /// The `/device/input` message of a tick.
    pub fn input(tick: u64, sample: &DeviceSample, deadline_missed: bool) -> OutMsg {
        OutMsg {
            channel: Channel::DeviceInput,
            data: DeviceInputMsg::from_tick(tick, sample, deadline_missed).encode(),
        }
    }

    /// The `/scene/switch` message of a tick, when switches were set before it.
    pub fn switches(r: &TickResult) -> Option<OutMsg> {
        (!r.switches.is_empty()).then(|| OutMsg {
            channel: Channel::Switch,
            data: SwitchMsg::from_tick(r.tick, &r.switches).encode(),
        })
    }

    /// The `/loop/timing` message of a tick.
    pub fn timing(tick: u64, start_late_ns: i64, compute_ns: u64) -> OutMsg {
        OutMsg {
            channel: Channel::Timing,
            data: TimingMsg::from_tick(tick, start_late_ns, compute_ns).encode(),
        }
    }

    /// Appends the verified outputs of tick `r` (state, force, events, Foxglove channels) to
    /// `out`, in their fixed order.
    pub fn outputs(&mut self, r: &TickResult, l: &HapticLoop, out: &mut Vec<OutMsg>) {
        let t_ns = self.log_time_ns(r.tick);
        self.state.clear();
        l.scene_state(&mut self.state);
        out.push(OutMsg {
            channel: Channel::State,
            data: StateMsg::from_tick(r, &self.state).encode(),
        });
        out.push(OutMsg {
            channel: Channel::Force,
            data: ForceMsg::from_tick(r).encode(),
        });
        if !r.events.is_empty() {
            out.push(OutMsg {
                channel: Channel::Events,
                data: EventsMsg::from_tick(r.tick, &r.events).encode(),
            });
        }
        if r.tick % self.display_every == 0 {
            self.prims.clear();
            l.scene().draw(&mut self.prims);
            let u = foxglove_out::scene_update(&self.prims, self.display_scale, t_ns);
            out.push(OutMsg {
                channel: Channel::FoxgloveScene,
                data: foxglove_out::encode(&u),
            });
            let tf = foxglove_out::cursor_transform(r.cursor_m, self.display_scale, t_ns);
            out.push(OutMsg {
                channel: Channel::FoxgloveTf,
                data: foxglove_out::encode(&tf),
            });
        }
        for e in &r.events {
            out.push(OutMsg {
                channel: Channel::FoxgloveLog,
                data: foxglove_out::encode(&foxglove_out::event_log(e, t_ns)),
            });
        }
    }
}

/// The switches of a recording as a schedule (tick, switch) for the runner, from its
/// `/scene/switch` messages (log time `start + tick · period_ns`).
pub fn switch_schedule(
    rec: &Recording,
    period_ns: u64,
) -> Result<Vec<(u64, crate::scene::Switch)>, RecordingError> {
    let start = rec.description.start_time_ns;
    let mut out = Vec::new();
    for m in rec.messages.iter().filter(|m| m.channel == Channel::Switch) {
        let bad = |detail: String| RecordingError::BadMessage {
            topic: Channel::Switch.topic().to_string(),
            log_time_ns: m.log_time_ns,
            detail,
        };
        let d = SwitchMsg::decode(&m.data).map_err(|e| bad(e.to_string()))?;
        let at = start.saturating_add(d.tick.saturating_mul(period_ns));
        if m.log_time_ns != at {
            return Err(bad(format!(
                "tick {} belongs at {at} ns, found at {} ns",
                d.tick, m.log_time_ns
            )));
        }
        out.extend(d.switches().into_iter().map(|s| (d.tick, s)));
    }
    Ok(out)
}

/// Writes `rec` (e.g. the salvaged part of a truncated recording) as a new, complete MCAP
/// file; the metadata records are copied. Returns what the writer did.
pub fn rewrite(
    rec: &Recording,
    path: &std::path::Path,
) -> Result<WriteSummary, writer::RecordError> {
    let mut w = Recorder::create(
        path,
        RecorderSetup {
            description: rec.description.clone(),
            flush_every_ns: 1_000_000_000,
        },
    )?;
    let mut cur: Option<TickMessages> = None;
    for m in rec
        .messages
        .iter()
        .filter(|m| m.channel != Channel::Description)
    {
        if cur.as_ref().is_some_and(|c| c.log_time_ns != m.log_time_ns) {
            if let Some(c) = cur.take() {
                w.write(c)?;
            }
        }
        let c = cur.get_or_insert_with(|| TickMessages {
            tick: 0,
            log_time_ns: m.log_time_ns,
            msgs: Vec::new(),
        });
        c.msgs.push(OutMsg {
            channel: m.channel,
            data: m.data.clone(),
        });
    }
    if let Some(c) = cur {
        w.write(c)?;
    }
    // The copy holds the ticks read (a salvage holds fewer than the session ran): its `session`
    // record says so, as the reader checks.
    let ticks = rec
        .messages
        .iter()
        .filter(|m| m.channel == Channel::DeviceInput)
        .count();
    for (name, md) in &rec.metadata {
        let mut md = md.clone();
        if name == "session" {
            if let Some(t) = md.insert("ticks".into(), ticks.to_string()) {
                if t != ticks.to_string() {
                    md.insert("ticks_in_the_original".into(), t);
                }
            }
        }
        w.metadata(name, md)?;
    }
    if !rec.metadata.contains_key("session") {
        // A salvaged file ends before the session's closing record: say how much it holds.
        let mut md = std::collections::BTreeMap::new();
        md.insert("ticks".to_string(), ticks.to_string());
        md.insert("salvaged".to_string(), "true".to_string());
        w.metadata("session", md)?;
    }
    w.finish()
}
