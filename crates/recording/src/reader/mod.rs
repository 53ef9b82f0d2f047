//! Reading recordings: every record in file order, with every integrity check a recording
//! carries. The jobs, one module each:
//!
//! - `framing` (the `mcap` crate's sans-io `LinearReader`): magic bytes, record framing, the
//!   data-section CRC and the summary-section CRC, each record placed at its byte offset;
//! - `chunk` (a second such reader, kept for the chunks of a file): decompression (zstd,
//!   lz4) and the chunk's CRC-32, checked before any of its records is used, then its records
//!   at their offsets in the decompressed bytes;
//! - `walk`: the data section's records (schemas, channels, messages, message indexes,
//!   metadata) through the bounded field parser [`crate::parse`];
//! - `ticks`: `/device/input` carries ticks 0, 1, 2, … in file order (no gap, no repeat),
//!   each tick ends with its `/loop/timing` message, and the count matches the `session`
//!   metadata record;
//! - `summary` and `check`: the summary section read, then checked against the records:
//!   statistics (message, channel, chunk and metadata counts, time range, messages per
//!   channel), chunk indexes (offset, length, times, sizes, message index offsets), the message
//!   indexes after each chunk, metadata indexes, summary offsets;
//! - `salvage`: a truncated file keeps its complete ticks (with `salvage`), or is an error
//!   that says how many are readable.
//!
//! Errors say what is wrong and where (not an MCAP file; the record and byte offset of a damaged
//! or inconsistent part; truncated after N complete ticks; a message that does not decode). A
//! damaged file is an error, never an abort or a panic: no size read from the file is allocated
//! before it is checked against the bytes that hold it (records against the file, a chunk's
//! uncompressed size against a bound of its compressed size).

mod check;
mod chunk;
mod framing;
mod salvage;
mod summary;
mod ticks;
mod walk;

#[cfg(test)]
mod tests;

use crate::channels::FORMAT_VERSION;
use crate::channels::messages::{Channel, DescriptionMsg};
use std::collections::BTreeMap;
use std::path::Path;

/// One message of a recording.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordedMessage {
    /// Its channel.
    pub channel: Channel,
    /// Log time, ns from the session start.
    pub log_time_ns: u64,
    /// Encoded bytes.
    pub data: Vec<u8>,
}

/// What the reader checked (all true / counted for a complete recording that was read).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Integrity {
    /// Chunks whose CRC-32 matched their decompressed records.
    pub chunk_crcs: u64,
    /// The data-section CRC matched.
    pub data_crc: bool,
    /// The summary-section CRC matched.
    pub summary_crc: bool,
    /// The summary (statistics, indexes, offsets) matched the records.
    pub summary: bool,
    /// Complete ticks read (ticks 0, 1, … in order, each with its input and timing messages).
    pub ticks: u64,
    /// The tick count matched the `session` metadata record.
    pub ticks_match_metadata: bool,
}

/// A recording read into memory.
#[derive(Clone, Debug)]
pub struct Recording {
    /// The scene description.
    pub description: DescriptionMsg,
    /// Messages of the known channels, in file order (the description included).
    pub messages: Vec<RecordedMessage>,
    /// Metadata records by name.
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// `(topic, schema name, message encoding)` of every channel in the file.
    pub channels: Vec<(String, String, String)>,
    /// Topics present in the file that this version does not know (their messages are skipped).
    pub unknown_topics: Vec<String>,
    /// When the file is truncated and was read leniently: why it ends early.
    pub truncated: Option<String>,
    /// File size, bytes.
    pub bytes: u64,
    /// What was checked.
    pub integrity: Integrity,
}

/// Errors reading a recording.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum RecordingError {
    /// The file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// OS error.
        message: String,
    },
    /// The file does not start with the MCAP magic.
    #[error("not an MCAP file (bad magic bytes)")]
    NotMcap,
    /// The file ends early (a crash or an interrupted copy). `ticks` complete ticks are
    /// readable; read it with salvage to use them.
    #[error(
        "truncated recording: {detail}; {ticks} complete ticks are readable (salvage them with --salvage)"
    )]
    Truncated {
        /// Complete ticks readable.
        ticks: u64,
        /// Where and how the file ends.
        detail: String,
    },
    /// A record is damaged, or does not agree with the rest of the file.
    #[error("corrupt recording: {record} at byte {offset}: {detail}")]
    Corrupt {
        /// Offset of the (top-level) record in the file, bytes.
        offset: u64,
        /// Which record.
        record: String,
        /// What is wrong.
        detail: String,
    },
    /// A salvage that recovers no complete tick.
    #[error("nothing to salvage: {detail}, before the end of its first tick")]
    NothingToSalvage {
        /// Where and how the file ends.
        detail: String,
    },
    /// No scene description (not a nanohaptics recording, or damaged at its start).
    #[error("the recording has no `/scene/description` message (not a nanohaptics recording?)")]
    NoDescription,
    /// A message that does not decode.
    #[error("bad message on {topic} at log time {log_time_ns} ns: {detail}")]
    BadMessage {
        /// Topic.
        topic: String,
        /// Log time, ns.
        log_time_ns: u64,
        /// Decoder error.
        detail: String,
    },
    /// A recording of another format version.
    #[error("recording format `{found}` is not supported (this build reads `{FORMAT_VERSION}`)")]
    Version {
        /// The format found.
        found: String,
    },
}

/// A [`RecordingError::Corrupt`] of the record at byte `at`.
fn corrupt(at: usize, record: impl Into<String>, detail: impl Into<String>) -> RecordingError {
    RecordingError::Corrupt {
        offset: at as u64,
        record: record.into(),
        detail: detail.into(),
    }
}

/// Reads a recording from bytes, with every check of the module documentation. With `salvage`,
/// a truncated file gives its complete ticks (and `truncated` says why it ends); without, it is
/// an error, and so is a salvage that finds no complete tick. A damaged or inconsistent file is
/// an error either way.
pub fn read_recording(buf: &[u8], salvage: bool) -> Result<Recording, RecordingError> {
    if buf.len() < mcap::MAGIC.len() || buf[..mcap::MAGIC.len()] != *mcap::MAGIC {
        return Err(RecordingError::NotMcap);
    }
    let mut records = framing::Framer::new(buf);
    let mut w = walk::Walk::default();
    let truncated = read_sections(&mut records, &mut w)?;
    salvage::finish(w, truncated, salvage, buf.len() as u64)
}

/// Both sections, checked; `Some(why)` when the file ends early.
fn read_sections(
    records: &mut framing::Framer<'_>,
    w: &mut walk::Walk,
) -> Result<Option<String>, RecordingError> {
    let data_end = match w.data_section(records)? {
        Err(why) => return Ok(Some(why)),
        Ok(d) => d,
    };
    w.data_end(&data_end)?;
    let mut s = summary::Summary::default();
    match s.read(records)? {
        Err(why) => Ok(Some(why)),
        Ok(footer) => {
            summary::check_footer(&s, &footer, data_end.end)?;
            w.integrity.summary_crc = true;
            check::check_summary(w, &s, footer.at)?;
            w.integrity.summary = true;
            Ok(None)
        }
    }
}

/// Reads a recording file (see [`read_recording`]).
pub fn read_recording_file(path: &Path, salvage: bool) -> Result<Recording, RecordingError> {
    let buf = std::fs::read(path).map_err(|e| RecordingError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    read_recording(&buf, salvage)
}
