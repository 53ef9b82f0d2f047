//! `nanoworld::Params` to and from Python dicts.
//!
//! The dict has exactly the layout of the scene's TOML table (field names
//! with their units, `interaction = {"game": {...}}` or `{"physical": {...}}`),
//! so `tomllib.load(f)` of a scene table can be passed as is. Reading goes
//! directly from the Python objects into serde (`deny_unknown_fields`; NaN and inf
//! reach validation, which names the field); writing mirrors the
//! struct field by field.

use nanoworld::{
    GamePair, GameParams, HouseParams, Interaction, LoadingZone, Pairs, Params, PhysicalParams,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use world_form::Limits;

/// `params` as Python passes it: "game", "physical", a dict, or None (game). A dict is
/// validated whole ([`Params::validate`]: the error names the field's dotted path).
pub(crate) fn params_from_py(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Params> {
    let Some(obj) = obj else {
        return Ok(Params::game_default());
    };
    if obj.is_none() {
        return Ok(Params::game_default());
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return match s.to_cow()?.as_ref() {
            "game" => Ok(Params::game_default()),
            "physical" => Ok(Params::physical_default()),
            other => Err(PyValueError::new_err(format!(
                "params = {other:?}: allowed \"game\", \"physical\" or a dict of the scene table"
            ))),
        };
    }
    if !obj.is_instance_of::<PyDict>() {
        return Err(PyValueError::new_err(
            "params: allowed \"game\", \"physical\" or a dict of the scene table",
        ));
    }
    let p: Params = crate::json::from_py(obj, "params")?;
    // Validated whole, here, for every entry point that takes a params dict (NanoWorld,
    // set_params, force_distance_curve): a field the call does not use is no less wrong.
    p.validate().map_err(crate::convert::value_error)?;
    Ok(p)
}

/// The device limits a nano world renders to, in world units: None takes the Falcon as the
/// preset scenes map it (`params.default_limits()`: 8 nN and 20 N/m in game mode, 80 nN and
/// 30 N/m in physical mode), or a dict {"max_force_n": N, "max_stiffness_n_per_m": N/m} (the
/// old key "max_stiffness_n_m" is still accepted).
pub(crate) fn limits_from_py(obj: Option<&Bound<'_, PyAny>>, params: &Params) -> PyResult<Limits> {
    match obj {
        Some(o) if !o.is_none() => {
            let l: Limits = crate::json::from_py(o, "device")?;
            l.validate()
                .map_err(|e| PyValueError::new_err(format!("device: {e}")))?;
            Ok(l)
        }
        _ => Ok(params.default_limits()),
    }
}

/// Device limits as a dict {"max_force_n": N, "max_stiffness_n_per_m": N/m}.
pub(crate) fn limits_to_py<'py>(py: Python<'py>, l: &Limits) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("max_force_n", l.max_force_n)?;
    d.set_item("max_stiffness_n_per_m", l.max_stiffness_n_per_m)?;
    Ok(d)
}

fn pairs<'py, T>(
    py: Python<'py>,
    p: &Pairs<T>,
    f: impl Fn(&T) -> PyResult<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("tip_substrate", f(&p.tip_substrate)?)?;
    d.set_item("tip_atom", f(&p.tip_atom)?)?;
    d.set_item("atom_atom", f(&p.atom_atom)?)?;
    d.set_item("atom_substrate", f(&p.atom_substrate)?)?;
    Ok(d)
}

fn game_pair<'py>(py: Python<'py>, g: &GamePair) -> PyResult<Bound<'py, PyAny>> {
    let d = PyDict::new(py);
    d.set_item("strength_n_m2", g.strength_n_m2)?;
    d.set_item("activation_gap_m", g.activation_gap_m)?;
    d.set_item("snap_gap_m", g.snap_gap_m)?;
    d.set_item("stiffness_n_per_m", g.stiffness_n_per_m)?;
    Ok(d.into_any())
}

fn interaction<'py>(py: Python<'py>, i: &Interaction) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match i {
        Interaction::Game(GameParams {
            pull_off_ratio,
            pairs: ps,
        }) => {
            let g = PyDict::new(py);
            g.set_item("pull_off_ratio", *pull_off_ratio)?;
            g.set_item("pairs", pairs(py, ps, |x| game_pair(py, x))?)?;
            d.set_item("game", g)?;
        }
        Interaction::Physical(PhysicalParams {
            hamaker_j,
            contact_gap_m,
            cantilever_stiffness_n_per_m,
        }) => {
            let g = PyDict::new(py);
            g.set_item(
                "hamaker_j",
                pairs(py, hamaker_j, |x| Ok(x.into_pyobject(py)?.into_any()))?,
            )?;
            g.set_item("contact_gap_m", *contact_gap_m)?;
            g.set_item(
                "cantilever_stiffness_n_per_m",
                *cantilever_stiffness_n_per_m,
            )?;
            d.set_item("physical", g)?;
        }
    }
    Ok(d)
}

fn zone<'py>(py: Python<'py>, z: &LoadingZone) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("min_xy_m", z.min_xy_m.to_vec())?;
    d.set_item("max_xy_m", z.max_xy_m.to_vec())?;
    d.set_item("spawn_xy_m", z.spawn_xy_m.to_vec())?;
    Ok(d)
}

fn house<'py>(py: Python<'py>, h: &HouseParams) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let slots: Vec<Vec<f64>> = h.slots_m.iter().map(|s| s.to_vec()).collect();
    d.set_item("slots_m", slots)?;
    d.set_item("tolerance_m", h.tolerance_m)?;
    Ok(d)
}

/// The scene table of `p` as a dict (round-trips through [`params_from_py`]).
pub(crate) fn params_to_py<'py>(py: Python<'py>, p: &Params) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let s = PyDict::new(py);
    s.set_item("nx", p.substrate.nx)?;
    s.set_item("ny", p.substrate.ny)?;
    s.set_item("spacing_m", p.substrate.spacing_m)?;
    s.set_item("atom_radius_m", p.substrate.atom_radius_m)?;
    d.set_item("substrate", s)?;
    let t = PyDict::new(py);
    t.set_item("radius_m", p.tip.radius_m)?;
    d.set_item("tip", t)?;
    let a = PyDict::new(py);
    a.set_item("radius_m", p.atoms.radius_m)?;
    a.set_item("mass_kg", p.atoms.mass_kg)?;
    a.set_item("max_count", p.atoms.max_count)?;
    d.set_item("atoms", a)?;
    d.set_item("interaction", interaction(py, &p.interaction)?)?;
    d.set_item("gravity_m_per_s2", p.gravity_m_per_s2)?;
    d.set_item("inertia", p.inertia)?;
    match &p.loading_zone {
        Some(z) => d.set_item("loading_zone", zone(py, z)?)?,
        None => d.set_item("loading_zone", py.None())?,
    }
    let xy: Vec<Vec<f64>> = p.initial_atoms_xy_m.iter().map(|s| s.to_vec()).collect();
    d.set_item("initial_atoms_xy_m", xy)?;
    match &p.house {
        Some(h) => d.set_item("house", house(py, h)?)?,
        None => d.set_item("house", py.None())?,
    }
    Ok(d)
}
