//! `nanohaptics.GaussianTrap`: the optical-well model of `ot-physics` with its
//! flow map, trajectories and thermal runs.

// Python signatures with keyword options map to long Rust parameter lists.
#![allow(clippy::too_many_arguments)]

use haptic_types::value::ValueError;
use nalgebra::SVector;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use ot_physics::langevin::{Scheme, ThermalRun, simulate};
use ot_physics::{Method, Phase, Propagator, TrapModel, paper};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert::{
    array1, array2, int_in, one_or_rows, point_or_rows, rows, value_error, vector,
};

/// The model in its dimension.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Model {
    /// The paper's planar well.
    D2(TrapModel<2>),
    /// A 3D well with an axial waist.
    D3(TrapModel<3>),
}

/// Run `$body` with `$m` bound to the `TrapModel<D>` of either dimension.
macro_rules! with_model {
    ($model:expr, $m:ident => $body:expr) => {
        match $model {
            Model::D2($m) => $body,
            Model::D3($m) => $body,
        }
    };
}

/// A particle in an elliptic Gaussian optical well
/// ``P = -depth * exp(-ln2 * (x²/a² + y²/b² [+ z²/c²]))``, SI units throughout.
///
/// Args:
///     depth: well depth P0 (J), > 0.
///     waist: the pair of lateral half-depth radii (a, b) (m), each > 0.
///     mass: particle mass (kg), or None for an overdamped particle (needs drag).
///     axial_waist: axial half-depth radius c (m); makes the trap 3D.
///     radius: particle radius (m); with viscosity switches Stokes drag
///         γ = 6πηr on.
///     viscosity: fluid viscosity η (Pa·s).
///     temperature: temperature (K); switches thermal noise on for
///         :meth:`brownian` (needs radius and viscosity).
///     external_force: constant external force (N), one entry per axis.
///
/// Positions handed to :meth:`force`, :meth:`potential`, :meth:`trajectory`
/// and :meth:`brownian` are particle positions relative to the trap centre;
/// ``offsets`` of :meth:`displacement` are trap-centre positions relative to
/// the particle (the paper's convention). Raises ValueError naming the
/// argument and its allowed range.
#[pyclass(frozen, module = "nanohaptics")]
#[derive(Debug, Clone)]
pub struct GaussianTrap {
    pub(crate) model: Model,
    /// Particle radius (m), or None.
    #[pyo3(get)]
    radius: Option<f64>,
    /// Fluid viscosity (Pa·s), or None.
    #[pyo3(get)]
    viscosity: Option<f64>,
    /// Temperature (K), or None (no thermal noise).
    #[pyo3(get)]
    temperature: Option<f64>,
}

impl GaussianTrap {
    /// Wrap a validated model (no radius/viscosity/temperature recorded).
    fn from_model(model: Model) -> Self {
        Self {
            model,
            radius: None,
            viscosity: None,
            temperature: None,
        }
    }

    /// The model without thermal noise: the deterministic dynamics the flow
    /// map and trajectories integrate.
    pub(crate) fn deterministic(&self) -> Model {
        fn without_noise<const D: usize>(mut m: TrapModel<D>) -> TrapModel<D> {
            m.kt = None;
            m
        }
        match self.model {
            Model::D2(m) => Model::D2(without_noise(m)),
            Model::D3(m) => Model::D3(without_noise(m)),
        }
    }

    /// Spatial dimension (2 or 3).
    pub(crate) fn dim(&self) -> usize {
        match self.model {
            Model::D2(_) => 2,
            Model::D3(_) => 3,
        }
    }
}

/// Most fixed-step substeps for one flow (4e7 force evaluations with RK4, about 1 s).
pub(crate) const MAX_FLOW_SUBSTEPS: i128 = 10_000_000;

/// Parse an integration method with its options, rejecting options the
/// method does not use (rather than ignoring them).
pub(crate) fn parse_method(
    method: &str,
    rtol: Option<f64>,
    substeps: Option<&Bound<'_, PyAny>>,
    max_substeps: i128,
) -> PyResult<Method> {
    let n = match substeps {
        None => None,
        Some(obj) => Some(int_in(obj, "substeps", 1, max_substeps)? as u32),
    };
    let m = Method::from_name(method, rtol, n).map_err(value_error)?;
    let adaptive = matches!(m, Method::Adaptive { .. } | Method::Dopri5 { .. });
    if rtol.is_some() && !adaptive {
        return Err(PyValueError::new_err(format!(
            "rtol is used only by \"adaptive\" and \"dopri5\", not by method {method:?}"
        )));
    }
    if n.is_some() && (adaptive || m == Method::PaperRk4) {
        return Err(PyValueError::new_err(format!(
            "substeps is used only by \"rk4\", \"rk8\", \"symplectic\", \"yoshida4\" and \"yoshida6\", not by method {method:?}"
        )));
    }
    Ok(m)
}

/// An overdamped particle has no velocity state: refuse a nonzero one.
pub(crate) fn check_overdamped_velocity<const D: usize>(
    model: &TrapModel<D>,
    v: &[SVector<f64, D>],
) -> PyResult<()> {
    if model.mass.is_none() && v.iter().any(|x| x.iter().any(|c| *c != 0.0)) {
        return Err(PyValueError::new_err(
            "velocity: must be zero for an overdamped trap (mass=None): it has no velocity state",
        ));
    }
    Ok(())
}

fn positive(value: f64, name: &str, unit: &str) -> PyResult<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(value_error(ValueError::out_of_range(
            name.to_string(),
            value,
            format!("finite and > 0 ({unit})"),
        )))
    }
}

/// A batch of flows: the offsets (N, D) (m), their initial velocities (one (D,) for all or
/// (N, D)) (m/s) and the model bound to a method over Δt.
struct FlowBatch<const D: usize> {
    offsets: Vec<SVector<f64, D>>,
    velocities: Vec<SVector<f64, D>>,
    prop: Propagator<D>,
}

impl<const D: usize> FlowBatch<D> {
    /// Read and check `offsets` and `velocity`, then bind `model` to `method` over `dt` (s).
    fn new(
        model: TrapModel<D>,
        offsets: &Bound<'_, PyAny>,
        velocity: &Bound<'_, PyAny>,
        dt: f64,
        method: Method,
    ) -> PyResult<Self> {
        let offsets = rows::<D>(offsets, "offsets", "m")?;
        let velocities = one_or_rows::<D>(velocity, "velocity", "m/s", offsets.len())?;
        check_overdamped_velocity(&model, &velocities)?;
        let prop = Propagator::new(model, method, dt).map_err(value_error)?;
        Ok(Self {
            offsets,
            velocities,
            prop,
        })
    }
}

fn displacement_d<const D: usize>(py: Python<'_>, b: FlowBatch<D>) -> PyResult<Py<PyArray2<f64>>> {
    let out = py
        .detach(|| {
            let mut out = vec![SVector::<f64, D>::zeros(); b.offsets.len()];
            b.prop
                .flow_batch(&b.offsets, &b.velocities, &mut out)
                .map(|_| out)
        })
        .map_err(value_error)?;
    if let Some(i) = out.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
        return Err(PyValueError::new_err(format!(
            "displacement[{i}] is not finite: dt = {} s is beyond what the integrator \
             can follow for this model (use a shorter dt)",
            world_form::numbers::fmt_num(b.prop.dt())
        )));
    }
    Ok(array2(py, &out)?.unbind())
}

/// Row-major flattening of D×D matrices (numpy's [i, j] order).
fn flat_matrices<const D: usize>(m: &[nalgebra::SMatrix<f64, D, D>]) -> Vec<f64> {
    m.iter()
        .flat_map(|a| (0..D * D).map(move |k| a[(k / D, k % D)]))
        .collect()
}

fn flow_jacobian_d<'py, const D: usize>(
    py: Python<'py>,
    b: FlowBatch<D>,
) -> PyResult<Bound<'py, PyDict>> {
    let flows = py
        .detach(|| {
            b.offsets
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let v = if b.velocities.len() == 1 {
                        &b.velocities[0]
                    } else {
                        &b.velocities[i]
                    };
                    b.prop.flow_jacobian(o, v)
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .map_err(value_error)?;
    let n = flows.len();
    let d = PyDict::new(py);
    let disp: Vec<SVector<f64, D>> = flows.iter().map(|f| f.displacement).collect();
    let vel: Vec<SVector<f64, D>> = flows.iter().map(|f| f.velocity).collect();
    d.set_item("displacement", array2(py, &disp)?)?;
    d.set_item("velocity", array2(py, &vel)?)?;
    for (name, m) in [
        (
            "d_offset",
            flows.iter().map(|f| f.d_offset).collect::<Vec<_>>(),
        ),
        ("d_velocity", flows.iter().map(|f| f.d_velocity).collect()),
        ("dv_offset", flows.iter().map(|f| f.dv_offset).collect()),
    ] {
        d.set_item(
            name,
            PyArray1::from_vec(py, flat_matrices(&m)).reshape([n, D, D])?,
        )?;
    }
    Ok(d)
}

type Trajectory<const D: usize> = (Vec<f64>, Vec<SVector<f64, D>>, Vec<SVector<f64, D>>);

fn trajectory_d<const D: usize>(
    py: Python<'_>,
    model: TrapModel<D>,
    offset: &Bound<'_, PyAny>,
    velocity: &Bound<'_, PyAny>,
    duration: f64,
    samples: usize,
    method: Method,
) -> PyResult<Py<PyTuple>> {
    let offset = vector::<D>(offset, "offset", "m")?;
    let v0 = vector::<D>(velocity, "velocity", "m/s")?;
    check_overdamped_velocity(&model, &[v0])?;
    let h = duration / (samples - 1) as f64;
    let prop = Propagator::new(model, method, h).map_err(value_error)?;
    let (t, r, v): Trajectory<D> = py
        .detach(|| {
            let mut y = Phase { r: -offset, v: v0 };
            if model.mass.is_none() {
                // Overdamped: the velocity is the drift velocity (F + F_ext)/γ.
                let g = model.drag.unwrap_or(f64::INFINITY);
                y.v = (model.well.force(&y.r) + model.external_force) / g;
            }
            let mut t = Vec::with_capacity(samples);
            let mut r = Vec::with_capacity(samples);
            let mut v = Vec::with_capacity(samples);
            t.push(0.0);
            r.push(y.r);
            v.push(y.v);
            for k in 1..samples {
                y = prop.phase(&y)?.end;
                t.push(k as f64 * h);
                r.push(y.r);
                v.push(y.v);
            }
            Ok::<_, ot_physics::PhysicsError>((t, r, v))
        })
        .map_err(value_error)?;
    let t = PyArray1::from_vec(py, t);
    let tuple = PyTuple::new(
        py,
        [
            t.into_any(),
            array2(py, &r)?.into_any(),
            array2(py, &v)?.into_any(),
        ],
    )?;
    Ok(tuple.unbind())
}

fn brownian_d<const D: usize>(
    py: Python<'_>,
    model: TrapModel<D>,
    run: ThermalRun,
    start: Option<&Bound<'_, PyAny>>,
) -> PyResult<Py<PyArray2<f64>>> {
    let r0 = match start {
        Some(s) => vector::<D>(s, "start", "m")?,
        None => SVector::zeros(),
    };
    let start = Phase {
        r: r0,
        v: SVector::zeros(),
    };
    let out = py
        .detach(|| simulate(&model, start, &run))
        .map_err(value_error)?;
    Ok(array2(py, &out)?.unbind())
}

fn force_d<const D: usize>(
    py: Python<'_>,
    model: &TrapModel<D>,
    positions: &Bound<'_, PyAny>,
) -> PyResult<Py<PyAny>> {
    let (p, single) = point_or_rows::<D>(positions, "positions", "m")?;
    let f: Vec<SVector<f64, D>> = p
        .iter()
        .map(|r| model.well.force(r) + model.external_force)
        .collect();
    Ok(if single {
        array1(py, &f[0]).into_any().unbind()
    } else {
        array2(py, &f)?.into_any().unbind()
    })
}

fn potential_d<const D: usize>(
    py: Python<'_>,
    model: &TrapModel<D>,
    positions: &Bound<'_, PyAny>,
) -> PyResult<Py<PyAny>> {
    let (p, single) = point_or_rows::<D>(positions, "positions", "m")?;
    let e: Vec<f64> = p.iter().map(|r| model.well.potential(r)).collect();
    Ok(if single {
        e[0].into_pyobject(py)?.into_any().unbind()
    } else {
        PyArray1::from_vec(py, e).into_any().unbind()
    })
}

/// The particle and its fluid, the same options in either dimension.
struct Particle {
    mass: Option<f64>,
    radius: Option<f64>,
    viscosity: Option<f64>,
    temperature: Option<f64>,
}

/// The validated model of `D` dimensions with these waists (m); `external_force` (N), one
/// entry per axis, defaults to zero.
fn build<const D: usize>(
    depth: f64,
    waists: [f64; D],
    p: Particle,
    external_force: Option<&Bound<'_, PyAny>>,
) -> PyResult<TrapModel<D>> {
    let f = match external_force {
        Some(f) => vector::<D>(f, "external_force", "N")?.into(),
        None => [0.0; D],
    };
    TrapModel::builder(depth, waists)
        .maybe_mass(p.mass)
        .radius(p.radius)
        .viscosity(p.viscosity)
        .temperature(p.temperature)
        .external_force(f)
        .build()
        .map_err(value_error)
}

fn tuple_of<'py>(py: Python<'py>, v: &[f64]) -> PyResult<Bound<'py, PyTuple>> {
    PyTuple::new(py, v.iter().copied())
}

#[pymethods]
impl GaussianTrap {
    #[new]
    #[pyo3(signature = (depth, waist, mass, *, axial_waist=None, radius=None, viscosity=None, temperature=None, external_force=None))]
    fn new(
        depth: f64,
        waist: &Bound<'_, PyAny>,
        mass: Option<f64>,
        axial_waist: Option<f64>,
        radius: Option<f64>,
        viscosity: Option<f64>,
        temperature: Option<f64>,
        external_force: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let numbers = crate::convert::numbers(waist, "waist")?;
        if numbers.shape != [2] {
            return Err(PyValueError::new_err(format!(
                "waist: expected the pair (a, b) of lateral waists in m, got {} values",
                numbers.data.len()
            )));
        }
        let (a, b) = (numbers.data[0], numbers.data[1]);
        let particle = Particle {
            mass,
            radius,
            viscosity,
            temperature,
        };
        let model = match axial_waist {
            None => Model::D2(build(depth, [a, b], particle, external_force)?),
            Some(c) => Model::D3(build(depth, [a, b, c], particle, external_force)?),
        };
        // ot-physics accepts any positive waist; one so small that the stiffness
        // 2·ln2·P0/w² overflows would integrate to NaN. Refuse it here, by name, until the
        // model's own validation bounds it.
        let k = with_model!(&model, m => m.well.stiffness().as_slice().to_vec());
        let names = ["waist[0]", "waist[1]", "axial_waist"];
        let waists = [a, b, axial_waist.unwrap_or(1.0)];
        for (i, ki) in k.iter().enumerate() {
            if !ki.is_finite() {
                return Err(value_error(ValueError::out_of_range(
                    names[i],
                    waists[i],
                    "a waist whose stiffness 2*ln2*depth/waist**2 is finite (m)",
                )));
            }
        }
        Ok(Self {
            model,
            radius,
            viscosity,
            temperature,
        })
    }

    /// Displacements (m) of the particle after ``dt`` (s), one per trap offset.
    ///
    /// Args:
    ///     offsets: (N, D) trap-centre positions relative to the particle (m).
    ///     velocity: the particle's initial velocity (m/s): one (D,) vector
    ///         for all rows or an (N, D) array. Must be zero when mass is None.
    ///     dt: the interval (s), > 0.
    ///     method: "adaptive" (DOP853 with error control, default),
    ///         "dopri5", "paper-rk4" (one RK4 step: the paper's difference
    ///         equation), "rk4", "rk8", "symplectic", "yoshida4", "yoshida6".
    ///     rtol: relative tolerance of "adaptive"/"dopri5" (default DEFAULT_RTOL).
    ///     substeps: equal substeps of the fixed-step methods (default 16,
    ///         3 for "rk8").
    ///
    /// Returns:
    ///     (N, D) float64 array of displacements (m). Thermal noise is not
    ///     applied here (see :meth:`brownian`). The GIL is released while
    ///     the batch runs.
    #[pyo3(signature = (offsets, velocity, dt, *, method="adaptive", rtol=None, substeps=None))]
    fn displacement(
        &self,
        py: Python<'_>,
        offsets: &Bound<'_, PyAny>,
        velocity: &Bound<'_, PyAny>,
        dt: f64,
        method: &str,
        rtol: Option<f64>,
        substeps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyArray2<f64>>> {
        let method = parse_method(method, rtol, substeps, MAX_FLOW_SUBSTEPS)?;
        with_model!(self.deterministic(), m => displacement_d(py, FlowBatch::new(m, offsets, velocity, dt, method)?))
    }

    /// The flow map with its derivatives (variational equations), per offset.
    ///
    /// Same arguments as :meth:`displacement`. Returns a dict of arrays:
    /// "displacement" (N, D) m, "velocity" (N, D) end velocity in m/s,
    /// "d_offset" (N, D, D) ∂displacement/∂offset (dimensionless),
    /// "d_velocity" (N, D, D) ∂displacement/∂v0 (s), "dv_offset" (N, D, D)
    /// ∂(end velocity)/∂offset (1/s); element [n, i, j] is ∂(row i)/∂(column j).
    /// The GIL is released.
    #[pyo3(signature = (offsets, velocity, dt, *, method="adaptive", rtol=None, substeps=None))]
    fn flow_jacobian<'py>(
        &self,
        py: Python<'py>,
        offsets: &Bound<'py, PyAny>,
        velocity: &Bound<'py, PyAny>,
        dt: f64,
        method: &str,
        rtol: Option<f64>,
        substeps: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let method = parse_method(method, rtol, substeps, MAX_FLOW_SUBSTEPS)?;
        with_model!(self.deterministic(), m => flow_jacobian_d(py, FlowBatch::new(m, offsets, velocity, dt, method)?))
    }

    /// Positions and velocities at ``samples`` evenly spaced times over
    /// ``duration`` with the trap fixed at the origin.
    ///
    /// Args:
    ///     offset: (D,) trap-centre position relative to the particle at t = 0 (m).
    ///     velocity: (D,) initial velocity (m/s); zero when mass is None.
    ///     duration: total time (s), > 0.
    ///     samples: number of samples including t = 0 and t = duration, >= 2.
    ///     method, rtol, substeps: as in :meth:`displacement`; the method is
    ///         applied over each interval duration / (samples - 1).
    ///
    /// Returns:
    ///     (t, positions, velocities): t (S,) in s; positions (S, D) of the
    ///     particle relative to the trap centre in m (the first row is
    ///     ``-offset``); velocities (S, D) in m/s (overdamped: the drift
    ///     velocity).
    #[pyo3(signature = (offset, velocity, duration, samples, *, method="adaptive", rtol=None, substeps=None))]
    fn trajectory(
        &self,
        py: Python<'_>,
        offset: &Bound<'_, PyAny>,
        velocity: &Bound<'_, PyAny>,
        duration: f64,
        samples: &Bound<'_, PyAny>,
        method: &str,
        rtol: Option<f64>,
        substeps: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyTuple>> {
        let method = parse_method(method, rtol, substeps, MAX_FLOW_SUBSTEPS)?;
        let duration = positive(duration, "duration", "s")?;
        let samples = int_in(samples, "samples", 2, 10_000_000)? as usize;
        with_model!(self.deterministic(), m => trajectory_d(py, m, offset, velocity, duration, samples, method))
    }

    /// Thermal motion: positions (m) relative to the trap centre (the trap
    /// fixed at the origin), sampled at ``sample_rate``.
    ///
    /// Needs radius, viscosity and temperature. The particle starts at rest
    /// at ``start`` (default: the trap centre); the first sample is one
    /// interval after the start, so there are round(duration·sample_rate)
    /// samples. Samples are instantaneous positions (they alias: see the
    /// guide). Same seed, same bits.
    ///
    /// Args:
    ///     duration: simulated time (s), > 0.
    ///     sample_rate: output rate (Hz), > 0.
    ///     seed: random seed, an integer 0 ..= 2**64 - 1.
    ///     method: "auto" (overdamped when m/γ < h/100 or mass is None,
    ///         otherwise BAOAB), "baoab", or "overdamped".
    ///     substeps: integration steps per sample interval, 1 ..= 1000000.
    ///     start: (D,) start position relative to the trap centre (m).
    ///
    /// Returns:
    ///     (N, D) float64 array of positions (m). The GIL is released.
    #[pyo3(signature = (duration, sample_rate, *, seed, method="auto", substeps=None, start=None))]
    fn brownian(
        &self,
        py: Python<'_>,
        duration: f64,
        sample_rate: f64,
        seed: &Bound<'_, PyAny>,
        method: &str,
        substeps: Option<&Bound<'_, PyAny>>,
        start: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyArray2<f64>>> {
        let seed = int_in(seed, "seed", 0, i128::from(u64::MAX))? as u64;
        let scheme = Scheme::from_name(method).map_err(value_error)?;
        let substeps = match substeps {
            Some(s) => int_in(s, "substeps", 1, 1_000_000)? as u32,
            None => 1,
        };
        let run = ThermalRun {
            duration,
            sample_rate,
            substeps,
            scheme,
            seed,
        };
        with_model!(self.model, m => brownian_d(py, m, run, start))
    }

    /// Force on the particle (N): the well's restoring force plus the
    /// external force, at ``positions`` relative to the trap centre (m).
    ///
    /// ``positions`` is one (D,) point (returns (D,)) or an (N, D) array
    /// (returns (N, D)).
    fn force(&self, py: Python<'_>, positions: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        with_model!(&self.model, m => force_d(py, m, positions))
    }

    /// Potential energy of the well (J) at ``positions`` relative to the
    /// trap centre (m): a float for one (D,) point, an (N,) array for (N, D).
    fn potential(&self, py: Python<'_>, positions: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        with_model!(&self.model, m => potential_d(py, m, positions))
    }

    /// Spatial dimension: 2, or 3 with an axial waist.
    #[getter]
    fn dimension(&self) -> usize {
        self.dim()
    }

    /// Well depth P0 (J).
    #[getter]
    fn depth(&self) -> f64 {
        with_model!(&self.model, m => m.well.depth())
    }

    /// Lateral waists (a, b) (m).
    #[getter]
    fn waist<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let w = with_model!(&self.model, m => m.well.waists().as_slice().to_vec());
        tuple_of(py, &w[..2])
    }

    /// Axial waist c (m), or None for a 2D trap.
    #[getter]
    fn axial_waist(&self) -> Option<f64> {
        match &self.model {
            Model::D2(_) => None,
            Model::D3(m) => Some(m.well.waists()[2]),
        }
    }

    /// Particle mass (kg), or None (overdamped).
    #[getter]
    fn mass(&self) -> Option<f64> {
        with_model!(&self.model, m => m.mass)
    }

    /// Stokes drag coefficient γ = 6πηr (kg/s), or None (no drag).
    #[getter]
    fn drag(&self) -> Option<f64> {
        with_model!(&self.model, m => m.drag)
    }

    /// Small-oscillation stiffness per axis κ_i = 2·ln2·P0 / w_i² (N/m).
    #[getter]
    fn stiffness<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let k = with_model!(&self.model, m => m.well.stiffness().as_slice().to_vec());
        tuple_of(py, &k)
    }

    /// Constant external force per axis (N).
    #[getter]
    fn external_force<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let f = with_model!(&self.model, m => m.external_force.as_slice().to_vec());
        tuple_of(py, &f)
    }

    fn __repr__(&self) -> String {
        let w = with_model!(&self.model, m => m.well.waists().as_slice().to_vec());
        let mass = with_model!(&self.model, m => m.mass);
        // Numbers by fmt_num: its shortest round-trip form is a Python literal of the value.
        let num = world_form::numbers::fmt_num;
        let opt = |v: Option<f64>| v.map_or("None".to_string(), num);
        let mut s = format!(
            "GaussianTrap(depth={}, waist=({}, {}), mass={}",
            num(self.depth()),
            num(w[0]),
            num(w[1]),
            opt(mass)
        );
        if let Some(c) = w.get(2) {
            s.push_str(&format!(", axial_waist={}", num(*c)));
        }
        for (name, v) in [
            ("radius", self.radius),
            ("viscosity", self.viscosity),
            ("temperature", self.temperature),
        ] {
            if v.is_some() {
                s.push_str(&format!(", {name}={}", opt(v)));
            }
        }
        s.push(')');
        s
    }
}

/// The optical-tweezers paper's trap (Lee, Lyons & LeBrun): depth 1e-15 J
/// (1e-6 nJ), waists (600e-9, 300e-9) m, mass 1e-15 kg (1e-12 g); no drag,
/// no noise. Use with ``PAPER_DT`` = 1e-6 s and ``PAPER_V0_MOVING`` =
/// (0.1, 0.1) m/s (100 nm/µs).
#[pyfunction]
pub fn paper_trap() -> PyResult<GaussianTrap> {
    let model = paper::model().map_err(value_error)?;
    Ok(GaussianTrap::from_model(Model::D2(model)))
}
