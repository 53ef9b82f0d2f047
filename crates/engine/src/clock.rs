//! The clocks a session's ticks run under: when tick `n` may start, how late it started and
//! whether its force came too late. [`TickEngine::cycle`](crate::runner::TickEngine::cycle)
//! asks its clock these three things and nothing else, so one step serves every front end:
//!
//! | clock | who runs under it | start lateness | deadline |
//! |---|---|---|---|
//! | [`Batch`] | `run` without a device, `render`, `demo`, the Python `Session` | 0 | never missed |
//! | [`Recorded`] | `replay --verify`: the recording's flags are inputs | 0 | the recorded flag |
//! | [`Wall`] | `run --realtime`, `play` with the page as the hand | against `start + n·period` | the next tick's start |
//! | [`DeviceClock`] | a bridged device paces the session | against the last start + period | one period after the sample arrived |
//! | [`Worker`] | a classroom worker ticking many sessions in one wake-up | against the worker's cycle `k` | the worker's next cycle |
//!
//! Only [`Wall`] and [`Worker`] read a shared schedule; none of them feeds the physics: a
//! missed deadline becomes the tick's logged input flag (zero force), so every session replays
//! bit for bit under [`Recorded`].

use crate::pacing::Pacing;
use crate::realtime::RtStatus;
use crate::timing::{Pacer, Percentiles};
use std::time::Instant;

/// When a session's ticks start and whether their force is late (see the module's table).
pub trait TickClock {
    /// Waits until tick `n` may start (before its sample is read); returns how late it starts
    /// against the clock's schedule, ns (0 for clocks without one).
    fn wait(&mut self, n: u64) -> i64;
    /// Tick `n`'s start lateness, ns, now that its sample is in hand at `t0`; `waited` is what
    /// [`TickClock::wait`] returned.
    fn started(&mut self, _n: u64, _t0: Instant, waited: i64) -> i64 {
        waited
    }
    /// The deadline flag a recording holds for tick `n`: an input of the tick (replay only).
    fn recorded_missed(&self, _n: u64) -> bool {
        false
    }
    /// Whether tick `n`, whose sample was in hand at `t0`, has missed its deadline now (its
    /// force is then replaced by zero).
    fn deadline_passed(&self, n: u64, t0: Instant) -> bool;
    /// Whether ticks run against the wall clock (their start lateness goes to the jitter
    /// statistics, and the tick thread may ask for real time).
    fn timed(&self) -> bool;
    /// The wake-up latency the clock's sleeps measured (none for clocks that never sleep).
    fn wakeups(&self) -> Percentiles {
        Percentiles::default()
    }
}

/// The clock a pacing policy names, for ticks of `period_ns` on a thread whose scheduling is
/// `rt` (a wall-clock schedule spins less under `SCHED_FIFO`).
pub fn for_pacing(pacing: Pacing, period_ns: u64, rt: &RtStatus) -> Box<dyn TickClock> {
    match pacing {
        Pacing::Batch => Box::new(Batch),
        Pacing::Recorded(flags) => Box::new(Recorded { flags }),
        Pacing::Realtime => Box::new(Wall::for_thread(period_ns, rt)),
        Pacing::DeviceClock => Box::new(DeviceClock::new(period_ns)),
    }
}

/// As fast as possible, never late: batch runs and scripted sessions.
#[derive(Clone, Copy, Debug, Default)]
pub struct Batch;

impl TickClock for Batch {
    fn wait(&mut self, _n: u64) -> i64 {
        0
    }
    fn deadline_passed(&self, _n: u64, _t0: Instant) -> bool {
        false
    }
    fn timed(&self) -> bool {
        false
    }
}

/// A recording's deadline flags as the ticks' inputs (replay), never late otherwise.
#[derive(Clone, Debug, Default)]
pub struct Recorded {
    /// Tick `n`'s recorded flag at index `n` (missing: not missed).
    pub flags: Vec<bool>,
}

impl TickClock for Recorded {
    fn wait(&mut self, _n: u64) -> i64 {
        0
    }
    fn recorded_missed(&self, n: u64) -> bool {
        usize::try_from(n)
            .ok()
            .and_then(|i| self.flags.get(i))
            .copied()
            .unwrap_or(false)
    }
    fn deadline_passed(&self, _n: u64, _t0: Instant) -> bool {
        false
    }
    fn timed(&self) -> bool {
        false
    }
}

/// The wall clock: tick `n` starts at `start + n · period` and must be done by the next
/// tick's start.
#[derive(Debug)]
pub struct Wall {
    /// The schedule (sleeps to absolute deadlines, measures its wake-ups).
    pub pacer: Pacer,
}

impl Wall {
    /// A schedule starting now with tick length `period_ns`, its spin chosen for the thread's
    /// scheduling `rt` ([`Pacer::for_thread`]).
    pub fn for_thread(period_ns: u64, rt: &RtStatus) -> Self {
        Wall {
            pacer: Pacer::for_thread(period_ns, rt),
        }
    }
}

impl TickClock for Wall {
    fn wait(&mut self, n: u64) -> i64 {
        self.pacer.wait_for(n)
    }
    fn deadline_passed(&self, n: u64, _t0: Instant) -> bool {
        self.pacer.deadline_passed(n)
    }
    fn timed(&self) -> bool {
        true
    }
    fn wakeups(&self) -> Percentiles {
        self.pacer.wakeups().percentiles()
    }
}

/// The device's own clock: a bridged device's samples pace the session; a tick is late when
/// its force leaves more than one period after its sample arrived.
#[derive(Clone, Copy, Debug)]
pub struct DeviceClock {
    period_ns: u64,
    prev_start: Option<Instant>,
}

impl DeviceClock {
    /// The device's clock for ticks of `period_ns`.
    pub fn new(period_ns: u64) -> Self {
        DeviceClock {
            period_ns,
            prev_start: None,
        }
    }
}

impl TickClock for DeviceClock {
    fn wait(&mut self, _n: u64) -> i64 {
        0
    }
    fn started(&mut self, _n: u64, t0: Instant, waited: i64) -> i64 {
        let late = match self.prev_start {
            Some(p) => t0.duration_since(p).as_nanos() as i64 - self.period_ns as i64,
            None => waited,
        };
        self.prev_start = Some(t0);
        late
    }
    fn deadline_passed(&self, _n: u64, t0: Instant) -> bool {
        t0.elapsed().as_nanos() as u64 > self.period_ns
    }
    fn timed(&self) -> bool {
        true
    }
}

/// A shared worker's cycle `k`: the worker waited for the cycle's start once for all the
/// sessions it holds; each session's tick started late by when its turn came, and must be
/// done by the worker's next cycle.
#[derive(Clone, Copy, Debug)]
pub struct Worker<'a> {
    /// The worker's schedule.
    pub pacer: &'a Pacer,
    /// The worker's cycle.
    pub k: u64,
}

impl TickClock for Worker<'_> {
    fn wait(&mut self, _n: u64) -> i64 {
        0
    }
    fn started(&mut self, _n: u64, t0: Instant, _waited: i64) -> i64 {
        t0.checked_duration_since(self.pacer.scheduled(self.k))
            .map_or(0, |d| d.as_nanos() as i64)
    }
    fn deadline_passed(&self, _n: u64, _t0: Instant) -> bool {
        self.pacer.deadline_passed(self.k)
    }
    fn timed(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn batch_and_recorded_are_never_late_and_recorded_reads_its_flags() {
        let t0 = Instant::now();
        let mut b = Batch;
        assert_eq!(b.wait(7), 0);
        assert!(!b.deadline_passed(7, t0 - Duration::from_secs(1)));
        assert!(!b.timed());
        let r = Recorded {
            flags: vec![false, true],
        };
        assert!(!r.recorded_missed(0));
        assert!(r.recorded_missed(1));
        assert!(!r.recorded_missed(2));
        assert!(!r.deadline_passed(1, t0 - Duration::from_secs(1)));
    }

    #[test]
    fn device_clock_counts_lateness_from_the_last_start() {
        let mut c = DeviceClock::new(1_000_000);
        let t0 = Instant::now();
        assert_eq!(c.started(0, t0, 0), 0);
        // The next sample arrived 1.5 periods later: 0.5 ms late.
        assert_eq!(c.started(1, t0 + Duration::from_micros(1500), 0), 500_000);
        // A sample that arrived 2 ms ago is past its 1 ms deadline.
        assert!(c.deadline_passed(1, Instant::now() - Duration::from_millis(2)));
        assert!(!c.deadline_passed(1, Instant::now() + Duration::from_secs(1)));
    }

    #[test]
    fn a_worker_cycle_is_late_by_its_turn_and_due_at_the_next_cycle() {
        let p = Pacer::with_spin(1_000_000, Duration::ZERO);
        let mut w = Worker { pacer: &p, k: 0 };
        let late = w.started(0, p.scheduled(0) + Duration::from_micros(300), 0);
        assert_eq!(late, 300_000);
        // Cycle 0 ends when cycle 1 starts, 1 ms after the pacer's start: not yet passed.
        let fresh = Worker {
            pacer: &p,
            k: 1_000_000,
        };
        assert!(!fresh.deadline_passed(0, Instant::now()));
        // A cycle long past is late.
        let old = Pacer::with_spin(1_000, Duration::ZERO);
        std::thread::sleep(Duration::from_millis(2));
        assert!(Worker { pacer: &old, k: 0 }.deadline_passed(0, Instant::now()));
    }
}
