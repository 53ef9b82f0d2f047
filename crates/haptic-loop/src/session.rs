//! Sessions: run a scene with a script (batch or real time), optionally record it, and get
//! per-tick arrays back; read a recording into the same arrays.
//!
//! ```no_run
//! use haptic_loop::session::{run_session, SceneSource, SessionOptions};
//! use haptic_devices::source::OperatorChoice;
//! let scene = SceneSource::from_path("scenes/wall.toml".as_ref()).unwrap();
//! let mut opts = SessionOptions::new(scene);
//! opts.operator = OperatorChoice::Hand(Default::default());
//! let report = run_session(&opts, &mut |_, _| {}).unwrap();
//! let peak = report.arrays.device_force_n.iter().map(|f| f[2]).fold(0.0, f64::max);
//! println!("{} ticks, peak force {peak} N", report.arrays.tick.len());
//! ```

use crate::live::LiveConfig;
use crate::scene::SceneFile;
use crate::setup::{Setup, SetupOptions};
use crate::sinks::{live_summary, start_live};
use haptic_devices::script::Script;
use haptic_devices::source::{DeviceSource, Driver, OperatorChoice, open_device};
use haptic_devices::{OperatorParams, ScriptError};
use haptic_engine::check::SceneError;
use haptic_engine::haptic::HapticLoop;
use haptic_engine::header::SessionHeader;
use haptic_engine::pacing::Pacing;
use haptic_engine::pacing::TickStats;
use haptic_engine::realtime::RtRequest;
use haptic_engine::runner::Runner;
use haptic_engine::totals::Totals;
use haptic_types::DeviceModel;
use haptic_types::Switch;
use haptic_types::TickTime;
use haptic_types::textpos::Location;
use haptic_types::textpos::field_position;
use haptic_types::value::ValueError;
use recording::WriteSummary;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use world_form::fmt_num;

pub use crate::arrays::SessionArrays;
pub use crate::error::SessionError;
pub use crate::record_sink::stats_metadata;
pub use crate::setup::{SceneSource, now_unix_ns, read_toml_text};

/// Options of a session.
#[derive(Clone, Debug)]
pub struct SessionOptions {
    /// The scene.
    pub scene: SceneSource,
    /// Script text; `None`: the scene's default script (local devices only).
    pub script: Option<String>,
    /// Where `script` came from, as errors name it (a path); `None`: `script`.
    pub script_origin: Option<String>,
    /// The device ([`DeviceSource::parse`]): a model overriding the scene file's, played by
    /// the script, or a device in another process over the UDP bridge instead of the script
    /// (it announces its own specifications); `None`: the scene's model.
    pub device: Option<DeviceSource>,
    /// How the script drives the device (local devices only).
    pub operator: OperatorChoice,
    /// Session length, s; `None`: the script's duration (a bridged device: until it says
    /// goodbye).
    pub seconds: Option<f64>,
    /// Pace ticks against the wall clock (a bridged device is always real time: its samples
    /// are the clock).
    pub realtime: bool,
    /// The real-time scheduling the tick thread asks for in a real-time session (default
    /// `SCHED_FIFO` 50, memory locked, pinned; see `haptic_engine::realtime`); `None`: ask for
    /// nothing (`--no-rt`). Batch sessions never ask.
    pub rt: Option<RtRequest>,
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
            script_origin: None,
            device: None,
            operator: OperatorChoice::ScriptHand,
            seconds: None,
            realtime: false,
            rt: Some(RtRequest::default()),
            out: None,
            live: None,
            arrays: true,
            start_time_ns: None,
        }
    }
}

/// What a session produced.
#[derive(Debug)]
pub struct SessionReport {
    /// The session's header (as recorded).
    pub header: SessionHeader,
    /// Per-tick arrays (empty when turned off).
    pub arrays: SessionArrays,
    /// Running totals (peak force, clamped and watchdog ticks, events, last state), kept
    /// whether or not the arrays are.
    pub totals: Totals,
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
    pub sinks: Vec<haptic_engine::runner::SinkTime>,
}

/// The script text for a local device (the given one or the scene's default script) and
/// where it came from, as errors name it (a path, `built-in NAME`, or `script`).
pub fn script_source(
    opts: &SessionOptions,
    file: &SceneFile,
) -> Result<(String, String), SessionError> {
    Ok(match &opts.script {
        Some(t) => (
            t.clone(),
            opts.script_origin
                .clone()
                .unwrap_or_else(|| "script".into()),
        ),
        None => {
            let rel = file
                .scene
                .default_script
                .as_ref()
                .ok_or(SessionError::NoScript)?;
            match opts.scene.scripts.iter().find(|(n, _)| n == rel) {
                Some((name, text)) => (text.clone(), format!("built-in {name}")),
                None => {
                    let p = match &opts.scene.dir {
                        Some(d) => d.join(rel),
                        None => PathBuf::from(rel),
                    };
                    let text = match read_toml_text(&p) {
                        Ok(t) => t,
                        Err(SessionError::Io { path, message }) => {
                            return Err(SessionError::DefaultScript {
                                at: Location {
                                    file: opts.scene.origin.clone(),
                                    at: field_position(&opts.scene.text, "scene.default_script"),
                                },
                                script: rel.clone(),
                                path,
                                message,
                            });
                        }
                        Err(e) => return Err(e),
                    };
                    (text, p.display().to_string())
                }
            }
        }
    })
}

/// Reads the script text for a local device (see [`script_source`]) and parses it; errors
/// name the file, line and column.
fn load_script(
    opts: &SessionOptions,
    file: &SceneFile,
    specs: &haptic_types::DeviceSpecs,
) -> Result<(Script, String, String), SessionError> {
    let (text, origin) = script_source(opts, file)?;
    let roles = file
        .device
        .roles_for(specs)
        .map_err(|e| opts.scene.locate(e))?;
    let script =
        Script::from_toml_with(&text, specs, &roles).map_err(|error| SessionError::ScriptFile {
            at: Location {
                at: error.position(&text),
                file: origin.clone(),
            },
            error: Box::new(error),
        })?;
    Ok((script, text, origin))
}

/// The first tick whose time (`n / rate_hz`, as the device sees it) is at or after `t_s`: the
/// tick a script event at `t_s` applies to.
pub fn tick_at(t_s: f64, rate_hz: u32) -> u64 {
    let mut n = (t_s * f64::from(rate_hz)).ceil().max(0.0) as u64;
    while n > 0 && TickTime::new(n - 1, rate_hz).time_s >= t_s {
        n -= 1;
    }
    while TickTime::new(n, rate_hz).time_s < t_s {
        n += 1;
    }
    n
}

/// A script's switches checked against the scene (errors name `switch[i].name` or
/// `switch[i].value` with the line and column) and turned into ticks.
fn script_switches(
    script: &Script,
    text: &str,
    origin: &str,
    scene: &dyn haptic_engine::scene::Scene,
    rate_hz: u32,
) -> Result<Vec<(u64, Switch)>, SessionError> {
    let mut out = Vec::with_capacity(script.switches.len());
    for sw in script.switches.iter() {
        if let Err(e) =
            haptic_types::switch::check(scene.kind(), scene.switches(), &sw.name, sw.value)
        {
            let i = sw.index;
            let field = match e {
                haptic_types::SwitchError::Unknown { .. } => format!("switch[{i}].name"),
                _ => format!("switch[{i}].value"),
            };
            return Err(SessionError::ScriptFile {
                at: Location {
                    at: field_position(text, &field),
                    file: origin.to_string(),
                },
                error: Box::new(ScriptError::Switch { field, source: e }),
            });
        }
        out.push((
            tick_at(sw.t_s, rate_hz),
            Switch {
                name: sw.name.clone(),
                value: sw.value,
            },
        ));
    }
    Ok(out)
}

/// The field a session length is named by in its errors.
const SESSION_LENGTH: &str = "session length [s]";

/// Validates a session length (s) and turns it into ticks at `rate_hz`: the length must be
/// finite, `0 < seconds ≤ 3600` and at least half a tick (it rounds to one tick or more).
pub fn ticks_for(seconds: f64, rate_hz: u32) -> Result<u64, SessionError> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0) {
        return Err(SessionError::Seconds(ValueError::out_of_range(
            SESSION_LENGTH,
            seconds,
            "0 < length ≤ 3600 s",
        )));
    }
    let ticks = (seconds * f64::from(rate_hz)).round() as u64;
    if ticks == 0 {
        let rate = f64::from(rate_hz);
        return Err(SessionError::Seconds(ValueError::out_of_range(
            SESSION_LENGTH,
            seconds,
            format!(
                "{} ≤ length ≤ 3600 s, one tick or more (a tick is {} ms at {rate_hz} Hz)",
                fmt_num(0.5 / rate),
                fmt_num(1e3 / rate)
            ),
        )));
    }
    Ok(ticks)
}

/// Runs a session (see the module example); `stop` ends it cleanly after the current tick.
pub fn run_session_until(
    opts: &SessionOptions,
    progress: &mut dyn FnMut(u64, u64),
    stop: Option<&AtomicBool>,
) -> Result<SessionReport, SessionError> {
    let file = opts.scene.parse()?;
    // One start time for the welcome and the description.
    let start_time_ns = opts.start_time_ns.unwrap_or_else(now_unix_ns);
    // 1. The device source: a script (rigid or through a simulated hand) or a bridged device,
    //    welcomed with the scene's rate, name and start time.
    let (driver, script) =
        match crate::setup::session_device(&file, opts.device.as_ref(), start_time_ns) {
            DeviceSource::Udp(b) => (Driver::Udp(b), None),
            DeviceSource::Model(model) => {
                let (script, text, origin) = load_script(opts, &file, model.specs())?;
                let driver = Driver::of_script(model, &opts.operator, &script)?;
                (driver, Some((script, text, origin)))
            }
        };
    let mut dev = open_device(&driver, script.as_ref().map(|s| &s.0))?;
    let result = run_with_device(
        opts,
        &driver,
        script,
        start_time_ns,
        dev.as_mut(),
        progress,
        stop,
    );
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
    driver: &Driver,
    script: Option<(Script, String, String)>,
    start_time_ns: u64,
    dev: &mut dyn haptic_types::HapticDevice,
    progress: &mut dyn FnMut(u64, u64),
    stop: Option<&AtomicBool>,
) -> Result<SessionReport, SessionError> {
    // The live view serves from the start: a viewer may connect before a bridged device's
    // hello arrives.
    let live = start_live(opts.live.as_ref())?;
    dev.open()?;
    let bridged = matches!(driver, Driver::Udp(_));
    let mode = if bridged || opts.realtime {
        "realtime"
    } else {
        "batch"
    };
    let setup = Setup::new(&SetupOptions {
        operator: Some(driver.describe()),
        script: script.as_ref().map(|(s, t, _)| (s.name.clone(), t.clone())),
        start_time_ns: Some(start_time_ns),
        keep_arrays: opts.arrays,
        out: opts.out.clone(),
        ..SetupOptions::new(&opts.scene, dev.specs().clone(), mode, &driver.link_name())
    })?;
    let rate = setup.rate_hz();
    let ticks = match (opts.seconds, &script) {
        (Some(s), _) => Some(ticks_for(s, rate)?),
        (None, Some((s, _, _))) => Some(ticks_for(s.duration_s, rate)?),
        (None, None) => None,
    };
    let switches = match &script {
        Some((s, text, origin)) => script_switches(s, text, origin, setup.lp.scene(), rate)?,
        None => Vec::new(),
    };
    let Setup {
        mut lp,
        header,
        mut sinks,
    } = setup;
    sinks.live = live;
    let pacing = if bridged {
        Pacing::DeviceClock
    } else if opts.realtime {
        Pacing::Realtime
    } else {
        Pacing::Batch
    };
    // The live view's menu (Foxglove's Parameters): switches set there are applied before
    // the next tick's step and recorded as that tick's switches.
    let menu = sinks.menu();
    let mut apply_menu = |_tick: u64, lp: &mut HapticLoop| {
        let Some(Ok(mut m)) = menu.as_ref().map(|m| m.try_lock()) else {
            return;
        };
        for (name, value) in m.take() {
            if lp.switch(&name, value).is_err() {
                // The world refused it: the menu shows what is in force.
                if let Some(v) = lp.scene().switch_value(&name) {
                    m.set_value(&name, v);
                }
            }
        }
    };
    let mut runner = Runner::new(sinks.list())
        .with_switches(switches)
        .with_realtime(opts.rt);
    if menu.is_some() {
        runner = runner.with_live(&mut apply_menu);
    }
    if let Some(f) = stop {
        runner = runner.stop_on(f);
    }
    let (stats, end) = runner.run(&mut lp, dev, &header, ticks, pacing, progress)?;
    let sink_times = runner.sink_times();
    drop(runner);
    if stats.ticks == 0 {
        return Err(SessionError::Option(
            "the session ended before its first tick (no device sample arrived)".into(),
        ));
    }
    let written = sinks.written();
    Ok(SessionReport {
        header,
        arrays: sinks.arrays,
        totals: sinks.totals,
        stats,
        written,
        end: end.name(),
        link: dev.link_counters(),
        live: live_summary(sinks.live),
        sinks: sink_times,
    })
}

/// Reads a recording file into arrays (`salvage`: accept a truncated file's complete part).
pub fn read_arrays(path: &Path, salvage: bool) -> Result<SessionArrays, SessionError> {
    let rec = recording::read_recording_file(path, salvage)?;
    Ok(SessionArrays::from_recording(&rec)?)
}

/// The operator by the name the command line's `--operator` and Python's `operator=` both
/// take: `rigid` (the stylus follows the script exactly), `hand` (as the script says: the
/// simulated hand with the script's `[operator]` parameters or the defaults, or a rigid
/// stylus for a script with `operator = "rigid"`), or `hand:key=value,...` (a simulated hand
/// with the default parameters changed: `mass_kg`, `stiffness_n_per_m`,
/// `damping_n_s_per_m`, `yield_force_n`, each checked against its range).
pub fn parse_operator(name: &str) -> Result<OperatorChoice, SessionError> {
    match (name, name.strip_prefix("hand:")) {
        ("rigid", _) => Ok(OperatorChoice::Rigid),
        ("hand", _) => Ok(OperatorChoice::ScriptHand),
        (_, Some(kv)) => Ok(OperatorChoice::Hand(
            OperatorParams::default().with_overrides(kv)?,
        )),
        (_, None) => Err(SessionError::Option(format!(
            "operator `{name}` is not one of: rigid, hand, hand:key=value,..."
        ))),
    }
}

/// A scene and its script made ready to run anywhere (see [`resolve`]).
#[derive(Clone, Debug)]
pub struct Resolved {
    /// The scene, its text with the scene overrides applied.
    pub source: SceneSource,
    /// The script's TOML text with the `operator.*` overrides applied.
    pub script: String,
    /// The scene file, parsed.
    pub file: SceneFile,
    /// The device model it runs with: the one asked for, or else the scene's.
    pub model: DeviceModel,
}

/// The scene `source` and its script (`script`: its text and where it came from; `None`: the
/// scene's default script) with `overrides` applied in order (dotted field name → value;
/// names under `operator` change the script's simulated hand, the others the scene; see
/// [`crate::scene::overrides`]), every field checked as a session would load it for `device`
/// (`None`: the scene's): names, types and ranges. Without overrides an error names the file,
/// line and column; with them, the overridden field by its dotted name.
pub fn resolve(
    mut source: SceneSource,
    script: Option<(String, String)>,
    overrides: &[(String, toml::Value)],
    device: Option<DeviceModel>,
) -> Result<Resolved, SessionError> {
    use crate::scene::overrides::{
        OverrideError, is_script_field, override_scene, override_script,
    };
    let from = |e: OverrideError| match e {
        OverrideError::Scene(e) => SessionError::Scene(e),
        OverrideError::Script(e) => SessionError::Script(e),
        field => SessionError::Option(field.to_string()),
    };
    let (script_ov, scene_ov): (Vec<_>, Vec<_>) = overrides
        .iter()
        .cloned()
        .partition(|(k, _)| is_script_field(k));
    // The file as read: its errors name the file, line and column.
    source.parse()?;
    source.text = override_scene(&source.text, &scene_ov).map_err(from)?;
    let located = scene_ov.is_empty();
    let scene_err = |e: SceneError| {
        if located {
            source.locate(e)
        } else {
            SessionError::Scene(e)
        }
    };
    let file = SceneFile::parse(&source.text).map_err(scene_err)?;
    let model = device.unwrap_or(file.device.model);
    // Ranges: the scene's own validation, as for a scene file.
    crate::scene::load_scene(&source.text, Some(model)).map_err(scene_err)?;
    let (base, origin) = match script {
        Some(t) => t,
        None => script_source(&SessionOptions::new(source.clone()), &file)?,
    };
    let specs = model.specs();
    Script::from_toml(&base, specs).map_err(|error| SessionError::ScriptFile {
        at: Location {
            at: error.position(&base),
            file: origin,
        },
        error: Box::new(error),
    })?;
    let script = override_script(&base, &script_ov, specs).map_err(from)?;
    Script::from_toml(&script, specs)?;
    Ok(Resolved {
        source,
        script,
        file,
        model,
    })
}
