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

use crate::device::script::{OperatorKind, Script};
use crate::device::{
    DeviceError, DeviceModel, HapticDevice, OperatorParams, ScriptError, ScriptedDevice,
    SimulatedOperator, TickTime,
};
use crate::haptic::HapticLoop;
use crate::pacing::{Pacer, Percentiles, TickStats};
use crate::record::messages::{
    self, Channel, DescriptionMsg, DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, TimingMsg,
};
use crate::record::writer::RecordError;
use crate::record::{
    OutMsg, Recorder, RecorderSetup, Recording, RecordingError, TickEncoder, TickMessages,
    WriteSummary,
};
use crate::scene::{SceneError, load_scene};
use crate::vec3::Vec3;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
}

/// A scene file's text and the folder it came from (to find its default script).
#[derive(Clone, Debug)]
pub struct SceneSource {
    /// TOML text.
    pub text: String,
    /// Folder for relative paths in the file.
    pub dir: Option<PathBuf>,
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
        })
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
    /// Script text; `None`: the scene's default script.
    pub script: Option<String>,
    /// Device model overriding the scene file's.
    pub device: Option<DeviceModel>,
    /// How the script drives the device.
    pub operator: OperatorChoice,
    /// Session length, s; `None`: the script's duration.
    pub seconds: Option<f64>,
    /// Pace ticks against the wall clock.
    pub realtime: bool,
    /// Record to this MCAP file.
    pub out: Option<PathBuf>,
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
            seconds: None,
            realtime: false,
            out: None,
        }
    }
}

/// Per-tick arrays of a session (struct of arrays; `state` is row-major ticks × fields).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct SessionArrays {
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// Names of the state columns.
    pub state_fields: Vec<String>,
    /// Tick index.
    pub tick: Vec<u64>,
    /// Raw device position, m, device frame.
    pub device_position_m: Vec<Vec3>,
    /// Raw button bits.
    pub device_buttons: Vec<u32>,
    /// Deadline-missed flag.
    pub deadline_missed: Vec<bool>,
    /// Cursor, world frame, m.
    pub cursor_m: Vec<Vec3>,
    /// Scene state, ticks × fields.
    pub state: Vec<f64>,
    /// Scene force, world frame, N.
    pub world_force_n: Vec<Vec3>,
    /// Force sent, device frame, N.
    pub device_force_n: Vec<Vec3>,
    /// Soft-engagement factor.
    pub engagement: Vec<f64>,
    /// Status bits (see `haptic::status`).
    pub status: Vec<u8>,
    /// Events: (tick, name, detail).
    pub events: Vec<(u64, String, String)>,
    /// Work per tick, ns (wall clock; not reproducible).
    pub compute_ns: Vec<u64>,
    /// Start lateness per tick, ns (real-time mode).
    pub start_late_ns: Vec<i64>,
}

impl SessionArrays {
    /// Empty arrays for a session at `rate_hz` with these state fields.
    pub fn new(rate_hz: u32, state_fields: Vec<String>) -> Self {
        SessionArrays {
            rate_hz,
            state_fields,
            ..Default::default()
        }
    }

    /// Reserves room for `ticks` more ticks, so that no array grows (and copies) mid-session.
    pub fn reserve(&mut self, ticks: usize) {
        let n = self.state_fields.len();
        self.tick.reserve(ticks);
        self.device_position_m.reserve(ticks);
        self.device_buttons.reserve(ticks);
        self.deadline_missed.reserve(ticks);
        self.cursor_m.reserve(ticks);
        self.state.reserve(ticks * n);
        self.world_force_n.reserve(ticks);
        self.device_force_n.reserve(ticks);
        self.engagement.reserve(ticks);
        self.status.reserve(ticks);
        self.compute_ns.reserve(ticks);
        self.start_late_ns.reserve(ticks);
    }

    /// Time of each tick, s.
    pub fn time_s(&self) -> Vec<f64> {
        self.tick
            .iter()
            .map(|&t| t as f64 / f64::from(self.rate_hz))
            .collect()
    }

    /// The column of state field `name`, if the scene has it.
    pub fn state_column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.state_fields.iter().position(|f| f == name)?;
        let n = self.state_fields.len();
        Some(self.state.chunks(n).map(|row| row[k]).collect())
    }

    /// Adds one message.
    pub fn push(
        &mut self,
        channel: Channel,
        data: &[u8],
    ) -> Result<(), crate::record::cdr::CdrError> {
        match channel {
            Channel::DeviceInput => {
                let m = DeviceInputMsg::decode(data)?;
                self.tick.push(m.tick);
                self.device_position_m.push(m.position_m);
                self.device_buttons.push(m.buttons);
                self.deadline_missed.push(m.deadline_missed);
            }
            Channel::State => {
                let m = StateMsg::decode(data, self.state_fields.len())?;
                self.cursor_m.push(m.cursor_m);
                self.state.extend_from_slice(&m.values);
            }
            Channel::Force => {
                let m = ForceMsg::decode(data)?;
                self.world_force_n.push(m.world_force_n);
                self.device_force_n.push(m.device_force_n);
                self.engagement.push(m.engagement);
                self.status.push(m.status);
            }
            Channel::Events => {
                let m = EventsMsg::decode(data)?;
                for (n, d) in m.names.into_iter().zip(m.details) {
                    self.events.push((m.tick, n, d));
                }
            }
            Channel::Timing => {
                let m = TimingMsg::decode(data)?;
                self.compute_ns.push(m.compute_ns);
                self.start_late_ns.push(m.start_late_ns);
            }
            _ => {}
        }
        Ok(())
    }

    /// Reads a whole recording into arrays.
    pub fn from_recording(rec: &Recording) -> Result<Self, RecordingError> {
        let d = &rec.description;
        let mut a = SessionArrays::new(d.rate_hz, d.state_fields.clone());
        for m in &rec.messages {
            a.push(m.channel, &m.data)
                .map_err(|e| RecordingError::BadMessage {
                    topic: m.channel.topic().to_string(),
                    log_time_ns: m.log_time_ns,
                    detail: e.to_string(),
                })?;
        }
        Ok(a)
    }
}

/// Reads a recording file into arrays (`salvage`: accept a truncated file's complete part).
pub fn read_arrays(path: &Path, salvage: bool) -> Result<SessionArrays, SessionError> {
    let rec = crate::record::read_recording_file(path, salvage)?;
    Ok(SessionArrays::from_recording(&rec)?)
}

/// How ticks are paced and where the deadline flag comes from.
pub enum Pacing<'a> {
    /// As fast as possible; no deadline.
    Batch,
    /// Against the wall clock; a tick whose force is ready after its deadline sends zero force.
    Realtime,
    /// Deadline flags read from a recording.
    Recorded(&'a dyn Fn(u64) -> bool),
}

/// Runs `ticks` ticks of `lp` with `dev`, handing each tick's messages to `sink`; `progress`
/// is called every 100 ticks with (done, total).
pub fn drive(
    lp: &mut HapticLoop,
    dev: &mut dyn HapticDevice,
    ticks: u64,
    pacing: Pacing<'_>,
    sink: &mut dyn FnMut(TickMessages) -> Result<(), SessionError>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<TickStats, SessionError> {
    let mut enc = TickEncoder::new(lp);
    let rate = lp.config().rate_hz;
    let mut compute = Vec::with_capacity(ticks as usize);
    let realtime = matches!(pacing, Pacing::Realtime);
    let mut jitter = Vec::with_capacity(if realtime { ticks as usize } else { 0 });
    let mut missed_count = 0;
    let start = Instant::now();
    let pacer = match pacing {
        Pacing::Realtime => Some(Pacer::new(lp.config().period_ns())),
        _ => None,
    };
    for n in 0..ticks {
        let late = match &pacer {
            Some(p) => p.wait_for(n),
            None => 0,
        };
        let t0 = Instant::now();
        let sample = dev.sample(TickTime::new(n, rate))?;
        let recorded_missed = match &pacing {
            Pacing::Recorded(f) => f(n),
            _ => false,
        };
        lp.tick(sample, recorded_missed);
        let missed = match &pacer {
            Some(p) if p.deadline_passed(n) => {
                lp.mark_deadline_missed();
                true
            }
            _ => recorded_missed,
        };
        let r = lp.last_result();
        dev.set_force(r.device_force_n);
        missed_count += u64::from(missed);
        let mut msgs = Vec::with_capacity(8);
        msgs.push(TickEncoder::input(n, &sample, missed));
        enc.outputs(r, lp, &mut msgs);
        let compute_ns = t0.elapsed().as_nanos() as u64;
        msgs.push(TickEncoder::timing(n, late, compute_ns));
        sink(TickMessages {
            tick: n,
            log_time_ns: enc.log_time_ns(n),
            msgs,
        })?;
        // The hand-off to the writer belongs to the tick's cost.
        compute.push(t0.elapsed().as_nanos() as u64);
        if pacer.is_some() {
            jitter.push(late.max(0) as u64);
        }
        if n % 100 == 99 || n + 1 == ticks {
            progress(n + 1, ticks);
        }
    }
    Ok(TickStats {
        ticks,
        compute: Percentiles::of(&compute),
        jitter: Percentiles::of(&jitter),
        missed: missed_count,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

/// What a session produced.
#[derive(Debug, serde::Serialize)]
pub struct SessionReport {
    /// The session's description (as recorded).
    pub description: DescriptionMsg,
    /// Per-tick arrays.
    pub arrays: SessionArrays,
    /// Tick-time statistics.
    pub stats: TickStats,
    /// What the writer did, when recording.
    pub written: Option<WriteSummary>,
}

/// Metadata record `session` of a recording: the tick statistics.
pub fn stats_metadata(stats: &TickStats, mode: &str) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("mode".into(), mode.into());
    m.insert("ticks".into(), stats.ticks.to_string());
    m.insert("compute_p50_ns".into(), stats.compute.p50_ns.to_string());
    m.insert("compute_p99_ns".into(), stats.compute.p99_ns.to_string());
    m.insert("compute_max_ns".into(), stats.compute.max_ns.to_string());
    m.insert("jitter_p99_ns".into(), stats.jitter.p99_ns.to_string());
    m.insert("jitter_max_ns".into(), stats.jitter.max_ns.to_string());
    m.insert("missed_deadlines".into(), stats.missed.to_string());
    m.insert("wall_s".into(), format!("{:.6}", stats.wall_s));
    m
}

/// Runs a session (see the module example).
pub fn run_session(
    opts: &SessionOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<SessionReport, SessionError> {
    let loaded = load_scene(&opts.scene.text, opts.device)?;
    let specs = loaded.config.specs.clone();
    let script_text = match &opts.script {
        Some(t) => t.clone(),
        None => {
            let rel = loaded
                .file
                .scene
                .default_script
                .as_ref()
                .ok_or(SessionError::NoScript)?;
            let p = match &opts.scene.dir {
                Some(d) => d.join(rel),
                None => PathBuf::from(rel),
            };
            read(&p)?
        }
    };
    let script = Script::from_toml(&script_text, &specs)?;
    let seconds = opts.seconds.unwrap_or(script.duration_s);
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(SessionError::Seconds(seconds));
    }
    let rate = loaded.config.rate_hz;
    let ticks = (seconds * f64::from(rate)).round() as u64;
    let fields = loaded.scene.state_fields();
    if let Some(bad) = fields.iter().find(|f| !messages::valid_field_name(f)) {
        return Err(SessionError::StateField(bad.clone()));
    }
    let (mut dev, operator): (Box<dyn HapticDevice>, String) = match &opts.operator {
        OperatorChoice::Rigid => (
            Box::new(ScriptedDevice::new(script.clone(), specs.clone())),
            "rigid".into(),
        ),
        OperatorChoice::Hand(p) => {
            p.validate()?;
            (
                Box::new(SimulatedOperator::new(script.clone(), specs.clone(), *p)),
                hand_name(p),
            )
        }
        OperatorChoice::ScriptHand if script.operator_kind == OperatorKind::Rigid => (
            Box::new(ScriptedDevice::new(script.clone(), specs.clone())),
            "rigid".into(),
        ),
        OperatorChoice::ScriptHand => {
            let p = script.operator.unwrap_or_default();
            (
                Box::new(SimulatedOperator::new(script.clone(), specs.clone(), p)),
                hand_name(&p),
            )
        }
    };
    let mode = if opts.realtime { "realtime" } else { "batch" };
    let description = DescriptionMsg {
        format: messages::FORMAT_VERSION.to_string(),
        scene_name: loaded.file.scene.name.clone(),
        scene_kind: loaded.scene.kind().to_string(),
        scene_toml: opts.scene.text.clone(),
        device_model: specs.name.to_string(),
        rate_hz: rate,
        mode: mode.to_string(),
        script_name: script.name.clone(),
        script_toml: script_text,
        operator,
        state_fields: fields.clone(),
    };
    let mut recorder = match &opts.out {
        Some(p) => Some(Recorder::create(
            p,
            RecorderSetup {
                description: description.clone(),
                flush_every_ns: 1_000_000_000,
            },
        )?),
        None => None,
    };
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let mut arrays = SessionArrays::new(rate, fields);
    arrays.reserve(ticks as usize);
    let mut sink = |t: TickMessages| -> Result<(), SessionError> {
        if let Some(rec) = recorder.as_mut() {
            // Arrays are decoded from the very bytes that are recorded.
            for m in &t.msgs {
                push_checked(&mut arrays, m)?;
            }
            rec.write(t)?;
        } else {
            for m in &t.msgs {
                push_checked(&mut arrays, m)?;
            }
        }
        Ok(())
    };
    let pacing = if opts.realtime {
        Pacing::Realtime
    } else {
        Pacing::Batch
    };
    let stats = drive(&mut lp, dev.as_mut(), ticks, pacing, &mut sink, progress)?;
    let written = match recorder {
        Some(mut r) => {
            r.metadata("session", stats_metadata(&stats, mode))?;
            Some(r.finish()?)
        }
        None => None,
    };
    Ok(SessionReport {
        description,
        arrays,
        stats,
        written,
    })
}

fn hand_name(p: &OperatorParams) -> String {
    format!(
        "hand ({} kg, {} N/m, {} N·s/m)",
        p.mass_kg, p.stiffness_n_per_m, p.damping_n_s_per_m
    )
}

fn push_checked(a: &mut SessionArrays, m: &OutMsg) -> Result<(), SessionError> {
    a.push(m.channel, &m.data).map_err(|e| {
        SessionError::Recording(RecordingError::BadMessage {
            topic: m.channel.topic().to_string(),
            log_time_ns: 0,
            detail: e.to_string(),
        })
    })
}
