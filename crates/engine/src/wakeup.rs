//! How promptly this machine wakes a sleeping thread, and which tick rates that allows: the
//! measurement behind `nanohaptics doctor`, as cyclictest makes it (a thread sleeps to absolute
//! deadlines and records how late each wake-up came).
//!
//! Not for: pacing a session ([`Pacer`](crate::timing::Pacer) measures its own wake-ups) or
//! setting up real time ([`realtime`](crate::realtime)).
//!
//! ```
//! use haptic_engine::wakeup::{measure, Verdict};
//! use std::time::Duration;
//! // 50 ms of wake-ups every 500 µs at normal priority.
//! let m = measure(Duration::from_micros(500), Duration::from_millis(50), None).unwrap();
//! assert!(m.samples >= 50);
//! assert!(m.latency.max_ns >= m.latency.p50_ns);
//! // A rate holds when no wake-up took more than half its period.
//! let v = m.verdict(1000);
//! assert!(matches!(v, Verdict::Holds | Verdict::Misses { .. }));
//! ```

use crate::realtime::{self, RtRequest, RtStatus};
use crate::timing::{Percentiles, sleep_until};
use std::time::{Duration, Instant};

/// The tick rates a session uses, Hz: the brick and nano worlds (1 kHz), a fast device servo
/// (4 kHz) and the optical tweezers (10 kHz).
pub const RATES_HZ: [u32; 3] = [1000, 4000, 10_000];

/// One measurement of wake-up latency.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Measurement {
    /// The scheduling the measuring thread had.
    pub realtime: RtStatus,
    /// Time between wake-ups asked for, ns.
    pub interval_ns: u64,
    /// Wake-ups measured.
    pub samples: u64,
    /// How late the wake-ups came, ns (p50 / p99 / p99.9 / max / mean).
    pub latency: Percentiles,
    /// Every wake-up's lateness, ns, sorted (for the rates' verdicts).
    #[serde(skip)]
    sorted_ns: Vec<u64>,
}

/// Whether a rate can be held, judged by the wake-ups measured.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "verdict")]
pub enum Verdict {
    /// No wake-up took more than half the period (the other half is the tick's work).
    Holds,
    /// Some did: about this many ticks a minute would start too late to finish in time.
    Misses {
        /// Expected missed deadlines per minute at this rate (the fraction of wake-ups later
        /// than half the period, times the ticks in a minute).
        per_minute: f64,
    },
}

impl Measurement {
    /// Whether `rate_hz` holds: every wake-up within half its period (see [`Verdict`]).
    pub fn verdict(&self, rate_hz: u32) -> Verdict {
        let half = 500_000_000 / u64::from(rate_hz.max(1));
        let late = self.sorted_ns.len() - self.sorted_ns.partition_point(|&v| v <= half);
        if late == 0 {
            Verdict::Holds
        } else {
            Verdict::Misses {
                per_minute: late as f64 / self.sorted_ns.len() as f64 * f64::from(rate_hz) * 60.0,
            }
        }
    }
}

/// Why a measurement could not be made.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum MeasureError {
    /// The interval or the duration is outside what a measurement can use.
    #[error(transparent)]
    Value(#[from] world_form::ValueError),
    /// The measuring thread could not be started.
    #[error("the measuring thread could not start: {0}")]
    Thread(String),
}

/// Measures wake-up latency for `duration`, sleeping to absolute deadlines `interval` apart on
/// a thread of its own, in real time when `rt` is given (as far as the system allows: see
/// [`Measurement::realtime`]).
pub fn measure(
    interval: Duration,
    duration: Duration,
    rt: Option<RtRequest>,
) -> Result<Measurement, MeasureError> {
    let interval_ns = interval.as_nanos() as u64;
    if !(10_000..=100_000_000).contains(&interval_ns) {
        return Err(world_form::ValueError::out_of_range(
            "interval_us",
            interval.as_secs_f64() * 1e6,
            "10 µs to 100 ms",
        )
        .into());
    }
    if duration < interval || duration > Duration::from_secs(3600) {
        return Err(world_form::ValueError::out_of_range(
            "seconds",
            duration.as_secs_f64(),
            "one interval to 3600 s",
        )
        .into());
    }
    std::thread::Builder::new()
        .name("wakeup-measure".into())
        .spawn(move || {
            let guard = realtime::enter_if(rt.as_ref());
            let n = (duration.as_nanos() / interval.as_nanos()) as usize;
            let mut late = Vec::with_capacity(n);
            let start = Instant::now() + interval;
            for k in 0..n {
                let at = start + interval * k as u32;
                sleep_until(at);
                late.push(Instant::now().saturating_duration_since(at).as_nanos() as u64);
            }
            let status = guard.status();
            drop(guard);
            let latency = Percentiles::of(&late);
            late.sort_unstable();
            Measurement {
                realtime: status,
                interval_ns,
                samples: late.len() as u64,
                latency,
                sorted_ns: late,
            }
        })
        .map_err(|e| MeasureError::Thread(e.to_string()))?
        .join()
        .map_err(|_| MeasureError::Thread("the measuring thread panicked".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(sorted_ns: Vec<u64>) -> Measurement {
        Measurement {
            realtime: RtStatus::default(),
            interval_ns: 500_000,
            samples: sorted_ns.len() as u64,
            latency: Percentiles::of(&sorted_ns),
            sorted_ns,
        }
    }

    #[test]
    fn a_rate_holds_when_every_wakeup_leaves_half_the_period() {
        // 1000 wake-ups: 998 at 5 µs, one at 60 µs, one at 300 µs.
        let mut v = vec![5_000; 998];
        v.extend([60_000, 300_000]);
        let m = with(v);
        assert_eq!(m.verdict(1000), Verdict::Holds); // half of 1 ms = 500 µs
        // 4 kHz (125 µs): one in 1000 too late → 240 a minute.
        assert_eq!(m.verdict(4000), Verdict::Misses { per_minute: 240.0 });
        // 10 kHz (50 µs): two in 1000 → 1200 a minute.
        assert_eq!(m.verdict(10_000), Verdict::Misses { per_minute: 1200.0 });
        // Exactly half the period still holds.
        assert_eq!(with(vec![50_000]).verdict(10_000), Verdict::Holds);
    }

    /// docs/realtime.md's `doctor` example on 4000 wake-ups of 500 µs: real time (max 287.1 µs,
    /// 3 wake-ups over 50 µs, all 3 over 125 µs) "1 kHz holds", "4 kHz no: ~180.0 late ticks a
    /// minute", "10 kHz no: ~450.0"; normal priority (139 over 500 µs, 155 over 125 µs, 3988
    /// over 50 µs) "~2085.0", "~9300.0", "~598200.0": the rule gives the printed rows.
    #[test]
    fn the_verdicts_of_the_realtime_doc_example_follow_from_its_wakeups() {
        let per_minute = |m: &Measurement, hz| match m.verdict(hz) {
            Verdict::Holds => None,
            Verdict::Misses { per_minute } => Some((per_minute * 10.0).round() / 10.0),
        };
        let mut rt = vec![10_400; 3997];
        rt.extend([130_000, 200_000, 287_100]);
        let rt = with(rt);
        assert_eq!(per_minute(&rt, 1000), None);
        assert_eq!(per_minute(&rt, 4000), Some(180.0));
        assert_eq!(per_minute(&rt, 10_000), Some(450.0));
        let mut normal = vec![40_000; 12];
        normal.extend(vec![61_800; 3988 - 155]);
        normal.extend(vec![200_000; 155 - 139]);
        normal.extend(vec![4_385_200; 139]);
        let normal = with(normal);
        assert_eq!(per_minute(&normal, 1000), Some(2085.0));
        assert_eq!(per_minute(&normal, 4000), Some(9300.0));
        assert_eq!(per_minute(&normal, 10_000), Some(598_200.0));
    }

    #[test]
    fn bad_interval_and_duration_are_refused_by_name() {
        let e = measure(Duration::from_micros(1), Duration::from_secs(1), None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "interval_us = 1 is out of range: allowed 10 µs to 100 ms"
        );
        let e = measure(Duration::from_millis(1), Duration::from_micros(10), None).unwrap_err();
        assert!(e.to_string().starts_with("seconds = "), "{e}");
    }

    #[test]
    fn measures_real_sleeps() {
        let m = measure(Duration::from_micros(200), Duration::from_millis(20), None).unwrap();
        assert_eq!(m.samples, 100);
        assert_eq!(m.realtime.policy(), "off");
        assert!(m.latency.p50_ns <= m.latency.max_ns);
        // Nothing wakes early, and a sleeping thread wakes within a second.
        assert!(m.latency.max_ns < 1_000_000_000);
    }
}
