//! Timers: wall-clock and thread-CPU time of a closure.
//!
//! Thread CPU time (`CLOCK_THREAD_CPUTIME_ID`, through the `cpu-time` crate) is what the code
//! costs: the time the thread waited for a core on a shared machine is left out. Wall time is
//! what it took, preemption included. Every timer here gives both where both are meaningful.

use crate::stats::Summary;
use cpu_time::ThreadTime;
use std::hint::black_box;
use std::time::Instant;

/// Wall-clock and thread-CPU time of one call, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Elapsed wall-clock time, s.
    pub wall_s: f64,
    /// CPU time of the calling thread, s.
    pub cpu_s: f64,
}

/// Runs `f` once and returns its value with the wall and thread-CPU time it took.
///
/// The wall clock is read inside the CPU clock: reading the thread-CPU clock is a system call
/// (about 1 µs on a loaded machine), reading `Instant` is not, so the wall time of a
/// sub-microsecond call stays clean and the CPU time carries the clock overhead.
pub fn span<T>(f: impl FnOnce() -> T) -> (T, Span) {
    let cpu = ThreadTime::now();
    let wall = Instant::now();
    let v = f();
    let wall_s = wall.elapsed().as_secs_f64();
    let cpu_s = cpu.elapsed().as_secs_f64();
    (v, Span { wall_s, cpu_s })
}

/// One wall and one thread-CPU sample per timed call, s.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timings {
    wall_s: Vec<f64>,
    cpu_s: Vec<f64>,
}

impl Timings {
    /// No samples yet, room for `n`.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            wall_s: Vec::with_capacity(n),
            cpu_s: Vec::with_capacity(n),
        }
    }

    /// Times `n` calls of `f` (its value passed through `black_box`), one sample per call.
    pub fn repeat<T>(n: usize, mut f: impl FnMut() -> T) -> Self {
        let mut t = Self::with_capacity(n);
        for _ in 0..n {
            t.time(|| black_box(f()));
        }
        t
    }

    /// Times one call of `f`, records its sample and returns its value. Work done outside the
    /// closure (preparing the input, checking the output) is not timed.
    pub fn time<T>(&mut self, f: impl FnOnce() -> T) -> T {
        let (v, s) = span(f);
        self.push(s);
        v
    }

    /// Records a sample measured elsewhere.
    pub fn push(&mut self, s: Span) {
        self.wall_s.push(s.wall_s);
        self.cpu_s.push(s.cpu_s);
    }

    /// How many samples.
    pub fn len(&self) -> usize {
        self.wall_s.len()
    }

    /// True before the first sample.
    pub fn is_empty(&self) -> bool {
        self.wall_s.is_empty()
    }

    /// Wall-clock samples in call order, s.
    pub fn wall_s(&self) -> &[f64] {
        &self.wall_s
    }

    /// Thread-CPU samples in call order, s.
    pub fn cpu_s(&self) -> &[f64] {
        &self.cpu_s
    }

    /// Percentiles of the wall-clock samples in µs; `None` without samples.
    pub fn wall_us(&self) -> Option<Summary> {
        Summary::of(self.wall_s.iter().map(|s| s * 1e6))
    }

    /// Percentiles of the thread-CPU samples in µs; `None` without samples.
    pub fn cpu_us(&self) -> Option<Summary> {
        Summary::of(self.cpu_s.iter().map(|s| s * 1e6))
    }
}

/// Thread-CPU time per item, s: `f` (which processes `items` items per call) is called
/// repeatedly in `blocks` blocks of at least `min_block_s` s each, and the cheapest block
/// counts. The minimum over blocks keeps other processes' interference (cache eviction,
/// frequency changes) out of the figure. `items` and `blocks` of 0 count as 1.
pub fn best_block_cpu_s(blocks: usize, min_block_s: f64, items: usize, mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..blocks.max(1) {
        let mut calls = 0usize;
        let t0 = ThreadTime::now();
        let elapsed = loop {
            f();
            calls += 1;
            let e = t0.elapsed().as_secs_f64();
            if e >= min_block_s {
                break e;
            }
        };
        best = best.min(elapsed / (calls * items.max(1)) as f64);
    }
    best
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Burns about `n` multiply-adds of thread CPU time.
    fn spin(n: u64) -> u64 {
        let mut x = 1u64;
        for i in 0..n {
            x = black_box(x.wrapping_mul(6364136223846793005).wrapping_add(i));
        }
        x
    }

    #[test]
    fn timings_record_one_sample_per_call_in_order() {
        let mut calls = 0;
        let t = Timings::repeat(5, || {
            calls += 1;
            spin(1000)
        });
        assert_eq!(calls, 5);
        assert_eq!(t.len(), 5);
        assert_eq!(t.cpu_s().len(), 5);
        assert!(t.wall_s().iter().all(|w| *w >= 0.0));
        assert!(t.cpu_us().unwrap().min() >= 0.0);
        let mut u = Timings::default();
        assert!(u.is_empty());
        assert!(u.wall_us().is_none());
        assert_eq!(u.time(|| 41 + 1), 42);
        u.push(Span {
            wall_s: 2.0,
            cpu_s: 1.0,
        });
        assert_eq!(u.wall_s()[1], 2.0);
        assert_eq!(u.cpu_s()[1], 1.0);
        assert_eq!(u.wall_us().unwrap().max(), 2e6);
    }

    #[test]
    fn span_measures_a_busy_loop_in_both_clocks() {
        let (v, s) = span(|| spin(20_000_000));
        assert_ne!(v, 0);
        // 2e7 dependent multiply-adds take at least 5 ms on any current core
        assert!(s.cpu_s > 5e-3, "cpu {} s", s.cpu_s);
        // the thread cannot run longer than the wall clock (small slack for clock granularity)
        assert!(
            s.cpu_s <= s.wall_s + 1e-3,
            "cpu {} > wall {}",
            s.cpu_s,
            s.wall_s
        );
    }

    #[test]
    fn best_block_divides_by_calls_and_items() {
        let mut calls = 0u64;
        let per_item = best_block_cpu_s(3, 2e-3, 10, || {
            calls += 1;
            spin(100_000);
        });
        assert!(calls >= 3);
        let (_, one) = span(|| spin(100_000));
        // one call is ten items: the per-item figure is about a tenth of one call's time
        assert!(
            per_item > 0.0 && per_item < one.cpu_s,
            "{per_item} vs {}",
            one.cpu_s
        );
    }
}
