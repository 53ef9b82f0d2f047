//! The recording's channels, each declared once: each message's struct, its CDR encoding,
//! its schema text, its per-tick columns and its rows in `docs/recording-format.md`.
//!
//! This sits below the recorder, the per-tick arrays and the replay verifier, which all read
//! and write these messages.

pub mod cdr;
pub mod declare;
pub mod doc;
pub mod messages;

/// Format version written in the scene description; bumped on any layout change.
pub const FORMAT_VERSION: &str = "nanohaptics-recording/3";
