//! `nanohaptics.NanoWorld`: the nano world of the teaching game (`nanoworld`),
//! its force–distance curve and the scripted house session.

use nalgebra::Vector3;
use nanoworld::{
    CurveSpec, Event, PairKind, TipContact, TipInput, World, force_distance_curve as curve,
    house_script as script,
};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::{SIGNAL_CHUNK_TICKS, array1, array2, int_in, rows, value_error, vector};
use crate::json::{tick_events, to_py};
use crate::params_dict::{limits_from_py, params_from_py};

/// What one tick of a batch left behind.
struct TickRecord {
    force: Vector3<f64>,
    unlimited: Vector3<f64>,
    saturated: bool,
    tip: Vector3<f64>,
    anchored: bool,
    carried: usize,
    score: usize,
    events: Vec<Event>,
}

/// The nano world of the teaching game: an AFM tip (the cursor) over fixed
/// substrate atoms, movable atoms from a loading zone, van der Waals
/// attraction, snap-to-contact, adhesion and pull-off, and a house blueprint.
///
/// Args:
///     start: (3,) initial cursor (tip) position (m).
///     params: "game" (the paper's laws, default), "physical" (real
///         constants: Hamaker forces, cantilever, DMT pull-off), or a dict
///         with the scene-table layout (see :func:`nano_params`). It has no
///         "max_force_n" any more: the limit comes from ``device``.
///     device: None (the Novint Falcon mapped as the preset scenes map it:
///         8 nN and 20 N/m for "game", 80 nN and 30 N/m for "physical") or a
///         dict {"max_force_n": N, "max_stiffness_n_per_m": N/m} in world
///         units. The force sent is scaled down to max_force_n; a stiffest
///         spring above max_stiffness_n_per_m is refused.
///
/// All positions are in m, forces in N (world units), times in s.
#[pyclass(module = "nanohaptics")]
pub struct NanoWorld {
    world: World,
}

#[pymethods]
impl NanoWorld {
    #[new]
    #[pyo3(signature = (start, *, params=None, device=None))]
    fn new(
        start: &Bound<'_, PyAny>,
        params: Option<&Bound<'_, PyAny>>,
        device: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let start = vector::<3>(start, "start", "m")?;
        let p = params_from_py(params)?;
        let limits = limits_from_py(device, &p)?;
        Ok(Self {
            world: World::new(&p, &limits, start).map_err(value_error)?,
        })
    }

    /// Advance one tick of ``dt_s`` (s, 1e-9 <= dt_s <= 1) with the cursor at
    /// ``position`` (3,) (m, each coordinate within ±1 m).
    ///
    /// Returns:
    ///     dict with "force" (3,) N to send to the device (finite, within
    ///     device["max_force_n"]), "unlimited_force" (3,) N before the device limit,
    ///     "saturated" bool, and "events": a list of dicts with a "type" key
    ///     ("snap", "pull_off", "atom_attached", "atom_transferred", ...), serde's
    ///     form of `nanoworld::Event` (a recording's event detail has the same form).
    #[pyo3(signature = (position, dt_s=1e-3))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
        dt_s: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let p = vector::<3>(position, "position", "m")?;
        let r = self
            .world
            .step(&TipInput { position_m: p }, dt_s)
            .map_err(value_error)?;
        let d = PyDict::new(py);
        d.set_item("force", array1(py, &r.force_n))?;
        d.set_item("unlimited_force", array1(py, &r.unlimited_force_n))?;
        d.set_item("saturated", r.saturated)?;
        let ev = PyList::empty(py);
        for e in &r.events {
            ev.append(to_py(py, e)?)?;
        }
        d.set_item("events", ev)?;
        Ok(d)
    }

    /// Step once per row of ``positions`` (T, 3) cursor positions (m), each
    /// tick ``dt_s`` (s). The GIL is released while the ticks run, in chunks
    /// of 10 000 ticks; Ctrl-C (KeyboardInterrupt) stops the batch between
    /// chunks, the world keeping the ticks already run. All rows are checked
    /// (finite, within ±1 m; dt_s in [1e-9, 1]) before the first tick, so a
    /// refused batch changes nothing; the refused row is named.
    ///
    /// Returns:
    ///     dict of per-tick arrays: "force" (T, 3) N, "unlimited_force"
    ///     (T, 3) N, "saturated" (T,) bool, "tip" (T, 3) tip centre after
    ///     the tick (m), "anchored" (T,) bool (tip held by a contact),
    ///     "carried" (T,) int (atoms on the tip), "score" (T,) int (filled
    ///     house slots), and "events": a list of (tick, event dict) with
    ///     tick the row index.
    #[pyo3(signature = (positions, dt_s=1e-3))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        positions: &Bound<'py, PyAny>,
        dt_s: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let path = rows::<3>(positions, "positions", "m")?;
        // Every row is checked before the first tick: a refused batch changes nothing.
        for (i, p) in path.iter().enumerate() {
            TipInput { position_m: *p }
                .check(dt_s)
                .map_err(|e| value_error(format!("positions[{i}]: {e}")))?;
        }
        let world = &mut self.world;
        let mut records = Vec::with_capacity(path.len());
        // Chunks of ticks without the GIL; Ctrl-C is honoured between chunks (the world
        // keeps the ticks already run).
        for (c, chunk) in path.chunks(SIGNAL_CHUNK_TICKS).enumerate() {
            py.detach(|| {
                for (k, p) in chunk.iter().enumerate() {
                    let r = world
                        .step(&TipInput { position_m: *p }, dt_s)
                        .map_err(|e| (c * SIGNAL_CHUNK_TICKS + k, e))?;
                    records.push(TickRecord {
                        force: r.force_n,
                        unlimited: r.unlimited_force_n,
                        saturated: r.saturated,
                        tip: world.tip_position_m(),
                        anchored: matches!(world.tip_contact(), TipContact::Anchored(_)),
                        carried: world.carried().len(),
                        score: world.house().score(),
                        events: r.events,
                    });
                }
                Ok::<_, (usize, nanoworld::StepError)>(())
            })
            .map_err(|(i, e)| value_error(format!("positions[{i}]: {e}")))?;
            py.check_signals()?;
        }
        let d = PyDict::new(py);
        let v = |f: fn(&TickRecord) -> Vector3<f64>| -> Vec<Vector3<f64>> {
            records.iter().map(f).collect()
        };
        d.set_item("force", array2(py, &v(|r| r.force))?)?;
        d.set_item("unlimited_force", array2(py, &v(|r| r.unlimited))?)?;
        d.set_item("tip", array2(py, &v(|r| r.tip))?)?;
        let sat: Vec<bool> = records.iter().map(|r| r.saturated).collect();
        d.set_item("saturated", PyArray1::from_vec(py, sat))?;
        let anch: Vec<bool> = records.iter().map(|r| r.anchored).collect();
        d.set_item("anchored", PyArray1::from_vec(py, anch))?;
        let carried: Vec<i64> = records.iter().map(|r| r.carried as i64).collect();
        d.set_item("carried", PyArray1::from_vec(py, carried))?;
        let score: Vec<i64> = records.iter().map(|r| r.score as i64).collect();
        d.set_item("score", PyArray1::from_vec(py, score))?;
        let events = records.iter().map(|r| r.events.as_slice());
        d.set_item("events", tick_events(py, events)?)?;
        Ok(d)
    }

    /// The attraction (3,) N the tip assembly would feel with the tip centre
    /// at ``position`` (3,) (m), from the pair laws alone, without stepping:
    /// nothing snaps or releases and the tick does not advance. Game mode:
    /// the summed pair laws; physical mode: the Hamaker forces on the tip and
    /// its carried particles. ValueError naming the axis if a coordinate is
    /// not finite or beyond 1 m.
    fn force_at<'py>(
        &self,
        py: Python<'py>,
        position: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let p = vector::<3>(position, "position", "m")?;
        let f = self.world.force_at(p).map_err(value_error)?;
        Ok(array1(py, &f))
    }

    /// Replace the parameters at run time (same forms as the constructor's
    /// ``params``). Strengths, stiffnesses, pull-off ratio, masses, gravity,
    /// inertia, force limit, loading zone and house may change; the mode and
    /// the geometry may not (ValueError naming the field).
    fn set_params(&mut self, params: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = params_from_py(Some(params))?;
        self.world.set_params(p).map_err(value_error)
    }

    /// The parameters in force, as a dict with the scene-table layout (serde's form of
    /// `nanoworld::Params`).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.world.params())
    }

    /// The device limits this world renders to, world units:
    /// {"max_force_n": N, "max_stiffness_n_per_m": N/m}.
    #[getter]
    fn device<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, self.world.limits())
    }

    /// Tip (apex) centre (3,) (m).
    #[getter]
    fn tip_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.world.tip_position_m())
    }

    /// Last cursor position (3,) (m).
    #[getter]
    fn cursor<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.world.cursor_m())
    }

    /// The tip's contact state: None when free, else a dict with "member"
    /// ("tip" or {"atom": i}), "target" ({"substrate_atom": j},
    /// "substrate_plane" or {"atom": i}), "pair" (as in the events), "tip_position"
    /// (3,) m where the tip is held, and "normal" (3,) unit contact normal.
    #[getter]
    fn contact<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        match self.world.tip_contact() {
            TipContact::Free => Ok(None),
            TipContact::Anchored(a) => {
                let d = PyDict::new(py);
                d.set_item("member", to_py(py, &a.member)?)?;
                d.set_item("target", to_py(py, &a.target)?)?;
                d.set_item("pair", to_py(py, &a.pair)?)?;
                d.set_item("tip_position", array1(py, &a.tip_position_m))?;
                d.set_item("normal", array1(py, &a.normal))?;
                Ok(Some(d))
            }
        }
    }

    /// Movable-atom centres (M, 3) (m), by index.
    #[getter]
    fn atoms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let p: Vec<Vector3<f64>> = self.world.atoms().iter().map(|a| a.position_m()).collect();
        array2(py, &p)
    }

    /// Indices of the atoms carried by the tip, ascending.
    #[getter]
    fn carried(&self) -> Vec<usize> {
        self.world.carried().to_vec()
    }

    /// Per movable atom: whether it is bonded to the substrate (M,) bool.
    #[getter]
    fn atom_on_substrate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let v: Vec<bool> = self
            .world
            .atoms()
            .iter()
            .map(|a| a.on_substrate())
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// Per movable atom: the indices of the atoms it is bonded to.
    #[getter]
    fn atom_bonds(&self) -> Vec<Vec<usize>> {
        self.world
            .atoms()
            .iter()
            .map(|a| a.bonds().to_vec())
            .collect()
    }

    /// Substrate-atom centres (S, 3) (m).
    #[getter]
    fn substrate<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        array2(py, self.world.substrate().positions())
    }

    /// Radii (m): {"tip": ..., "atom": ..., "substrate": ...}.
    #[getter]
    fn radii<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("tip", self.world.tip_radius_m())?;
        d.set_item("atom", self.world.atom_radius_m())?;
        d.set_item("substrate", self.world.substrate().radius_m())?;
        Ok(d)
    }

    /// The derived pair laws: {pair: {"snap_gap_m", "snap_force_n",
    /// "pull_off_n", "stiffness_n_per_m", "contact_gap_m", "cutoff_gap_m",
    /// "floor_gap_m", "coef_n_m2", "shift_n"}} for the four pairs.
    #[getter]
    fn laws<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for k in PairKind::ALL {
            let l = self.world.laws().get(k);
            let e = PyDict::new(py);
            e.set_item("coef_n_m2", l.coef_n_m2)?;
            e.set_item("shift_n", l.shift_n)?;
            e.set_item("cutoff_gap_m", l.cutoff_gap_m)?;
            e.set_item("floor_gap_m", l.floor_gap_m)?;
            e.set_item("snap_gap_m", l.snap_gap_m)?;
            e.set_item("contact_gap_m", l.contact_gap_m)?;
            e.set_item("stiffness_n_per_m", l.stiffness_n_per_m)?;
            e.set_item("snap_force_n", l.snap_force_n)?;
            e.set_item("pull_off_n", l.pull_off_n)?;
            d.set_item(to_py(py, &k)?, e)?;
        }
        Ok(d)
    }

    /// The house task: {"slots" (K, 3) m, "tolerance_m", "filled" (list of
    /// atom index or None per slot), "score" (filled slots), "complete"}.
    #[getter]
    fn house<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let h = self.world.house();
        let d = PyDict::new(py);
        d.set_item("slots", array2(py, h.slots_m())?)?;
        d.set_item("tolerance_m", h.tolerance_m())?;
        d.set_item("filled", h.filled().to_vec())?;
        d.set_item("score", h.score())?;
        d.set_item("complete", h.is_complete())?;
        Ok(d)
    }

    /// Ticks stepped so far.
    #[getter]
    fn tick(&self) -> u64 {
        self.world.tick()
    }

    /// Simulated time: the sum of all tick lengths (s).
    #[getter]
    fn time(&self) -> f64 {
        self.world.time_s()
    }

    /// The scripted house session for this world: (T, 3) cursor positions
    /// (m) at most ``step_m`` (m, 0 < step_m <= 1e-6) apart that fetch each atom
    /// from the loading zone and set it down in its blueprint slot.
    #[pyo3(signature = (step_m=2e-12))]
    fn house_script<'py>(
        &self,
        py: Python<'py>,
        step_m: f64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = script(&self.world, step_m).map_err(value_error)?;
        let p: Vec<Vector3<f64>> = s.iter().map(|t| t.position_m).collect();
        array2(py, &p)
    }

    fn __repr__(&self) -> String {
        let mode = match self.world.params().interaction {
            nanoworld::Interaction::Game(_) => "game",
            nanoworld::Interaction::Physical(_) => "physical",
        };
        format!(
            "NanoWorld(mode={mode}, substrate_atoms={}, movable_atoms={}, tick={})",
            self.world.substrate().len(),
            self.world.atoms().len(),
            self.world.tick()
        )
    }
}

/// The default parameters as a dict with the scene-table layout: edit and
/// pass to :class:`NanoWorld` or :func:`force_distance_curve`.
///
/// Args:
///     mode: "game" (the paper's laws) or "physical" (real constants).
#[pyfunction]
#[pyo3(signature = (mode=String::from("game")), text_signature = "(mode='game')")]
pub fn nano_params<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = crate::convert::mode_arg)] mode: String,
) -> PyResult<Bound<'py, PyAny>> {
    match mode.as_str() {
        "game" => to_py(py, &nanoworld::Params::game_default()),
        "physical" => to_py(py, &nanoworld::Params::physical_default()),
        other => Err(PyValueError::new_err(format!(
            "mode = {other:?}: allowed \"game\", \"physical\""
        ))),
    }
}

/// An approach–retract force–distance curve of the bare tip over the
/// substrate of ``params`` (movable atoms, loading zone and house removed),
/// measured by stepping a real world.
///
/// Args:
///     params: "game" (default), "physical" or a scene-table dict.
///     xy_m: lateral cursor position (x, y) (m), default (0, 0).
///     far_gap_m: cursor gap where the sweep starts and ends (m),
///         0 < far_gap_m <= 1e-6. The gap is between the undeflected tip
///         surface and the substrate's top surface.
///     near_gap_m: cursor gap where approach turns into retraction (m),
///         < far_gap_m (negative: press).
///     steps: ticks per leg, 2 ..= 10**7 (default 2000).
///     dt_s: tick length (s), 0 < dt_s <= 1.
///     device: the device limits, as for :class:`NanoWorld`.
///
/// Returns:
///     dict with "approach_gap" and "approach_force" ((steps+1,) m and N,
///     gap decreasing), "retract_gap" and "retract_force" (gap increasing),
///     "snap_index" and "pull_off_index" (int or None: the tick of the snap
///     on approach and of the release on retraction), and "hysteresis"
///     (J): the energy dissipated over the loop, −∮F dz. Force is the z
///     component sent to the device (negative: towards the substrate).
#[pyfunction]
#[pyo3(signature = (params=None, *, xy_m=None, far_gap_m=2e-9, near_gap_m=0.0, steps=None, dt_s=1e-3, device=None))]
#[allow(clippy::too_many_arguments)]
pub fn force_distance_curve<'py>(
    py: Python<'py>,
    params: Option<&Bound<'py, PyAny>>,
    xy_m: Option<&Bound<'py, PyAny>>,
    far_gap_m: f64,
    near_gap_m: f64,
    steps: Option<&Bound<'py, PyAny>>,
    dt_s: f64,
    device: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = params_from_py(params)?;
    let limits = limits_from_py(device, &p)?;
    let xy = match xy_m {
        Some(v) => vector::<2>(v, "xy_m", "m")?,
        None => nalgebra::Vector2::zeros(),
    };
    let spec = CurveSpec {
        xy_m: [xy.x, xy.y],
        far_gap_m,
        near_gap_m,
        steps: match steps {
            Some(n) => int_in(n, "steps", 2, 10_000_000)? as usize,
            None => 2000,
        },
        dt_s,
    };
    let c = py
        .detach(|| curve(&p, &limits, &spec))
        .map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("approach_gap", PyArray1::from_vec(py, c.approach_gap_m))?;
    d.set_item("approach_force", PyArray1::from_vec(py, c.approach_force_n))?;
    d.set_item("retract_gap", PyArray1::from_vec(py, c.retract_gap_m))?;
    d.set_item("retract_force", PyArray1::from_vec(py, c.retract_force_n))?;
    d.set_item("snap_index", c.snap_index)?;
    d.set_item("pull_off_index", c.pull_off_index)?;
    d.set_item("hysteresis", c.hysteresis_j)?;
    Ok(d)
}
