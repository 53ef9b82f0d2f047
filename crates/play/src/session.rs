//! One live session of the game, whatever front end holds it: `play` (the page or a bridged
//! device as the hand, on its own thread), a classroom student (their page as the hand, ticked
//! by a shared worker) and a classroom device (bridged, on its own thread).
//!
//! [`PageSession::open`] sets the world up and tells the pages what is played;
//! [`PageSession::step`] is one cycle under any clock (it starts the session — the publisher,
//! the sinks — when its hand is there, applies the switches the pages asked for, ticks through
//! the engine's one step, and says when the session ended); [`PageSession::run`] steps it on
//! its own thread until the end; [`PageSession::finish`] closes the recording, tells the pages
//! the end and returns the one [`SessionSummary`].

use crate::input::PageDevice;
use crate::protocol::{EndReport, Hello, LatencyMs, Mapping, ServerMsg, SwitchInfo, TickWorkMs};
use crate::publish::{self, PlaySink, PublishSummary, ToPublisher};
use crate::server::{SceneLink, Shared};
use haptic_devices::bridge::UdpDevice;
use haptic_devices::source::DeviceSource;
use haptic_engine::HapticLoop;
use haptic_engine::clock::{self, TickClock};
use haptic_engine::header::SessionHeader;
use haptic_engine::pacing::{Pacing, TickStats};
use haptic_engine::realtime::{self, RtRequest};
use haptic_engine::runner::{Cycle, EndReason, TickEngine};
use haptic_engine::timing::Percentiles;
use haptic_loop::session::{SceneSource, SessionError};
use haptic_loop::setup::{Setup, SetupOptions};
use haptic_loop::sinks::SessionSinks;
use haptic_types::{DeviceSpecs, HapticDevice};
use recording::WriteSummary;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::thread::JoinHandle;

/// The hand of a session: the page, or a device bridged over UDP (opened: its hello arrived).
pub enum Hand {
    /// The page's pointer, keyboard or gamepad ([`PageDevice`]).
    Page(PageDevice),
    /// A device in another process over the UDP bridge.
    Bridged(Box<UdpDevice>),
}

impl Hand {
    /// Opens the hand of a session: a bridged device (made for the session by
    /// `haptic_loop::setup::session_device`: its hello is awaited here), or the page with the
    /// scene's device model.
    pub fn open(device: DeviceSource, shared: &Shared) -> Result<Hand, SessionError> {
        Ok(match device {
            DeviceSource::Udp(b) => {
                let mut dev = UdpDevice::new(b);
                dev.open().map_err(SessionError::Device)?;
                Hand::Bridged(Box::new(dev))
            }
            DeviceSource::Model(m) => {
                Hand::Page(PageDevice::new(m.specs().clone(), shared.input.clone()))
            }
        })
    }

    fn device(&mut self) -> &mut dyn HapticDevice {
        match self {
            Hand::Page(d) => d,
            Hand::Bridged(d) => d.as_mut(),
        }
    }

    fn device_ref(&self) -> &dyn HapticDevice {
        match self {
            Hand::Page(d) => d,
            Hand::Bridged(d) => d.as_ref(),
        }
    }

    /// Whether the page is the hand (it must press Start before the first tick).
    pub fn is_page(&self) -> bool {
        matches!(self, Hand::Page(_))
    }
}

/// What a session is set up from.
pub struct SessionSpec<'a> {
    /// The scene.
    pub scene: &'a SceneSource,
    /// The scene's name, as the pages show it.
    pub scene_name: &'a str,
    /// The recording, MCAP.
    pub out: PathBuf,
    /// Where the pages download the recording once the session ended (`/recording.mcap`,
    /// with the student's token in a class).
    pub recording_url: String,
    /// The session's start time, ns since the Unix epoch (the recording's and a bridged
    /// device's welcome's).
    pub start_time_ns: u64,
    /// Who operates it, as the recording names it.
    pub operator: String,
    /// The device's link, as the recording names it (`page`, `udp:…`).
    pub link: String,
    /// Session length, s, as the pages show it (`None`: open-ended).
    pub seconds: Option<f64>,
    /// Ticks to run (`None`: until the player, the teacher or the device ends it).
    pub ticks: Option<u64>,
}

/// Where a session is, for its [`Reporter`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Ticks run.
    pub ticks: u64,
    /// Missed deadlines.
    pub missed: u64,
    /// The session's last report (at its finish, off the tick thread): it must not be skipped.
    pub last: bool,
}

/// Called every few ticks ([`PageSession::with_reporter`]) on the tick thread, and once at the
/// finish, with where the session is and the loop: what a teacher page shows of a student.
pub type Reporter = Box<dyn FnMut(&Progress, &HapticLoop) + Send>;

/// Called after every tick with the loop ([`PageSession::with_watcher`]); `true` completes the
/// session (a lesson step's condition met).
pub type Watcher = Box<dyn FnMut(&HapticLoop) -> bool + Send>;

/// What one [`PageSession::step`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// The page has not pressed Start yet: nothing ran.
    Waiting,
    /// A tick ran.
    Ticked,
    /// The session ended (now or before): [`PageSession::finish`] it.
    Ended,
}

/// What a live session produced: the one summary `play` and the classroom both wrap.
#[derive(Clone, Debug, Default)]
pub struct SessionSummary {
    /// How it ended: `completed` (its length ran), `stopped` (the player, the teacher or the
    /// program ended it), `device_ended` (a bridged device said goodbye); the words of
    /// [`EndReason::name`].
    pub end: &'static str,
    /// Tick statistics (ticks, missed deadlines, tick work, real time granted).
    pub stats: TickStats,
    /// The scene's state after the last tick (name, value): the score and its parts.
    pub state: Vec<(String, f64)>,
    /// The recording.
    pub recording: PathBuf,
    /// What the recorder wrote.
    pub written: Option<WriteSummary>,
    /// Page input to the force of the first tick that used it, ms (page hand only).
    pub input_latency_ms: Option<LatencyMs>,
    /// What the pages were sent.
    pub published: PublishSummary,
    /// A failure that ended the session early, if any.
    pub error: Option<String>,
}

impl SessionSummary {
    /// The value of state field `name` after the last tick.
    pub fn state(&self, name: &str) -> Option<f64> {
        self.state.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }
}

/// One live session: its world, hand, sinks, the pages' publisher and its end report.
pub struct PageSession {
    shared: Arc<Shared>,
    lp: HapticLoop,
    header: SessionHeader,
    sinks: SessionSinks,
    hand: Hand,
    engine: TickEngine,
    play_sink: Option<PlaySink>,
    tx: Option<Sender<ToPublisher>>,
    publisher: Option<JoinHandle<PublishSummary>>,
    ticks: Option<u64>,
    out: PathBuf,
    recording_url: String,
    started: bool,
    end: Option<EndReason>,
    error: Option<String>,
    reporter: Option<(u64, Reporter)>,
    watcher: Option<Watcher>,
    sound_block_ticks: u64,
}

impl PageSession {
    /// Sets the session up for `hand` (the scene, its world, the header and the sinks, the
    /// recording opened) and tells the server and every page of `shared` what is played.
    pub fn open(
        spec: &SessionSpec<'_>,
        hand: Hand,
        shared: Arc<Shared>,
    ) -> Result<PageSession, SessionError> {
        Self::open_with_switches(spec, hand, shared, &[])
    }

    /// [`PageSession::open`] with `switches` (name, value) set on the world before its first
    /// tick: recorded as that tick's switches (so a replay sets them too) and shown in the
    /// pages' menu from the start. A lesson step's switches.
    pub fn open_with_switches(
        spec: &SessionSpec<'_>,
        hand: Hand,
        shared: Arc<Shared>,
        switches: &[(&str, f64)],
    ) -> Result<PageSession, SessionError> {
        let specs = hand.device_ref().specs().clone();
        let Setup {
            mut lp,
            header,
            sinks,
        } = Setup::new(&SetupOptions {
            operator: Some(spec.operator.clone()),
            keep_arrays: false,
            out: Some(spec.out.clone()),
            start_time_ns: Some(spec.start_time_ns),
            ..SetupOptions::new(spec.scene, specs.clone(), "realtime", &spec.link)
        })?;
        for (name, value) in switches {
            lp.switch(name, *value)
                .map_err(|error| SessionError::Switch { tick: 0, error })?;
        }
        announce(
            &shared,
            spec.scene_name,
            &lp,
            &specs,
            hand.is_page(),
            spec.seconds,
        );
        Ok(PageSession {
            shared,
            lp,
            header,
            sinks,
            hand,
            engine: TickEngine::new(Vec::new()),
            play_sink: None,
            tx: None,
            publisher: None,
            ticks: spec.ticks,
            out: spec.out.clone(),
            recording_url: spec.recording_url.clone(),
            started: false,
            end: None,
            error: None,
            reporter: None,
            watcher: None,
            sound_block_ticks: publish::SOUND_BLOCK_TICKS,
        })
    }

    /// Calls `reporter` after every `every` ticks, and once more at the end.
    pub fn with_reporter(mut self, every: u64, reporter: Reporter) -> Self {
        self.reporter = Some((every.max(1), reporter));
        self
    }

    /// Calls `watcher` after every tick; the session completes (ends as `completed`) after the
    /// tick on which it returns `true`.
    pub fn with_watcher(mut self, watcher: Watcher) -> Self {
        self.watcher = Some(watcher);
        self
    }

    /// Hands the pages' sound ticks over every `ticks` ticks when nothing sounds (default
    /// [`publish::SOUND_BLOCK_TICKS`]).
    pub fn with_sound_block(mut self, ticks: u64) -> Self {
        self.sound_block_ticks = ticks.max(1);
        self
    }

    /// The session's link to its pages.
    pub fn shared(&self) -> &Arc<Shared> {
        &self.shared
    }

    /// Whether it ended ([`PageSession::finish`] it).
    pub fn ended(&self) -> bool {
        self.end.is_some()
    }

    /// Ends it at its next step (the player, the teacher or the program stops it).
    pub fn request_end(&self) {
        self.shared.end_requested.store(true, Ordering::Relaxed);
    }

    /// Whether its next step begins it or has begun it: its hand is there (a page's first
    /// input; a bridged device at once), or its end was asked for, or it has begun.
    pub fn ready(&self) -> bool {
        self.started
            || self.end.is_some()
            || self.shared.end_requested.load(Ordering::Relaxed)
            || !self.hand.is_page()
            || self.shared.input.latest().1.is_some()
    }

    /// Begins it now when it is [`PageSession::ready`] and has not begun: the pages' publisher
    /// and the recording's start (a thread each and a file), which a shared tick worker should
    /// not wait for. Its first step then runs its first tick. Nothing else changes: the same
    /// recording, the same ticks.
    pub fn begin(&mut self) {
        if !self.started && self.end.is_none() && self.ready() {
            self.start();
        }
    }

    /// Starts the session: the pages' publisher, the sinks (the recording's start).
    fn start(&mut self) {
        let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
        let sh = self.shared.clone();
        let rate = self.lp.config().rate_hz;
        let fields = self.lp.scene().state_fields();
        let prox = haptic_loop::sound::proximity_on_distance_m(self.lp.scene().kind())
            .filter(|_| fields.iter().any(|f| f == "nearest_m"));
        match std::thread::Builder::new()
            .name("play-publish".into())
            .spawn(move || publish::run_publisher(rx, sh, rate, fields, prox))
        {
            Ok(h) => self.publisher = Some(h),
            Err(e) => self.fail(format!("cannot start the pages' publisher: {e}")),
        }
        self.play_sink = Some(
            PlaySink::new(tx.clone(), self.shared.clone()).with_block_ticks(self.sound_block_ticks),
        );
        self.tx = Some(tx);
        self.started = true;
        let mut list = self.sinks.list();
        if let Some(p) = self.play_sink.as_mut() {
            list.push(p);
        }
        let r = self
            .engine
            .start(&mut list, &self.lp, &self.header, self.ticks);
        drop(list);
        if let Err(e) = r {
            self.fail(SessionError::from(e).to_string());
        }
    }

    fn fail(&mut self, message: String) {
        self.error.get_or_insert(message);
        self.end.get_or_insert(EndReason::Stopped);
    }

    /// One cycle of the session under `clock`: starts it once its hand is there (a page's
    /// Start; a bridged device at once), ends it when its ticks ran, when the end was asked
    /// for or when the device said goodbye, and otherwise runs one tick — the pages' switches
    /// applied before it — through the engine's one step.
    pub fn step(&mut self, clock: &mut dyn TickClock) -> Step {
        if self.end.is_some() {
            return Step::Ended;
        }
        let end_asked = self.shared.end_requested.load(Ordering::Relaxed);
        if !self.started {
            if !end_asked && self.hand.is_page() && self.shared.input.latest().1.is_none() {
                return Step::Waiting;
            }
            // Ended before it began: an empty recording, complete and verifiable.
            self.start();
        }
        if self.end.is_some() {
            return Step::Ended;
        }
        let n = self.engine.ticks();
        if self.ticks.is_some_and(|t| n >= t) {
            self.end = Some(EndReason::Completed);
            return Step::Ended;
        }
        if end_asked {
            self.end = Some(EndReason::Stopped);
            return Step::Ended;
        }
        let (shared, tx) = (&self.shared, self.tx.as_ref());
        let mut hook = |tick: u64, lp: &mut HapticLoop| {
            if let Some(tx) = tx {
                apply_page_switches(shared, tx, tick, lp);
            }
        };
        let mut list = self.sinks.list();
        if let Some(p) = self.play_sink.as_mut() {
            list.push(p);
        }
        let r = self.engine.cycle(
            &mut list,
            &mut self.lp,
            self.hand.device(),
            clock,
            Some(&mut hook),
        );
        drop(list);
        match r {
            Ok(Cycle::Ticked) => {}
            Ok(Cycle::DeviceEnded) => {
                self.end = Some(EndReason::DeviceEnded);
                return Step::Ended;
            }
            Err(e) => {
                self.fail(SessionError::from(e).to_string());
                return Step::Ended;
            }
        }
        if let Some((every, report)) = self.reporter.as_mut()
            && n % *every == 0
        {
            let p = Progress {
                ticks: n + 1,
                missed: self.engine.missed(),
                last: false,
            };
            report(&p, &self.lp);
        }
        if let Some(watch) = self.watcher.as_mut()
            && watch(&self.lp)
        {
            self.end = Some(EndReason::Completed);
        }
        Step::Ticked
    }

    /// Steps the session on this thread until it ends or `stop` is raised, paced by `pacing`
    /// (the wall clock for a page, the device's clock for a bridged device), the thread in
    /// real time as `rt` asks; what real time it got goes to the statistics.
    pub fn run(&mut self, pacing: Pacing, rt: Option<&RtRequest>, stop: &AtomicBool) {
        let timed = !matches!(pacing, Pacing::Batch | Pacing::Recorded(_));
        let guard = realtime::enter_if(rt.filter(|_| timed));
        realtime::advise_once(&guard.status());
        let mut clock = clock::for_pacing(pacing, self.lp.config().period_ns(), &guard.status());
        loop {
            if stop.load(Ordering::Relaxed) {
                self.request_end();
            }
            if self.step(clock.as_mut()) == Step::Ended {
                break;
            }
        }
        self.engine
            .set_pacing_report(clock.wakeups(), guard.status());
    }

    /// Closes the session: the statistics, the recording's end, the device's release, the
    /// publisher's last frame, and the end screen with the recording's download for its pages.
    pub fn finish(mut self) -> SessionSummary {
        if !self.started {
            self.start();
        }
        let end = self.end.unwrap_or(EndReason::Stopped);
        let ticks = self.engine.ticks();
        if let Some((_, report)) = self.reporter.as_mut() {
            let p = Progress {
                ticks,
                missed: self.engine.missed(),
                last: true,
            };
            report(&p, &self.lp);
        }
        let link = self.hand.device_ref().link_counters();
        let mut list = self.sinks.list();
        if let Some(p) = self.play_sink.as_mut() {
            list.push(p);
        }
        let stats = self.engine.finish(&mut list, &link);
        drop(list);
        let latencies = self
            .play_sink
            .take()
            .map(|mut p| std::mem::take(&mut p.input_latency_ms))
            .unwrap_or_default();
        self.tx = None;
        let closed = self.hand.device().close();
        let published = self
            .publisher
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        let written = self.sinks.written();
        let input_latency_ms = LatencyMs::of(&latencies);
        let (stats, failed) = match stats {
            Ok(s) => (s, None),
            Err(e) => (
                TickStats::default(),
                Some(SessionError::from(e).to_string()),
            ),
        };
        let error = self
            .error
            .take()
            .or(failed)
            .or(closed.err().map(|e| SessionError::Device(e).to_string()));
        let rate = self.lp.config().rate_hz;
        let end_msg = end_message(
            &self.recording_url,
            &self.out,
            end,
            &stats,
            rate,
            &self.sinks.totals,
            input_latency_ms,
            written.as_ref(),
        );
        offer_end(&self.shared, &self.out, &end_msg);
        SessionSummary {
            end: end.name(),
            stats,
            state: self.sinks.totals.state(),
            recording: self.out.clone(),
            written,
            input_latency_ms,
            published,
            error,
        }
    }
}

/// The page's `hello`: the scene, the device, the view's mapping, the menu of switches with
/// their values now and the state fields.
pub(crate) fn hello_message(
    scene_name: &str,
    lp: &HapticLoop,
    specs: &DeviceSpecs,
    page_is_hand: bool,
    seconds: Option<f64>,
) -> ServerMsg {
    let scene = lp.scene();
    let config = lp.config();
    ServerMsg::Hello(Hello {
        scene: scene_name.to_string(),
        kind: scene.kind().to_string(),
        rate_hz: config.rate_hz,
        device: specs.name.to_string(),
        workspace_radius_m: specs.workspace_radius_m,
        max_force_n: specs.limits.max_force_n,
        buttons: specs
            .button_strs()
            .into_iter()
            .map(str::to_string)
            .collect(),
        page_is_hand,
        display_scale: config.display_scale,
        mapping: Mapping {
            origin_m: config.mapping.origin_m,
            workspace_scale: config.mapping.workspace_scale,
        },
        switches: scene
            .switches()
            .iter()
            .map(|s| SwitchInfo {
                name: s.name.to_string(),
                min: s.min,
                max: s.max,
                boolean: s.boolean,
                doc: s.doc.to_string(),
                value: scene.switch_value(s.name),
            })
            .collect(),
        state_fields: scene.state_fields(),
        seconds,
    })
}

/// Tells the server and every page what is played: the scene's switches and the device (for
/// checking page messages), and the `hello` (kept for pages that connect later).
fn announce(
    shared: &Shared,
    scene_name: &str,
    lp: &HapticLoop,
    specs: &DeviceSpecs,
    page_is_hand: bool,
    seconds: Option<f64>,
) {
    let scene = lp.scene();
    if let Ok(mut s) = shared.scene.lock() {
        *s = Some(SceneLink {
            switches: scene.switches(),
            kind: scene.kind(),
            workspace_radius_m: specs.workspace_radius_m,
            button_mask: specs.button_mask(),
            page_is_hand,
        });
    }
    let hello = hello_message(scene_name, lp, specs, page_is_hand, seconds).to_json();
    if let Ok(mut h) = shared.hello.lock() {
        *h = Some(hello.clone());
    }
    shared.broadcast(&tungstenite::Message::text(hello));
}

fn stats_ms(p: &Percentiles) -> TickWorkMs {
    TickWorkMs {
        p50_ms: p.p50_ns as f64 * 1e-6,
        p99_ms: p.p99_ns as f64 * 1e-6,
        max_ms: p.max_ns as f64 * 1e-6,
    }
}

/// The page's `end`: the session's figures and where to download its recording (`url`, the
/// file `out`).
#[allow(clippy::too_many_arguments)]
fn end_message(
    url: &str,
    out: &std::path::Path,
    end: EndReason,
    stats: &TickStats,
    rate_hz: u32,
    totals: &haptic_engine::totals::Totals,
    input_latency_ms: Option<LatencyMs>,
    written: Option<&WriteSummary>,
) -> ServerMsg {
    ServerMsg::End(EndReport {
        end,
        ticks: stats.ticks,
        seconds: stats.ticks as f64 / f64::from(rate_hz),
        missed_deadlines: stats.missed,
        tick_work: stats_ms(&stats.compute),
        state: totals
            .state_fields
            .iter()
            .cloned()
            .zip(totals.last_state.iter().copied())
            .collect(),
        peak_device_force_n: totals.peak_device_force_n,
        events: totals.events,
        input_latency_ms,
        recording: url.to_string(),
        recording_file: out.file_name().map(|n| n.to_string_lossy().to_string()),
        recording_bytes: written.map(|w| w.bytes),
    })
}

/// Offers the recording `out` for download and tells every page (and later ones) the end.
fn offer_end(shared: &Shared, out: &std::path::Path, end_msg: &ServerMsg) {
    if let Ok(mut r) = shared.recording.lock() {
        *r = Some(out.to_path_buf());
    }
    let text = end_msg.to_json();
    if let Ok(mut e) = shared.end.lock() {
        *e = Some(text.clone());
    }
    shared.broadcast(&tungstenite::Message::text(text));
}

/// Applies before tick `tick` the switches pages (or a teacher) asked for: each told to the
/// publisher as applied on `tick`, or refused with the reason (to the page that asked).
fn apply_page_switches(shared: &Shared, tx: &Sender<ToPublisher>, tick: u64, lp: &mut HapticLoop) {
    // Never wait for a page's thread: a busy queue waits for the next tick.
    let reqs = match shared.switches.try_lock() {
        Ok(mut q) if !q.is_empty() => std::mem::take(&mut *q),
        _ => return,
    };
    for (page, name, value) in reqs {
        let m = match lp.switch(&name, value) {
            Ok(()) => ToPublisher::Switched { tick, name, value },
            Err(e) => ToPublisher::Refused {
                page,
                message: e.to_string(),
            },
        };
        let _ = tx.send(m);
    }
}
