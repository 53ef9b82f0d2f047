//! Real-time pacing and tick-time statistics. The only place that reads the wall clock; nothing
//! measured here feeds the physics (a missed deadline becomes a logged input flag).

use std::time::{Duration, Instant};

/// Paces ticks against the wall clock: tick `n` starts at `start + n · period`.
#[derive(Debug)]
pub struct Pacer {
    start: Instant,
    period_ns: u64,
    spin: Duration,
}

impl Pacer {
    /// A pacer starting now with tick length `period_ns`.
    pub fn new(period_ns: u64) -> Self {
        Pacer {
            start: Instant::now(),
            period_ns,
            // Sleep until this close to the start time, then spin (sleep granularity).
            spin: Duration::from_micros(100),
        }
    }

    fn scheduled(&self, tick: u64) -> Instant {
        self.start + Duration::from_nanos(self.period_ns.saturating_mul(tick))
    }

    /// Waits for the start of `tick`; returns how late it actually starts, ns (≥ 0).
    pub fn wait_for(&self, tick: u64) -> i64 {
        let target = self.scheduled(tick);
        let now = Instant::now();
        if target > now + self.spin {
            std::thread::sleep(target - now - self.spin);
        }
        while Instant::now() < target {
            std::hint::spin_loop();
        }
        Instant::now().duration_since(target).as_nanos() as i64
    }

    /// True when the deadline of `tick` (the start of the next tick) has passed.
    pub fn deadline_passed(&self, tick: u64) -> bool {
        Instant::now() > self.scheduled(tick + 1)
    }
}

/// Summary of a distribution of durations, ns.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Percentiles {
    /// Median, ns.
    pub p50_ns: u64,
    /// 99th percentile, ns.
    pub p99_ns: u64,
    /// 99.9th percentile, ns.
    pub p999_ns: u64,
    /// Largest, ns.
    pub max_ns: u64,
    /// Mean, ns.
    pub mean_ns: f64,
}

impl Percentiles {
    /// Percentiles of `samples` (nearest-rank); zeros when empty.
    pub fn of(samples: &[u64]) -> Self {
        if samples.is_empty() {
            return Percentiles::default();
        }
        let mut v = samples.to_vec();
        v.sort_unstable();
        let rank = |q: f64| {
            let i = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
            v[i - 1]
        };
        Percentiles {
            p50_ns: rank(0.5),
            p99_ns: rank(0.99),
            p999_ns: rank(0.999),
            max_ns: v[v.len() - 1],
            mean_ns: v.iter().map(|&x| x as f64).sum::<f64>() / v.len() as f64,
        }
    }
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
    /// Wall time of the whole run, s.
    pub wall_s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let v: Vec<u64> = (1..=1000).collect();
        let p = Percentiles::of(&v);
        assert_eq!(
            (p.p50_ns, p.p99_ns, p.p999_ns, p.max_ns),
            (500, 990, 999, 1000)
        );
        assert_eq!(p.mean_ns, 500.5);
        assert_eq!(Percentiles::of(&[]), Percentiles::default());
    }

    #[test]
    fn pacer_never_starts_early() {
        let p = Pacer::new(200_000);
        let mut prev = Instant::now();
        for n in 0..20 {
            let late = p.wait_for(n);
            assert!(late >= 0);
            let now = Instant::now();
            assert!(now >= p.scheduled(n));
            assert!(now >= prev);
            prev = now;
        }
    }
}
