//! # nanohaptics-recording: the recording format, alone
//!
//! What it is for: reading and writing nanohaptics sessions as MCAP files, so that any tool
//! can read them without the engine.
//!
//! - [`channels`]: every channel of a recording, its CDR message (declared once: schema text,
//!   encoder, decoder and per-tick columns come from one declaration) and the format version;
//! - [`encode`]: the messages of one tick ([`TickEncoder`]), the same code for recording and
//!   for replay so that replay compares exactly what was written;
//! - [`edit`]: a recording's switch schedule and its rewrite as a new complete file;
//! - [`writer`]: a writer thread that never stalls a tick ([`Recorder`]);
//! - [`reader`]: the strict reader ([`read_recording`]): framing, decompression and CRCs by the
//!   `mcap` crate's sans-io reader; on top, the summary against the records, tick order and
//!   count, and salvage of a truncated file, with byte offsets in its errors; [`parse`] is its
//!   bounded field parser;
//! - [`foxglove_out`]: the Foxglove scene, transform and log messages of a tick.
//!
//! What it is not: no haptic loop, no scenes, no devices. It knows the shared types of
//! `haptic-types` (a tick's result, events, switches, primitives, device specifications) and
//! nothing of the engine that produces them. Layout and schemas: `docs/recording-format.md`.

pub mod channels;
pub mod edit;
pub mod encode;
pub mod foxglove_out;
pub mod parse;
pub mod reader;
pub mod writer;

pub use channels::messages::{Channel, DescriptionMsg};
pub use edit::{rewrite, switch_schedule};
pub use encode::{OutMsg, TickEncoder, TickMessages};
/// The bytes every MCAP file starts with (to tell a recording from a scene file).
pub use mcap::MAGIC;
pub use reader::{Integrity, Recording, RecordingError, read_recording, read_recording_file};
pub use writer::{Recorder, RecorderSetup, WriteSummary};
