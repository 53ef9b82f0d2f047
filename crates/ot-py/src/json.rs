//! serde values to and from Python objects, for crates whose types derive
//! `Serialize`/`Deserialize` (parameters, views, events): the one conversion of the wheel.
//! A value reaches Python in serde's form (the form a recording's event detail and a scene
//! file's table have: `{"type": "snap", "member": "tip", "target": {"substrate_atom": 0}}`),
//! and a dict comes back through serde, so what a getter returns is accepted as it is.

use haptic_types::value::out_of_range;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyInt, PyList, PyString, PyTuple};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

/// A JSON value as a Python object (dicts, lists, floats, ints, bools, None).
pub(crate) fn value_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(value_to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, value_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// Any serialisable value as a Python object.
pub(crate) fn to_py<'py, T: Serialize>(py: Python<'py>, t: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(t)
        .map_err(|e| PyValueError::new_err(format!("cannot convert to Python: {e}")))?;
    value_to_py(py, &v)
}

/// The events of a batch as a list of `(tick, event dict)`, `tick` the row index of the tick
/// that raised it.
pub(crate) fn tick_events<'a, 'py, E: Serialize + 'a>(
    py: Python<'py>,
    per_tick: impl Iterator<Item = &'a [E]>,
) -> PyResult<Bound<'py, PyList>> {
    let ev = PyList::empty(py);
    for (k, events) in per_tick.enumerate() {
        for e in events {
            ev.append((k, to_py(py, e)?))?;
        }
    }
    Ok(ev)
}

/// A Python value (dicts, lists, tuples, numpy arrays, floats, ints, bools,
/// strings) as a TOML value, keeping every float as it is — NaN and ±inf
/// included, so that they reach the wrapped crate's validation, which names
/// the field and its range. A `None` inside a dict means the key is absent.
/// `path` names the value in errors (`params.substrate.nx`).
pub(crate) fn py_to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<toml::Value> {
    if obj.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return obj
            .extract::<i64>()
            .map(toml::Value::Integer)
            .map_err(|_| PyValueError::new_err(out_of_range(path, obj, "a 64-bit integer")));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                PyTypeError::new_err(format!("{path}: keys must be strings, got {k:?}"))
            })?;
            if v.is_none() {
                continue;
            }
            let inner = py_to_toml(&v, &format!("{path}.{key}"))?;
            t.insert(key, inner);
        }
        return Ok(toml::Value::Table(t));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, v) in obj.try_iter()?.enumerate() {
            out.push(py_to_toml(&v?, &format!("{path}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    if obj.hasattr("tolist")? {
        // numpy arrays and scalars.
        return py_to_toml(&obj.call_method0("tolist")?, path);
    }
    Err(PyTypeError::new_err(format!(
        "{path}: expected a number, bool, string, list or dict, got {}",
        obj.get_type().name()?
    )))
}

/// A Python dict as a deserialisable value, converted directly (no JSON text:
/// NaN and inf survive to the crate's validation, which names the field).
/// Errors name the argument and the key path; arrays with more elements than
/// the field takes are refused.
pub(crate) fn from_py<T: DeserializeOwned>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<T> {
    let v = py_to_toml(obj, name)?;
    v.try_into::<T>().map_err(|e| {
        let text = e.to_string().trim_end().replace('\n', " ");
        PyValueError::new_err(format!("{name}: {text}"))
    })
}
