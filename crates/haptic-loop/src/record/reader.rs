//! Reading recordings: every record in file order, chunk CRCs checked, with errors that say
//! what is wrong (not an MCAP file, corrupt chunk, truncated after tick N, bad message).

use super::messages::{Channel, DescriptionMsg, FORMAT_VERSION};
use mcap::read::{ChunkFlattener, Options};
use mcap::records::Record;
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
        /// Ticks with their device input readable.
        ticks: u64,
        /// The reader's error.
        detail: String,
    },
    /// A record or chunk is damaged.
    #[error("corrupt recording: {0}")]
    Corrupt(String),
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

/// Largest uncompressed chunk accepted, bytes (the writer makes 8 MiB chunks).
const MAX_CHUNK: u64 = 1 << 30;

/// Walks the file's top-level records (opcode u8, length u64) and refuses a chunk whose
/// announced uncompressed size is beyond any plausible bound before the MCAP reader allocates
/// it: a damaged size field is an error naming the byte offset, never an abort. A length that
/// runs past the end stops the walk (the reader then reports the truncation).
fn check_chunk_sizes(buf: &[u8]) -> Result<(), RecordingError> {
    let u64_at = |at: usize| -> Option<u64> {
        buf.get(at..at + 8)
            .map(|b| u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
    };
    let mut at = 8usize;
    while let (Some(&op), Some(len)) = (buf.get(at), u64_at(at + 1)) {
        let body = at + 9;
        let Some(end) = usize::try_from(len).ok().and_then(|l| body.checked_add(l)) else {
            return Ok(());
        };
        if end > buf.len() {
            return Ok(());
        }
        if op == 0x06 {
            // Chunk: start u64, end u64, uncompressed size u64, crc u32, compression string,
            // records length u64, records.
            let size = u64_at(body + 16).unwrap_or(0);
            let bound = MAX_CHUNK.min(len.saturating_mul(1000).saturating_add(1 << 20));
            if size > bound {
                return Err(RecordingError::Corrupt(format!(
                    "chunk at byte {at}: uncompressed size {size} bytes is over the bound of \
                     {bound} bytes for a {len}-byte chunk (a damaged size field)"
                )));
            }
        }
        if op == 0x02 {
            return Ok(()); // footer
        }
        at = end;
    }
    Ok(())
}

/// Reads a recording from bytes. With `salvage`, a truncated file gives the complete part
/// (and `truncated` says why it ends); without, it is an error.
pub fn read_recording(buf: &[u8], salvage: bool) -> Result<Recording, RecordingError> {
    if buf.len() < 8 || &buf[..8] != mcap::MAGIC {
        return Err(RecordingError::NotMcap);
    }
    check_chunk_sizes(buf)?;
    let flat = ChunkFlattener::new_with_options(buf, Options::ValidateChunkCrcs.into())
        .map_err(|e| RecordingError::Corrupt(e.to_string()))?;
    let mut topics: BTreeMap<u16, Option<Channel>> = BTreeMap::new();
    let mut schemas: BTreeMap<u16, String> = BTreeMap::new();
    let mut messages = Vec::new();
    let mut metadata = BTreeMap::new();
    let mut channels = Vec::new();
    let mut unknown_topics = Vec::new();
    let mut truncated = None;
    let mut saw_end = false;
    for rec in flat {
        let rec = match rec {
            Ok(r) => r,
            Err(e) => {
                let eof = matches!(
                    e,
                    mcap::McapError::UnexpectedEof | mcap::McapError::UnexpectedEoc
                ) || e.to_string().contains("end of file")
                    || matches!(e, mcap::McapError::BadMagic);
                if eof {
                    truncated = Some(e.to_string());
                    break;
                }
                return Err(RecordingError::Corrupt(e.to_string()));
            }
        };
        match rec {
            Record::Schema { header, .. } => {
                schemas.insert(header.id, header.name.clone());
            }
            Record::Channel(c) => {
                let known = Channel::from_topic(&c.topic);
                if known.is_none() {
                    unknown_topics.push(c.topic.clone());
                }
                if !topics.contains_key(&c.id) {
                    channels.push((
                        c.topic.clone(),
                        schemas.get(&c.schema_id).cloned().unwrap_or_default(),
                        c.message_encoding.clone(),
                    ));
                }
                topics.insert(c.id, known);
            }
            Record::Message { header, data } => match topics.get(&header.channel_id) {
                Some(Some(ch)) => messages.push(RecordedMessage {
                    channel: *ch,
                    log_time_ns: header.log_time,
                    data: data.into_owned(),
                }),
                Some(None) => {}
                None => {
                    return Err(RecordingError::Corrupt(format!(
                        "message {} refers to unknown channel {}",
                        header.sequence, header.channel_id
                    )));
                }
            },
            Record::Metadata(m) => {
                metadata.insert(m.name, m.metadata);
            }
            Record::DataEnd(_) => {
                saw_end = true;
                break;
            }
            _ => {}
        }
    }
    if !saw_end && truncated.is_none() {
        truncated = Some("the file ends before its data-end record".to_string());
    }
    let desc_msg = messages
        .iter()
        .find(|m| m.channel == Channel::Description)
        .ok_or(RecordingError::NoDescription)?;
    let description =
        DescriptionMsg::decode(&desc_msg.data).map_err(|e| RecordingError::BadMessage {
            topic: Channel::Description.topic().to_string(),
            log_time_ns: desc_msg.log_time_ns,
            detail: e.to_string(),
        })?;
    if description.format != FORMAT_VERSION {
        return Err(RecordingError::Version {
            found: description.format,
        });
    }
    if let Some(detail) = &truncated {
        if !salvage {
            let ticks = messages
                .iter()
                .filter(|m| m.channel == Channel::DeviceInput)
                .count() as u64;
            return Err(RecordingError::Truncated {
                ticks,
                detail: detail.clone(),
            });
        }
    }
    Ok(Recording {
        description,
        messages,
        metadata,
        channels,
        unknown_topics,
        truncated,
        bytes: buf.len() as u64,
    })
}

/// Reads a recording file (see [`read_recording`]).
pub fn read_recording_file(path: &Path, salvage: bool) -> Result<Recording, RecordingError> {
    let buf = std::fs::read(path).map_err(|e| RecordingError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    read_recording(&buf, salvage)
}
