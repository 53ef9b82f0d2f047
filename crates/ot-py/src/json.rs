//! serde values to and from Python objects, for crates whose types derive
//! `Serialize`/`Deserialize` (parameters, views, events).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
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

/// A Python dict (through `json.dumps`) as a deserialisable value; errors
/// name the argument.
pub(crate) fn from_py<T: DeserializeOwned>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<T> {
    let json = obj
        .py()
        .import("json")?
        .call_method1("dumps", (obj,))
        .map_err(|e| PyValueError::new_err(format!("{name}: not JSON-serialisable ({e})")))?;
    let text: String = json.extract()?;
    serde_json::from_str::<T>(&text).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}

/// `CamelCase` to `snake_case`.
fn snake(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// An externally tagged enum value (`"Name"` or `{"Name": {fields}}`) as a
/// flat dict `{"type": "name", **fields}`.
pub(crate) fn tagged_to_py<'py, T: Serialize>(
    py: Python<'py>,
    t: &T,
) -> PyResult<Bound<'py, PyDict>> {
    let v = serde_json::to_value(t)
        .map_err(|e| PyValueError::new_err(format!("cannot convert to Python: {e}")))?;
    let d = PyDict::new(py);
    match &v {
        Value::String(s) => d.set_item("type", snake(s))?,
        Value::Object(m) if m.len() == 1 => {
            for (k, inner) in m {
                d.set_item("type", snake(k))?;
                match inner {
                    Value::Object(fields) => {
                        for (f, x) in fields {
                            d.set_item(f, value_to_py(py, x)?)?;
                        }
                    }
                    other => d.set_item("value", value_to_py(py, other)?)?,
                }
            }
        }
        other => d.set_item("value", value_to_py(py, other)?)?,
    }
    Ok(d)
}

#[cfg(test)]
mod tests {
    use super::snake;

    #[test]
    fn camel_case_becomes_snake_case() {
        assert_eq!(snake("GrabMissed"), "grab_missed");
        assert_eq!(snake("Spawned"), "spawned");
        assert_eq!(snake("TouchBegan"), "touch_began");
    }
}
