//! numpy arrays in and out, argument checks and error mapping.
//!
//! Every check here is about the *shape* of what Python passed (array
//! dimensions, finite numbers, integer ranges) and names the argument; the
//! physical ranges are checked by the wrapped crates and their typed errors are
//! raised unchanged as `ValueError`.

use haptic_types::value::{ValueError, out_of_range};
use nalgebra::SVector;
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyInt, PyString};

/// Ticks a batch call runs without the GIL before it checks for signals
/// (Ctrl-C): about 10 ms to 1 s of work, so an interrupt is honoured promptly.
pub(crate) const SIGNAL_CHUNK_TICKS: usize = 10_000;

/// Raise a crate error as `ValueError` with its `Display` text (which names
/// the field and the allowed range).
pub(crate) fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Format a shape the way numpy prints it: `(3,)`, `(4, 2)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(|s| s.to_string()).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// An array-like of numbers read as float64: data in row-major order and shape.
pub(crate) struct Numbers {
    /// Values in C (row-major) order.
    pub data: Vec<f64>,
    /// numpy shape.
    pub shape: Vec<usize>,
}

/// Read any array-like of numbers (list, tuple, numpy array of any real dtype).
pub(crate) fn numbers(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Numbers> {
    let arr: PyArrayLikeDyn<'_, f64, AllowTypeChange> = obj.extract().map_err(|e: PyErr| {
        PyValueError::new_err(format!("{name}: expected an array of real numbers ({e})"))
    })?;
    let view = arr.as_array();
    Ok(Numbers {
        shape: view.shape().to_vec(),
        data: view.iter().copied().collect(),
    })
}

/// Fail on the first non-finite value, naming its index.
fn all_finite(n: &Numbers, name: &str, unit: &str) -> PyResult<()> {
    let Some(k) = n.data.iter().position(|v| !v.is_finite()) else {
        return Ok(());
    };
    let mut idx = Vec::with_capacity(n.shape.len());
    let mut rest = k;
    for (d, _) in n.shape.iter().enumerate() {
        let stride: usize = n.shape[d + 1..].iter().product();
        idx.push((rest / stride).to_string());
        rest %= stride;
    }
    Err(value_error(ValueError::out_of_range(
        format!("{name}[{}]", idx.join(", ")),
        n.data[k],
        format!("finite ({unit})"),
    )))
}

fn to_vectors<const D: usize>(data: &[f64]) -> Vec<SVector<f64, D>> {
    data.chunks_exact(D)
        .map(SVector::<f64, D>::from_column_slice)
        .collect()
}

/// An array-like of finite numbers whose shape `fits`: otherwise a ValueError
/// `"{name}: expected shape {expected}, got (...)"`, then one naming the first non-finite value.
fn shaped(
    obj: &Bound<'_, PyAny>,
    name: &str,
    unit: &str,
    fits: impl FnOnce(&[usize]) -> bool,
    expected: impl FnOnce() -> String,
) -> PyResult<Numbers> {
    let n = numbers(obj, name)?;
    if !fits(&n.shape) {
        return Err(PyValueError::new_err(format!(
            "{name}: expected shape {}, got {}",
            expected(),
            shape_text(&n.shape)
        )));
    }
    all_finite(&n, name, unit)?;
    Ok(n)
}

/// An `(N, D)` array of finite numbers as N vectors.
pub(crate) fn rows<const D: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    unit: &str,
) -> PyResult<Vec<SVector<f64, D>>> {
    let fits = |s: &[usize]| s.len() == 2 && s[1] == D;
    let n = shaped(obj, name, unit, fits, || format!("(N, {D})"))?;
    Ok(to_vectors(&n.data))
}

/// A `(D,)` array of finite numbers.
pub(crate) fn vector<const D: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    unit: &str,
) -> PyResult<SVector<f64, D>> {
    let n = shaped(obj, name, unit, |s| s == [D], || format!("({D},)"))?;
    Ok(SVector::<f64, D>::from_column_slice(&n.data))
}

/// A `(D,)` array (one vector for all rows) or an `(N, D)` array (one per row).
pub(crate) fn one_or_rows<const D: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    unit: &str,
    n_rows: usize,
) -> PyResult<Vec<SVector<f64, D>>> {
    let fits = |s: &[usize]| s == [D] || s == [n_rows, D];
    let n = shaped(obj, name, unit, fits, || {
        format!("({D},) or ({n_rows}, {D})")
    })?;
    Ok(to_vectors(&n.data))
}

/// A `(D,)` array or an `(N, D)` array of finite numbers; returns the vectors
/// and whether a single vector was given.
pub(crate) fn point_or_rows<const D: usize>(
    obj: &Bound<'_, PyAny>,
    name: &str,
    unit: &str,
) -> PyResult<(Vec<SVector<f64, D>>, bool)> {
    let fits = |s: &[usize]| s == [D] || (s.len() == 2 && s[1] == D);
    let n = shaped(obj, name, unit, fits, || format!("({D},) or (N, {D})"))?;
    Ok((to_vectors(&n.data), n.shape == [D]))
}

/// A Python integer in `lo ..= hi`: TypeError naming `name` for a non-integer (a bool is
/// not a count), ValueError naming it and the range for an integer outside it (however
/// large: no OverflowError).
pub(crate) fn int_in(obj: &Bound<'_, PyAny>, name: &str, lo: i128, hi: i128) -> PyResult<i128> {
    if obj.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected an integer, got bool"
        )));
    }
    let v: i128 = match obj.extract() {
        Ok(v) => v,
        Err(_) if obj.is_instance_of::<PyInt>() => {
            return Err(PyValueError::new_err(out_of_range(
                name,
                obj,
                &format!("{lo} ..= {hi}"),
            )));
        }
        Err(_) => {
            return Err(PyTypeError::new_err(format!(
                "{name}: expected an integer, got {}",
                type_name(obj)
            )));
        }
    };
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(PyValueError::new_err(out_of_range(
            name,
            v,
            &format!("{lo} ..= {hi}"),
        )))
    }
}

/// The Python type name of `obj` (`int`, `str`, ...), for messages.
pub(crate) fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "object".to_string())
}

/// A Python `str` argument: TypeError naming `name` otherwise.
pub(crate) fn text(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<String> {
    match obj.cast::<PyString>() {
        Ok(s) => Ok(s.to_cow()?.into_owned()),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name}: expected a str, got {}",
            type_name(obj)
        ))),
    }
}

/// Most ticks a batch argument (`max_ticks`, `settle_ticks`) may ask for: 10^12 (over 30
/// years at 1 kHz).
pub(crate) const MAX_BATCH_TICKS: i128 = 1_000_000_000_000;

/// `max_ticks` of `BrickWorld.run_wall_script`: a whole number 0 ..= 10^12.
pub(crate) fn max_ticks_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    Ok(int_in(obj, "max_ticks", 0, MAX_BATCH_TICKS)? as usize)
}

/// `settle_ticks` of `BrickWorld.run_wall_script`: a whole number 0 ..= 10^12.
pub(crate) fn settle_ticks_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    Ok(int_in(obj, "settle_ticks", 0, MAX_BATCH_TICKS)? as usize)
}

/// `mode` of `nano_params`: a str.
pub(crate) fn mode_arg(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    text(obj, "mode")
}

/// The sample rates `render_audio` accepts.
pub(crate) const SAMPLE_RATES: &str = "8000–192000 Hz";

/// `sample_rate` of `render_audio`: a whole number of Hz, 8000 ..= 192000.
pub(crate) fn sample_rate_arg(obj: &Bound<'_, PyAny>) -> PyResult<i64> {
    int_in(obj, "sample_rate", 8_000, 192_000)
        .map(|v| v as i64)
        .map_err(|e| {
            Python::attach(|py| {
                if e.is_instance_of::<PyValueError>(py) {
                    PyValueError::new_err(out_of_range("sample_rate", obj, SAMPLE_RATES))
                } else {
                    e
                }
            })
        })
}

/// N vectors as an `(N, D)` float64 array.
pub(crate) fn array2<'py, const D: usize>(
    py: Python<'py>,
    v: &[SVector<f64, D>],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = v.iter().flat_map(|x| x.iter().copied()).collect();
    PyArray1::from_vec(py, flat).reshape([v.len(), D])
}

/// Flat row-major data as a `(rows, cols)` float64 array.
pub(crate) fn array2_flat(
    py: Python<'_>,
    flat: Vec<f64>,
    cols: usize,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let rows = flat.len().checked_div(cols).unwrap_or(0);
    PyArray1::from_vec(py, flat).reshape([rows, cols])
}

/// A vector as a `(D,)` float64 array.
pub(crate) fn array1<'py, const D: usize>(
    py: Python<'py>,
    v: &SVector<f64, D>,
) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

#[cfg(test)]
mod tests {
    use super::shape_text;

    #[test]
    fn shapes_print_like_numpy() {
        assert_eq!(shape_text(&[3]), "(3,)");
        assert_eq!(shape_text(&[4, 2]), "(4, 2)");
        assert_eq!(shape_text(&[]), "()");
    }
}
