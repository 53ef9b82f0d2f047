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
//!   (through [`haptic_engine::runner::Runner::with_live`]), recorded as switches.
//! - **The protocol** ([`protocol`]): one typed message enum per direction, [`protocol::ServerMsg`]
//!   and [`protocol::PageMsg`], tabled in `docs/play.md`.
//!
//! - **The lesson** ([`lesson`]): `play --lesson` takes one student through a lesson of
//!   `nanohaptics-teaching`, each step its own session and recording, its condition watched on
//!   the tick thread ([`PlayConfig::lesson`]; `docs/teaching.md`).
//! - **The classroom** ([`classroom`]): one server for a whole class, a session per student
//!   ticked by shared workers, a teacher page, the recordings as one zip.
//! - **Safe to reach** ([`webguard::gate`]): `Host` and `Origin` checked on every request and
//!   upgrade, limits on connections, message size and rate, every refusal answered and counted.
//!
//! What it is not: it is no general web server (the page's fixed files
//! [`server::PAGE_FILES`], `/ws`, and `/recording.mcap` once the session ended; `play` on
//! loopback only), it has no accounts and no TLS, and it is not the Foxglove live view
//! (`nanohaptics run --live`). The page is plain HTML, CSS and JavaScript modules built into
//! the binary; it needs no npm, no bundler and no network.

pub mod background;
pub mod classroom;

pub mod http;
pub mod input;
pub mod lesson;
pub mod protocol;
pub mod publish;
pub mod replay;
pub mod server;
pub mod session;
pub mod wslink;

use haptic_devices::bridge::BridgeConfig;
use haptic_devices::source::DeviceSource;
use haptic_engine::pacing::Pacing;
use haptic_loop::session::{SceneSource, SessionError, now_unix_ns, ticks_for};
use haptic_loop::setup::session_device;
pub use protocol::LatencyMs;
use server::{Server, Shared};
use session::{Hand, PageSession, SessionSpec, SessionSummary};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use webguard::gate::{Limits, RefusedCounts};

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
    /// nothing (`--no-rt`). What it got is in the summary's `session.stats.realtime`.
    pub rt: Option<haptic_engine::realtime::RtRequest>,
    /// A lesson to take the student through (`play --lesson`): the scene above is then unused,
    /// each step runs its own, recorded to `out` without its extension, a directory, as
    /// `STEP-ID.mcap` ([`lesson`]).
    pub lesson: Option<teaching::Lesson>,
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
            rt: Some(haptic_engine::realtime::RtRequest::default()),
            lesson: None,
        }
    }
}

/// What a play session produced.
#[derive(Debug)]
pub struct PlaySummary {
    /// The page's URL.
    pub url: String,
    /// The session: how it ended, its ticks, state, recording, latencies and what the pages
    /// were sent.
    pub session: SessionSummary,
    /// Pages connected during the session.
    pub pages_served: u64,
    /// Messages not queued to a page that could not keep up.
    pub messages_dropped: u64,
    /// Page messages refused (protocol and switch errors), each answered with its error.
    pub page_messages_refused: u64,
    /// Requests, connections and messages the server refused, by reason (forged `Host` or
    /// `Origin`, limits).
    pub refused: RefusedCounts,
    /// The lesson, when one was played: the student's progress and each step's world.
    pub lesson: Option<LessonOutcome>,
}

/// What a lesson of `play --lesson` came to.
#[derive(Debug)]
pub struct LessonOutcome {
    /// The student's progress (answers, ticks on each step, test scores).
    pub progress: teaching::Progress,
    /// Each step's world as it ran, in order (its recording, its met tick).
    pub runs: Vec<lesson::StepRun>,
    /// The directory of the steps' recordings.
    pub dir: PathBuf,
    /// The lesson's report written there when it ended (`class-steps.csv`, `class-tests.csv`,
    /// `class-report.md` and its charts; [`lesson::report`]).
    pub report: Vec<PathBuf>,
}

impl PlaySummary {
    /// One line for a person: how it ended, ticks, missed deadlines, score and recording.
    pub fn line(&self) -> String {
        let s = &self.session;
        format!(
            "{}: {} ticks, {} missed deadlines, score {}, recording {}; real time: {}",
            s.end,
            s.stats.ticks,
            s.stats.missed,
            s.state("score").unwrap_or(0.0),
            s.recording.display(),
            s.stats.realtime.describe()
        )
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
    /// The session failed while it ran (its device, a sink or a scheduled switch); the
    /// recording holds every tick before the failure.
    #[error("the session ended early: {0}")]
    Failed(String),
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
    if let Some(lesson) = &config.lesson {
        // Neither applies to a lesson: refused, not ignored.
        let refuse = |m: &str| Err(PlayError::Session(SessionError::Option(m.into())));
        if config.seconds.is_some() {
            return refuse(
                "--seconds does not apply to a lesson: each step ends when its condition is met, \
                 and the lesson when the student finishes it or ends it",
            );
        }
        if config.device.is_some() {
            return refuse(
                "--device does not apply to a lesson: each step's world takes the page as the hand",
            );
        }
        return run_lesson(config, lesson.clone(), stop, on_ready);
    }
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
    let (shared, mut server, url) = serve_page(config, on_ready)?;

    let hand = Hand::open(device, &shared)?;
    let page_is_hand = hand.is_page();
    let (link, operator) = match &config.device {
        Some(b) => (format!("udp:{}", b.bind), "person (bridged device)"),
        None => ("page".to_string(), "person (browser page)"),
    };
    let spec = SessionSpec {
        scene: scene_src,
        scene_name: &file.scene.name,
        out: config.out.clone(),
        recording_url: "/recording.mcap".into(),
        start_time_ns,
        operator: operator.into(),
        link,
        seconds: config.seconds,
        ticks,
    };
    let mut session = PageSession::open(&spec, hand, shared.clone())?
        .with_sound_block(publish::PLAY_SOUND_BLOCK_TICKS);
    if page_is_hand && !shared.input.wait_first(stop) {
        server.stop(&shared);
        return Err(PlayError::NotStarted);
    }
    let pacing = if page_is_hand {
        Pacing::Realtime
    } else {
        Pacing::DeviceClock
    };
    session.run(pacing, config.rt.as_ref(), stop);
    let session = session.finish();
    if let Some(e) = &session.error {
        server.stop(&shared);
        return Err(PlayError::Failed(e.clone()));
    }
    serve_end_screen(config, stop);
    server.stop(&shared);
    Ok(summary(url, session, &shared, &server, None))
}

/// `run` with a lesson: serves the page, takes the student through `lesson` (each step's world
/// in real time, the page the hand), then serves the completion screen as `run` does the end
/// screen. The summary's session is the last step's (each step's is in the lesson's runs).
fn run_lesson(
    config: &PlayConfig,
    lesson: teaching::Lesson,
    stop: &AtomicBool,
    on_ready: &mut dyn FnMut(&str),
) -> Result<PlaySummary, PlayError> {
    let (shared, mut server, url) = serve_page(config, on_ready)?;
    let mut driver =
        lesson::LessonDriver::new(lesson, shared.clone(), config.out.with_extension(""));
    let r = driver.run(Pacing::Realtime, config.rt.as_ref(), stop);
    if let Err(e) = r {
        server.stop(&shared);
        return Err(PlayError::Failed(e.to_string()));
    }
    serve_end_screen(config, stop);
    server.stop(&shared);
    let dir = driver.dir().to_path_buf();
    let progress = driver.progress().clone();
    let report = if driver.runs().is_empty() {
        Vec::new()
    } else {
        lesson::report::write(&dir, "student", driver.lesson(), &progress, driver.runs())
            .map_err(|e| PlayError::Failed(format!("the lesson's report: {e}")))?
    };
    let runs = driver.into_runs();
    let Some(session) = runs.last().map(|r| r.session.clone()) else {
        return Err(PlayError::NotStarted);
    };
    let lesson = LessonOutcome {
        progress,
        runs,
        dir,
        report,
    };
    Ok(summary(url, session, &shared, &server, Some(lesson)))
}

/// Starts the page's server on `config`'s port and tells `on_ready` its address.
fn serve_page(
    config: &PlayConfig,
    on_ready: &mut dyn FnMut(&str),
) -> Result<(Arc<Shared>, Server, String), PlayError> {
    let shared = Arc::new(Shared::default());
    let server =
        Server::start(config.port, shared.clone(), config.limits.clone()).map_err(|e| {
            PlayError::Serve {
                port: config.port,
                message: e.to_string(),
            }
        })?;
    let url = server.url();
    on_ready(&url);
    Ok((shared, server, url))
}

/// What a `play` run came to: its `session` (a lesson's last step's), what the server at `url`
/// served and refused, and the `lesson` when one was played.
fn summary(
    url: String,
    session: SessionSummary,
    shared: &Shared,
    server: &Server,
    lesson: Option<LessonOutcome>,
) -> PlaySummary {
    PlaySummary {
        url,
        session,
        pages_served: shared.pages_served.load(Ordering::Relaxed),
        messages_dropped: shared.dropped.load(Ordering::Relaxed),
        page_messages_refused: shared.refused.load(Ordering::Relaxed),
        refused: server.gate().refused.snapshot(),
        lesson,
    }
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
