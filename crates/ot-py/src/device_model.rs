//! A haptic device held by a hand, as physics (`haptic_devices`), and the closed-loop check of
//! a scene through it (`haptic_loop::closed_loop`).

use haptic_devices::{Grip, Hold, Mechanics, Plant};
use haptic_types::value::{ValueError, finite3};
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::value_error;

/// A 3-vector argument: exactly three finite numbers, or a ValueError naming the argument.
fn vec3_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; 3]> {
    let v: Vec<f64> = obj
        .extract()
        .map_err(|_| value_error(format!("{name}: expected 3 numbers")))?;
    match v.as_slice() {
        [x, y, z] => {
            finite3(name, [*x, *y, *z]).map_err(value_error)?;
            Ok([*x, *y, *z])
        }
        _ => Err(value_error(format!(
            "{name}: expected 3 numbers, got {}",
            v.len()
        ))),
    }
}

fn mechanics(model: &str, counts: bool) -> PyResult<Mechanics> {
    let m = Mechanics::preset(model).map_err(|e| value_error(format!("model: {e}")))?;
    Ok(if counts { m } else { m.without_quantization() })
}

fn grip_arg(grip: &str) -> PyResult<Grip> {
    Grip::parse(grip).map_err(|e| value_error(format!("grip: {e}")))
}

/// A haptic device held by a hand: moving mass, viscous friction, encoder counts, force
/// resolution, the force held over each tick and rendered at the device's servo rate, and a
/// hand that follows the operator's intended path as a spring-damper.
///
/// Args:
///     model: "falcon", "touch", "delta3" or "inverse3" (figures and sources in
///         docs/devices.md).
///     grip: "loose" (300 N/m, 2 N·s/m), "firm" (1000 N/m, 8 N·s/m) or "k=…,b=…[,m=…]".
///     counts: encoder counts and force resolution on (False: ideal sensing).
///     start: (3,) m, device frame, where the stylus rests at first.
///
/// Close the loop around a :class:`Session` by hand, or with
/// :func:`nanohaptics.closed_loop`::
///
///     dev = nh.DeviceModel("falcon", grip="loose")
///     with nh.Session("wall") as s:
///         for k in range(1000):
///             f = s.tick(dev.reading)
///             dev.advance(1e-3, f, intent_position=[0, 0, -0.006], stiffness=s.stiffness)
#[pyclass(name = "DeviceModel", module = "nanohaptics")]
pub struct DeviceModel {
    plant: Plant,
}

#[pymethods]
impl DeviceModel {
    #[new]
    #[pyo3(signature = (model = "falcon", *, grip = "loose", counts = true, start = None))]
    fn new(
        model: &str,
        grip: &str,
        counts: bool,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let start = match start {
            Some(s) => vec3_arg(s, "start")?,
            None => [0.0; 3],
        };
        Ok(DeviceModel {
            plant: Plant::new(mechanics(model, counts)?, grip_arg(grip)?, start),
        })
    }

    /// Holds ``force`` (3,) N (with the local ``stiffness`` (3, 3) N/m around the last
    /// reading, if given) for ``dt_s`` s while the hand pulls toward ``intent_position`` (3,) m
    /// moving at ``intent_velocity`` (3,) m/s (default 0).
    #[pyo3(signature = (dt_s, force, intent_position, intent_velocity = None, stiffness = None))]
    fn advance(
        &mut self,
        dt_s: f64,
        force: &Bound<'_, PyAny>,
        intent_position: &Bound<'_, PyAny>,
        intent_velocity: Option<&Bound<'_, PyAny>>,
        stiffness: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<()> {
        if !(dt_s.is_finite() && dt_s > 0.0 && dt_s <= 1.0) {
            return Err(value_error(ValueError::out_of_range(
                "dt_s",
                dt_s,
                "0 < dt_s ≤ 1 s",
            )));
        }
        let f = vec3_arg(force, "force")?;
        let xi = vec3_arg(intent_position, "intent_position")?;
        let vi = match intent_velocity {
            Some(v) => vec3_arg(v, "intent_velocity")?,
            None => [0.0; 3],
        };
        let mut k = [0.0; 9];
        if let Some(s) = stiffness {
            let a = s.as_array();
            if a.shape() != [3, 3] || a.iter().any(|v| !v.is_finite()) {
                return Err(value_error(format!(
                    "stiffness: expected a (3, 3) array of finite N/m, got shape {:?}",
                    a.shape()
                )));
            }
            for (i, v) in a.iter().enumerate() {
                k[i] = *v;
            }
        }
        let hold = Hold {
            force_n: f,
            stiffness_n_per_m: k,
            p0_m: self.plant.reading_m(),
        };
        self.plant.advance(dt_s, |_| (xi, vi), &hold);
        Ok(())
    }

    /// What the encoders report, (3,) m: the position in whole counts.
    #[getter]
    fn reading<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.plant.reading_m())
    }

    /// True position of the end effector, (3,) m.
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.plant.position_m())
    }

    /// True velocity of the end effector, (3,) m/s.
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.plant.velocity_m_per_s())
    }

    /// Work the motors have done on the hand since the start, J.
    #[getter]
    fn energy_to_hand_j(&self) -> f64 {
        self.plant.energy_to_hand_j()
    }

    /// Time advanced so far, s.
    #[getter]
    fn time_s(&self) -> f64 {
        self.plant.time_s()
    }

    /// The device's figures: name, moving_mass_kg, viscous_n_s_per_m, encoder_quantum_m,
    /// force_quantum_n, servo_rate_hz, max_force_n, max_stiffness_n_per_m,
    /// workspace_radius_m; and the grip's stiffness_n_per_m, damping_n_s_per_m, mass_kg.
    #[getter]
    fn specs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let m = self.plant.mechanics();
        let g = self.plant.grip();
        let d = PyDict::new(py);
        d.set_item("name", m.name)?;
        d.set_item("moving_mass_kg", m.moving_mass_kg)?;
        d.set_item("viscous_n_s_per_m", m.viscous_n_s_per_m)?;
        d.set_item("encoder_quantum_m", m.encoder_quantum_m)?;
        d.set_item("force_quantum_n", m.force_quantum_n)?;
        d.set_item("servo_rate_hz", m.servo_rate_hz)?;
        d.set_item("max_force_n", m.limits.max_force_n)?;
        d.set_item("max_stiffness_n_per_m", m.limits.max_stiffness_n_per_m)?;
        d.set_item("workspace_radius_m", m.workspace_radius_m)?;
        let gd = PyDict::new(py);
        gd.set_item("stiffness_n_per_m", g.stiffness_n_per_m)?;
        gd.set_item("damping_n_s_per_m", g.damping_n_s_per_m)?;
        gd.set_item("mass_kg", g.mass_kg)?;
        d.set_item("grip", gd)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let m = self.plant.mechanics();
        format!(
            "DeviceModel({:?}, grip={:?})",
            m.name,
            self.plant.grip().label()
        )
    }
}

/// Plays a scene's script through a modelled device held by a hand, in closed loop, and
/// reports whether the rendering is stable there (the test of issue 22, in Rust).
///
/// Args:
///     scene: a scene path, a built-in name, or a dict of :func:`resolve_scene`.
///     script: a script path (default: the scene's default script).
///     model, grip, counts: as :class:`DeviceModel`.
///     seconds: how long (default: the script's duration).
///
/// Returns:
///     dict: "stable" (bool), "ticks", "undeclared_jumps" (force changes above 1 N in one
///     tick with no grab, release, impact, snap or pull-off within 50 ms), "max_jump_n",
///     "hf_fraction" (power of the felt force above 50 Hz), "min_observer_j" and
///     "reserve_j" (the passivity observer), "safety_ticks", "energy_to_hand_j",
///     "peak_force_n", "max_stiffness_n_per_m", "house_complete_s" (s, None without a house
///     task): serde's form of ``haptic_loop::closed_loop::Report`` with "stable" first.
#[pyfunction]
#[pyo3(signature = (scene, *, script = None, model = "falcon", grip = "loose", counts = true, seconds = None))]
pub fn check_closed_loop<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    script: Option<&Bound<'py, PyAny>>,
    model: &str,
    grip: &str,
    counts: bool,
    seconds: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mech = mechanics(model, counts)?;
    let grip = grip_arg(grip)?;
    if let Some(s) = seconds
        && !(s.is_finite() && s > 0.0 && s <= 3600.0)
    {
        return Err(value_error(ValueError::out_of_range(
            "seconds",
            s,
            "0 < seconds ≤ 3600 s",
        )));
    }
    let r = crate::session::resolve(scene, script, None, None)?;
    let (text, script) = (r.source.text.clone(), r.script.clone());
    let rep = py
        .detach(|| haptic_loop::closed_loop::run(&text, &script, mech, grip, seconds))
        .map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("stable", rep.stable())?;
    d.update(crate::json::to_py(py, &rep)?.cast::<pyo3::types::PyMapping>()?)?;
    Ok(d)
}
