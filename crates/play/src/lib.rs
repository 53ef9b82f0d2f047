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
//! - **Live sound** ([`publish`]): the same synthesis as `render --audio --proximity`
//!   ([`render::audio::StreamSynth`]), streamed to the pages in 5 ms blocks.
//! - **The live menu**: the scene's switches, set from a page and applied before the next tick
//!   (through [`haptic_loop::runner::Runner::with_live`]), recorded as switches.
//!
//! What it is not: it is no general web server (loopback only, four paths: `/`, `/play.js`,
//! `/play.css`, `/ws`, and `/recording.mcap` once the session ended), it has no accounts and
//! no TLS, and it is not the Foxglove live view (`nanohaptics run --live`). The page is plain
//! HTML, CSS and JavaScript built into the binary; it needs no npm and no network.

pub mod input;
pub mod protocol;
pub mod publish;
pub mod server;

use haptic_devices::bridge::{BridgeConfig, UdpDevice};
use haptic_devices::pacing::{Percentiles, TickStats};
use haptic_loop::record_sink::RecorderSink;
use haptic_loop::runner::{EndReason, Pacing, Runner};
use haptic_loop::scene::load_scene_for;
use haptic_loop::session::{SceneSource, SessionError, now_unix_ns, ticks_for};
use haptic_loop::sink::Sink;
use haptic_loop::totals::Totals;
use haptic_loop::{HapticDevice, HapticLoop};
use input::PageDevice;
use publish::{PlaySink, PublishSummary, ToPublisher};
use recording::WriteSummary;
use recording::channels::messages;
use serde_json::json;
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
        }
    }
}

/// Latency figures, ms.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LatencyMs {
    /// Samples.
    pub n: usize,
    /// Median, ms.
    pub p50: f64,
    /// 99th percentile (nearest rank), ms.
    pub p99: f64,
    /// Largest, ms.
    pub max: f64,
}

impl LatencyMs {
    /// Figures of `v` (`None` when empty).
    pub fn of(v: &[f64]) -> Option<Self> {
        if v.is_empty() {
            return None;
        }
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        let rank = |q: f64| s[((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1];
        Some(LatencyMs {
            n: s.len(),
            p50: rank(0.5),
            p99: rank(0.99),
            max: s[s.len() - 1],
        })
    }
}

/// What a play session produced.
#[derive(Debug)]
pub struct PlaySummary {
    /// The page's URL.
    pub url: String,
    /// How it ended: `completed` (its `seconds` ran), `ended` (the player ended it on the
    /// page, or `stop`), `device_ended` (a bridged device said goodbye).
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
}

impl PlaySummary {
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

fn stats_ms(p: &Percentiles) -> serde_json::Value {
    json!({"p50_ms": p.p50_ns as f64 * 1e-6, "p99_ms": p.p99_ns as f64 * 1e-6, "max_ms": p.max_ns as f64 * 1e-6})
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
    // The scene with the file's device model: its rate and, for the page, the device.
    let model_specs = file.device.model.specs().clone();
    let preload =
        load_scene_for(&scene_src.text, model_specs.clone()).map_err(|e| scene_src.locate(e))?;
    let rate = preload.config.rate_hz;
    let ticks = config.seconds.map(|s| ticks_for(s, rate)).transpose()?;
    let shared = Arc::new(Shared::default());
    let mut server = Server::start(config.port, shared.clone()).map_err(|e| PlayError::Serve {
        port: config.port,
        message: e.to_string(),
    })?;
    let url = server.url();
    on_ready(&url);

    // The hand.
    let mut page_dev;
    let mut udp_dev;
    let dev: &mut dyn HapticDevice = match &config.device {
        Some(b) => {
            let mut b = b.clone();
            b.rate_hz = rate;
            b.scene = file.scene.name.clone();
            b.start_time_ns = now_unix_ns();
            udp_dev = UdpDevice::new(b);
            udp_dev.open().map_err(SessionError::Device)?;
            &mut udp_dev
        }
        None => {
            page_dev = PageDevice::new(model_specs.clone(), shared.input.clone());
            &mut page_dev
        }
    };
    let specs = dev.specs().clone();
    let loaded = if config.device.is_some() {
        load_scene_for(&scene_src.text, specs.clone()).map_err(|e| scene_src.locate(e))?
    } else {
        preload
    };
    let fields = loaded.scene.state_fields();
    if let Some(bad) = fields.iter().find(|f| !messages::valid_field_name(f)) {
        return Err(SessionError::StateField(bad.clone()).into());
    }
    let kind = loaded.scene.kind();
    let switches = loaded.scene.switches();
    let page_is_hand = config.device.is_none();
    let link = SceneLink {
        switches,
        kind,
        workspace_radius_m: specs.workspace_radius_m,
        button_mask: specs.button_mask(),
        page_is_hand,
    };
    let hello = json!({
        "type": "hello",
        "scene": file.scene.name,
        "kind": kind,
        "rate_hz": rate,
        "device": specs.name,
        "workspace_radius_m": specs.workspace_radius_m,
        "max_force_n": specs.limits.max_force_n,
        "buttons": specs.button_strs(),
        "page_is_hand": page_is_hand,
        "display_scale": loaded.config.display_scale,
        "mapping": {
            "origin_m": loaded.config.mapping.origin_m,
            "workspace_scale": loaded.config.mapping.workspace_scale,
        },
        "switches": switches.iter().map(|s| json!({
            "name": s.name, "min": s.min, "max": s.max, "boolean": s.boolean, "doc": s.doc,
            "value": loaded.scene.switch_value(s.name),
        })).collect::<Vec<_>>(),
        "state_fields": fields,
        "sample_rate_hz": publish::SAMPLE_RATE_HZ,
        "seconds": config.seconds,
    });
    if let Ok(mut s) = shared.scene.lock() {
        *s = Some(link);
    }
    if let Ok(mut h) = shared.hello.lock() {
        *h = Some(hello.to_string());
    }
    shared.broadcast(&tungstenite::Message::text(hello.to_string()));
    if page_is_hand && !shared.input.wait_first(stop) {
        server.stop();
        return Err(PlayError::NotStarted);
    }

    // The session.
    let mut description = loaded.description(
        &scene_src.text,
        "realtime",
        &match &config.device {
            Some(b) => format!("udp:{}", b.bind),
            None => "page".to_string(),
        },
        now_unix_ns(),
    );
    description.operator = if page_is_hand {
        "person (browser page)".into()
    } else {
        "person (bridged device)".into()
    };
    let prox = haptic_loop::sound::proximity_on_distance_m(kind)
        .filter(|_| fields.iter().any(|f| f == "nearest_m"));
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
    let publisher = {
        let sh = shared.clone();
        let f = fields.clone();
        std::thread::Builder::new()
            .name("play-publish".into())
            .spawn(move || publish::run_publisher(rx, sh, rate, f, prox))
            .map_err(|e| PlayError::Serve {
                port: config.port,
                message: e.to_string(),
            })?
    };
    let mut totals = Totals::default();
    let mut recorder = RecorderSink::new(config.out.clone());
    let mut play_sink = PlaySink::new(tx.clone(), shared.clone());
    let hook_tx = tx;
    let hook_shared = shared.clone();
    let mut hook = move |tick: u64, lp: &mut HapticLoop| {
        if stop.load(Ordering::Relaxed) {
            hook_shared.end_requested.store(true, Ordering::Relaxed);
        }
        // Never wait for a page's thread: a busy queue waits for the next tick.
        let reqs = match hook_shared.switches.try_lock() {
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
            let _ = hook_tx.send(m);
        }
    };
    let pacing = if page_is_hand {
        Pacing::Realtime
    } else {
        Pacing::DeviceClock
    };
    let result = {
        let sinks: Vec<&mut dyn Sink> = vec![&mut totals, &mut recorder, &mut play_sink];
        let mut runner = Runner::new(sinks)
            .with_live(&mut hook)
            .stop_on(&shared.end_requested);
        runner.run(&mut lp, dev, &description, ticks, pacing, &mut |_, _| {})
    };
    drop(hook);
    let latencies = std::mem::take(&mut play_sink.input_latency_ms);
    drop(play_sink);
    let closed = dev.close();
    let published = publisher.join().unwrap_or_default();
    let (stats, end) = result.map_err(SessionError::from)?;
    closed.map_err(SessionError::Device)?;
    let end = match end {
        EndReason::Completed => "completed",
        EndReason::Stopped => "ended",
        EndReason::DeviceEnded => "device_ended",
    };
    let state: Vec<(String, f64)> = totals
        .state_fields
        .iter()
        .cloned()
        .zip(totals.last_state.iter().copied())
        .collect();
    let input_latency_ms = LatencyMs::of(&latencies);
    if let Ok(mut r) = shared.recording.lock() {
        *r = Some(config.out.clone());
    }
    let written = recorder.summary().cloned();
    let end_msg = json!({
        "type": "end",
        "end": end,
        "ticks": stats.ticks,
        "seconds": stats.ticks as f64 / f64::from(rate),
        "missed_deadlines": stats.missed,
        "tick_work": stats_ms(&stats.compute),
        "state": totals.state_fields.iter().zip(&totals.last_state)
            .map(|(k, v)| (k.clone(), json!(v))).collect::<serde_json::Map<_, _>>(),
        "peak_device_force_n": totals.peak_device_force_n,
        "events": totals.events,
        "input_latency_ms": input_latency_ms,
        "recording": "/recording.mcap",
        "recording_file": config.out.file_name().map(|n| n.to_string_lossy().to_string()),
        "recording_bytes": written.as_ref().map(|w| w.bytes),
    });
    if let Ok(mut e) = shared.end.lock() {
        *e = Some(end_msg.to_string());
    }
    shared.broadcast(&tungstenite::Message::text(end_msg.to_string()));
    // The end screen and the download.
    let until = config
        .keep_serving_s
        .filter(|s| s.is_finite() && *s >= 0.0)
        .map(|s| Instant::now() + Duration::from_secs_f64(s.min(86_400.0)));
    while !stop.load(Ordering::Relaxed) && until.is_none_or(|u| Instant::now() < u) {
        std::thread::sleep(Duration::from_millis(20));
    }
    server.stop();
    Ok(PlaySummary {
        url,
        end,
        stats,
        state,
        recording: config.out.clone(),
        written,
        input_latency_ms,
        published,
        pages_served: shared.pages_served.load(Ordering::Relaxed),
        messages_dropped: shared.dropped.load(Ordering::Relaxed),
        page_messages_refused: shared.refused.load(Ordering::Relaxed),
    })
}
