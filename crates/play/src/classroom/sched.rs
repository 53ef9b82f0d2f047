//! Pacing without a thread per student: a few workers (one per core, at most four), each
//! ticking every session it holds once per period, in turn, in one wake-up against one
//! wall-clock schedule (ros2_control's pattern: one real-time thread runs every controller in
//! sequence). A session's tick `n` runs in its worker's cycle `k0 + n`; its deadline is the start
//! of the next cycle, as [`haptic_engine::timing::Pacer`] counts it for `play` (a missed
//! deadline sends zero force and is recorded, so the session still replays bit for bit). A
//! session that ended leaves its worker for the finisher thread, which closes its recording and
//! tells its pages, so ending never delays the others' ticks.
//!
//! What a worker does each cycle ([`Roster`]) is apart from the clock, so its order, its
//! hand-over of ended sessions and its figures ([`CycleStats`]) are tested without one.

use super::live::Live;
use haptic_engine::realtime::{self, RtRequest, RtStatus};
use haptic_engine::timing::{DurationHistogram, Pacer, Percentiles};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

/// How long a worker spins before each cycle (the rest it sleeps): its sessions' deadlines are
/// a whole period away, so the cores go to the other workers and the pages instead.
const SPIN: Duration = Duration::from_micros(20);

/// What a worker ticks: a student's session (or their step's world) as [`Live`] is.
pub(crate) trait Ticked {
    /// This session's part of worker cycle `k` of `pacer`.
    fn cycle(&mut self, k: u64, pacer: &Pacer);
    /// Whether it ended (it leaves the worker).
    fn ended(&self) -> bool;
    /// Ends it at its next cycle.
    fn request_end(&self);
}

impl Ticked for Box<Live> {
    fn cycle(&mut self, k: u64, pacer: &Pacer) {
        Live::cycle(self, k, pacer);
    }
    fn ended(&self) -> bool {
        Live::ended(self)
    }
    fn request_end(&self) {
        Live::request_end(self);
    }
}

/// A worker's sessions, in the order they came: each cycle ticks every one of them once, in that
/// order, then hands over the ones that ended (in the order they are held).
pub(crate) struct Roster<T> {
    held: Vec<T>,
}

impl<T: Ticked> Roster<T> {
    /// No session.
    pub(crate) fn new() -> Self {
        Roster { held: Vec::new() }
    }

    /// Takes `t`: it ticks from the next cycle on.
    pub(crate) fn admit(&mut self, t: T) {
        self.held.push(t);
    }

    /// Sessions held.
    pub(crate) fn len(&self) -> usize {
        self.held.len()
    }

    /// Cycle `k`: every session's step (each asked to end first when `stopping`), then the
    /// ended ones, removed, in the order they were held.
    pub(crate) fn cycle(&mut self, k: u64, pacer: &Pacer, stopping: bool) -> Vec<T> {
        for t in self.held.iter_mut() {
            if stopping {
                t.request_end();
            }
            t.cycle(k, pacer);
        }
        if !self.held.iter().any(|t| t.ended()) {
            return Vec::new();
        }
        let (ended, going): (Vec<T>, Vec<T>) = std::mem::take(&mut self.held)
            .into_iter()
            .partition(|t| t.ended());
        self.held = going;
        ended
    }
}

/// A worker's cycles, as the class's summary reports them: how late each began, how long its
/// sessions took, and how many ran past their deadline.
#[derive(Clone, Debug)]
pub struct CycleStats {
    /// The period, ns.
    pub period_ns: u64,
    /// Cycles run (with at least one session).
    pub cycles: u64,
    /// Cycles whose last session ended after the cycle's deadline (the next cycle's start).
    pub late_cycles: u64,
    /// Of those, the cycles that began a whole period late or more (the worker was not
    /// running when its cycle was due), the rest took too long once begun.
    pub began_late: u64,
    /// The most sessions the worker held in one cycle.
    pub most_sessions: usize,
    /// Sessions ticked, summed over the cycles (for the cost per session).
    pub session_ticks: u64,
    started: DurationHistogram,
    work: DurationHistogram,
}

impl CycleStats {
    /// No cycle yet, at period `period_ns`.
    pub fn new(period_ns: u64) -> Self {
        CycleStats {
            period_ns,
            cycles: 0,
            late_cycles: 0,
            began_late: 0,
            most_sessions: 0,
            session_ticks: 0,
            started: DurationHistogram::new(),
            work: DurationHistogram::new(),
        }
    }

    /// One cycle of `sessions` sessions that began `late_ns` after its start time and took
    /// `work_ns`.
    pub fn record(&mut self, sessions: usize, late_ns: u64, work_ns: u64) {
        self.cycles += 1;
        self.session_ticks += sessions as u64;
        self.most_sessions = self.most_sessions.max(sessions);
        self.started.record(late_ns);
        self.work.record(work_ns);
        if late_ns.saturating_add(work_ns) > self.period_ns {
            self.late_cycles += 1;
            if late_ns >= self.period_ns {
                self.began_late += 1;
            }
        }
    }

    /// How late the cycles began, ns.
    pub fn started(&self) -> Percentiles {
        self.started.percentiles()
    }

    /// How long the cycles' sessions took, ns.
    pub fn work(&self) -> Percentiles {
        self.work.percentiles()
    }

    /// One line for a summary: `20000 cycles of up to 15 sessions, 3 late (2 begun a period
    /// late); start p99 45 µs, max 1.2 ms; one session's tick 11.3 µs`.
    pub fn describe(&self) -> String {
        let st = self.started();
        let ms = |ns: u64| {
            if ns >= 1_000_000 {
                format!("{:.1} ms", ns as f64 / 1e6)
            } else {
                format!("{} µs", ns / 1000)
            }
        };
        format!(
            "{} cycles of up to {} sessions, {} late ({} begun a period late); start p99 {}, \
             max {}; one session's tick {:.1} µs",
            self.cycles,
            self.most_sessions,
            self.late_cycles,
            self.began_late,
            ms(st.p99_ns),
            ms(st.max_ns),
            self.per_session_ns() / 1e3
        )
    }

    /// One session's tick, ns: the cycles' work over the sessions they ticked (0 with none).
    pub fn per_session_ns(&self) -> f64 {
        if self.session_ticks == 0 {
            return 0.0;
        }
        self.work.percentiles().mean_ns * self.cycles as f64 / self.session_ticks as f64
    }
}

/// What a worker reports when it stops.
#[derive(Clone, Debug)]
pub struct WorkerReport {
    /// The real-time scheduling it got.
    pub realtime: RtStatus,
    /// Its cycles.
    pub cycles: CycleStats,
}

/// One worker's loop: asks for real time (`rt`), takes new sessions from `inbox`, ticks every
/// session each cycle, hands ended ones to `finished`; on `stop` it ends every session and
/// returns what real time it got and its cycles.
pub(crate) fn worker(
    inbox: Receiver<Box<Live>>,
    finished: Sender<Box<Live>>,
    period_ns: u64,
    load: Arc<AtomicUsize>,
    stop: Arc<AtomicBool>,
    rt: Option<RtRequest>,
) -> WorkerReport {
    let guard = realtime::enter_if(rt.as_ref());
    realtime::advise_once(&guard.status());
    let cycles = run_worker(inbox, finished, period_ns, load, stop);
    WorkerReport {
        realtime: guard.status(),
        cycles,
    }
}

fn run_worker(
    inbox: Receiver<Box<Live>>,
    finished: Sender<Box<Live>>,
    period_ns: u64,
    load: Arc<AtomicUsize>,
    stop: Arc<AtomicBool>,
) -> CycleStats {
    let mut pacer = Pacer::with_spin(period_ns, SPIN);
    let mut stats = CycleStats::new(period_ns);
    let mut k: u64 = 0;
    let mut roster: Roster<Box<Live>> = Roster::new();
    loop {
        if roster.len() == 0 {
            // Idle: wait for a session without spinning, then start a fresh schedule.
            match inbox.recv_timeout(Duration::from_millis(50)) {
                Ok(l) => roster.admit(l),
                Err(RecvTimeoutError::Timeout) if !stop.load(Ordering::Relaxed) => continue,
                Err(_) => return stats,
            }
            pacer = Pacer::with_spin(period_ns, SPIN);
            k = 0;
        }
        while let Ok(l) = inbox.try_recv() {
            roster.admit(l);
        }
        let stopping = stop.load(Ordering::Relaxed);
        let late = pacer.wait_for(k);
        let began = Instant::now();
        let n = roster.len();
        let ended = roster.cycle(k, &pacer, stopping);
        stats.record(n, late.max(0) as u64, began.elapsed().as_nanos() as u64);
        for l in ended {
            load.fetch_sub(1, Ordering::Relaxed);
            if finished.send(l).is_err() {
                return stats;
            }
        }
        k += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;
    use std::rc::Rc;

    /// A session that logs (its id, the cycle) at each tick and ends after `ticks` of them or
    /// when asked.
    struct Fake {
        id: u32,
        ticks: u32,
        ran: u32,
        end: std::cell::Cell<bool>,
        log: Rc<RefCell<Vec<(u32, u64)>>>,
    }

    impl Ticked for Fake {
        fn cycle(&mut self, k: u64, _pacer: &Pacer) {
            if self.ended() {
                return;
            }
            self.log.borrow_mut().push((self.id, k));
            self.ran += 1;
        }
        fn ended(&self) -> bool {
            self.end.get() || self.ran >= self.ticks
        }
        fn request_end(&self) {
            self.end.set(true);
        }
    }

    fn fake(id: u32, ticks: u32, log: &Rc<RefCell<Vec<(u32, u64)>>>) -> Fake {
        Fake {
            id,
            ticks,
            ran: 0,
            end: std::cell::Cell::new(false),
            log: log.clone(),
        }
    }

    #[test]
    fn every_session_ticks_once_a_cycle_in_the_order_it_came_and_ended_ones_leave_in_order() {
        let log = Rc::new(RefCell::new(Vec::new()));
        let pacer = Pacer::with_spin(1_000_000, Duration::ZERO);
        let mut r = Roster::new();
        r.admit(fake(1, 3, &log));
        r.admit(fake(2, 1, &log));
        r.admit(fake(3, 2, &log));
        let ids = |v: Vec<Fake>| v.iter().map(|f| f.id).collect::<Vec<_>>();
        assert_eq!(ids(r.cycle(0, &pacer, false)), vec![2]);
        // A session admitted between cycles ticks from the next one, after those held.
        r.admit(fake(4, 5, &log));
        assert_eq!(ids(r.cycle(1, &pacer, false)), vec![3]);
        assert_eq!(ids(r.cycle(2, &pacer, false)), vec![1]);
        assert_eq!(r.len(), 1);
        assert_eq!(
            *log.borrow(),
            vec![
                (1, 0),
                (2, 0),
                (3, 0),
                (1, 1),
                (3, 1),
                (4, 1),
                (1, 2),
                (4, 2)
            ]
        );
        // Stopping: the session is asked to end and leaves at that cycle without a tick.
        assert_eq!(ids(r.cycle(3, &pacer, true)), vec![4]);
        assert_eq!(r.len(), 0);
        assert_eq!(log.borrow().len(), 8);
    }

    #[test]
    fn a_cycle_is_late_when_its_start_and_its_work_pass_the_period() {
        let mut s = CycleStats::new(1_000_000);
        s.record(10, 100_000, 300_000); // on time
        s.record(10, 800_000, 200_000); // exactly at the deadline: on time
        s.record(10, 800_000, 200_001); // 1 ns over: late, begun in time
        s.record(10, 1_000_000, 100_000); // begun a period late
        s.record(20, 0, 1_500_000); // too much work
        assert_eq!((s.cycles, s.late_cycles, s.began_late), (5, 3, 1));
        assert_eq!((s.most_sessions, s.session_ticks), (20, 60));
        // Work 2.300001 ms over 60 session ticks in 5 cycles.
        let want = (300_000.0 + 200_000.0 + 200_001.0 + 100_000.0 + 1_500_000.0) / 60.0;
        assert!(
            (s.per_session_ns() - want).abs() < 1e-6,
            "{}",
            s.per_session_ns()
        );
        assert_eq!(s.work().max_ns, 1_500_000);
        assert_eq!(s.started().max_ns, 1_000_000);
        assert_eq!(CycleStats::new(1).per_session_ns(), 0.0);
        assert_eq!(
            s.describe(),
            "5 cycles of up to 20 sessions, 3 late (1 begun a period late); start p99 999 µs, \
             max 1.0 ms; one session's tick 38.3 µs"
        );
    }
}
