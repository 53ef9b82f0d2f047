//! Range checks and the scene error: a leaf every scene module uses (it imports no other
//! scene module).

use haptic_types::textpos::{Position, field_position, position};

/// Errors in a scene file.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SceneError {
    /// Not valid TOML for a scene (unknown field, wrong type, missing field, ...).
    #[error("scene: {message}")]
    Syntax {
        /// What the TOML reader found wrong and what it expected.
        message: String,
        /// Byte offset in the text where it went wrong, when known.
        offset: Option<usize>,
    },
    /// A world refused its parameters.
    #[error("scene: {section}: {message}")]
    World {
        /// The scene table the world reads, e.g. `nanoworld.params`.
        section: String,
        /// The offending field's dotted path inside `section`, when the world names one.
        field: Option<String>,
        /// The world's own message (names the field and the allowed range).
        message: String,
    },
    /// A value out of its allowed range (the one wording of
    /// [`haptic_types::value::out_of_range`]; a number shown by [`fmt_num`]).
    #[error("scene: {}", haptic_types::value::out_of_range(&format!("`{field}`"), value, allowed))]
    OutOfRange {
        /// Field path, e.g. `mapping.force_scale`.
        field: String,
        /// The value found, as shown: a number by [`fmt_num`], other values as written.
        value: String,
        /// The allowed range in words.
        allowed: String,
    },
    /// `scene.kind` names no known world, or its table is missing.
    #[error("scene: `scene.kind` = \"{kind}\" {problem}")]
    Kind {
        /// The kind found.
        kind: String,
        /// What is wrong.
        problem: String,
    },
    /// The file could not be read.
    #[error("scene: cannot read {path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// OS error.
        message: String,
    },
}

impl SceneError {
    /// Where in the scene's `text` the error is: the TOML reader's position, or the named
    /// field's value (`None` when neither is known).
    pub fn position(&self, text: &str) -> Option<Position> {
        match self {
            SceneError::Syntax { offset, .. } => offset.map(|o| position(text, o)),
            SceneError::OutOfRange { field, .. } => field_position(text, field),
            SceneError::Kind { .. } => field_position(text, "scene.kind"),
            SceneError::World { section, field, .. } => field
                .as_ref()
                .and_then(|f| field_position(text, &format!("{section}.{f}")))
                .or_else(|| field_position(text, section)),
            SceneError::Io { .. } => None,
        }
    }
}

/// Builds the out-of-range error of a number, shown by [`fmt_num`].
pub fn out_of_range(field: &str, value: f64, allowed: impl Into<String>) -> SceneError {
    out_of_range_text(field, fmt_num(value), allowed)
}

/// Builds the out-of-range error of a value that is not one number (a name, a vector, a
/// table), `shown` as written (numbers in it by [`fmt_num`]).
pub fn out_of_range_text(
    field: &str,
    shown: impl Into<String>,
    allowed: impl Into<String>,
) -> SceneError {
    SceneError::OutOfRange {
        field: field.to_string(),
        value: shown.into(),
        allowed: allowed.into(),
    }
}

use world_form::fmt_num;

/// Checks `lo ≤ value ≤ hi` (and finite).
pub fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<(), SceneError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(out_of_range(
            field,
            value,
            format!("{} ≤ {field} ≤ {}", fmt_num(lo), fmt_num(hi)),
        ))
    }
}

/// Checks `0 < value ≤ hi` (and finite).
pub fn check_positive(field: &str, value: f64, hi: f64) -> Result<(), SceneError> {
    if value.is_finite() && value > 0.0 && value <= hi {
        Ok(())
    } else {
        Err(out_of_range(
            field,
            value,
            format!("0 < {field} ≤ {}", fmt_num(hi)),
        ))
    }
}
