//! `nanohaptics.Session`: the haptic loop stepped one tick at a time from Python (as
//! `mujoco.mj_step` is), with the same sinks as every session (MCAP recorder, per-tick arrays).
//! A Python driver, a notebook or a test hands in each device reading and gets the force back.

use haptic_devices::source::DeviceSource;
use haptic_loop::session::SceneSource;
use haptic_loop::stepper::{Stepper, StepperOptions};
use haptic_types::Buttons;
use haptic_types::DeviceSample;
use haptic_types::value::out_of_range;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use std::sync::{Mutex, PoisonError};

use crate::convert::numbers;
use crate::json::to_py;
use crate::session::{arrays_to_py, path_arg, session_error};

/// A haptic-loop session stepped one tick at a time from Python.
///
/// Args:
///     scene: path to a scene TOML file.
///     device: None (the scene's), "falcon" or "touch": its limits (force,
///         stiffness, workspace, buttons) apply.
///     out: path of an MCAP recording to write, or None. The recording
///         replays bit for bit (``nanohaptics replay OUT --verify``).
///     arrays: keep the per-tick arrays (returned by :meth:`close`).
///
/// Each :meth:`tick` takes the device reading (position in metres, device
/// frame; buttons) and returns the force to render (N, device frame): finite
/// and within the device's maximum, zero on an invalid reading.
///
/// A session may be used, and dropped, from any thread (one call at a time).
#[pyclass(module = "nanohaptics")]
pub struct Session {
    // A Mutex makes the session `Sync`, as pyo3 asks of a class any thread may reach; the
    // calls that change it hold `&mut self` and take it without locking.
    inner: Mutex<Option<Stepper>>,
}

impl Session {
    /// What `f` reads from the open session's stepper (a closed session raises RuntimeError).
    /// `f` makes no Python object: Python runs nothing (no finalizer that might call this
    /// session again) while the lock is held.
    fn read<R>(&self, f: impl FnOnce(&Stepper) -> R) -> PyResult<R> {
        // A panic while the lock was held cannot leave a stepper half-changed for a reader
        // here (only `&mut self` calls change it, without the lock): take it back.
        let guard = self.inner.lock().unwrap_or_else(PoisonError::into_inner);
        guard
            .as_ref()
            .map(f)
            .ok_or_else(|| PyRuntimeError::new_err("the session is closed"))
    }

    /// The open session's stepper, to change (a closed session raises RuntimeError).
    fn stepper_mut(&mut self) -> PyResult<&mut Stepper> {
        self.inner
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("the session is closed"))
    }
}

fn buttons_arg(obj: Option<&Bound<'_, PyAny>>, names: &[String]) -> PyResult<u32> {
    let Some(obj) = obj else {
        return Ok(0);
    };
    if let Ok(bits) = obj.extract::<i64>() {
        let allowed = if names.len() >= 32 {
            u32::MAX as i64
        } else {
            (1i64 << names.len()) - 1
        };
        if !(0..=allowed).contains(&bits) {
            return Err(PyValueError::new_err(out_of_range(
                "buttons",
                bits,
                &format!("0–{allowed} (bit i is button i: {})", names.join(", ")),
            )));
        }
        return Ok(bits as u32);
    }
    let mut bits = 0u32;
    for item in obj.try_iter().map_err(|_| {
        PyValueError::new_err(format!(
            "buttons: expected an int (bits) or a list of button names ({})",
            names.join(", ")
        ))
    })? {
        let item = item?;
        let name = item.cast::<PyString>().map_err(|_| {
            PyValueError::new_err(format!(
                "buttons: expected button names ({}), got {}",
                names.join(", "),
                item.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?;
        let n: String = name.extract()?;
        let n = n.as_str();
        let i = names.iter().position(|b| b == n).ok_or_else(|| {
            PyValueError::new_err(format!(
                "buttons: no button {n:?} on this device (allowed: {})",
                names.join(", ")
            ))
        })?;
        bits |= 1 << i;
    }
    Ok(bits)
}

#[pymethods]
impl Session {
    #[new]
    #[pyo3(signature = (scene, *, device=None, out=None, arrays=true))]
    fn new(
        scene: &Bound<'_, PyAny>,
        device: Option<&Bound<'_, PyAny>>,
        out: Option<&Bound<'_, PyAny>>,
        arrays: bool,
    ) -> PyResult<Self> {
        let source = SceneSource::resolve(&path_arg(scene, "scene")?).map_err(session_error)?;
        let mut o = StepperOptions::new(source);
        o.device = match crate::session::device_from_py(device)? {
            None => None,
            Some(DeviceSource::Model(m)) => Some(m),
            Some(DeviceSource::Udp(_)) => {
                return Err(PyValueError::new_err(format!(
                    "device = {:?}: a stepped session is driven by its caller, so its device \
                     is a model: allowed falcon or touch (a bridged device runs with run_scene)",
                    device.map(|d| d.to_string()).unwrap_or_default()
                )));
            }
        };
        o.out = out.map(|p| path_arg(p, "out")).transpose()?;
        o.arrays = arrays;
        Ok(Session {
            inner: Mutex::new(Some(Stepper::new(o).map_err(session_error)?)),
        })
    }

    /// Runs one tick with the device at ``position`` (3,) m (device frame)
    /// and ``buttons`` (int bits, or a list of button names); returns the
    /// force to render, (3,) N, device frame.
    #[pyo3(signature = (position, buttons=None))]
    fn tick<'py>(
        &mut self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        buttons: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = numbers(position, "position")?;
        if p.shape != [3] {
            return Err(PyValueError::new_err(format!(
                "position: expected shape (3,) in metres, got {} values",
                p.data.len()
            )));
        }
        let s = self.stepper_mut()?;
        let names: Vec<String> = s
            .haptic_loop()
            .config()
            .specs
            .button_names
            .iter()
            .map(|b| b.to_string())
            .collect();
        let bits = buttons_arg(buttons, &names)?;
        let r = s
            .tick(DeviceSample::new(
                [p.data[0], p.data[1], p.data[2]],
                Buttons(bits),
            ))
            .map_err(session_error)?;
        Ok(PyArray1::from_slice(py, &r.device_force_n))
    }

    /// Sets a run-time switch of the scene before the next tick (the
    /// teaching game's menu: ``gravity_m_per_s2``, ``friction``, ``inertia``,
    /// ``adhesion_scale``, ``atom_mass_kg``, ...), recorded as that tick's
    /// input. ``value``: a number, or True / False for on/off switches.
    ///
    /// Raises ValueError naming the switch and its allowed range.
    fn switch(&mut self, name: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let v: f64 = if let Ok(b) = value.cast::<pyo3::types::PyBool>() {
            f64::from(u8::from(b.is_true()))
        } else {
            value.extract::<f64>().map_err(|_| {
                PyValueError::new_err(format!("switch `{name}`: value must be a number or a bool"))
            })?
        };
        self.stepper_mut()?.switch(name, v).map_err(session_error)
    }

    /// Local stiffness sent with the last force, (3, 3) N/m, device frame.
    #[getter]
    fn stiffness<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let k = self.read(|s| s.haptic_loop().last_result().device_stiffness_n_per_m)?;
        PyArray1::from_slice(py, &k).reshape([3, 3])
    }

    /// Status bits of the last tick (1 clamped, 2 input invalid, 4 deadline
    /// missed, 8 stiffness over cap, 16 force invalid, 32 watchdog, 64 passivity
    /// controller, 128 force-rate limit).
    #[getter]
    fn status(&self) -> PyResult<u8> {
        self.read(|s| s.haptic_loop().last_result().status)
    }

    /// Events of the last tick: [(name, detail)].
    #[getter]
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let events = self.read(|s| s.haptic_loop().last_result().events.clone())?;
        let l = PyList::empty(py);
        for e in &events {
            l.append((e.name.as_str(), e.detail.as_str()))?;
        }
        Ok(l)
    }

    /// Cursor of the last tick, (3,) m, world frame.
    #[getter]
    fn cursor<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let c = self.read(|s| s.haptic_loop().last_result().cursor_m)?;
        Ok(PyArray1::from_slice(py, &c))
    }

    /// The scene's state after the last tick: {field: value}.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (fields, values) = self.read(|s| {
            let lp = s.haptic_loop();
            let mut v = Vec::new();
            lp.scene_state(&mut v);
            (lp.scene().state_fields(), v)
        })?;
        let d = PyDict::new(py);
        for (k, x) in fields.into_iter().zip(values) {
            d.set_item(k, x)?;
        }
        Ok(d)
    }

    /// Index of the next tick.
    #[getter]
    fn tick_index(&self) -> PyResult<u64> {
        self.read(|s| s.haptic_loop().next_tick())
    }

    /// Tick rate, Hz.
    #[getter]
    fn rate_hz(&self) -> PyResult<u32> {
        self.read(|s| s.haptic_loop().config().rate_hz)
    }

    /// The device's specifications: name, max_force_n, max_stiffness_n_per_m,
    /// workspace_radius_m, buttons.
    #[getter]
    fn device<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.read(|st| st.haptic_loop().config().specs.clone())?;
        let d = PyDict::new(py);
        d.set_item("name", s.name.as_ref())?;
        d.set_item("max_force_n", s.limits.max_force_n)?;
        d.set_item("max_stiffness_n_per_m", s.limits.max_stiffness_n_per_m)?;
        d.set_item("workspace_radius_m", s.workspace_radius_m)?;
        let b: Vec<&str> = s.button_names.iter().map(|b| b.as_ref()).collect();
        d.set_item("buttons", b)?;
        Ok(d)
    }

    /// Ends the session (closes the recording) and returns the per-tick
    /// arrays of :func:`run_scene` with "stats". A closed session refuses
    /// further ticks.
    fn close<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self
            .inner
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
            .ok_or_else(|| PyRuntimeError::new_err("the session is already closed"))?;
        let report = s.finish().map_err(session_error)?;
        let stats = to_py(py, &report.stats)?;
        let d = arrays_to_py(py, report.arrays)?;
        d.set_item("stats", stats)?;
        Ok(d)
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_exc))]
    fn __exit__(
        &mut self,
        py: Python<'_>,
        _exc: &Bound<'_, pyo3::types::PyTuple>,
    ) -> PyResult<bool> {
        if self
            .inner
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner)
            .is_some()
        {
            self.close(py)?;
        }
        Ok(false)
    }
}
