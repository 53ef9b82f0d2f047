//! # play: the teaching game in a browser
//!
//! `nanohaptics play [SCENE]` serves one page on loopback, HTTP and WebSocket on one port: the
//! world drawn live (Canvas 2D, orbit and zoom), the player's pointer, keyboard or gamepad as
//! the haptic device, the live sound of `render --audio`, the scene's menu of switches, the
//! house task's score and time, and at the end the session's figures and its recording to
//! download. This crate is that server: [`run`] is its one entry point.
//!
//! What it is for:
//!
//! - **The page as a device** ([`input`]): the hand the page sends is sampled at every tick
//!   (zero-order hold) and recorded as the tick's input, so a session replays bit for bit with
//!   `nanohaptics replay --verify`; the loop's watchdog ramps the force to zero when the page
//!   goes away.
//! - **A real device too**: with [`PlayConfig::device`] a device bridged over UDP is the hand
//!   and the pages only watch and listen.
//! - **Live sound** ([`publish`]): the pages synthesise it from each tick's sounds and distance
//!   (sent as binary sound ticks), in an AudioWorklet that runs the same synthesis as
//!   `render --audio --proximity` ([`render::audio::StreamSynth`]) at the page's sample rate.
//! - **The live menu**: the scene's switches, set from a page and applied before the next tick
//!   (through [`haptic_loop::runner::Runner::with_live`]), recorded as switches.
//! - **The protocol** ([`protocol`]): one typed message enum per direction, [`protocol::ServerMsg`]
//!   and [`protocol::PageMsg`], tabled in `docs/play.md`.
//!
//! - **The classroom** ([`classroom`]): one server for a whole class, a session per student
//!   ticked by shared workers, a teacher page, the recordings as one zip.
//! - **Safe to reach** ([`gate`], `webguard`): `Host` and `Origin` checked on every request and
//!   upgrade, limits on connections, message size and rate, every refusal answered and counted.
//!
//! What it is not: it is no general web server (the page's fixed files
//! [`server::PAGE_FILES`], `/ws`, and `/recording.mcap` once the session ended; `play` on
//! loopback only), it has no accounts and no TLS, and it is not the Foxglove live view
//! (`nanohaptics run --live`). The page is plain HTML, CSS and JavaScript modules built into
//! the binary; it needs no npm, no bundler and no network.

pub mod background;
pub mod classroom;
pub mod gate;
pub mod http;
pub mod input;
pub mod protocol;
pub mod publish;
pub mod server;

use gate::{Limits, RefusedCounts};
use haptic_devices::bridge::{BridgeConfig, UdpDevice};
use haptic_devices::pacing::Percentiles;
use haptic_devices::source::DeviceSource;
use haptic_loop::HapticLoop;
use haptic_loop::pacing::{Pacing, TickStats};
use haptic_loop::runner::{EndReason, Runner};
use haptic_loop::session::{SceneSource, SessionError, now_unix_ns, ticks_for};
use haptic_loop::setup::{Setup, SetupOptions, session_device};
use haptic_loop::totals::Totals;
use haptic_types::DeviceSpecs;
use haptic_types::HapticDevice;
use input::PageDevice;
pub use protocol::LatencyMs;
use protocol::{EndReport, Hello, Mapping, ServerMsg, SwitchInfo, TickWorkMs};
use publish::{PlaySink, PublishSummary, ToPublisher};
use recording::WriteSummary;
use server::{SceneLink, Server, Shared};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Default port of the page.
pub const DEFAULT_PORT: u16 = 8080;

/// What to play.
#[derive(Clone, Debug)]
pub struct PlayConfig {
    /// The scene (`SceneSource::resolve("brickworld")` for the built-in brick world).
    pub scene: SceneSource,
    /// Loopback port of the page (0: any free port).
    pub port: u16,
    /// A device over the UDP bridge as the hand (`None`: the page is the hand).
    pub device: Option<BridgeConfig>,
    /// The recording, MCAP.
    pub out: PathBuf,
    /// Session length, s (0 < s ≤ 3600; `None`: until the player ends it on the page or `stop`
    /// is raised).
    pub seconds: Option<f64>,
    /// After the session, keep serving the end screen and the recording's download this long,
    /// s (`None`: until `stop` is raised).
    pub keep_serving_s: Option<f64>,
    /// What the server accepts (connections, message size and rate).
    pub limits: Limits,
    /// The tick thread's real-time scheduling (default `SCHED_FIFO` 50, memory locked, pinned;
    /// the server's, publisher's and pages' threads stay at normal priority); `None`: ask for
    /// nothing (`--no-rt`). What it got is in [`PlaySummary::stats`]`.realtime`.
    pub rt: Option<haptic_devices::realtime::RtRequest>,
}

impl PlayConfig {
    /// The page as the hand on port 8080, until the player ends the session, the end screen
    /// served until `stop`.
    pub fn new(scene: SceneSource, out: PathBuf) -> Self {
        PlayConfig {
            scene,
            port: DEFAULT_PORT,
            device: None,
            out,
            seconds: None,
            keep_serving_s: None,
            limits: Limits::default(),
            rt: Some(haptic_devices::realtime::RtRequest::default()),
        }
    }
}

/// What a play session produced.
#[derive(Debug)]
pub struct PlaySummary {
    /// The page's URL.
    pub url: String,
    /// How it ended: `completed` (its `seconds` ran), `stopped` (the player ended it on the
    /// page, or `stop`), `device_ended` (a bridged device said goodbye); the words of
    /// [`EndReason::name`], as `haptic_loop::session` reports them.
    pub end: &'static str,
    /// Tick statistics (ticks, missed deadlines, tick work).
    pub stats: TickStats,
    /// The scene's state after the last tick (name, value): the score and its parts.
    pub state: Vec<(String, f64)>,
    /// The recording.
    pub recording: PathBuf,
    /// What the recorder wrote.
    pub written: Option<WriteSummary>,
    /// Page input to the force of the first tick that used it, ms (page device only).
    pub input_latency_ms: Option<LatencyMs>,
    /// What the pages were sent.
    pub published: PublishSummary,
    /// Pages connected during the session.
    pub pages_served: u64,
    /// Messages not queued to a page that could not keep up.
    pub messages_dropped: u64,
    /// Page messages refused (protocol and switch errors), each answered with its error.
    pub page_messages_refused: u64,
    /// Requests, connections and messages the server refused, by reason (forged `Host` or
    /// `Origin`, limits).
    pub refused: RefusedCounts,
}

impl PlaySummary {
    /// One line for a person: how it ended, ticks, missed deadlines, score and recording.
    pub fn line(&self) -> String {
        format!(
            "{}: {} ticks, {} missed deadlines, score {}, recording {}; real time: {}",
            self.end,
            self.stats.ticks,
            self.stats.missed,
            self.state("score").unwrap_or(0.0),
            self.recording.display(),
            self.stats.realtime.describe()
        )
    }

    /// The value of state field `name` after the last tick.
    pub fn state(&self, name: &str) -> Option<f64> {
        self.state.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }
}

/// Why a play session failed.
#[derive(Debug, thiserror::Error)]
pub enum PlayError {
    /// The scene, the device, the recording or the session length.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The port could not be served.
    #[error(
        "cannot serve the page on 127.0.0.1:{port}: {message} (choose another with --port, or --port 0 for any free port)"
    )]
    Serve {
        /// The port asked for.
        port: u16,
        /// The OS error.
        message: String,
    },
    /// Stopped before any page pressed Start (nothing was recorded).
    #[error("stopped before a page started the session: nothing was recorded")]
    NotStarted,
}

fn stats_ms(p: &Percentiles) -> TickWorkMs {
    TickWorkMs {
        p50_ms: p.p50_ns as f64 * 1e-6,
        p99_ms: p.p99_ns as f64 * 1e-6,
        max_ms: p.max_ns as f64 * 1e-6,
    }
}

/// The hand of a play session: the page, or a device bridged over UDP.
enum Hand {
    Page(PageDevice),
    Bridged(Box<UdpDevice>),
}

impl Hand {
    /// Opens the hand of a session: a bridged device (`device` made for the session by
    /// [`session_device`]: its hello is awaited here), or the page with the scene's model.
    fn open(device: DeviceSource, shared: &Shared) -> Result<Hand, PlayError> {
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

    fn is_page(&self) -> bool {
        matches!(self, Hand::Page(_))
    }

    /// The link and the operator as the recording names them.
    fn describe(&self, config: &PlayConfig) -> (String, &'static str) {
        match &config.device {
            Some(b) => (format!("udp:{}", b.bind), "person (bridged device)"),
            None => ("page".to_string(), "person (browser page)"),
        }
    }
}

/// The page's `hello`: the scene, the device, the view's mapping, the menu of switches with
/// their values now and the state fields.
fn hello_message(
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
pub(crate) fn announce(
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

/// The page's `end`: the session's figures and where to download its recording (`url`, the
/// file `out`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn end_message(
    url: &str,
    out: &std::path::Path,
    end: EndReason,
    stats: &TickStats,
    rate_hz: u32,
    totals: &Totals,
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
pub(crate) fn offer_end(shared: &Shared, out: &std::path::Path, end_msg: &ServerMsg) {
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
pub(crate) fn apply_page_switches(
    shared: &Shared,
    tx: &std::sync::mpsc::Sender<ToPublisher>,
    tick: u64,
    lp: &mut HapticLoop,
) {
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

/// The hook run before each tick's step: raises the end on `stop`, and applies the switches
/// pages asked for.
fn switch_hook<'a>(
    stop: &'a AtomicBool,
    shared: Arc<Shared>,
    tx: std::sync::mpsc::Sender<ToPublisher>,
) -> impl FnMut(u64, &mut HapticLoop) + 'a {
    move |tick: u64, lp: &mut HapticLoop| {
        if stop.load(Ordering::Relaxed) {
            shared.end_requested.store(true, Ordering::Relaxed);
        }
        apply_page_switches(&shared, &tx, tick, lp);
    }
}

/// A play session running on its own thread (see [`start`]).
pub struct Running {
    /// The page's URL.
    pub url: String,
    /// The session's thread; joins with what [`run`] returned.
    pub handle: std::thread::JoinHandle<Result<PlaySummary, PlayError>>,
}

/// Runs [`run`] on its own thread and returns as soon as the page is served, with its URL;
/// raise `stop` to end it. A session that fails before serving (a busy port, a bad scene)
/// returns its error here.
pub fn start(config: PlayConfig, stop: Arc<AtomicBool>) -> Result<Running, PlayError> {
    let (tx, rx) = std::sync::mpsc::channel();
    let port = config.port;
    let handle = std::thread::Builder::new()
        .name("play".into())
        .spawn(move || {
            run(&config, &stop, &mut |u| {
                let _ = tx.send(u.to_string());
            })
        })
        .map_err(|e| PlayError::Serve {
            port,
            message: e.to_string(),
        })?;
    match rx.recv() {
        Ok(url) => Ok(Running { url, handle }),
        // The session ended before serving: its own error.
        Err(_) => match handle.join() {
            Ok(Err(e)) => Err(e),
            Ok(Ok(_)) | Err(_) => Err(PlayError::Serve {
                port,
                message: "the session's thread ended before serving the page".into(),
            }),
        },
    }
}

/// Runs a play session: serves the page (its URL is given to `on_ready` as soon as the port
/// is bound, before any device or page), waits for the hand (a page's Start, or the bridged
/// device's hello), runs the scene in real time at its tick rate while recording to
/// [`PlayConfig::out`], and after the end keeps serving the end screen and the recording's
/// download for [`PlayConfig::keep_serving_s`]. Raising `stop` ends the session cleanly (the
/// recording is complete) and then the serving.
pub fn run(
    config: &PlayConfig,
    stop: &AtomicBool,
    on_ready: &mut dyn FnMut(&str),
) -> Result<PlaySummary, PlayError> {
    let scene_src = &config.scene;
    let file = scene_src.parse()?;
    // One start time for a bridged device's welcome and the recording.
    let start_time_ns = now_unix_ns();
    let bridge = config.device.clone().map(DeviceSource::Udp);
    let device = session_device(&file, bridge.as_ref(), start_time_ns);
    if bridge.is_some() {
        // The scene's values are checked before waiting for the device (its own limits, which
        // the device announces, are checked when the session is set up after its hello).
        haptic_loop::scene::load_scene(&scene_src.text, Some(file.device.model))
            .map_err(|e| scene_src.locate(e))?;
    }
    let rate = file.loop_.rate_hz;
    let ticks = config.seconds.map(|s| ticks_for(s, rate)).transpose()?;
    let shared = Arc::new(Shared::default());
    let mut server =
        Server::start(config.port, shared.clone(), config.limits.clone()).map_err(|e| {
            PlayError::Serve {
                port: config.port,
                message: e.to_string(),
            }
        })?;
    let url = server.url();
    on_ready(&url);

    let mut hand = Hand::open(device, &shared)?;
    let page_is_hand = hand.is_page();
    let specs = hand.device().specs().clone();
    let (link, operator) = hand.describe(config);
    let Setup {
        mut lp,
        header,
        mut sinks,
    } = Setup::new(&SetupOptions {
        operator: Some(operator.to_string()),
        keep_arrays: false,
        out: Some(config.out.clone()),
        start_time_ns: Some(start_time_ns),
        ..SetupOptions::new(scene_src, specs.clone(), "realtime", &link)
    })?;
    let fields = lp.scene().state_fields();
    let kind = lp.scene().kind();
    announce(
        &shared,
        &file.scene.name,
        &lp,
        &specs,
        page_is_hand,
        config.seconds,
    );
    if page_is_hand && !shared.input.wait_first(stop) {
        server.stop(&shared);
        return Err(PlayError::NotStarted);
    }

    // The session.
    let prox = haptic_loop::sound::proximity_on_distance_m(kind)
        .filter(|_| fields.iter().any(|f| f == "nearest_m"));
    let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
    let sh = shared.clone();
    let publisher = std::thread::Builder::new()
        .name("play-publish".into())
        .spawn(move || publish::run_publisher(rx, sh, rate, fields, prox))
        .map_err(|e| PlayError::Serve {
            port: config.port,
            message: e.to_string(),
        })?;
    let mut play_sink = PlaySink::new(tx.clone(), shared.clone());
    let mut hook = switch_hook(stop, shared.clone(), tx);
    let pacing = if page_is_hand {
        Pacing::Realtime
    } else {
        Pacing::DeviceClock
    };
    let result = {
        let mut list = sinks.list();
        list.push(&mut play_sink);
        let mut runner = Runner::new(list)
            .with_live(&mut hook)
            .stop_on(&shared.end_requested)
            .with_realtime(config.rt);
        runner.run(
            &mut lp,
            hand.device(),
            &header,
            ticks,
            pacing,
            &mut |_, _| {},
        )
    };
    drop(hook);
    let latencies = std::mem::take(&mut play_sink.input_latency_ms);
    drop(play_sink);
    let closed = hand.device().close();
    let published = publisher.join().unwrap_or_default();
    let (stats, end) = result.map_err(SessionError::from)?;
    closed.map_err(SessionError::Device)?;
    let totals = &sinks.totals;
    let state = totals.state();
    let input_latency_ms = LatencyMs::of(&latencies);
    let written = sinks.written();
    let end_msg = end_message(
        "/recording.mcap",
        &config.out,
        end,
        &stats,
        rate,
        totals,
        input_latency_ms,
        written.as_ref(),
    );
    offer_end(&shared, &config.out, &end_msg);
    serve_end_screen(config, stop);
    server.stop(&shared);
    Ok(PlaySummary {
        url,
        end: end.name(),
        stats,
        state,
        recording: config.out.clone(),
        written,
        input_latency_ms,
        published,
        pages_served: shared.pages_served.load(Ordering::Relaxed),
        messages_dropped: shared.dropped.load(Ordering::Relaxed),
        page_messages_refused: shared.refused.load(Ordering::Relaxed),
        refused: server.gate().refused.snapshot(),
    })
}

/// Keeps the server up (the end screen and the recording's download) for
/// [`PlayConfig::keep_serving_s`] or until `stop`.
fn serve_end_screen(config: &PlayConfig, stop: &AtomicBool) {
    let until = config
        .keep_serving_s
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map(|s| Instant::now() + Duration::from_secs_f64(s.min(86_400.0)));
    while !stop.load(Ordering::Relaxed) && until.is_none_or(|u| Instant::now() < u) {
        std::thread::sleep(Duration::from_millis(20));
    }
}
