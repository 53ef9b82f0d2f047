//! Per-tick arrays of a session (struct of arrays), filled straight from the loop as a sink of
//! the runner, or decoded from a recording.

use haptic_engine::haptic::HapticLoop;
use haptic_engine::sink::{SessionInfo, Sink, SinkError, TickView};
use recording::channels::cdr::CdrError;
use recording::channels::messages::{
    Channel, DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, TickColumns, TimingMsg,
};
use recording::{Recording, RecordingError};

/// Per-tick arrays of a session: the columns declared with the recording's messages
/// ([`TickColumns`], reached through `Deref`: `a.tick`, `a.device_force_n`, `a.state`, …) and
/// the events.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SessionArrays {
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// Names of the state columns (each with its unit).
    pub state_fields: Vec<String>,
    /// The per-tick columns.
    #[serde(flatten)]
    pub columns: TickColumns,
    /// Events: (tick, name, detail).
    pub events: Vec<(u64, String, String)>,
}

impl std::ops::Deref for SessionArrays {
    type Target = TickColumns;
    fn deref(&self) -> &TickColumns {
        &self.columns
    }
}

impl std::ops::DerefMut for SessionArrays {
    fn deref_mut(&mut self) -> &mut TickColumns {
        &mut self.columns
    }
}

impl SessionArrays {
    /// Empty arrays for a session at `rate_hz` with these state fields.
    pub fn new(rate_hz: u32, state_fields: Vec<String>) -> Self {
        SessionArrays {
            rate_hz,
            state_fields,
            ..Default::default()
        }
    }

    /// Reserves room for `ticks` more ticks, so that no array grows (and copies) mid-session.
    pub fn reserve(&mut self, ticks: usize) {
        let n = self.state_fields.len();
        self.columns.reserve(ticks, n);
    }

    /// Time of each tick, s.
    pub fn time_s(&self) -> Vec<f64> {
        self.tick
            .iter()
            .map(|&t| t as f64 / f64::from(self.rate_hz))
            .collect()
    }

    /// The column of state field `name`, if the scene has it.
    pub fn state_column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.state_fields.iter().position(|f| f == name)?;
        let n = self.state_fields.len();
        Some(self.state.chunks(n).map(|row| row[k]).collect())
    }

    /// Adds one tick straight from the loop: each message is built from the tick as a plain
    /// struct (never encoded) and its column fields are appended.
    pub fn push_tick(&mut self, t: &TickView<'_>) {
        let r = t.result;
        let c = &mut self.columns;
        DeviceInputMsg::from_tick(r.tick, &t.sample, t.deadline_missed).push_columns(c);
        // The state message's columns, with the scene's fields written in place.
        c.cursor_m.push(r.cursor_m);
        t.lp.scene_state(&mut c.state);
        ForceMsg::from_tick(r).push_columns(c);
        TimingMsg::from_tick(r.tick, t.start_late_ns, t.compute_ns).push_columns(c);
        for e in &r.events {
            self.events.push((r.tick, e.name.clone(), e.detail.clone()));
        }
    }

    /// Adds one recorded message.
    pub fn push(&mut self, channel: Channel, data: &[u8]) -> Result<(), CdrError> {
        match channel {
            Channel::State => {
                StateMsg::decode(data, self.state_fields.len())?.push_columns(&mut self.columns)
            }
            Channel::Events => {
                let m = EventsMsg::decode(data)?;
                for (n, d) in m.names.into_iter().zip(m.details) {
                    self.events.push((m.tick, n, d));
                }
            }
            other => other.push_columns(data, &mut self.columns)?,
        }
        Ok(())
    }

    /// Reads a whole recording into arrays.
    pub fn from_recording(rec: &Recording) -> Result<Self, RecordingError> {
        let d = &rec.description;
        let mut a = SessionArrays::new(d.rate_hz, d.state_fields.clone());
        for m in &rec.messages {
            a.push(m.channel, &m.data)
                .map_err(|e| RecordingError::BadMessage {
                    topic: m.channel.topic().to_string(),
                    log_time_ns: m.log_time_ns,
                    detail: e.to_string(),
                })?;
        }
        Ok(a)
    }
}

impl Sink for SessionArrays {
    fn name(&self) -> &'static str {
        "arrays"
    }

    fn start(&mut self, info: &SessionInfo<'_>, _lp: &HapticLoop) -> Result<(), SinkError> {
        self.rate_hz = info.config.rate_hz;
        self.state_fields = info.header.state_fields.clone();
        if let Some(n) = info.ticks {
            self.reserve(n.min(1 << 24) as usize);
        }
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        self.push_tick(t);
        Ok(())
    }
}
