//! Per-tick arrays of a session (struct of arrays), filled straight from the loop as a sink of
//! the runner, or decoded from a recording.

use crate::channels::messages::{
    Channel, DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, TimingMsg,
};
use crate::haptic::HapticLoop;
use crate::record::{Recording, RecordingError};
use crate::sink::{SessionInfo, Sink, SinkError, TickView};
use crate::vec3::Vec3;

/// Per-tick arrays of a session (struct of arrays; `state` is row-major ticks × fields).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SessionArrays {
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// Names of the state columns.
    pub state_fields: Vec<String>,
    /// Tick index.
    pub tick: Vec<u64>,
    /// Raw device position, m, device frame.
    pub device_position_m: Vec<Vec3>,
    /// Raw button bits.
    pub device_buttons: Vec<u32>,
    /// Deadline-missed flag.
    pub deadline_missed: Vec<bool>,
    /// The device's sequence number of each reading.
    pub device_seq: Vec<u64>,
    /// Age of each reading, ticks (0: fresh).
    pub device_age_ticks: Vec<u32>,
    /// Cursor, world frame, m.
    pub cursor_m: Vec<Vec3>,
    /// Scene state, ticks × fields.
    pub state: Vec<f64>,
    /// Scene force, world frame, N.
    pub world_force_n: Vec<Vec3>,
    /// Force sent, device frame, N.
    pub device_force_n: Vec<Vec3>,
    /// Soft-engagement factor.
    pub engagement: Vec<f64>,
    /// Watchdog factor (1: device samples fresh).
    pub watchdog: Vec<f64>,
    /// Local stiffness sent with the force, N/m, device frame, row-major 3×3.
    pub device_stiffness_n_per_m: Vec<[f64; 9]>,
    /// Status bits (see `haptic::status`).
    pub status: Vec<u8>,
    /// Events: (tick, name, detail).
    pub events: Vec<(u64, String, String)>,
    /// Work per tick, ns (wall clock; not reproducible).
    pub compute_ns: Vec<u64>,
    /// Start lateness per tick, ns (real-time mode).
    pub start_late_ns: Vec<i64>,
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
        self.tick.reserve(ticks);
        self.device_position_m.reserve(ticks);
        self.device_buttons.reserve(ticks);
        self.deadline_missed.reserve(ticks);
        self.device_seq.reserve(ticks);
        self.device_age_ticks.reserve(ticks);
        self.watchdog.reserve(ticks);
        self.device_stiffness_n_per_m.reserve(ticks);
        self.cursor_m.reserve(ticks);
        self.state.reserve(ticks * n);
        self.world_force_n.reserve(ticks);
        self.device_force_n.reserve(ticks);
        self.engagement.reserve(ticks);
        self.status.reserve(ticks);
        self.compute_ns.reserve(ticks);
        self.start_late_ns.reserve(ticks);
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

    /// Adds one tick straight from the loop (no encoding).
    pub fn push_tick(&mut self, t: &TickView<'_>) {
        let r = t.result;
        self.tick.push(r.tick);
        self.device_position_m.push(t.sample.position_m);
        self.device_buttons.push(t.sample.buttons.0);
        self.deadline_missed.push(t.deadline_missed);
        self.device_seq.push(t.sample.seq);
        self.device_age_ticks.push(t.sample.age_ticks);
        self.cursor_m.push(r.cursor_m);
        t.lp.scene_state(&mut self.state);
        self.world_force_n.push(r.world_force_n);
        self.device_force_n.push(r.device_force_n);
        self.engagement.push(r.engagement);
        self.status.push(r.status);
        self.watchdog.push(r.watchdog);
        self.device_stiffness_n_per_m
            .push(r.device_stiffness_n_per_m);
        for e in &r.events {
            self.events.push((r.tick, e.name.clone(), e.detail.clone()));
        }
        self.compute_ns.push(t.compute_ns);
        self.start_late_ns.push(t.start_late_ns);
    }

    /// Adds one message.
    pub fn push(
        &mut self,
        channel: Channel,
        data: &[u8],
    ) -> Result<(), crate::channels::cdr::CdrError> {
        match channel {
            Channel::DeviceInput => {
                let m = DeviceInputMsg::decode(data)?;
                self.tick.push(m.tick);
                self.device_position_m.push(m.position_m);
                self.device_buttons.push(m.buttons);
                self.deadline_missed.push(m.deadline_missed);
                self.device_seq.push(m.seq);
                self.device_age_ticks.push(m.age_ticks);
            }
            Channel::State => {
                let m = StateMsg::decode(data, self.state_fields.len())?;
                self.cursor_m.push(m.cursor_m);
                self.state.extend_from_slice(&m.values);
            }
            Channel::Force => {
                let m = ForceMsg::decode(data)?;
                self.world_force_n.push(m.world_force_n);
                self.device_force_n.push(m.device_force_n);
                self.engagement.push(m.engagement);
                self.status.push(m.status);
                self.watchdog.push(m.watchdog);
                self.device_stiffness_n_per_m
                    .push(m.device_stiffness_n_per_m);
            }
            Channel::Events => {
                let m = EventsMsg::decode(data)?;
                for (n, d) in m.names.into_iter().zip(m.details) {
                    self.events.push((m.tick, n, d));
                }
            }
            Channel::Timing => {
                let m = TimingMsg::decode(data)?;
                self.compute_ns.push(m.compute_ns);
                self.start_late_ns.push(m.start_late_ns);
            }
            _ => {}
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
        self.state_fields = info.description.state_fields.clone();
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
