//! `nanohaptics.BrickWorld`: the macro world of the teaching game
//! (`brickworld`): bricks under gravity, the cursor proxy, grab/throw/rotate.

use brickworld::script::WallScript;
use brickworld::{
    BrickId, BrickPlacement, BrickProps, CursorInput, Grip, Params, StepReport, World,
};
use haptic_devices::source::DeviceSource;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use world_form::Limits;

use crate::convert::{SIGNAL_CHUNK_TICKS, array2_flat, int_in, numbers, value_error, vector};
use crate::json::{from_py, tick_events, to_py};

/// The grip commands by their names in `brickworld::Grip`.
const GRIP_KEYS: [&str; 4] = ["hold", "turn_x", "turn_y", "turn_z"];
/// The same commands by the Falcon button names this module has always accepted.
const BUTTON_KEYS: [&str; 4] = ["center", "rotate_x", "rotate_y", "rotate_z"];

fn grip_of(b: [bool; 4]) -> Grip {
    Grip {
        hold: b[0],
        turn_x: b[1],
        turn_y: b[2],
        turn_z: b[3],
    }
}

/// The hand's grip commands as Python passes them: None (all up), a dict with keys among
/// hold/turn_x/turn_y/turn_z (or the older center/rotate_x/rotate_y/rotate_z, still
/// accepted), or a sequence of four truth values in that order.
fn parse_buttons(obj: Option<&Bound<'_, PyAny>>, name: &str) -> PyResult<Grip> {
    let Some(obj) = obj else {
        return Ok(Grip::default());
    };
    if obj.is_none() {
        return Ok(Grip::default());
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut b = [false; 4];
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyValueError::new_err(format!(
                    "{name}: keys must be strings among {GRIP_KEYS:?} or {BUTTON_KEYS:?}"
                ))
            })?;
            let found = GRIP_KEYS.iter().position(|n| *n == key);
            let Some(i) = found.or_else(|| BUTTON_KEYS.iter().position(|n| *n == key)) else {
                return Err(PyValueError::new_err(format!(
                    "{name}: unknown button {key:?}: allowed {GRIP_KEYS:?} or {BUTTON_KEYS:?}"
                )));
            };
            b[i] = v.is_truthy()?;
        }
        return Ok(grip_of(b));
    }
    let n = numbers(obj, name)?;
    if n.shape != [4] {
        return Err(PyValueError::new_err(format!(
            "{name}: expected a dict or 4 values (hold, turn_x, turn_y, turn_z), got {} values",
            n.data.len()
        )));
    }
    Ok(grip_of([
        n.data[0] != 0.0,
        n.data[1] != 0.0,
        n.data[2] != 0.0,
        n.data[3] != 0.0,
    ]))
}

/// The `device` argument: None (the Falcon), a device name read as every `device=` of the
/// wheel reads it ([`crate::session::device_from_py`]: a model in this process, whose limits
/// the world renders to; a bridged device is refused), or a dict of limits.
fn device_from_py(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Limits> {
    let Some(obj) = obj else {
        return Ok(Limits::FALCON);
    };
    if let Ok(s) = obj.cast::<PyString>() {
        return match crate::session::device_from_py(Some(obj))? {
            Some(DeviceSource::Model(m)) => Ok(m.specs().limits),
            _ => Err(PyValueError::new_err(format!(
                "device = {:?}: the brick world renders to a model in this process \
                 (\"falcon\", \"touch\") or a dict with max_force_n and max_stiffness_n_per_m, \
                 not a bridged device",
                s.to_cow()?
            ))),
        };
    }
    let d: Limits = from_py(obj, "device")?;
    d.validate().map_err(value_error)?;
    Ok(d)
}

fn brick_id(world: &World, obj: &Bound<'_, PyAny>) -> PyResult<BrickId> {
    let id = int_in(obj, "brick", 0, i128::from(u32::MAX))? as u32;
    let b = BrickId(id);
    world.brick(b).map(|_| b).map_err(value_error)
}

/// Per-tick record of a batch.
struct Tick {
    report: StepReport,
    proxy: [f64; 3],
    held: i64,
    filled: usize,
    /// Every brick's centre (m) and orientation [x, y, z, w] after the tick, in id order.
    poses: Vec<([f64; 3], [f64; 4])>,
}

/// Per-tick arrays of a batch, as a dict.
fn ticks_to_py<'py>(
    py: Python<'py>,
    ticks: &[Tick],
    inputs: &[CursorInput],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let flat = |f: fn(&StepReport) -> [f64; 3]| -> Vec<f64> {
        ticks.iter().flat_map(|t| f(&t.report)).collect()
    };
    d.set_item("force", array2_flat(py, flat(|r| r.force_n), 3)?)?;
    d.set_item(
        "spring_force",
        array2_flat(py, flat(|r| r.spring_force_n), 3)?,
    )?;
    d.set_item(
        "weight_force",
        array2_flat(py, flat(|r| r.weight_force_n), 3)?,
    )?;
    d.set_item(
        "inertia_force",
        array2_flat(py, flat(|r| r.inertia_force_n), 3)?,
    )?;
    d.set_item(
        "coupling_force",
        array2_flat(py, flat(|r| r.coupling_force_n), 3)?,
    )?;
    d.set_item(
        "acceleration",
        array2_flat(py, flat(|r| r.acceleration_m_per_s2), 3)?,
    )?;
    let proxy: Vec<f64> = ticks.iter().flat_map(|t| t.proxy).collect();
    d.set_item("proxy", array2_flat(py, proxy, 3)?)?;
    let cursor: Vec<f64> = inputs.iter().flat_map(|i| i.position_m()).collect();
    d.set_item("cursor", array2_flat(py, cursor, 3)?)?;
    let buttons: Vec<bool> = inputs
        .iter()
        .flat_map(|i| {
            let b = i.grip();
            [b.hold, b.turn_x, b.turn_y, b.turn_z]
        })
        .collect();
    d.set_item(
        "buttons",
        PyArray1::from_vec(py, buttons).reshape([inputs.len(), 4])?,
    )?;
    let sat: Vec<bool> = ticks.iter().map(|t| t.report.saturated).collect();
    d.set_item("saturated", PyArray1::from_vec(py, sat))?;
    let k: Vec<f64> = ticks.iter().map(|t| t.report.stiffness_n_per_m).collect();
    d.set_item("stiffness", PyArray1::from_vec(py, k))?;
    let pen: Vec<f64> = ticks.iter().map(|t| t.report.proxy_penetration_m).collect();
    d.set_item("penetration", PyArray1::from_vec(py, pen))?;
    let held: Vec<i64> = ticks.iter().map(|t| t.held).collect();
    d.set_item("held", PyArray1::from_vec(py, held))?;
    let filled: Vec<i64> = ticks.iter().map(|t| t.filled as i64).collect();
    d.set_item("filled", PyArray1::from_vec(py, filled))?;
    let events = ticks.iter().map(|t| t.report.events.as_slice());
    d.set_item("events", tick_events(py, events)?)?;
    // Brick poses: (T, B, 3) and (T, B, 4) with B the brick count after the last tick; a
    // brick that did not exist yet at a tick has position 0 and orientation [0, 0, 0, 1]
    // there ("brick_count" (T,) says how many existed).
    let b = ticks.last().map_or(0, |t| t.poses.len());
    let mut pos = Vec::with_capacity(ticks.len() * b * 3);
    let mut rot = Vec::with_capacity(ticks.len() * b * 4);
    for t in ticks {
        for k in 0..b {
            let (p, q) = t
                .poses
                .get(k)
                .copied()
                .unwrap_or(([0.0; 3], [0.0, 0.0, 0.0, 1.0]));
            pos.extend(p);
            rot.extend(q);
        }
    }
    d.set_item(
        "brick_position_m",
        PyArray1::from_vec(py, pos).reshape([ticks.len(), b, 3])?,
    )?;
    d.set_item(
        "brick_orientation_xyzw",
        PyArray1::from_vec(py, rot).reshape([ticks.len(), b, 4])?,
    )?;
    let counts: Vec<i64> = ticks.iter().map(|t| t.poses.len() as i64).collect();
    d.set_item("brick_count", PyArray1::from_vec(py, counts))?;
    Ok(d)
}

fn record(world: &World, report: StepReport) -> Tick {
    Tick {
        report,
        proxy: world.proxy_position_m(),
        held: world.held_brick().map_or(-1, |b| i64::from(b.0)),
        filled: world.score().filled,
        poses: world
            .bricks()
            .map(|b| (b.position_m, b.orientation_xyzw))
            .collect(),
    }
}

/// The macro world of the teaching game: bricks on the ground (z = 0) under
/// gravity, simulated with rapier, handled through a haptic cursor proxy.
///
/// Args:
///     params: None (defaults) or a dict with the scene-table layout; missing
///         fields take their defaults (see :attr:`params` for the full set:
///         dt_s, gravity_m_per_s2, restitution, friction, inertia, brick_mass_kg,
///         brick_half_extents_m, loading_zone, blueprint, bricks, ...).
///     device: a device model by the name every ``device=`` of the wheel
///         takes: "falcon" (default; Novint Falcon: 8 N, 3000 N/m, CHAI3D's
///         figures) or "touch" (3D Systems Touch: 3.3 N, 400 N/m; the default
///         1000 N/m proxy is then too stiff: pass a softer
///         ``proxy_stiffness_n_per_m``), rendering to that model's limits; or
///         a dict {"max_force_n": ..., "max_stiffness_n_per_m": ...} (the old
///         key "max_stiffness_n_m" is still accepted). An unknown name is
///         refused as :func:`run_scene` refuses it; a bridged device
///         ("udp:...") is refused.
///
/// Units: m, kg, s, N; quaternions are [x, y, z, w]. Buttons (the hand's grip
/// commands) are None, a dict with keys among hold/turn_x/turn_y/turn_z (the
/// older center/rotate_x/rotate_y/rotate_z are still accepted), or four truth
/// values in that order.
#[pyclass(module = "nanohaptics")]
pub struct BrickWorld {
    world: World,
}

#[pymethods]
impl BrickWorld {
    #[new]
    #[pyo3(signature = (params=None, *, device=None))]
    fn new(params: Option<&Bound<'_, PyAny>>, device: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        let p: Params = match params {
            Some(obj) if !obj.is_none() => from_py(obj, "params")?,
            _ => Params::default(),
        };
        let dev = device_from_py(device)?;
        Ok(Self {
            world: World::new(&p, &dev).map_err(value_error)?,
        })
    }

    /// Add a brick with its centre at ``center_m`` (3,) (m), turned by the
    /// rotation vector ``rotation_deg`` (axis · angle, degrees), moving at
    /// ``velocity_m_per_s`` (3,) (m/s, each in [-100, 100]), with its own
    /// ``mass_kg`` ([1e-3, 100]), ``friction`` ([0, 10]) and ``restitution``
    /// ([0, 1]); None takes the world's value (a contact uses the mean of
    /// its two bodies' friction and restitution). Returns its id.
    #[pyo3(signature = (center_m, rotation_deg=None, *, velocity_m_per_s=None, mass_kg=None, friction=None, restitution=None))]
    fn add_brick(
        &mut self,
        center_m: &Bound<'_, PyAny>,
        rotation_deg: Option<&Bound<'_, PyAny>>,
        velocity_m_per_s: Option<&Bound<'_, PyAny>>,
        mass_kg: Option<f64>,
        friction: Option<f64>,
        restitution: Option<f64>,
    ) -> PyResult<u32> {
        let c = vector::<3>(center_m, "center_m", "m")?;
        let r = match rotation_deg {
            Some(r) if !r.is_none() => vector::<3>(r, "rotation_deg", "deg")?,
            _ => nalgebra::Vector3::zeros(),
        };
        let v = match velocity_m_per_s {
            Some(v) if !v.is_none() => vector::<3>(v, "velocity_m_per_s", "m/s")?,
            _ => nalgebra::Vector3::zeros(),
        };
        let id = self
            .world
            .add_brick_with(
                BrickPlacement {
                    center_m: [c.x, c.y, c.z],
                    rotation_deg: [r.x, r.y, r.z],
                },
                BrickProps {
                    velocity_m_per_s: [v.x, v.y, v.z],
                    mass_kg,
                    friction,
                    restitution,
                },
            )
            .map_err(value_error)?;
        Ok(id.0)
    }

    /// One tick of ``params["dt_s"]`` with the cursor at ``position_m`` (3,)
    /// (m, inside the workspace box) and the given buttons.
    ///
    /// Returns:
    ///     the step report as a dict: "tick", "force_n" (device force, N,
    ///     within the device limit), "saturated", "spring_force_n",
    ///     "stiffness_n_per_m", "weight_force_n", "inertia_force_n" (the paper's
    ///     inertia), "coupling_force_n" (the virtual coupling's pull on the hand),
    ///     "acceleration_m_per_s2", "proxy_penetration_m" and "events" (dicts
    ///     with a "type" key: "grabbed", "released", "thrown", "rotated",
    ///     "spawned", "touch_began", "slot_filled", ...).
    #[pyo3(signature = (position_m, buttons=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        position_m: &Bound<'py, PyAny>,
        buttons: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = vector::<3>(position_m, "position_m", "m")?;
        let b = parse_buttons(buttons, "buttons")?;
        let input = self.world.input([p.x, p.y, p.z], b).map_err(value_error)?;
        let r = self.world.step(&input);
        to_py(py, &r)
    }

    /// Step once per row of ``positions_m`` (T, 3) (m) with ``buttons``: None,
    /// one button set for every tick, or a (T, 4) array of truth values. All
    /// rows are checked before the first tick; the GIL is released while the
    /// ticks run.
    ///
    /// Returns:
    ///     dict of per-tick arrays: "force", "spring_force", "weight_force",
    ///     "inertia_force", "coupling_force" (T, 3) N, "acceleration" (T, 3) m/s², "proxy"
    ///     (T, 3) m (after the tick), "cursor" (T, 3) m, "buttons" (T, 4)
    ///     bool, "saturated" (T,) bool, "stiffness" (T,) N/m, "penetration"
    ///     (T,) m, "held" (T,) int (brick id or -1), "filled" (T,) int
    ///     (blueprint slots filled), "brick_position_m" (T, B, 3) m and
    ///     "brick_orientation_xyzw" (T, B, 4) after each tick (B: bricks
    ///     after the last tick; a brick not yet spawned reads 0 and
    ///     [0, 0, 0, 1]), "brick_count" (T,) int, and "events": list of
    ///     (tick, dict). The GIL is released in chunks of 10 000 ticks;
    ///     Ctrl-C (KeyboardInterrupt) stops the batch between chunks.
    #[pyo3(signature = (positions_m, buttons=None))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        positions_m: &Bound<'py, PyAny>,
        buttons: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let path = crate::convert::rows::<3>(positions_m, "positions_m", "m")?;
        let per_tick: Vec<Grip> = match buttons {
            Some(b) if !b.is_none() && !b.is_instance_of::<PyDict>() => {
                let n = numbers(b, "buttons")?;
                if n.shape == [4] {
                    vec![parse_buttons(Some(b), "buttons")?; path.len()]
                } else if n.shape == [path.len(), 4] {
                    n.data
                        .chunks_exact(4)
                        .map(|c| grip_of([c[0] != 0.0, c[1] != 0.0, c[2] != 0.0, c[3] != 0.0]))
                        .collect()
                } else {
                    return Err(PyValueError::new_err(format!(
                        "buttons: expected None, a dict, 4 values or shape ({}, 4)",
                        path.len()
                    )));
                }
            }
            other => vec![parse_buttons(other, "buttons")?; path.len()],
        };
        let mut inputs = Vec::with_capacity(path.len());
        for (i, (p, b)) in path.iter().zip(&per_tick).enumerate() {
            inputs.push(
                self.world
                    .input([p.x, p.y, p.z], *b)
                    .map_err(|e| PyValueError::new_err(format!("positions_m[{i}]: {e}")))?,
            );
        }
        let world = &mut self.world;
        let mut ticks: Vec<Tick> = Vec::with_capacity(inputs.len());
        // Chunks without the GIL; Ctrl-C is honoured between chunks (the world keeps the
        // ticks already run).
        for chunk in inputs.chunks(SIGNAL_CHUNK_TICKS) {
            py.detach(|| {
                for i in chunk {
                    let r = world.step(i);
                    ticks.push(record(world, r));
                }
            });
            py.check_signals()?;
        }
        ticks_to_py(py, &ticks, &inputs)
    }

    /// Run the scripted wall builder (a loading zone and a blueprint are
    /// needed) from the cursor at ``start_m`` (3,) (m, outside the loading
    /// zone) until every slot has been served or ``max_ticks`` ticks, then
    /// ``settle_ticks`` more with the cursor parked. Same per-tick arrays as
    /// :meth:`run`; the GIL is released.
    #[pyo3(signature = (start_m, max_ticks=40_000, settle_ticks=1000))]
    fn run_wall_script<'py>(
        &mut self,
        py: Python<'py>,
        start_m: &Bound<'py, PyAny>,
        #[pyo3(from_py_with = crate::convert::max_ticks_arg)] max_ticks: usize,
        #[pyo3(from_py_with = crate::convert::settle_ticks_arg)] settle_ticks: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = vector::<3>(start_m, "start_m", "m")?;
        let start = [s.x, s.y, s.z];
        let park = self
            .world
            .input(start, Grip::default())
            .map_err(|e| PyValueError::new_err(format!("start_m: {e}")))?;
        let mut script = WallScript::new(&self.world, start).ok_or_else(|| {
            PyValueError::new_err("loading_zone is missing: the wall script fetches bricks from it")
        })?;
        let world = &mut self.world;
        let mut ticks = Vec::new();
        let mut inputs = Vec::new();
        // Chunks without the GIL; Ctrl-C is honoured between chunks.
        while !script.done() && ticks.len() < max_ticks {
            let end = (ticks.len() + SIGNAL_CHUNK_TICKS).min(max_ticks);
            py.detach(|| {
                while !script.done() && ticks.len() < end {
                    let i = script.next_input(world)?;
                    let r = world.step(&i);
                    ticks.push(record(world, r));
                    inputs.push(i);
                }
                Ok::<_, brickworld::InputError>(())
            })
            .map_err(value_error)?;
            py.check_signals()?;
        }
        let mut left = settle_ticks;
        while left > 0 {
            let n = left.min(SIGNAL_CHUNK_TICKS);
            py.detach(|| {
                for _ in 0..n {
                    let r = world.step(&park);
                    ticks.push(record(world, r));
                    inputs.push(park);
                }
            });
            left -= n;
            py.check_signals()?;
        }
        ticks_to_py(py, &ticks, &inputs)
    }

    /// Every brick, with the same keys as :meth:`brick`: {"id" (B,) int,
    /// "position_m" (B, 3) m, "orientation_xyzw" (B, 4) [x, y, z, w],
    /// "half_extents_m" (B, 3) m, "velocity_m_per_s" (B, 3) m/s, "held" (B,)
    /// bool, "sleeping" (B,) bool}, in id order.
    #[getter]
    fn bricks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let b: Vec<_> = self.world.bricks().collect();
        let d = PyDict::new(py);
        let ids: Vec<i64> = b.iter().map(|v| i64::from(v.id.0)).collect();
        d.set_item("id", PyArray1::from_vec(py, ids))?;
        let f3 = |f: fn(&brickworld::BrickView) -> [f64; 3]| -> Vec<f64> {
            b.iter().flat_map(f).collect()
        };
        d.set_item("position_m", array2_flat(py, f3(|v| v.position_m), 3)?)?;
        let q: Vec<f64> = b.iter().flat_map(|v| v.orientation_xyzw).collect();
        d.set_item(
            "orientation_xyzw",
            PyArray1::from_vec(py, q).reshape([b.len(), 4])?,
        )?;
        d.set_item(
            "half_extents_m",
            array2_flat(py, f3(|v| v.half_extents_m), 3)?,
        )?;
        d.set_item(
            "velocity_m_per_s",
            array2_flat(py, f3(|v| v.velocity_m_per_s), 3)?,
        )?;
        let held: Vec<bool> = b.iter().map(|v| v.held).collect();
        d.set_item("held", PyArray1::from_vec(py, held))?;
        let sl: Vec<bool> = b.iter().map(|v| v.sleeping).collect();
        d.set_item("sleeping", PyArray1::from_vec(py, sl))?;
        Ok(d)
    }

    /// One brick by id: {"id", "position_m", "orientation_xyzw",
    /// "half_extents_m", "velocity_m_per_s", "held", "sleeping"}.
    fn brick<'py>(&self, py: Python<'py>, id: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let b = brick_id(&self.world, id)?;
        to_py(py, &self.world.brick(b).map_err(value_error)?)
    }

    /// Proxy (god-object) centre (3,) m: never inside a brick or the ground.
    #[getter]
    fn proxy_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.world.proxy_position_m())
    }

    /// Last cursor position (3,) m.
    #[getter]
    fn cursor_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.world.cursor_position_m())
    }

    /// Id of the carried brick, or None.
    #[getter]
    fn held_brick(&self) -> Option<u32> {
        self.world.held_brick().map(|b| b.0)
    }

    /// What the cursor (or carried brick) touches, as the events name it: a list of
    /// "ground", {"brick": id} and {"obstacle": index}.
    #[getter]
    fn touching<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.world.touching())
    }

    /// Blueprint slots: list of {"position_m", "orientation_xyzw", "filled_by"}.
    #[getter]
    fn slots<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let s: Vec<_> = self.world.slots().collect();
        to_py(py, &s)
    }

    /// House score: {"filled": int, "total": int}.
    #[getter]
    fn score<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.world.score())
    }

    /// Fixed boxes besides the ground: list of {"position_m", "orientation_xyzw", "half_extents_m"}.
    #[getter]
    fn obstacles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let o: Vec<_> = self.world.obstacles().collect();
        to_py(py, &o)
    }

    /// Bricks the physics engine is simulating (not asleep).
    #[getter]
    fn awake_brick_count(&self) -> usize {
        self.world.awake_brick_count()
    }

    /// The parameters in force, as a full dict (scene-table layout).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.world.params())
    }

    /// The device limits: {"max_force_n", "max_stiffness_n_per_m"}.
    #[getter]
    fn device<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.world.limits())
    }

    /// Ticks stepped so far.
    #[getter]
    fn tick(&self) -> u64 {
        self.world.tick()
    }

    /// Simulated time (s).
    #[getter]
    fn time(&self) -> f64 {
        self.world.time_s()
    }

    /// Gravity magnitude (m/s², 0 switches it off), validated.
    fn set_gravity(&mut self, g_m_per_s2: f64) -> PyResult<()> {
        self.world.set_gravity(g_m_per_s2).map_err(value_error)
    }

    /// Restitution of every contact (0..1), validated.
    fn set_restitution(&mut self, e: f64) -> PyResult<()> {
        self.world.set_restitution(e).map_err(value_error)
    }

    /// Coulomb friction coefficient of every contact, validated.
    fn set_friction(&mut self, mu: f64) -> PyResult<()> {
        self.world.set_friction(mu).map_err(value_error)
    }

    /// How a carried brick's inertia is felt: ``"coupling"`` (a spring-damper the device can
    /// hold; ``True`` means this), ``"paper"`` (the paper's ``-M a`` from sampled positions) or
    /// ``"off"`` (``False``: weight only).
    fn set_inertia(&mut self, mode: &Bound<'_, PyAny>) -> PyResult<()> {
        let m = if let Ok(on) = mode.extract::<bool>() {
            if on {
                brickworld::Inertia::Coupling
            } else {
                brickworld::Inertia::Off
            }
        } else {
            match mode.extract::<String>().as_deref() {
                Ok("coupling") => brickworld::Inertia::Coupling,
                Ok("paper") => brickworld::Inertia::Paper,
                Ok("off") => brickworld::Inertia::Off,
                _ => {
                    return Err(pyo3::exceptions::PyValueError::new_err(format!(
                        "inertia = {} is not allowed (allowed: \"coupling\", \"paper\", \"off\", True, False)",
                        mode.repr().map(|r| r.to_string()).unwrap_or_default()
                    )));
                }
            }
        };
        self.world.set_inertia(m);
        Ok(())
    }

    /// Mass of every brick (kg), validated.
    fn set_brick_mass(&mut self, kg: f64) -> PyResult<()> {
        self.world.set_brick_mass(kg).map_err(value_error)
    }

    fn __repr__(&self) -> String {
        format!(
            "BrickWorld(bricks={}, tick={}, held={:?})",
            self.world.brick_count(),
            self.world.tick(),
            self.world.held_brick().map(|b| b.0)
        )
    }
}
