//! The recording's channels: each message's struct, its CDR encoding and its schema text.
//!
//! This sits below the recorder, the per-tick arrays and the replay verifier, which all read
//! and write these messages.

pub mod cdr;
pub mod messages;

/// Format version written in the scene description; bumped on any layout change.
pub const FORMAT_VERSION: &str = "nanohaptics-recording/3";
