//! The messages of one tick, encoded (the same code for recording and for replay, so replay
//! compares exactly what was written).

use crate::channels::messages::Channel;
use crate::channels::messages::{
    DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, SwitchMsg, TimingMsg,
};
use crate::foxglove_out;
use haptic_types::{DeviceSample, Primitive, TickResult};

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
#[derive(Clone, Debug)]
pub struct TickEncoder {
    start_ns: u64,
    period_ns: u64,
    display_every: u64,
    display_scale: f64,
    prims: Vec<Primitive>,
}

impl TickEncoder {
    /// An encoder for a session that started at `start_ns` (ns since the Unix epoch; log times
    /// are `start_ns + tick · period_ns`), drawing the scene every `display_every` ticks (≥ 1)
    /// at `display_scale` (display units per metre).
    pub fn new(start_ns: u64, period_ns: u64, display_every: u32, display_scale: f64) -> Self {
        TickEncoder {
            start_ns,
            period_ns,
            display_every: u64::from(display_every.max(1)),
            display_scale,
            prims: Vec::new(),
        }
    }

    /// True when tick `tick` carries the scene's drawing (`/foxglove/scene`, `/foxglove/tf`).
    pub fn draws(&self, tick: u64) -> bool {
        tick % self.display_every == 0
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
    /// `out`, in their fixed order: `state` is the scene's state fields of the tick; `draw`
    /// appends the scene's drawing to the vector it is given, and is called only on ticks
    /// that [`TickEncoder::draws`].
    pub fn outputs(
        &mut self,
        r: &TickResult,
        state: &[f64],
        draw: &mut dyn FnMut(&mut Vec<Primitive>),
        out: &mut Vec<OutMsg>,
    ) {
        let t_ns = self.log_time_ns(r.tick);
        out.push(OutMsg {
            channel: Channel::State,
            data: StateMsg::from_tick(r, state).encode(),
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
        if self.draws(r.tick) {
            self.prims.clear();
            draw(&mut self.prims);
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
