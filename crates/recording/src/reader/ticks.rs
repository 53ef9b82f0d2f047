//! Tick order: `/device/input` carries ticks 0, 1, 2, … in file order (no gap, no repeat),
//! each tick ends with its `/loop/timing` message, and the count of ticks matches the `session`
//! metadata record. Also the messages read so far, and where the last complete tick ends (what
//! a salvage keeps).

use super::{RecordedMessage, RecordingError, corrupt};
use crate::channels::messages::{Channel, DeviceInputMsg};

/// The ticks read so far.
#[derive(Default)]
pub(super) struct Ticks {
    /// Messages of the known channels, in file order.
    pub messages: Vec<RecordedMessage>,
    /// `messages.len()` after the last complete tick.
    pub complete: usize,
    /// `/device/input` messages read.
    pub inputs: u64,
    /// `/loop/timing` messages read (complete ticks).
    pub timings: u64,
}

/// Why a message does not fit the ticks.
pub(super) enum TickError {
    /// It does not decode.
    Bad(RecordingError),
    /// It breaks the tick order: what is wrong (the caller places it).
    Order(String),
}

impl TickError {
    /// As an error of the record `record()` at byte `at`.
    pub fn place(self, at: usize, record: &dyn Fn() -> String) -> RecordingError {
        match self {
            TickError::Bad(e) => e,
            TickError::Order(detail) => corrupt(at, record(), detail),
        }
    }
}

fn span(a: u64, b: u64) -> String {
    if a == b {
        format!("tick {a} is missing")
    } else {
        format!("ticks {a}–{b} are missing")
    }
}

impl Ticks {
    /// A message of `channel` at `log_time` ns with `data`: its place in the tick order.
    pub fn message(
        &mut self,
        channel: Channel,
        log_time: u64,
        data: &[u8],
    ) -> Result<(), TickError> {
        match channel {
            Channel::DeviceInput => {
                let d = DeviceInputMsg::decode(data).map_err(|e| {
                    TickError::Bad(RecordingError::BadMessage {
                        topic: channel.topic().to_string(),
                        log_time_ns: log_time,
                        detail: e.to_string(),
                    })
                })?;
                self.input(d.tick).map_err(TickError::Order)
            }
            Channel::Timing => self.timing(log_time).map_err(TickError::Order),
            _ => Ok(()),
        }
    }

    /// A `/device/input` message of tick `tick`: the next tick, after a complete one.
    fn input(&mut self, tick: u64) -> Result<(), String> {
        let want = self.inputs;
        if tick != want {
            return Err(match (want, tick) {
                (0, t) => format!(
                    "the first /device/input is tick {t}, not tick 0 ({})",
                    span(0, t - 1)
                ),
                (w, t) if t > w => format!(
                    "/device/input tick {t} follows tick {}: {}",
                    w - 1,
                    span(w, t - 1)
                ),
                (w, t) => format!(
                    "/device/input tick {t} follows tick {}: tick {t} repeats",
                    w - 1
                ),
            });
        }
        if self.timings != self.inputs {
            return Err(format!(
                "tick {} has no /loop/timing message (each tick ends with one)",
                want.saturating_sub(1)
            ));
        }
        self.inputs += 1;
        Ok(())
    }

    /// A `/loop/timing` message: the end of the tick whose input came last.
    fn timing(&mut self, log_time: u64) -> Result<(), String> {
        if self.timings + 1 != self.inputs {
            return Err(format!(
                "a /loop/timing message at log time {log_time} ns is not the end of a tick \
                 ({} /device/input and {} /loop/timing messages before it)",
                self.inputs, self.timings
            ));
        }
        self.timings += 1;
        Ok(())
    }

    /// At the data end: the last tick has its `/loop/timing` message.
    pub fn last_is_complete(&self) -> Result<(), String> {
        if self.inputs == self.timings {
            return Ok(());
        }
        Err(format!(
            "the last tick ({}) has no /loop/timing message",
            self.inputs.saturating_sub(1)
        ))
    }

    /// At the data end: the `ticks` entry of the `session` metadata record (`None`: missing)
    /// is the count of ticks read.
    pub fn match_metadata(&self, ticks: Option<&str>) -> Result<(), String> {
        let n = ticks.unwrap_or("(missing)");
        if n.parse::<u64>().ok() == Some(self.inputs) {
            return Ok(());
        }
        Err(format!(
            "ticks = {n}, the data section holds {} ticks",
            self.inputs
        ))
    }

    /// Keeps whole ticks only (a tick ends with its `/loop/timing` message), and the
    /// description.
    pub fn keep_complete(&mut self) {
        let tail = self.messages.split_off(self.complete);
        self.messages.extend(
            tail.into_iter()
                .filter(|m| m.channel == Channel::Description),
        );
    }
}
