//! The inverse trap solver, working envelope and command clipping of
//! `ot-envelope`, on a [`GaussianTrap`].

use haptic_types::value::{ValueError, out_of_range};
use nalgebra::{SVector, Vector3};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use ot_envelope::envelope3::working_envelope_3d as envelope3;
use ot_envelope::{ClipMode, clip_command as clip, solve_trap as solve, working_envelope as we};
use ot_physics::{Propagator, TrapModel};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::convert::{array1, array2, int_in, value_error, vector};
use crate::interrupt::interruptible_flows;
use crate::trap::{GaussianTrap, Model, check_overdamped_velocity, parse_method};

/// Fewest RK4 substeps used when `method="rk4"` and no `substeps` is given: within 0.21 nm
/// of converged dynamics at the paper's constants (ot-envelope guide).
const DEFAULT_RK4_SUBSTEPS: u32 = 8;

/// Largest `ω·h` (rad) of the default RK4 step, `ω` the trap's fastest rate and `h` the
/// substep: the paper's tick with 8 substeps has `ω·h = 0.49`. A longer tick gets more
/// substeps so that its step stays as accurate; with a fixed 8, a 2.5 µs tick's RK4 map folds
/// where the true flow does not (a 21.7-million-vertex envelope in 10 s instead of 540
/// vertices in 40 ms).
const DEFAULT_RK4_OMEGA_H: f64 = 0.5;

/// Most fixed-step substeps for a tick map: an envelope, inverse or steering call runs some
/// hundreds of flows, so 10^4 RK4 substeps is already about 1 s of work (the error budget
/// never asks for more than 512).
const MAX_TICK_MAP_SUBSTEPS: i128 = 10_000;

/// The default substeps of `method="rk4"` for a tick `dt` (s) of `model`:
/// `max(8, ⌈ω·Δt / 0.5⌉)`, at most [`MAX_TICK_MAP_SUBSTEPS`].
fn default_substeps<const D: usize>(model: &TrapModel<D>, dt: f64) -> u32 {
    let n = (model.fastest_rate() * dt / DEFAULT_RK4_OMEGA_H).ceil();
    if n.is_finite() && n > f64::from(DEFAULT_RK4_SUBSTEPS) {
        n.min(MAX_TICK_MAP_SUBSTEPS as f64) as u32
    } else {
        DEFAULT_RK4_SUBSTEPS
    }
}

/// The tick map of a trap: its deterministic model, a method and Δt.
fn tick<const D: usize>(
    py: Python<'_>,
    model: TrapModel<D>,
    dt: f64,
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'_, PyAny>>,
) -> PyResult<Propagator<D>> {
    let default = default_substeps(&model, dt).into_pyobject(py)?.into_any();
    let substeps = match substeps {
        None if method == "rk4" => Some(&default),
        s => s,
    };
    let m = parse_method(method, rtol, substeps, MAX_TICK_MAP_SUBSTEPS)?;
    Propagator::new(model, m, dt).map_err(value_error)
}

/// The deterministic model of a 2D `trap` for the function `call`, and the particle's
/// initial `velocity` (2,) (m/s) checked against it.
fn planar(
    trap: &GaussianTrap,
    call: &str,
    velocity: &Bound<'_, PyAny>,
) -> PyResult<(TrapModel<2>, SVector<f64, 2>)> {
    let model = match trap.deterministic() {
        Model::D2(m) => m,
        Model::D3(_) => {
            return Err(PyValueError::new_err(format!(
                "trap: {call} needs a 2D trap (axial_waist=None); use working_envelope_3d for 3D"
            )));
        }
    };
    let v = vector::<2>(velocity, "velocity", "m/s")?;
    check_overdamped_velocity(&model, &[v])?;
    Ok((model, v))
}

/// Every trap offset (trap centre relative to the particle, m) that moves a
/// particle of initial ``velocity`` (2,) (m/s) by ``target`` (2,) (m) in one
/// tick ``dt`` (s), found by Newton with the exact Jacobian inside
/// ot-envelope's default search region (3 waists around the free drift).
/// The tick map (``method``) samples the region and seeds Newton; every
/// offset is then polished under the true dynamics (the default adaptive
/// method, within 0.01 nm of converged), so it reproduces the target within
/// 0.01 nm whatever the tick map's own error.
///
/// Args:
///     trap: a 2D :class:`GaussianTrap`.
///     method, rtol, substeps: the tick's integrator, as in
///         :meth:`GaussianTrap.displacement`; default "rk4" with
///         max(8, ⌈ω·dt / 0.5⌉) substeps (ω the trap's fastest rate: 8 at the
///         paper's tick, as many more as keep ω·h ≤ 0.5 for a longer one).
///
/// Returns:
///     (M, 2) float64 array of offsets (m), in a deterministic order;
///     (0, 2) when no offset in the region reaches the target. The GIL is
///     released.
#[pyfunction]
#[pyo3(signature = (trap, velocity, dt, target, *, method="rk4", rtol=None, substeps=None))]
#[allow(clippy::too_many_arguments)]
pub fn solve_trap<'py>(
    py: Python<'py>,
    trap: &GaussianTrap,
    velocity: &Bound<'py, PyAny>,
    dt: f64,
    target: &Bound<'py, PyAny>,
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (model, v0) = planar(trap, "solve_trap", velocity)?;
    let target = vector::<2>(target, "target", "m")?;
    let prop = tick(py, model, dt, method, rtol, substeps)?;
    let s = interruptible_flows(py, || solve(&prop, &v0, &target))?.map_err(value_error)?;
    array2(py, s.offsets())
}

/// The working envelope: the boundary of every displacement (m) reachable in
/// one tick ``dt`` (s) by a particle of initial ``velocity`` (2,) (m/s).
///
/// Args:
///     trap: a 2D :class:`GaussianTrap`.
///     tol: geometric tolerance of the polygon (m); default 0.5e-9.
///     method, rtol, substeps: as in :func:`solve_trap`.
///
/// Returns:
///     (K, 2) float64 polygon of displacements (m), counter-clockwise, first
///     vertex not repeated. The GIL is released.
#[pyfunction]
#[pyo3(signature = (trap, velocity, dt, *, tol=None, method="rk4", rtol=None, substeps=None))]
#[allow(clippy::too_many_arguments)]
pub fn working_envelope<'py>(
    py: Python<'py>,
    trap: &GaussianTrap,
    velocity: &Bound<'py, PyAny>,
    dt: f64,
    tol: Option<f64>,
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (model, v0) = planar(trap, "working_envelope", velocity)?;
    let prop = tick(py, model, dt, method, rtol, substeps)?;
    let e = interruptible_flows(py, || we(&prop, &v0, tol))?.map_err(value_error)?;
    array2(py, &e.polygon)
}

/// Clip a commanded displacement ``command`` (2,) (m) to the working
/// envelope of this tick (paper §2.4).
///
/// Args:
///     trap, velocity, dt, tol, method, rtol, substeps: as in
///         :func:`working_envelope` (the envelope is computed for the call).
///     mode: "radial" (the paper's rule: along the segment from zero
///         displacement, or the free drift when zero is unreachable, to the
///         command, stop at the first crossing) or "nearest" (the nearest
///         boundary point).
///
/// Returns:
///     (allowed, excess): two (2,) arrays (m); excess = command − allowed,
///     zero inside the envelope.
#[pyfunction]
#[pyo3(signature = (trap, velocity, dt, command, *, mode="radial", tol=None, method="rk4", rtol=None, substeps=None))]
#[allow(clippy::too_many_arguments)]
pub fn clip_command<'py>(
    py: Python<'py>,
    trap: &GaussianTrap,
    velocity: &Bound<'py, PyAny>,
    dt: f64,
    command: &Bound<'py, PyAny>,
    mode: &str,
    tol: Option<f64>,
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (model, v0) = planar(trap, "clip_command", velocity)?;
    let command = vector::<2>(command, "command", "m")?;
    let mode = match mode {
        "radial" | "nearest" => ClipMode::from_name(mode).map_err(value_error)?,
        other => {
            return Err(PyValueError::new_err(format!(
                "mode = {other:?}: allowed \"radial\", \"nearest\""
            )));
        }
    };
    let prop = tick(py, model, dt, method, rtol, substeps)?;
    let c = interruptible_flows(py, || {
        we(&prop, &v0, tol).and_then(|e| clip(&e, &command, mode))
    })?
    .map_err(value_error)?;
    PyTuple::new(py, [array1(py, &c.allowed), array1(py, &c.excess)])
}

/// The 3D working envelope as a closed triangle mesh of displacements (m):
/// rays on an icosphere of ``level`` subdivisions (0 ..= 6, default 4), marched out to
/// ``reach`` waists in steps of ``step`` waists.
///
/// Args:
///     trap: a 3D :class:`GaussianTrap` (with axial_waist).
///     velocity: (3,) initial velocity (m/s).
///     dt: the tick (s).
///     method, rtol, substeps: as in :func:`solve_trap`.
///
/// Returns:
///     (vertices, triangles): (V, 3) float64 displacements (m) and (T, 3)
///     int64 vertex indices, outward-facing counter-clockwise.
#[pyfunction]
#[pyo3(signature = (trap, velocity, dt, *, level=None, reach=3.0, step=0.1, method="rk4", rtol=None, substeps=None))]
#[allow(clippy::too_many_arguments)]
pub fn working_envelope_3d<'py>(
    py: Python<'py>,
    trap: &GaussianTrap,
    velocity: &Bound<'py, PyAny>,
    dt: f64,
    level: Option<&Bound<'py, PyAny>>,
    reach: f64,
    step: f64,
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let Model::D3(model) = trap.deterministic() else {
        return Err(PyValueError::new_err(
            "trap: working_envelope_3d needs a 3D trap (give axial_waist)",
        ));
    };
    let v: Vector3<f64> = vector::<3>(velocity, "velocity", "m/s")?;
    check_overdamped_velocity(&model, &[v])?;
    let level = match level {
        Some(l) => int_in(l, "level", 0, 6)? as u32,
        None => 4,
    };
    let prop = tick(py, model, dt, method, rtol, substeps)?;
    let e = interruptible_flows(py, || envelope3(&prop, &v, level, reach, step))?
        .map_err(value_error)?;
    let tri: Vec<i64> = e
        .mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(i64::from))
        .collect();
    let n = e.mesh.triangles.len();
    PyTuple::new(
        py,
        [
            array2(py, &e.mesh.vertices)?.into_any(),
            PyArray1::from_vec(py, tri).reshape([n, 3])?.into_any(),
        ],
    )
}

/// Largest number of polygon vertices × angles [`polygon_radius`] takes in one call.
const MAX_RADIUS_PAIRS: usize = 100_000_000;

/// The farthest crossing of the ray from `centre` at each angle of `angles` with the closed
/// polygon `poly` (same unit as the points; 0 where the ray meets no edge): the edge
/// `a + s·(b − a)`, `0 ≤ s < 1`, met at `t > 0` along the unit direction.
fn radius_of(poly: &[SVector<f64, 2>], centre: &SVector<f64, 2>, angles: &[f64]) -> Vec<f64> {
    let rel: Vec<SVector<f64, 2>> = poly.iter().map(|p| p - centre).collect();
    angles
        .iter()
        .map(|&th| {
            let (dy, dx) = th.sin_cos();
            let mut best = 0.0_f64;
            for (k, a) in rel.iter().enumerate() {
                let b = rel[(k + 1) % rel.len()];
                let (ex, ey) = (b.x - a.x, b.y - a.y);
                // ray t·d meets the edge a + s·e: solve [d, −e] (t, s) = a
                let den = dx * (-ey) - dy * (-ex);
                if den == 0.0 {
                    continue;
                }
                let t = (a.x * (-ey) - a.y * (-ex)) / den;
                let s = (dx * a.y - dy * a.x) / den;
                if (0.0..1.0).contains(&s) && t > 0.0 && t > best {
                    best = t;
                }
            }
            best
        })
        .collect()
}

/// The radial function of a polygon about a point: for each angle of ``angles`` (rad,
/// counter-clockwise from +x), the distance from ``centre`` (2,) to the farthest crossing of
/// that ray with the closed polygon ``polygon`` (K, 2) (0 where the ray meets no edge; same
/// unit as the points). A working envelope contains its free drift, so its radial function
/// about it describes it fully (a ray that grazes a fold still sees the outer boundary).
///
/// Returns:
///     (M,) float64 array. The GIL is released: threads computing radial functions of
///     different envelopes run in parallel.
#[pyfunction]
pub fn polygon_radius<'py>(
    py: Python<'py>,
    polygon: &Bound<'py, PyAny>,
    centre: &Bound<'py, PyAny>,
    angles: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let poly = crate::convert::rows::<2>(polygon, "polygon", "m")?;
    if poly.len() < 3 {
        return Err(PyValueError::new_err(format!(
            "polygon: expected at least 3 vertices, got {}",
            poly.len()
        )));
    }
    let centre = vector::<2>(centre, "centre", "m")?;
    let a = crate::convert::numbers(angles, "angles")?;
    if a.shape.len() != 1 {
        return Err(PyValueError::new_err(
            "angles: expected a 1-dimensional array of angles (rad)",
        ));
    }
    if let Some(k) = a.data.iter().position(|v| !v.is_finite()) {
        return Err(value_error(ValueError::out_of_range(
            format!("angles[{k}]"),
            a.data[k],
            "finite (rad)",
        )));
    }
    if poly.len().saturating_mul(a.data.len()) > MAX_RADIUS_PAIRS {
        return Err(PyValueError::new_err(out_of_range(
            "polygon × angles",
            format!("{} vertices × {} angles", poly.len(), a.data.len()),
            &format!("at most {MAX_RADIUS_PAIRS} pairs"),
        )));
    }
    let r = py.detach(|| radius_of(&poly, &centre, &a.data));
    Ok(PyArray1::from_vec(py, r))
}
