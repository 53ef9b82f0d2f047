//! `nanoworld::Params` and device limits from Python arguments.
//!
//! The dict has exactly the layout of the scene's TOML table (field names
//! with their units, `interaction = {"game": {...}}` or `{"physical": {...}}`),
//! so `tomllib.load(f)` of a scene table can be passed as is. Reading goes
//! directly from the Python objects into serde (`deny_unknown_fields`; NaN and inf
//! reach validation, which names the field); writing is serde's form
//! ([`crate::json::to_py`]), so a dict read back equals the one written.

use nanoworld::Params;
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
