//! The one form of a bad number: a field that is not finite, or outside its allowed range.
//!
//! Every crate that checks numbers given by a user (scene files, primitives, device packets,
//! Python arguments) says it the same way: `field must be finite, got NaN` or
//! `field = value is out of range: allowed RANGE`. Crates with their own error enums wrap
//! [`ValueError`] (or write their variants with [`out_of_range`]'s wording).

use thiserror::Error;

/// A number that is not finite or not in its allowed range.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ValueError {
    /// A number is NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NotFinite {
        /// Dotted name of the field, e.g. `sphere.center_m[1]`.
        field: String,
        /// The value given.
        value: f64,
    },
    /// A number lies outside its allowed range.
    #[error("{field} = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// Dotted name of the field.
        field: String,
        /// The value given.
        value: f64,
        /// The allowed range, written out with its unit, e.g. `(0, 50] frames/s`.
        allowed: &'static str,
    },
}

/// The out-of-range message for a field whose allowed range is only known at run time
/// (`field = value is out of range: allowed RANGE`), the same wording as
/// [`ValueError::OutOfRange`].
pub fn out_of_range(field: &str, value: impl std::fmt::Display, allowed: &str) -> String {
    format!("{field} = {value} is out of range: allowed {allowed}")
}

/// Checks that `value` is finite (`field` is built only on error).
pub fn finite(field: impl FnOnce() -> String, value: f64) -> Result<f64, ValueError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(ValueError::NotFinite {
            field: field(),
            value,
        })
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
        let e = ValueError::OutOfRange {
            field: "fps".into(),
            value: 60.5,
            allowed: "(0, 50] frames/s",
        };
        assert_eq!(e.to_string(), out_of_range("fps", 60.5, "(0, 50] frames/s"));
        assert_eq!(
            e.to_string(),
            "fps = 60.5 is out of range: allowed (0, 50] frames/s"
        );
    }
}
