//! Sessions: run a scene with a script (batch or real time), optionally record it, and get
//! per-tick arrays back; read a recording into the same arrays.
//!
//! ```no_run
//! use haptic_loop::session::{run_session, OperatorChoice, SceneSource, SessionOptions};
//! let scene = SceneSource::from_path("scenes/wall.toml".as_ref()).unwrap();
//! let mut opts = SessionOptions::new(scene);
//! opts.operator = OperatorChoice::Hand(Default::default());
//! let report = run_session(&opts, &mut |_, _| {}).unwrap();
//! let peak = report.arrays.device_force_n.iter().map(|f| f[2]).fold(0.0, f64::max);
//! println!("{} ticks, peak force {peak} N", report.arrays.tick.len());
//! ```

use crate::bridge::BridgeConfig;
use crate::device::script::{OperatorKind, Script};
use crate::device::source::{DeviceSource, open_device};
use crate::device::{DeviceError, DeviceModel, OperatorParams, ScriptError};
use crate::haptic::HapticLoop;
use crate::live::{LiveConfig, LiveSink};
use crate::pacing::TickStats;
use crate::record::messages::{self, DescriptionMsg};
use crate::record::sink::RecorderSink;
use crate::record::writer::RecordError;
use crate::record::{RecordingError, WriteSummary};
use crate::runner::{EndReason, Pacing, Runner, Sink};
use crate::scene::{SceneError, SceneFile, load_scene_for};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

pub use crate::arrays::SessionArrays;
pub use crate::record::sink::stats_metadata;

/// Errors of a session.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The scene file.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The script.
    #[error(transparent)]
    Script(#[from] ScriptError),
    /// The device.
    #[error("device: {0}")]
    Device(#[from] DeviceError),
    /// Writing the recording.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Reading a recording.
    #[error(transparent)]
    Recording(#[from] RecordingError),
    /// No script given and the scene names no default script.
    #[error("no script: pass --script or set `scene.default_script` in the scene file")]
    NoScript,
    /// A file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// OS error.
        message: String,
    },
    /// Session length out of range.
    #[error("session length {0} s is out of range (allowed: 0 < seconds ≤ 3600)")]
    Seconds(f64),
    /// A scene reported a state field name that cannot be a message field.
    #[error("scene state field `{0}` is not a lower-snake-case field name")]
    StateField(String),
    /// The live view could not start or publish.
    #[error("live view: {0}")]
    Live(String),
    /// An option out of range or inconsistent with another.
    #[error("{0}")]
    Option(String),
}

/// A scene file's text and the folder it came from (to find its default script).
#[derive(Clone, Debug)]
pub struct SceneSource {
    /// TOML text.
    pub text: String,
    /// Folder for relative paths in the file.
    pub dir: Option<PathBuf>,
    /// Scripts that come with the scene (a built-in scene's default script), file name → text;
    /// consulted before the disk.
    pub scripts: Vec<(String, String)>,
}

fn read(path: &Path) -> Result<String, SessionError> {
    std::fs::read_to_string(path).map_err(|e| SessionError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}

impl SceneSource {
    /// Reads a scene file.
    pub fn from_path(path: &Path) -> Result<Self, SessionError> {
        Ok(SceneSource {
            text: read(path)?,
            dir: path.parent().map(Path::to_path_buf),
            scripts: Vec::new(),
        })
    }

    /// A scene file on disk, or else a built-in scene by name (`wall`, `wall.toml`): files on
    /// disk override the built-ins, so this works from any directory.
    pub fn resolve(arg: &Path) -> Result<Self, SessionError> {
        if arg.exists() {
            return Self::from_path(arg);
        }
        // `wall`, `wall.toml` or `scenes/wall.toml` (the repository's path, from anywhere).
        let parent_ok = arg
            .parent()
            .is_none_or(|p| p.as_os_str().is_empty() || p == Path::new("scenes"));
        let name = arg
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        match crate::builtin::find(&name) {
            Some(b) if parent_ok => Ok(SceneSource {
                text: b.scene.to_string(),
                dir: None,
                scripts: vec![(b.script_file.to_string(), b.script.to_string())],
            }),
            _ => Err(SessionError::Io {
                path: arg.display().to_string(),
                message: format!(
                    "no such file, and not a built-in scene (built-in: {}; `nanohaptics scenes export DIR` writes editable copies)",
                    crate::builtin::names()
                ),
            }),
        }
    }
}

/// How the script drives the device.
#[derive(Clone, Debug, PartialEq)]
pub enum OperatorChoice {
    /// The stylus follows the script exactly (forces do not move it).
    Rigid,
    /// A simulated hand follows the script and is pushed by the rendered force.
    Hand(OperatorParams),
    /// As the script says (`[script] operator`): a hand with its `[operator]` parameters (or
    /// the defaults), or a rigid stylus.
    ScriptHand,
}

/// Options of a session.
#[derive(Clone, Debug)]
pub struct SessionOptions {
    /// The scene.
    pub scene: SceneSource,
    /// Script text; `None`: the scene's default script (local devices only).
    pub script: Option<String>,
    /// Device model overriding the scene file's (local devices only: a bridged device announces
    /// its own specifications).
    pub device: Option<DeviceModel>,
    /// How the script drives the device (local devices only).
    pub operator: OperatorChoice,
    /// A device in another process over the UDP bridge instead of the script.
    pub bridge: Option<BridgeConfig>,
    /// Session length, s; `None`: the script's duration (a bridged device: until it says
    /// goodbye).
    pub seconds: Option<f64>,
    /// Pace ticks against the wall clock (a bridged device is always real time: its samples
    /// are the clock).
    pub realtime: bool,
    /// Record to this MCAP file.
    pub out: Option<PathBuf>,
    /// Serve a live Foxglove view while the session runs.
    pub live: Option<LiveConfig>,
    /// Keep the per-tick arrays (default true; long live sessions may turn them off).
    pub arrays: bool,
    /// Session start written in the description, ns since the Unix epoch (`None`: the wall
    /// clock now). Pin it to make a batch recording byte-identical across runs.
    pub start_time_ns: Option<u64>,
}

impl SessionOptions {
    /// Batch run of `scene` with its default script, through a simulated hand with the script's
    /// parameters, not recorded.
    pub fn new(scene: SceneSource) -> Self {
        SessionOptions {
            scene,
            script: None,
            device: None,
            operator: OperatorChoice::ScriptHand,
            bridge: None,
            seconds: None,
            realtime: false,
            out: None,
            live: None,
            arrays: true,
            start_time_ns: None,
        }
    }
}

/// What a session produced.
#[derive(Debug, serde::Serialize)]
pub struct SessionReport {
    /// The session's description (as recorded).
    pub description: DescriptionMsg,
    /// Per-tick arrays (empty when turned off).
    pub arrays: SessionArrays,
    /// Tick-time statistics.
    pub stats: TickStats,
    /// What the writer did, when recording.
    pub written: Option<WriteSummary>,
    /// How the run ended: `completed`, `device_ended` or `stopped`.
    pub end: &'static str,
    /// The device link's counters (bridged devices), name → count.
    pub link: Vec<(&'static str, u64)>,
    /// What the live view published, when serving one.
    pub live: Option<crate::live::LiveSummary>,
    /// Time each sink took per tick, ns.
    pub sinks: Vec<crate::runner::SinkTime>,
}

/// Reads the script text for a local device: the given one or the scene's default script.
pub fn script_text(opts: &SessionOptions, file: &SceneFile) -> Result<String, SessionError> {
    match &opts.script {
        Some(t) => Ok(t.clone()),
        None => {
            let rel = file
                .scene
                .default_script
                .as_ref()
                .ok_or(SessionError::NoScript)?;
            if let Some((_, text)) = opts.scene.scripts.iter().find(|(n, _)| n == rel) {
                return Ok(text.clone());
            }
            let p = match &opts.scene.dir {
                Some(d) => d.join(rel),
                None => PathBuf::from(rel),
            };
            read(&p)
        }
    }
}

/// Wall-clock time now, ns since the Unix epoch (information only: it never reaches the
/// physics).
pub fn now_unix_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

/// Validates a session length and turns it into ticks.
pub fn ticks_for(seconds: f64, rate_hz: u32) -> Result<u64, SessionError> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(SessionError::Seconds(seconds));
    }
    Ok((seconds * f64::from(rate_hz)).round() as u64)
}

/// Runs a session (see the module example); `stop` ends it cleanly after the current tick.
pub fn run_session_until(
    opts: &SessionOptions,
    progress: &mut dyn FnMut(u64, u64),
    stop: Option<&AtomicBool>,
) -> Result<SessionReport, SessionError> {
    let file = SceneFile::parse(&opts.scene.text)?;
    // 1. The device source: a script (rigid or through a simulated hand) or a bridged device.
    let (source, script) = match &opts.bridge {
        Some(b) => (DeviceSource::Udp(b.clone()), None),
        None => {
            let model = opts.device.unwrap_or(file.device.model);
            let text = script_text(opts, &file)?;
            let script = Script::from_toml(&text, model.specs())?;
            let source = match &opts.operator {
                OperatorChoice::Rigid => DeviceSource::Script(model),
                OperatorChoice::Hand(p) => {
                    p.validate()?;
                    DeviceSource::Hand(model, *p)
                }
                OperatorChoice::ScriptHand if script.operator_kind == OperatorKind::Rigid => {
                    DeviceSource::Script(model)
                }
                OperatorChoice::ScriptHand => {
                    DeviceSource::Hand(model, script.operator.unwrap_or_default())
                }
            };
            (source, Some((script, text)))
        }
    };
    let mut dev = open_device(&source, script.as_ref().map(|s| &s.0))?;
    let result = run_with_device(opts, &source, script, dev.as_mut(), progress, stop);
    let closed = dev.close();
    let report = result?;
    closed?;
    Ok(report)
}

/// Runs a session to its end (see the module example).
pub fn run_session(
    opts: &SessionOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<SessionReport, SessionError> {
    run_session_until(opts, progress, None)
}

fn run_with_device(
    opts: &SessionOptions,
    source: &DeviceSource,
    script: Option<(Script, String)>,
    dev: &mut dyn crate::device::HapticDevice,
    progress: &mut dyn FnMut(u64, u64),
    stop: Option<&AtomicBool>,
) -> Result<SessionReport, SessionError> {
    dev.open()?;
    let specs = dev.specs().clone();
    let loaded = load_scene_for(&opts.scene.text, specs.clone())?;
    let rate = loaded.config.rate_hz;
    let ticks = match (opts.seconds, &script) {
        (Some(s), _) => Some(ticks_for(s, rate)?),
        (None, Some((s, _))) => Some(ticks_for(s.duration_s, rate)?),
        (None, None) => None,
    };
    let fields = loaded.scene.state_fields();
    if let Some(bad) = fields.iter().find(|f| !messages::valid_field_name(f)) {
        return Err(SessionError::StateField(bad.clone()));
    }
    let bridged = opts.bridge.is_some();
    let mode = if bridged || opts.realtime {
        "realtime"
    } else {
        "batch"
    };
    let (script_name, script_toml) = match &script {
        Some((s, t)) => (s.name.clone(), t.clone()),
        None => (String::new(), String::new()),
    };
    let mut description = DescriptionMsg::new(
        &opts.scene.text,
        &loaded,
        mode,
        &source.link_name(),
        opts.start_time_ns.unwrap_or_else(now_unix_ns),
    );
    description.script_name = script_name;
    description.script_toml = script_toml;
    description.operator = source.describe();
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let mut arrays = SessionArrays::new(rate, fields);
    let mut recorder = opts.out.clone().map(RecorderSink::new);
    let mut live = match &opts.live {
        Some(c) => Some(LiveSink::new(c.clone())?),
        None => None,
    };
    let mut sinks: Vec<&mut dyn Sink> = Vec::new();
    if opts.arrays {
        sinks.push(&mut arrays);
    }
    if let Some(r) = recorder.as_mut() {
        sinks.push(r);
    }
    if let Some(l) = live.as_mut() {
        sinks.push(l);
    }
    let pacing = if bridged {
        Pacing::DeviceClock
    } else if opts.realtime {
        Pacing::Realtime
    } else {
        Pacing::Batch
    };
    let mut runner = Runner::new(sinks);
    if let Some(f) = stop {
        runner = runner.stop_on(f);
    }
    let (stats, end) = runner.run(&mut lp, dev, &description, ticks, pacing, progress)?;
    let sink_times = runner.sink_times();
    drop(runner);
    if stats.ticks == 0 {
        return Err(SessionError::Option(
            "the session ended before its first tick (no device sample arrived)".into(),
        ));
    }
    Ok(SessionReport {
        description,
        arrays,
        stats,
        written: recorder.and_then(|r| r.summary().cloned()),
        end: match end {
            EndReason::Completed => "completed",
            EndReason::DeviceEnded => "device_ended",
            EndReason::Stopped => "stopped",
        },
        link: dev.link_counters(),
        live: live.map(|l| l.summary()),
        sinks: sink_times,
    })
}

/// Reads a recording file into arrays (`salvage`: accept a truncated file's complete part).
pub fn read_arrays(path: &Path, salvage: bool) -> Result<SessionArrays, SessionError> {
    let rec = crate::record::read_recording_file(path, salvage)?;
    Ok(SessionArrays::from_recording(&rec)?)
}
