//! The errors of a lesson file: what is wrong (naming the field and what is allowed) and where
//! (`file:line:column`, found by the scene files' own [`haptic_types::textpos`]).

use haptic_types::SwitchError;
use haptic_types::textpos::{Location, Position, field_position, position};

/// What is wrong in a lesson file.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
pub enum LessonError {
    /// Not valid TOML for a lesson (unknown field, wrong type, missing field, …), in the TOML
    /// reader's words.
    #[error("lesson: {message}")]
    Syntax {
        /// What the TOML reader found wrong and what it expected.
        message: String,
        /// Byte offset in the text where it went wrong, when known.
        offset: Option<usize>,
    },
    /// A field's value is not allowed: `problem` says what is allowed.
    #[error("lesson: `{field}` {problem}")]
    Invalid {
        /// Dotted field path (`step[2].done.when`).
        field: String,
        /// What is wrong and what is allowed, starting with the value when there is one
        /// (`= "moon" is not a condition (allowed: …)`).
        problem: String,
    },
    /// A switch the step's scene does not offer, or a value outside its range.
    #[error("lesson: `{field}`: {source}")]
    Switch {
        /// Field path (`step[2].switches.gravity_m_per_s2`).
        field: String,
        /// What the scene allows.
        source: SwitchError,
    },
    /// The lesson file cannot be read.
    #[error("lesson: cannot read the file: {message}")]
    Io {
        /// The OS error.
        message: String,
    },
    /// A step's scene cannot be read or built.
    #[error("lesson: `{field}` = \"{scene}\": {message}")]
    Scene {
        /// Field path (`step[2].scene`).
        field: String,
        /// The scene as written.
        scene: String,
        /// The session's error (names the scene file, line and column when it is one).
        message: String,
    },
}

impl LessonError {
    /// Where in the lesson's `text` the error is: the TOML reader's position, or the named
    /// field's value (or the deepest table of its path that is present).
    pub fn position(&self, text: &str) -> Option<Position> {
        match self {
            LessonError::Syntax { offset, .. } => offset.map(|o| position(text, o)),
            LessonError::Io { .. } => None,
            // A field that is absent (`step` of a lesson without steps): the `[lesson]` table.
            LessonError::Invalid { field, .. }
            | LessonError::Switch { field, .. }
            | LessonError::Scene { field, .. } => {
                field_position(text, field).or_else(|| field_position(text, "lesson"))
            }
        }
    }

    /// An invalid field: `` `field` problem``.
    pub fn invalid(field: impl Into<String>, problem: impl Into<String>) -> Self {
        LessonError::Invalid {
            field: field.into(),
            problem: problem.into(),
        }
    }
}

/// A lesson file's error with its place: `file:line:column: lesson: …`.
#[derive(Clone, Debug, thiserror::Error, PartialEq)]
#[error("{at}: {error}")]
pub struct LessonFileError {
    /// The file and, when known, line and column.
    pub at: Location,
    /// What is wrong.
    pub error: Box<LessonError>,
}

impl LessonFileError {
    /// `error` located in `text`, the file called `file`.
    pub fn locate(error: LessonError, text: &str, file: &str) -> Self {
        LessonFileError {
            at: Location {
                file: file.to_string(),
                at: error.position(text),
            },
            error: Box::new(error),
        }
    }
}
