//! The one form of a bad number: a field that is not finite, or outside its allowed range.
//!
//! Every crate that checks numbers given by a user (scene files, world parameters, primitives,
//! device packets, Python arguments) says it the same way: `field must be finite, got NaN` or
//! `field = value is out of range: allowed RANGE`, the value written by [`fmt_num`]. Crates
//! with their own error enums wrap [`ValueError`] (`#[error(transparent)]`); a message whose
//! value is not one number (a count shown with its unit, a Python object) is written with
//! [`out_of_range`].
//!
//! ```
//! use world_form::value::ValueError;
//! let e = ValueError::out_of_range("dt_s", 1e-300, "1e-9 ≤ dt_s ≤ 1 s");
//! assert_eq!(e.to_string(), "dt_s = 1e-300 is out of range: allowed 1e-9 ≤ dt_s ≤ 1 s");
//! ```

use std::borrow::Cow;

use crate::numbers::fmt_num;

/// A number that is not finite or not in its allowed range.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ValueError {
    /// A number is NaN or infinite.
    #[error("{field} must be finite, got {}", fmt_num(*value))]
    NotFinite {
        /// Name of the field as the user wrote it, e.g. `sphere.center_m[1]` or
        /// `` `mass_kg` ``.
        field: Cow<'static, str>,
        /// The value given (in the field's unit).
        value: f64,
    },
    /// A number lies outside its allowed range (or is not finite where the range says so).
    #[error("{field} = {} is out of range: allowed {allowed}", fmt_num(*value))]
    OutOfRange {
        /// Name of the field as the user wrote it.
        field: Cow<'static, str>,
        /// The value given (in the field's unit).
        value: f64,
        /// The allowed range, written out with its unit, e.g. `(0, 50] frames/s`.
        allowed: Cow<'static, str>,
    },
}

impl ValueError {
    /// A [`ValueError::OutOfRange`].
    pub fn out_of_range(
        field: impl Into<Cow<'static, str>>,
        value: f64,
        allowed: impl Into<Cow<'static, str>>,
    ) -> Self {
        ValueError::OutOfRange {
            field: field.into(),
            value,
            allowed: allowed.into(),
        }
    }

    /// The field's name.
    pub fn field(&self) -> &str {
        match self {
            ValueError::NotFinite { field, .. } | ValueError::OutOfRange { field, .. } => field,
        }
    }

    /// The value refused (in the field's unit).
    pub fn value(&self) -> f64 {
        match self {
            ValueError::NotFinite { value, .. } | ValueError::OutOfRange { value, .. } => *value,
        }
    }

    /// The same error with its field renamed by `f` (a prefix, a path into a table).
    pub fn map_field(self, f: impl FnOnce(&str) -> String) -> Self {
        match self {
            ValueError::NotFinite { field, value } => ValueError::NotFinite {
                field: f(&field).into(),
                value,
            },
            ValueError::OutOfRange {
                field,
                value,
                allowed,
            } => ValueError::OutOfRange {
                field: f(&field).into(),
                value,
                allowed,
            },
        }
    }
}

/// The out-of-range message of a value that is not one `f64` (a count, an image size, a
/// Python object, a vector), `shown` as the user should read it: `field = shown is out of
/// range: allowed RANGE`, the wording of [`ValueError::OutOfRange`]. A number should be shown
/// with [`fmt_num`].
pub fn out_of_range(field: &str, shown: impl std::fmt::Display, allowed: &str) -> String {
    format!("{field} = {shown} is out of range: allowed {allowed}")
}

/// Checks that `value` is finite (`field` is built only on error).
pub fn finite(field: impl FnOnce() -> String, value: f64) -> Result<f64, ValueError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ValueError::NotFinite {
            field: field().into(),
            value,
        })
    }
}

/// Checks that `value` is finite and passes its range test `ok`; else a
/// [`ValueError::OutOfRange`] naming `field` and the range `allowed`, written out with its unit.
pub fn in_range(
    field: impl Into<Cow<'static, str>>,
    value: f64,
    ok: bool,
    allowed: impl Into<Cow<'static, str>>,
) -> Result<(), ValueError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ValueError::out_of_range(field, value, allowed))
    }
}

/// Checks that every component of `p` is finite (`field[i]` names a bad one).
pub fn finite3(field: &str, p: [f64; 3]) -> Result<(), ValueError> {
    for (i, v) in p.iter().enumerate() {
        finite(|| format!("{field}[{i}]"), *v)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_field_and_range() {
        assert_eq!(
            finite3("arrow.to_m", [0.0, f64::INFINITY, 0.0])
                .unwrap_err()
                .to_string(),
            "arrow.to_m[1] must be finite, got inf"
        );
        let e = ValueError::out_of_range("fps", 60.5, "(0, 50] frames/s");
        assert_eq!(
            e.to_string(),
            out_of_range("fps", fmt_num(60.5), "(0, 50] frames/s")
        );
        assert_eq!(
            e.to_string(),
            "fps = 60.5 is out of range: allowed (0, 50] frames/s"
        );
        assert_eq!((e.field(), e.value()), ("fps", 60.5));
    }

    #[test]
    fn values_are_written_by_fmt_num() {
        let e = ValueError::out_of_range("dt_s", 5e-6, "0 < dt_s ≤ 1.6e-6 s");
        assert_eq!(
            e.to_string(),
            "dt_s = 5e-6 is out of range: allowed 0 < dt_s ≤ 1.6e-6 s"
        );
        let e = ValueError::out_of_range("x", 1e308, "|x| ≤ 1").map_field(|f| format!("`{f}`"));
        assert_eq!(
            e.to_string(),
            "`x` = 1e308 is out of range: allowed |x| ≤ 1"
        );
    }
}
