//! Sessions of the haptic loop (`haptic-loop`): run a scene with a script and
//! get per-tick arrays back; read an MCAP recording into the same arrays.

use haptic_devices::source::OperatorChoice;
use haptic_devices::source::{DEVICE_FORMS, DeviceNameError, DeviceSource};
use haptic_loop::scene::overrides::{is_script_field, override_scene};
use haptic_loop::session::{
    Resolved, SceneSource, SessionArrays, SessionError, SessionOptions, parse_operator,
    read_arrays, read_toml_text, run_session_until,
};
use haptic_types::DeviceModel;
use haptic_types::value::{ValueError, out_of_range};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use recording::RecordingError;
use recording::channels::declare::ColumnData;
use std::path::PathBuf;

use crate::convert::{array2_flat, value_error};
use crate::json::{from_py, py_to_toml, to_py};

/// File errors as `OSError`, everything else (bad scene, script, options,
/// corrupt recording) as `ValueError`, with the crate's text.
pub(crate) fn session_error(e: SessionError) -> PyErr {
    match e {
        SessionError::Io { .. }
        | SessionError::DefaultScript { .. }
        | SessionError::Recording(RecordingError::Io { .. }) => PyOSError::new_err(e.to_string()),
        // Creating or writing the recording (a full disk): OSError with the OS's errno, the
        // path and the ticks that reached the disk in its text.
        SessionError::Record(r) => match r.os_code() {
            Some(code) => PyOSError::new_err((code, r.to_string())),
            None => PyOSError::new_err(r.to_string()),
        },
        other => PyValueError::new_err(other.to_string()),
    }
}

pub(crate) fn path_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<PathBuf> {
    obj.extract::<PathBuf>()
        .map_err(|_| PyValueError::new_err(format!("{name}: expected a path (str or os.PathLike)")))
}

/// Per-tick arrays as a dict of numpy arrays: every declared column
/// (`recording::channels::messages::TickColumns`) by its element type (integers as int64,
/// `float64[3]` as (T, 3), `float64[9]` as (T, 3, 3), the scene state as (T, F)), plus
/// `rate_hz`, `state_fields`, `time_s` and `events`.
pub(crate) fn arrays_to_py<'py>(py: Python<'py>, a: SessionArrays) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = a.tick.len();
    let fields = a.state_fields.len();
    d.set_item("rate_hz", a.rate_hz)?;
    d.set_item("time_s", PyArray1::from_vec(py, a.time_s()))?;
    for (info, data) in a.columns.columns() {
        let int = |v: Vec<i64>| PyArray1::from_vec(py, v).into_any();
        let arr = match data {
            ColumnData::U8(v) => PyArray1::from_slice(py, v).into_any(),
            ColumnData::Bool(v) => PyArray1::from_slice(py, v).into_any(),
            ColumnData::U32(v) => int(v.iter().map(|&x| i64::from(x)).collect()),
            // Tick indices, counters and durations in ns stay far below 2^63.
            ColumnData::U64(v) => int(v.iter().map(|&x| x as i64).collect()),
            ColumnData::I64(v) => PyArray1::from_slice(py, v).into_any(),
            ColumnData::F64(v) => PyArray1::from_slice(py, v).into_any(),
            ColumnData::Vec3(v) => {
                array2_flat(py, v.iter().flatten().copied().collect(), 3)?.into_any()
            }
            ColumnData::Mat3(v) => {
                let k: Vec<f64> = v.iter().flatten().copied().collect();
                PyArray1::from_vec(py, k)
                    .reshape([v.len(), 3, 3])?
                    .into_any()
            }
            ColumnData::Table(v) => {
                let rows = v.len().checked_div(fields).unwrap_or(n);
                PyArray1::from_slice(py, v)
                    .reshape([rows, fields])?
                    .into_any()
            }
        };
        d.set_item(info.name, arr)?;
    }
    d.set_item("state_fields", a.state_fields)?;
    let ev = PyList::empty(py);
    for (t, name, detail) in a.events {
        ev.append((t, name, detail))?;
    }
    d.set_item("events", ev)?;
    Ok(d)
}

/// The `operator` argument: None (`hand`, the default), a name as the command line's
/// `--operator` takes it (`rigid`, `hand`, `hand:key=value,...`: one parser,
/// [`parse_operator`]), or a dict of hand parameters (`hand:` with those values).
fn operator_from_py(obj: Option<&Bound<'_, PyAny>>) -> PyResult<OperatorChoice> {
    let Some(obj) = obj else {
        return Ok(OperatorChoice::ScriptHand);
    };
    if let Ok(s) = obj.cast::<PyString>() {
        return parse_operator(&s.to_cow()?).map_err(session_error);
    }
    Ok(OperatorChoice::Hand(from_py(obj, "operator")?))
}

/// The `device` argument ([`DeviceSource::parse`]): a model name, or `udp:HOST:PORT` /
/// `udp:PORT` for a device in another process; `None`: the scene's model.
pub(crate) fn device_from_py(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<DeviceSource>> {
    let Some(o) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let name: String = o
        .extract()
        .map_err(|_| PyValueError::new_err(format!("device: allowed {DEVICE_FORMS}")))?;
    DeviceSource::parse(&name).map(Some).map_err(|e| match e {
        DeviceNameError::Unknown(_) => {
            PyValueError::new_err(format!("device = {name:?}: allowed {DEVICE_FORMS}"))
        }
        DeviceNameError::Address(m) => PyValueError::new_err(format!("device = {name:?}: {m}")),
    })
}

type Overrides = Vec<(String, toml::Value)>;

/// The error for an `overrides` argument that is not a dict: the form it takes.
const OVERRIDES_FORM: &str = concat!(
    "overrides: expected a dict of dotted field names to values, e.g. ",
    r#"{"optical_tweezers.stiffness_n_per_m": 0.4, "loop.rate_hz": 2000}"#,
);

/// The `overrides` argument: a dict of dotted field name → value, in the dict's order.
fn overrides_from_py(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Overrides> {
    let mut out = Vec::new();
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(out);
    };
    let d = obj
        .cast::<PyDict>()
        .map_err(|_| PyValueError::new_err(OVERRIDES_FORM))?;
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "overrides: keys must be dotted field names (str), got {k}"
            ))
        })?;
        let value = py_to_toml(&v, &format!("overrides[{key:?}]"))?;
        out.push((key, value));
    }
    Ok(out)
}

/// The scene argument: a path or built-in name, or a dict of `resolve_scene` (its scene and
/// script texts).
fn scene_source(scene: &Bound<'_, PyAny>) -> PyResult<(SceneSource, Option<String>)> {
    let Ok(d) = scene.cast::<PyDict>() else {
        let source = SceneSource::resolve(&path_arg(scene, "scene")?).map_err(session_error)?;
        return Ok((source, None));
    };
    let text = |key: &str| -> PyResult<Option<String>> {
        match d.get_item(key)? {
            Some(v) if !v.is_none() => Ok(Some(v.extract().map_err(|_| {
                PyValueError::new_err(format!("scene[{key:?}]: expected a str of TOML"))
            })?)),
            _ => Ok(None),
        }
    };
    let scene_toml = text("scene_toml")?.ok_or_else(|| {
        PyValueError::new_err(
            "scene: a dict scene needs \"scene_toml\" (and \"script_toml\"), as resolve_scene returns",
        )
    })?;
    let source = SceneSource::from_text(scene_toml, "scene_toml");
    Ok((source, text("script_toml")?))
}

/// `scene` (a path, a built-in name, or a dict of `resolve_scene`) and `script`, with
/// `overrides` applied and every field checked by the engine's resolution
/// ([`haptic_loop::session::resolve`]).
pub(crate) fn resolve(
    scene: &Bound<'_, PyAny>,
    script: Option<&Bound<'_, PyAny>>,
    overrides: Option<&Bound<'_, PyAny>>,
    device: Option<DeviceModel>,
) -> PyResult<Resolved> {
    let (source, script_toml) = scene_source(scene)?;
    let script = match script {
        Some(s) => {
            let p = path_arg(s, "script")?;
            let text = read_toml_text(&p).map_err(session_error)?;
            Some((text, p.display().to_string()))
        }
        None => script_toml.map(|t| (t, "script_toml".to_string())),
    };
    let overrides = overrides_from_py(overrides)?;
    haptic_loop::session::resolve(source, script, &overrides, device).map_err(session_error)
}

/// A scene ready to run anywhere: its files read and `overrides` applied and validated
/// here, so that a sweep fails before its first run and a worker on another machine needs no
/// files.
///
/// Args:
///     scene: path to a scene TOML file, a built-in scene name, or a dict
///         returned by this function (overrides are then applied on top).
///     script: path to a script TOML file; default: the scene's
///         ``default_script``.
///     overrides: dict of dotted field name → value, e.g.
///         ``{"optical_tweezers.stiffness_n_per_m": 0.4, "loop.rate_hz": 2000}``;
///         ``operator.*`` names change the simulated hand (the script's
///         ``[operator]`` table: mass_kg, stiffness_n_per_m,
///         damping_n_s_per_m, yield_force_n).
///     device: None (the scene's), "falcon" or "touch" (ranges such as the
///         stiffness cap depend on it).
///
/// Returns:
///     dict: "name", "kind", "device", "scene_toml", "script_toml" (str),
///     plain data that pickles; pass it to :func:`run_scene` or :func:`sweep`.
///
/// Raises ValueError naming the field: an unknown name (with the valid names
/// at that level), a wrong type, or a value out of the field's range (the
/// same errors as a scene file's).
#[pyfunction]
#[pyo3(signature = (scene, *, script=None, overrides=None, device=None))]
pub fn resolve_scene<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    script: Option<&Bound<'py, PyAny>>,
    overrides: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let model = match device_from_py(device)? {
        None => None,
        Some(DeviceSource::Model(m)) => Some(m),
        Some(DeviceSource::Udp(_)) => {
            return Err(PyValueError::new_err(
                "device: resolve_scene takes \"falcon\" or \"touch\" (a bridged device announces its own)",
            ));
        }
    };
    let r = resolve(scene, script, overrides, model)?;
    let d = PyDict::new(py);
    d.set_item("name", &r.file.scene.name)?;
    d.set_item("kind", &r.file.scene.kind)?;
    d.set_item("device", r.model.name())?;
    d.set_item("scene_toml", &r.source.text)?;
    d.set_item("script_toml", &r.script)?;
    Ok(d)
}

/// Run a scene of the haptic loop in batch mode (no wall clock) with a
/// script driving the device, and return every tick as arrays.
///
/// Args:
///     scene: path to a scene TOML file (``scenes/*.toml``), a built-in scene
///         name, or a dict of :func:`resolve_scene`.
///     script: path to a script TOML file; default: the scene's
///         ``default_script``.
///     seconds: session length (s), 0 < seconds <= 3600; default: the
///         script's duration.
///     operator: as the command line's ``--operator``: "hand" (default: as
///         the script says, a simulated hand pushed by the rendered force with
///         the script's ``[operator]`` parameters or the defaults, or a rigid
///         stylus for a script with ``operator = "rigid"``), "rigid" (the
///         stylus follows the script exactly), "hand:key=value,..." (a
///         simulated hand with those of mass_kg, stiffness_n_per_m,
///         damping_n_s_per_m, yield_force_n changed from the defaults), or a
///         dict of those hand parameters (the same as "hand:...").
///     device: None (the scene's), "falcon", "touch", "udp:HOST:PORT" or "udp:PORT":
///         wait there for a device in another process (see
///         ``nanohaptics.bridge``) and run in real time against it until it
///         says goodbye or ``seconds`` pass.
///     out: path of an MCAP recording to write, or None.
///     wait_s: how long to wait for a bridged device's hello, s.
///     overrides: dict of dotted field name → value changing the scene (and,
///         with ``operator.*`` names, the simulated hand), validated as in
///         :func:`resolve_scene`.
///     rt_priority: the SCHED_FIFO priority (1–99) the tick thread asks for
///         in a real-time session (a bridged device), with memory locked and
///         a core of its own; None asks for nothing (the command line's
///         ``--no-rt``). A refusal is said once on stderr with its fix;
///         ``stats["realtime"]`` says what was granted and
///         ``stats["wakeup"]`` how late the thread woke (ns).
///
/// Returns:
///     dict: "rate_hz", "state_fields" (names of the state columns), per-tick
///     arrays "tick", "time_s", "device_position_m" (T, 3) (device frame),
///     "device_buttons" (T,) bits, "deadline_missed", "cursor_m" (T, 3)
///     (world frame), "state" (T, F), "world_force_n" (T, 3),
///     "device_force_n" (T, 3) (force sent, device frame), "engagement",
///     "status", "compute_ns" (wall clock, not reproducible),
///     "start_late_ns", "events" [(tick, name, detail)], and "stats" (tick
///     timing). The GIL is released while the session runs.
#[pyfunction]
#[allow(clippy::too_many_arguments)] // Python keyword arguments
#[pyo3(signature = (scene, *, script=None, seconds=None, operator=None, device=None, out=None, wait_s=120.0, overrides=None, rt_priority=Some(i64::from(haptic_engine::realtime::DEFAULT_PRIORITY))))]
pub fn run_scene<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    script: Option<&Bound<'py, PyAny>>,
    seconds: Option<f64>,
    operator: Option<&Bound<'py, PyAny>>,
    device: Option<&Bound<'py, PyAny>>,
    out: Option<&Bound<'py, PyAny>>,
    wait_s: f64,
    overrides: Option<&Bound<'py, PyAny>>,
    rt_priority: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let rt = rt_priority
        .map(haptic_engine::realtime::RtRequest::with_priority)
        .transpose()
        .map_err(|e| value_error(e.map_field(|_| "rt_priority".into())))?;
    if !(wait_s.is_finite() && (0.0..=86400.0).contains(&wait_s)) {
        return Err(value_error(ValueError::out_of_range(
            "wait_s",
            wait_s,
            "0–86400 s",
        )));
    }
    let mut opts = match device_from_py(device)? {
        Some(DeviceSource::Udp(mut b)) => {
            // A device in another process: no script, so only the scene's fields change.
            let ov = overrides_from_py(overrides)?;
            if let Some((k, _)) = ov.iter().find(|(k, _)| is_script_field(k)) {
                return Err(PyValueError::new_err(format!(
                    "override `{k}`: the simulated hand is not used with a bridged device"
                )));
            }
            let (mut source, _) = scene_source(scene)?;
            source.text = override_scene(&source.text, &ov).map_err(value_error)?;
            b.wait_s = wait_s;
            let mut opts = SessionOptions::new(source);
            opts.device = Some(DeviceSource::Udp(b));
            opts
        }
        model => {
            let m = match model {
                Some(DeviceSource::Model(m)) => Some(m),
                _ => None,
            };
            let r = resolve(scene, script, overrides, m)?;
            let mut opts = SessionOptions::new(r.source);
            opts.script = Some(r.script);
            opts.device = model;
            opts
        }
    };
    opts.seconds = seconds;
    opts.rt = rt;
    opts.operator = operator_from_py(operator)?;
    opts.out = match out {
        Some(o) => Some(path_arg(o, "out")?),
        None => None,
    };
    // Ctrl-C stops the session after its current tick (the recording is finished and
    // verifiable) and raises KeyboardInterrupt.
    let report = crate::interrupt::interruptible(py, |stop| {
        run_session_until(&opts, &mut |_, _| {}, Some(stop.as_ref()))
    })?
    .map_err(session_error)?;
    let stats = to_py(py, &report.stats)?;
    let link: std::collections::BTreeMap<&str, u64> = report.link.iter().copied().collect();
    stats.set_item("link", to_py(py, &link)?)?;
    stats.set_item("end", report.end)?;
    stats.set_item("sinks", to_py(py, &report.sinks)?)?;
    let d = arrays_to_py(py, report.arrays)?;
    d.set_item("stats", stats)?;
    Ok(d)
}

/// Read an MCAP recording of the haptic loop into the per-tick arrays of
/// :func:`run_scene` (without "stats").
///
/// Args:
///     path: the recording.
///     salvage: accept a truncated file's complete part instead of failing.
///
/// Raises OSError when the file cannot be read and ValueError when it is not
/// a valid recording (naming what is wrong).
#[pyfunction]
#[pyo3(signature = (path, *, salvage=false))]
pub fn read_recording<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    salvage: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let p = path_arg(path, "path")?;
    let a = py
        .detach(|| read_arrays(&p, salvage))
        .map_err(session_error)?;
    arrays_to_py(py, a)
}

/// The sound of a recorded session, as `nanohaptics render REC --audio` writes
/// it: an impact sound per collision (loudness from its impulse), a click at
/// snap-to-contact and another at pull-off, and with ``proximity`` a tone whose
/// pitch rises as the cursor nears the nearest object.
///
/// Args:
///     path: the recording (MCAP).
///     proximity: add the proximity tone (brick and nano worlds).
///     sample_rate: Hz, 8000–192000.
///     out: also write a 16-bit WAV file there.
///
/// Returns (samples, sample_rate): float32 mono samples in [-0.98, 0.98].
/// Raises OSError when the file cannot be read and ValueError for a bad
/// recording or argument (naming it).
#[pyfunction]
#[pyo3(signature = (path, *, proximity=false, sample_rate=44100, out=None))]
pub fn render_audio<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    proximity: bool,
    #[pyo3(from_py_with = crate::convert::sample_rate_arg)] sample_rate: i64,
    out: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyArray1<f32>>, u32)> {
    let p = path_arg(path, "path")?;
    let out = out.map(|o| path_arg(o, "out")).transpose()?;
    if !(8_000..=192_000).contains(&sample_rate) {
        return Err(PyValueError::new_err(out_of_range(
            "sample_rate",
            sample_rate,
            crate::convert::SAMPLE_RATES,
        )));
    }
    let rate = sample_rate as u32;
    let s = py.detach(|| -> PyResult<_> {
        let rec = recording::read_recording_file(&p, false)
            .map_err(|e| session_error(SessionError::from(e)))?;
        let arrays = haptic_loop::session::SessionArrays::from_recording(&rec)
            .map_err(|e| session_error(SessionError::from(e)))?;
        let s = haptic_loop::sound::session_sound(
            &arrays,
            &rec.description.scene_kind,
            proximity,
            rate,
        )
        .map_err(value_error)?;
        if let Some(o) = &out {
            s.write_wav(o)
                .map_err(|e| PyOSError::new_err(e.to_string()))?;
        }
        Ok(s)
    })?;
    Ok((PyArray1::from_vec(py, s.samples), rate))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use haptic_devices::OperatorParams;
    use haptic_devices::source::OperatorChoice;
    use haptic_loop::session::{SceneSource, parse_operator, resolve};
    use toml::Value;

    #[test]
    fn operator_names_are_the_command_lines() {
        assert_eq!(parse_operator("rigid").unwrap(), OperatorChoice::Rigid);
        assert_eq!(parse_operator("hand").unwrap(), OperatorChoice::ScriptHand);
        assert_eq!(
            parse_operator("hand:stiffness_n_per_m=100,yield_force_n=0.5").unwrap(),
            OperatorChoice::Hand(OperatorParams {
                stiffness_n_per_m: 100.0,
                yield_force_n: 0.5,
                ..OperatorParams::default()
            })
        );
        let err = |s: &str| parse_operator(s).unwrap_err().to_string();
        assert_eq!(
            err("script"),
            "operator `script` is not one of: rigid, hand, hand:key=value,..."
        );
        assert_eq!(
            err("hand:mass_kg=20"),
            "script: `mass_kg` = 20 is out of range: allowed 0.01 ≤ mass_kg ≤ 10"
        );
    }

    #[test]
    fn overrides_go_to_the_scene_or_the_simulated_hand_by_name() {
        let wall = SceneSource::builtin("wall").unwrap();
        let ov = [
            (
                "operator.stiffness_n_per_m".to_string(),
                Value::Float(150.0),
            ),
            ("loop.rate_hz".to_string(), Value::Integer(2000)),
        ];
        let r = resolve(wall.clone(), None, &ov, None).unwrap();
        assert!(
            r.source
                .text
                .starts_with("# scene with overrides: loop.rate_hz = 2000\n")
        );
        assert!(
            r.script
                .starts_with("# script with overrides: operator.stiffness_n_per_m = 150.0\n")
        );
        assert_eq!(r.file.loop_.rate_hz, 2000);
        // No overrides: the files as written, the scene's device.
        let r = resolve(wall.clone(), None, &[], None).unwrap();
        assert_eq!(r.source.text, wall.text);
        assert_eq!(r.model, haptic_types::DeviceModel::Falcon);
        // A range error: the scene's own, naming the field.
        let e = resolve(
            wall,
            None,
            &[ov[1].clone(), ("loop.rate_hz".into(), Value::Integer(999))],
            None,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("scene: `loop.rate_hz` = 999 is out of range"),
            "{e}"
        );
    }
}
