//! The one runner: a haptic loop, a device source, a pacing policy and a list of sinks.
//!
//! ```text
//! device source ──sample──▶ HapticLoop::tick ──TickView──▶ sinks
//!  (script, hand, replay,     (fixed dt, clamp,            (MCAP recorder, per-tick arrays,
//!   UDP bridge, Python)        stiffness cap, watchdog)     replay verifier, frames, live view)
//! ```
//!
//! Every way a session is driven goes through [`TickEngine::cycle`], the one way time advances,
//! under one of the clocks of [`crate::clock`]: from a device by [`Runner::run`] (`nanohaptics
//! run`, `replay --verify`, `render`, `demo`, a bridged `play`, the closed-loop checks), by a
//! live page session's own step (`play`, a classroom student, on a shared worker's clock), or
//! one tick per call by `haptic_loop::stepper::Stepper` (Python's `Session`). A sink sees each
//! tick once, after the force was sent to the device, and must not block: the recorder and the
//! live view hand their data to threads of their own.
//!
//! Adding a sink is one new file implementing [`Sink`](crate::sink::Sink) and one line where the
//! session builds its list of sinks (`haptic_loop::sinks`).

use crate::clock::{self, TickClock};
use crate::haptic::HapticLoop;
use crate::header::SessionHeader;
use crate::pacing::{Pacing, TickStats};
use crate::realtime::{self, RtRequest, RtStatus};
use crate::sink::{SessionInfo, Sink, SinkError, TickView};
use crate::timing::{DurationHistogram, Percentiles};
use haptic_types::DeviceError;
use haptic_types::HapticDevice;
use haptic_types::TickTime;
use haptic_types::switch::{Switch, SwitchError};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The device failed.
    #[error("device: {0}")]
    Device(#[from] DeviceError),
    /// A sink failed.
    #[error(transparent)]
    Sink(#[from] SinkError),
    /// A scheduled switch could not be applied.
    #[error("tick {tick}: {error}")]
    Switch {
        /// The tick it was due at.
        tick: u64,
        /// Why the world refused it.
        error: SwitchError,
    },
}

/// How a run ended; written (serde, [`EndReason::name`]) as `completed`, `device_ended` or
/// `stopped`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EndReason {
    /// The planned number of ticks ran.
    Completed,
    /// The device ended the session (a bridged device said goodbye).
    DeviceEnded,
    /// The stop flag was raised (Ctrl-C, Python interrupt, the page's End button).
    Stopped,
}

impl EndReason {
    /// The one spelling of the reason, in summaries, reports and the page: `completed`,
    /// `device_ended` or `stopped`.
    pub fn name(self) -> &'static str {
        match self {
            EndReason::Completed => "completed",
            EndReason::DeviceEnded => "device_ended",
            EndReason::Stopped => "stopped",
        }
    }
}

/// What a live session does before each tick's step (see [`Runner::with_live`]): called with
/// the tick's index and the loop.
pub type LiveHook<'a> = dyn FnMut(u64, &mut HapticLoop) + 'a;

/// What one [`TickEngine::cycle`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cycle {
    /// A tick ran.
    Ticked,
    /// The device ended the session (a bridged device said goodbye); no tick ran.
    DeviceEnded,
}

/// The one way a session's time advances: cycle by cycle ([`TickEngine::cycle`]), the clock's
/// wait, the device's sample, the scheduled switches, the live hook, the loop's tick, the
/// deadline flag, the force to the device and the hand-off to the sinks, with the run's
/// statistics. [`Runner::run`] loops over it; a live page session steps it once per cycle of
/// its worker.
pub struct TickEngine {
    switches: Vec<(u64, Switch)>,
    compute: DurationHistogram,
    jitter: DurationHistogram,
    sink_ns: Vec<DurationHistogram>,
    missed: u64,
    ticks: u64,
    started: Instant,
    wakeup: Percentiles,
    realtime: RtStatus,
}

impl TickEngine {
    /// An engine applying `switches` (tick, switch) before their ticks' steps (sorted by tick;
    /// several at one tick apply in the given order).
    pub fn new(mut switches: Vec<(u64, Switch)>) -> Self {
        switches.sort_by_key(|(t, _)| *t);
        TickEngine {
            switches,
            compute: DurationHistogram::new(),
            jitter: DurationHistogram::new(),
            sink_ns: Vec::new(),
            missed: 0,
            ticks: 0,
            started: Instant::now(),
            wakeup: Percentiles::default(),
            realtime: RtStatus::default(),
        }
    }

    /// Starts a run of `ticks` ticks (`None`: open-ended) of `lp`: calls every sink's `start`
    /// with `header` and resets the statistics.
    pub fn start(
        &mut self,
        sinks: &mut [&mut dyn Sink],
        lp: &HapticLoop,
        header: &SessionHeader,
        ticks: Option<u64>,
    ) -> Result<(), RunError> {
        let info = SessionInfo {
            header,
            config: lp.config(),
            ticks,
        };
        for s in sinks.iter_mut() {
            s.start(&info, lp)?;
        }
        // Constant memory whatever the session's length (a soak runs for hours).
        self.compute = DurationHistogram::new();
        self.jitter = DurationHistogram::new();
        self.sink_ns = vec![DurationHistogram::new(); sinks.len()];
        self.missed = 0;
        self.ticks = 0;
        self.started = Instant::now();
        self.wakeup = Percentiles::default();
        self.realtime = RtStatus::default();
        Ok(())
    }

    /// What the pacing measured and got, for the run's statistics: the tick thread's wake-up
    /// latency and its real-time scheduling.
    pub fn set_pacing_report(&mut self, wakeup: Percentiles, realtime: RtStatus) {
        self.wakeup = wakeup;
        self.realtime = realtime;
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Ticks so far whose force came too late (zero force was sent).
    pub fn missed(&self) -> u64 {
        self.missed
    }

    /// One whole cycle of the session: waits for tick `n`'s start under `clock`, reads the
    /// device's sample for it, applies tick `n`'s scheduled switches and then `live`, steps the
    /// loop, replaces the force by zero when `clock` says the deadline passed, hands the
    /// command (with the local model, for a protocol-2 device) to `dev` and then the tick to
    /// every sink. The one way a session's time advances, whoever drives it and whatever the
    /// clock ([`crate::clock`]).
    pub fn cycle(
        &mut self,
        sinks: &mut [&mut dyn Sink],
        lp: &mut HapticLoop,
        dev: &mut dyn HapticDevice,
        clock: &mut dyn TickClock,
        live: Option<&mut LiveHook<'_>>,
    ) -> Result<Cycle, RunError> {
        let n = self.ticks;
        let waited = clock.wait(n);
        let sample = match dev.sample(TickTime::new(n, lp.config().rate_hz)) {
            Ok(s) => s,
            Err(DeviceError::Ended) => return Ok(Cycle::DeviceEnded),
            Err(e) => return Err(e.into()),
        };
        // The tick starts when its sample is in hand (for a device clock, when it arrived).
        let t0 = Instant::now();
        let late_ns = clock.started(n, t0, waited);
        let recorded_missed = clock.recorded_missed(n);
        let due = self.switches.partition_point(|(t, _)| *t < n);
        for (_, sw) in self.switches[due..].iter().take_while(|(t, _)| *t == n) {
            lp.switch(&sw.name, sw.value)
                .map_err(|error| RunError::Switch { tick: n, error })?;
        }
        if let Some(hook) = live {
            hook(n, lp);
        }
        lp.tick(sample, recorded_missed);
        let missed = recorded_missed || clock.deadline_passed(n, t0);
        if missed && !recorded_missed {
            lp.mark_deadline_missed();
        }
        if dev.wants_local_model() {
            dev.set_local_model(lp.local_model(dev.local_model_version()));
        }
        dev.set_force(&lp.command(sample.seq))?;
        let compute_ns = t0.elapsed().as_nanos() as u64;
        self.missed += u64::from(missed);
        let view = TickView {
            sample,
            deadline_missed: missed,
            result: lp.last_result(),
            lp,
            start_late_ns: late_ns,
            compute_ns,
        };
        for (s, times) in sinks.iter_mut().zip(self.sink_ns.iter_mut()) {
            let t = Instant::now();
            s.tick(&view)?;
            times.record(t.elapsed().as_nanos() as u64);
        }
        // The hand-off to the sinks belongs to the tick's cost.
        self.compute.record(t0.elapsed().as_nanos() as u64);
        if clock.timed() && n > 0 {
            self.jitter.record(late_ns.unsigned_abs());
        }
        self.ticks += 1;
        Ok(Cycle::Ticked)
    }

    /// Ends the run: the statistics, handed with the device's link counters to every sink's
    /// `finish`.
    pub fn finish(
        &mut self,
        sinks: &mut [&mut dyn Sink],
        link: &[(&'static str, u64)],
    ) -> Result<TickStats, RunError> {
        let stats = TickStats {
            ticks: self.ticks,
            compute: self.compute.percentiles(),
            jitter: self.jitter.percentiles(),
            missed: self.missed,
            wakeup: self.wakeup,
            realtime: self.realtime,
            wall_s: self.started.elapsed().as_secs_f64(),
        };
        for s in sinks.iter_mut() {
            s.finish(&stats, link)?;
        }
        Ok(stats)
    }

    /// How long each sink took per tick (the servo tick pays for it), with the sinks' names.
    pub fn sink_times(&self, sinks: &[&mut dyn Sink]) -> Vec<SinkTime> {
        sinks
            .iter()
            .zip(&self.sink_ns)
            .map(|(s, t)| SinkTime {
                sink: s.name(),
                tick: t.percentiles(),
            })
            .collect()
    }
}

/// Runs ticks of a loop against a device and hands each to the sinks.
pub struct Runner<'s> {
    sinks: Vec<&'s mut dyn Sink>,
    stop: Option<&'s AtomicBool>,
    engine: TickEngine,
    live: Option<&'s mut LiveHook<'s>>,
    rt: Option<RtRequest>,
}

/// Time each sink took per tick (its `tick` call), ns.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SinkTime {
    /// The sink's name.
    pub sink: &'static str,
    /// Percentiles of its per-tick time, ns.
    pub tick: Percentiles,
}

impl<'s> Runner<'s> {
    /// A runner handing ticks to `sinks`, in order.
    pub fn new(sinks: Vec<&'s mut dyn Sink>) -> Self {
        Runner {
            sinks,
            stop: None,
            engine: TickEngine::new(Vec::new()),
            live: None,
            rt: Some(RtRequest::default()),
        }
    }

    /// The real-time scheduling the tick thread asks for in a wall-clock or device-clock run
    /// (default: [`RtRequest::default`], `SCHED_FIFO` 50 with memory locked and a core of its
    /// own); `None` asks for nothing (`--no-rt`). A refusal is said once per process on standard
    /// error, with its fix, and the run goes on at normal priority; the statistics say what was
    /// granted. Batch and replay runs never ask.
    pub fn with_realtime(mut self, rt: Option<RtRequest>) -> Self {
        self.rt = rt;
        self
    }

    /// Sets switches at given ticks (tick, switch): each is applied just before its tick's
    /// step (a script's `[[switch]]` entries, or a recording's `/scene/switch` on replay).
    /// Several at one tick apply in the given order.
    pub fn with_switches(mut self, switches: Vec<(u64, Switch)>) -> Self {
        self.engine = TickEngine::new(switches);
        self
    }

    /// Calls `hook(tick, loop)` before each tick's step, after that tick's scheduled switches:
    /// a live session applies there what arrived since the last tick (a menu's switches, through
    /// [`HapticLoop::switch`], which records them as the tick's input on `/scene/switch`, so a
    /// replay applies them, as scheduled switches, on the same tick).
    pub fn with_live(mut self, hook: &'s mut LiveHook<'s>) -> Self {
        self.live = Some(hook);
        self
    }

    /// Stops the run cleanly (after the current tick) when `flag` becomes true.
    pub fn stop_on(mut self, flag: &'s AtomicBool) -> Self {
        self.stop = Some(flag);
        self
    }

    /// Runs `ticks` ticks (`None`: until the device ends the session) of `lp` with `dev`
    /// (opened by the caller); `progress` is called every 100 ticks with (done, planned or 0).
    /// The sinks' `start` is called first and their `finish` last (also when the run stops).
    pub fn run(
        &mut self,
        lp: &mut HapticLoop,
        dev: &mut dyn HapticDevice,
        header: &SessionHeader,
        ticks: Option<u64>,
        pacing: Pacing,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(TickStats, EndReason), RunError> {
        let timed = !matches!(pacing, Pacing::Batch | Pacing::Recorded(_));
        self.engine.start(&mut self.sinks, lp, header, ticks)?;
        let period_ns = lp.config().period_ns();
        // The tick thread in real time for the run (the sinks' threads, started above, and any
        // it starts later stay at normal priority); back as it was when the guard drops.
        let rt = realtime::enter_if(self.rt.as_ref().filter(|_| timed));
        realtime::advise_once(&rt.status());
        let mut clock = clock::for_pacing(pacing, period_ns, &rt.status());
        let mut end = EndReason::Completed;
        let mut n = 0u64;
        while ticks.is_none_or(|t| n < t) {
            if self.stop.is_some_and(|f| f.load(Ordering::Relaxed)) {
                end = EndReason::Stopped;
                break;
            }
            let step = self.engine.cycle(
                &mut self.sinks,
                lp,
                dev,
                clock.as_mut(),
                self.live.as_deref_mut(),
            )?;
            if step == Cycle::DeviceEnded {
                end = EndReason::DeviceEnded;
                break;
            }
            n += 1;
            if n % 100 == 0 || ticks == Some(n) {
                progress(n, ticks.unwrap_or(0));
            }
        }
        let link = dev.link_counters();
        self.engine.set_pacing_report(clock.wakeups(), rt.status());
        let stats = self.engine.finish(&mut self.sinks, &link)?;
        Ok((stats, end))
    }

    /// How long each sink took per tick in the last run (the servo tick pays for it).
    pub fn sink_times(&self) -> Vec<SinkTime> {
        self.engine.sink_times(&self.sinks)
    }
}
