//! Real-time pacing and tick-time statistics. The only place that reads the wall clock; nothing
//! measured here feeds the physics (a missed deadline becomes a logged input flag).

use std::time::{Duration, Instant};

/// Paces ticks against the wall clock: tick `n` starts at `start + n · period`.
///
/// Each wait sleeps to an absolute time (`clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)` on
/// Linux, so a late wake-up never shifts the schedule) a short stretch before the start time,
/// then spins the rest. How late each sleep woke is the machine's wake-up latency, kept as a
/// histogram ([`Pacer::wakeups`]), as cyclictest measures it.
#[derive(Debug)]
pub struct Pacer {
    start: Instant,
    period_ns: u64,
    spin: Duration,
    wakeups: DurationHistogram,
}

/// The spin a normal-priority thread needs: the scheduler's wake-up latency is often tens of
/// µs, and a 10 kHz tick has 100 µs.
const SPIN_NORMAL: Duration = Duration::from_micros(100);

impl Pacer {
    /// A pacer starting now with tick length `period_ns`, spinning the last 100 µs before each
    /// start (the precision a 10 kHz loop needs at normal priority).
    pub fn new(period_ns: u64) -> Self {
        Self::with_spin(period_ns, SPIN_NORMAL)
    }

    /// A pacer for a thread in the scheduling `rt` describes: with `SCHED_FIFO` the wake-up
    /// comes within tens of µs, so it spins a quarter of the period, at most 50 µs, and leaves the
    /// core to others for the rest; at normal priority as [`Pacer::new`].
    pub fn for_thread(period_ns: u64, rt: &crate::realtime::RtStatus) -> Self {
        let spin = if rt.priority.is_some() {
            Duration::from_nanos((period_ns / 4).min(50_000))
        } else {
            SPIN_NORMAL
        };
        Self::with_spin(period_ns, spin)
    }

    /// A pacer starting now with tick length `period_ns` that sleeps until `spin` before each
    /// start time and spins the rest (a scheduler of many sessions at 1 kHz spins little and
    /// leaves the core to the others).
    pub fn with_spin(period_ns: u64, spin: Duration) -> Self {
        Pacer {
            start: Instant::now(),
            period_ns,
            spin,
            wakeups: DurationHistogram::new(),
        }
    }

    /// How long it spins before each start time.
    pub fn spin(&self) -> Duration {
        self.spin
    }

    /// When tick 0 starts.
    pub fn start(&self) -> Instant {
        self.start
    }

    /// When `tick` starts.
    pub fn scheduled(&self, tick: u64) -> Instant {
        self.start + Duration::from_nanos(self.period_ns.saturating_mul(tick))
    }

    /// Waits for the start of `tick`; returns how late it actually starts, ns (≥ 0).
    pub fn wait_for(&mut self, tick: u64) -> i64 {
        self.wait_until(self.scheduled(tick))
    }

    /// Waits until `target` (sleeping to `target − spin`, then spinning); returns how late it
    /// started, ns (≥ 0). The sleep's own lateness goes to [`Pacer::wakeups`].
    pub fn wait_until(&mut self, target: Instant) -> i64 {
        let now = Instant::now();
        if target > now + self.spin {
            let wake_at = target - self.spin;
            sleep_until(wake_at);
            let woke = Instant::now();
            self.wakeups
                .record(woke.saturating_duration_since(wake_at).as_nanos() as u64);
        }
        while Instant::now() < target {
            std::hint::spin_loop();
        }
        Instant::now().duration_since(target).as_nanos() as i64
    }

    /// How late each sleep woke against the time it asked for, ns: the machine's wake-up
    /// latency as this thread sees it (p50 / p99 / p99.9 / max).
    pub fn wakeups(&self) -> &DurationHistogram {
        &self.wakeups
    }

    /// True when the deadline of `tick` (the start of the next tick) has passed.
    pub fn deadline_passed(&self, tick: u64) -> bool {
        Instant::now() > self.scheduled(tick + 1)
    }
}

/// Sleeps until `at` by the monotonic clock (which `Instant` reads on Linux): an absolute
/// sleep, resumed after a signal.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
pub fn sleep_until(at: Instant) {
    // The monotonic time of `at`: now's, plus the distance to `at`.
    let mut now = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec into a local.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut now) };
    let ahead = at.saturating_duration_since(Instant::now());
    if ahead.is_zero() {
        return;
    }
    let ns = now.tv_nsec as u64 + u64::from(ahead.subsec_nanos());
    let ts = libc::timespec {
        tv_sec: now.tv_sec + ahead.as_secs() as libc::time_t + (ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (ns % 1_000_000_000) as libc::c_long,
    };
    loop {
        // SAFETY: an absolute sleep on a local timespec; no remainder is written.
        let r = unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &ts,
                std::ptr::null_mut(),
            )
        };
        if r != libc::EINTR {
            return;
        }
    }
}

/// Sleeps until `at` (other systems: a relative sleep).
#[cfg(not(target_os = "linux"))]
pub fn sleep_until(at: Instant) {
    std::thread::sleep(at.saturating_duration_since(Instant::now()));
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

/// A streaming distribution of durations in constant memory (about 60 KB), for sessions of any
/// length: values below 256 ns are counted exactly; above, each power of two is split into 128
/// buckets, so a reported percentile is within 1/128 (0.8 %) of the nearest-rank sample, never
/// above the largest sample. The largest sample and the mean are exact.
#[derive(Clone, Debug)]
pub struct DurationHistogram {
    counts: Vec<u64>,
    n: u64,
    sum: u128,
    max: u64,
}

/// Sub-buckets per power of two above [`EXACT`] (relative bucket width 1/128).
const SUB: u64 = 128;
/// Values below this are counted exactly.
const EXACT: u64 = 2 * SUB;

impl Default for DurationHistogram {
    fn default() -> Self {
        Self::new()
    }
}

impl DurationHistogram {
    /// An empty histogram.
    pub fn new() -> Self {
        // Exact buckets, then 128 per power of two from 2^8 to 2^63.
        DurationHistogram {
            counts: vec![0; (EXACT + (64 - 8) * SUB) as usize],
            n: 0,
            sum: 0,
            max: 0,
        }
    }

    fn bucket(v: u64) -> usize {
        if v < EXACT {
            return v as usize;
        }
        let e = 63 - u64::from(v.leading_zeros()); // 2^e <= v < 2^(e+1), e >= 8
        let sub = (v >> (e - 7)) - SUB; // the 7 bits below the leading one
        (EXACT + (e - 8) * SUB + sub) as usize
    }

    /// The smallest value of bucket `b`.
    fn floor(b: usize) -> u64 {
        let b = b as u64;
        if b < EXACT {
            return b;
        }
        let e = (b - EXACT) / SUB + 8;
        let sub = (b - EXACT) % SUB;
        (SUB + sub) << (e - 7)
    }

    /// Counts one duration, ns.
    pub fn record(&mut self, ns: u64) {
        self.counts[Self::bucket(ns)] += 1;
        self.n += 1;
        self.sum += u128::from(ns);
        self.max = self.max.max(ns);
    }

    /// Number of durations counted.
    pub fn len(&self) -> u64 {
        self.n
    }

    /// True when nothing was counted.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Nearest-rank percentiles (zeros when empty): each the smallest value of the bucket that
    /// holds the nearest-rank sample (exact below 256 ns), the exact maximum and mean.
    pub fn percentiles(&self) -> Percentiles {
        if self.n == 0 {
            return Percentiles::default();
        }
        let rank = |q: f64| {
            let want = world_form::numbers::nearest_rank(self.n, q).unwrap_or(self.n);
            let mut seen = 0;
            for (b, c) in self.counts.iter().enumerate() {
                seen += c;
                if seen >= want {
                    return Self::floor(b).min(self.max);
                }
            }
            self.max
        };
        Percentiles {
            p50_ns: rank(0.5),
            p99_ns: rank(0.99),
            p999_ns: rank(0.999),
            max_ns: self.max,
            mean_ns: self.sum as f64 / self.n as f64,
        }
    }
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
    fn histogram_is_exact_below_256_ns_and_within_1_in_128_above() {
        let mut h = DurationHistogram::new();
        for v in 1..=200u64 {
            h.record(v);
        }
        assert_eq!(
            h.percentiles(),
            Percentiles::of(&(1..=200).collect::<Vec<_>>())
        );
        // Spread over nine decades: every percentile within 1/128 below the exact one.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut v = Vec::new();
        let mut h = DurationHistogram::new();
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let s = 100 + (x % 1_000_000_000) / (1 + (x >> 40) % 1000);
            v.push(s);
            h.record(s);
        }
        let (a, b) = (h.percentiles(), Percentiles::of(&v));
        for (got, want) in [
            (a.p50_ns, b.p50_ns),
            (a.p99_ns, b.p99_ns),
            (a.p999_ns, b.p999_ns),
        ] {
            assert!(
                got <= want && (want - got) as f64 <= want as f64 / 128.0,
                "{got} vs {want}"
            );
        }
        assert_eq!(a.max_ns, b.max_ns);
        assert!((a.mean_ns - b.mean_ns).abs() <= 1e-9 * b.mean_ns);
        assert_eq!(h.len(), 100_000);
        // Bucket edges round-trip, up to the largest u64.
        for v in [255u64, 256, 257, 511, 512, 1 << 40, u64::MAX] {
            let f = DurationHistogram::floor(DurationHistogram::bucket(v));
            assert!(f <= v && (v - f) as f64 <= v as f64 / 128.0, "{v}: {f}");
        }
        assert_eq!(
            DurationHistogram::new().percentiles(),
            Percentiles::default()
        );
    }

    /// docs/realtime.md, "sleep": with `SCHED_FIFO` the spin is a quarter of the period, at most
    /// 50 µs; without it, 100 µs.
    #[test]
    fn the_spin_is_a_quarter_period_up_to_50_us_with_fifo_and_100_us_without() {
        let fifo = crate::realtime::RtStatus {
            requested: true,
            priority: Some(50),
            ..Default::default()
        };
        let refused = crate::realtime::RtStatus {
            requested: true,
            ..Default::default()
        };
        let us = |p: Pacer| p.spin().as_nanos();
        // 1 kHz: a quarter is 250 µs, capped at 50 µs; 10 kHz: a quarter, 25 µs.
        assert_eq!(us(Pacer::for_thread(1_000_000, &fifo)), 50_000);
        assert_eq!(us(Pacer::for_thread(100_000, &fifo)), 25_000);
        for period_ns in [1_000_000, 100_000] {
            assert_eq!(us(Pacer::for_thread(period_ns, &refused)), 100_000);
            assert_eq!(
                us(Pacer::for_thread(
                    period_ns,
                    &crate::realtime::RtStatus::default()
                )),
                100_000
            );
            assert_eq!(us(Pacer::new(period_ns)), 100_000);
        }
    }

    #[test]
    fn pacer_never_starts_early() {
        let mut p = Pacer::new(200_000);
        let mut prev = Instant::now();
        for n in 0..20 {
            let late = p.wait_for(n);
            assert!(late >= 0);
            let now = Instant::now();
            assert!(now >= p.scheduled(n));
            assert!(now >= prev);
            prev = now;
        }
        // Every 200 µs wait beyond the first slept, and the sleeps' lateness was measured.
        assert!(p.wakeups().len() >= 10, "{}", p.wakeups().len());
    }

    #[test]
    fn absolute_sleep_never_wakes_early() {
        for us in [0u64, 50, 300, 2000] {
            let at = Instant::now() + Duration::from_micros(us);
            sleep_until(at);
            assert!(Instant::now() >= at, "{us} µs");
        }
    }
}
