//! How a session's ticks are paced ([`Pacing`]) and what the pacing measured ([`TickStats`]):
//! the runner paces by the first and fills the second; the sinks, the summaries and the
//! recording's `session` metadata read it.
//!
//! Not for: the wall-clock sleeper itself (`crate::timing::Pacer`, shared with the
//! fake device) or the percentile arithmetic (`crate::timing::Percentiles`).

use crate::realtime::RtStatus;
use crate::timing::Percentiles;

/// How ticks are paced and where the deadline flag comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum Pacing {
    /// As fast as possible; no deadline.
    Batch,
    /// Tick `n` starts at `start + n · period` by the wall clock; a tick whose force is ready
    /// after the start of the next one sends zero force (`deadline.missed`).
    Realtime,
    /// The device's samples are the clock (a bridged device: `sample` returns when a reading
    /// arrives or the watchdog's wait expires); the deadline is one period after the tick starts.
    DeviceClock,
    /// Deadline flags read from a recording (replay).
    Recorded(Vec<bool>),
}

/// Tick-time statistics of a session.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TickStats {
    /// Ticks run.
    pub ticks: u64,
    /// Work per tick (device read, world step, force, encoding, hand-off to the writer), ns.
    pub compute: Percentiles,
    /// Start lateness against the schedule (real-time mode only; zeros in batch), ns.
    pub jitter: Percentiles,
    /// Ticks whose deadline was missed (real-time mode only).
    pub missed: u64,
    /// How late the tick thread's sleeps woke against the time they asked for (wall-clock
    /// pacing only; zeros otherwise), ns: the machine's wake-up latency as cyclictest reports
    /// it.
    pub wakeup: Percentiles,
    /// The real-time scheduling the tick thread asked for and got.
    pub realtime: RtStatus,
    /// Wall time of the whole run, s.
    pub wall_s: f64,
}
