//! Reading recordings: every record in file order through a bounded parser ([`super::parse`]),
//! with every integrity check a recording carries:
//!
//! - each chunk's CRC-32 (of its decompressed records), the data-section CRC and the
//!   summary-section CRC (a recording changed in any byte a CRC covers is refused);
//! - the summary against the records: statistics (message, channel, chunk and metadata counts,
//!   time range, messages per channel), chunk indexes (offset, length, times, sizes, message
//!   index offsets), the message indexes after each chunk, metadata indexes, summary offsets;
//! - the ticks: `/device/input` carries ticks 0, 1, 2, … in file order (no gap, no repeat),
//!   each tick ends with its `/loop/timing` message, and the count matches the `session`
//!   metadata record.
//!
//! Errors say what is wrong and where (not an MCAP file; the record and byte offset of a damaged
//! or inconsistent part; truncated after N complete ticks; a message that does not decode). A
//! damaged file is an error, never an abort or a panic: no size read from the file is allocated
//! before it is checked against the bytes that hold it.

use crate::channels::FORMAT_VERSION;
use crate::channels::messages::{Channel, DescriptionMsg, DeviceInputMsg};
use crate::parse::{self, ChunkIndexRec, FrameError, Framed, MessageRec, op, op_name};
use std::collections::BTreeMap;
use std::path::Path;

/// The 8 bytes an MCAP file starts and ends with.
const MAGIC: &[u8; 8] = b"\x89MCAP0\r\n";

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

/// Largest uncompressed chunk accepted, bytes (the writer makes 8 MiB chunks).
const MAX_CHUNK: u64 = 1 << 30;

fn corrupt(at: usize, record: impl Into<String>, detail: impl Into<String>) -> RecordingError {
    RecordingError::Corrupt {
        offset: at as u64,
        record: record.into(),
        detail: detail.into(),
    }
}

/// What the data section held about one chunk.
#[derive(Default)]
struct ChunkInfo {
    at: usize,
    length: u64,
    start_time: u64,
    end_time: u64,
    compression: String,
    compressed_size: u64,
    uncompressed_size: u64,
    /// `(log time, offset in the decompressed records)` of each message, by channel.
    entries: BTreeMap<u16, Vec<(u64, u64)>>,
    /// Offsets of the message index records that follow the chunk, by channel.
    index_offsets: BTreeMap<u16, u64>,
    index_len: u64,
}

#[derive(Default)]
struct Walk {
    schemas: BTreeMap<u16, parse::Schema>,
    channel_recs: BTreeMap<u16, parse::ChannelRec>,
    topics: BTreeMap<u16, Option<Channel>>,
    channels: Vec<(String, String, String)>,
    unknown_topics: Vec<String>,
    messages: Vec<RecordedMessage>,
    /// `messages.len()` after the last complete tick.
    complete: usize,
    inputs: u64,
    timings: u64,
    metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// `(offset, length, name)` of each metadata record.
    metadata_recs: Vec<(u64, u64, String)>,
    chunks: Vec<ChunkInfo>,
    attachments: u64,
    message_count: u64,
    per_channel: BTreeMap<u16, u64>,
    time_range: Option<(u64, u64)>,
    integrity: Integrity,
}

fn frame_detail(e: FrameError, at: usize, total: usize) -> String {
    match e {
        FrameError::ShortHeader { left } => format!(
            "the file ends at byte {total}, {left} bytes into the record header at byte {at}"
        ),
        FrameError::PastEnd { opcode, len, left } => format!(
            "the {} record at byte {at} announces {len} bytes, the file ends {left} bytes into it",
            op_name(opcode)
        ),
    }
}

fn span(a: u64, b: u64) -> String {
    if a == b {
        format!("tick {a} is missing")
    } else {
        format!("ticks {a}–{b} are missing")
    }
}

impl Walk {
    fn schema(&mut self, b: &[u8]) -> Result<(), String> {
        let s = parse::schema(b)?;
        if s.id == 0 {
            return Err("schema id 0 is reserved (no schema)".into());
        }
        match self.schemas.get(&s.id) {
            Some(prev) if *prev != s => Err(format!(
                "schema {} (`{}`) is defined again, differently",
                s.id, s.name
            )),
            Some(_) => Ok(()),
            None => {
                self.schemas.insert(s.id, s);
                Ok(())
            }
        }
    }

    fn channel(&mut self, b: &[u8]) -> Result<(), String> {
        let c = parse::channel(b)?;
        let schema = match c.schema_id {
            0 => String::new(),
            id => match self.schemas.get(&id) {
                Some(s) => s.name.clone(),
                None => {
                    return Err(format!(
                        "channel {} (`{}`) refers to schema {id}, which is not defined before it",
                        c.id, c.topic
                    ));
                }
            },
        };
        match self.channel_recs.get(&c.id) {
            Some(prev) if *prev != c => Err(format!(
                "channel {} (`{}`) is defined again, differently",
                c.id, c.topic
            )),
            Some(_) => Ok(()),
            None => {
                let known = Channel::from_topic(&c.topic);
                if known.is_none() {
                    self.unknown_topics.push(c.topic.clone());
                }
                self.channels
                    .push((c.topic.clone(), schema, c.message_encoding.clone()));
                self.topics.insert(c.id, known);
                self.channel_recs.insert(c.id, c);
                Ok(())
            }
        }
    }

    /// One message; `at` and `record` place errors.
    fn message(
        &mut self,
        m: MessageRec<'_>,
        at: usize,
        record: &dyn Fn() -> String,
    ) -> Result<(), RecordingError> {
        let Some(known) = self.topics.get(&m.channel_id).copied() else {
            return Err(corrupt(
                at,
                record(),
                format!(
                    "message {} refers to channel {}, which is not defined before it",
                    m.sequence, m.channel_id
                ),
            ));
        };
        self.message_count += 1;
        *self.per_channel.entry(m.channel_id).or_default() += 1;
        self.time_range = Some(match self.time_range {
            None => (m.log_time, m.log_time),
            Some((a, b)) => (a.min(m.log_time), b.max(m.log_time)),
        });
        let Some(ch) = known else {
            return Ok(());
        };
        match ch {
            Channel::DeviceInput => {
                let d = DeviceInputMsg::decode(m.data).map_err(|e| RecordingError::BadMessage {
                    topic: ch.topic().to_string(),
                    log_time_ns: m.log_time,
                    detail: e.to_string(),
                })?;
                let want = self.inputs;
                if d.tick != want {
                    let detail = match (want, d.tick) {
                        (0, t) => format!(
                            "the first /device/input is tick {t}, not tick 0 ({})",
                            span(0, t - 1)
                        ),
                        (w, t) if t > w => format!(
                            "/device/input tick {t} follows tick {}: {}",
                            w - 1,
                            span(w, t - 1)
                        ),
                        (w, t) => format!(
                            "/device/input tick {t} follows tick {}: tick {t} repeats",
                            w - 1
                        ),
                    };
                    return Err(corrupt(at, record(), detail));
                }
                if self.timings != self.inputs {
                    return Err(corrupt(
                        at,
                        record(),
                        format!(
                            "tick {} has no /loop/timing message (each tick ends with one)",
                            want.saturating_sub(1)
                        ),
                    ));
                }
                self.inputs += 1;
            }
            Channel::Timing => {
                if self.timings + 1 != self.inputs {
                    return Err(corrupt(
                        at,
                        record(),
                        format!(
                            "a /loop/timing message at log time {} ns is not the end of a tick \
                             ({} /device/input and {} /loop/timing messages before it)",
                            m.log_time, self.inputs, self.timings
                        ),
                    ));
                }
                self.timings += 1;
            }
            _ => {}
        }
        self.messages.push(RecordedMessage {
            channel: ch,
            log_time_ns: m.log_time,
            data: m.data.to_vec(),
        });
        if ch == Channel::Timing {
            self.complete = self.messages.len();
        }
        Ok(())
    }

    fn chunk(&mut self, f: &Framed<'_>) -> Result<(), RecordingError> {
        let c = parse::chunk(f.body).map_err(|d| corrupt(f.at, "chunk", d))?;
        let bound = MAX_CHUNK.min(
            (c.records.len() as u64)
                .saturating_mul(1000)
                .saturating_add(1 << 20),
        );
        if c.uncompressed_size > bound {
            return Err(corrupt(
                f.at,
                "chunk",
                format!(
                    "uncompressed size {} bytes is over the bound of {bound} bytes for a \
                     {}-byte chunk (a damaged size field)",
                    c.uncompressed_size,
                    f.body.len()
                ),
            ));
        }
        let recs = parse::decompress(&c.compression, c.records, c.uncompressed_size)
            .map_err(|d| corrupt(f.at, "chunk", d))?;
        let crc = crc32fast::hash(&recs);
        if c.uncompressed_crc == 0 {
            return Err(corrupt(
                f.at,
                "chunk",
                "its CRC is 0 (not written; nanohaptics writes one for every chunk)",
            ));
        }
        if crc != c.uncompressed_crc {
            return Err(corrupt(
                f.at,
                "chunk",
                format!(
                    "the CRC-32 of its {} decompressed bytes is 0x{crc:08x}, the chunk says \
                     0x{:08x} (the chunk was changed or damaged)",
                    recs.len(),
                    c.uncompressed_crc
                ),
            ));
        }
        self.integrity.chunk_crcs += 1;
        let mut info = ChunkInfo {
            at: f.at,
            length: (f.end() - f.at) as u64,
            start_time: c.start_time,
            end_time: c.end_time,
            compression: c.compression.clone(),
            compressed_size: c.records.len() as u64,
            uncompressed_size: c.uncompressed_size,
            ..ChunkInfo::default()
        };
        let mut times: Option<(u64, u64)> = None;
        let mut p = 0usize;
        while let Some(r) = parse::frame(&recs, p) {
            let inner = r.map_err(|e| {
                corrupt(
                    f.at,
                    "chunk",
                    format!(
                        "its decompressed records end inside the record at byte {p} of them ({})",
                        match e {
                            FrameError::ShortHeader { left } =>
                                format!("{left} bytes of a 9-byte record header"),
                            FrameError::PastEnd { opcode, len, left } => format!(
                                "a {} record announcing {len} bytes, {left} are left",
                                op_name(opcode)
                            ),
                        }
                    ),
                )
            })?;
            let here = || {
                format!(
                    "{} record at byte {p} of the decompressed records of the chunk",
                    op_name(inner.opcode)
                )
            };
            match inner.opcode {
                op::SCHEMA => self
                    .schema(inner.body)
                    .map_err(|d| corrupt(f.at, here(), d))?,
                op::CHANNEL => self
                    .channel(inner.body)
                    .map_err(|d| corrupt(f.at, here(), d))?,
                op::MESSAGE => {
                    let m = parse::message(inner.body).map_err(|d| corrupt(f.at, here(), d))?;
                    self.message(m, f.at, &here)?;
                    info.entries
                        .entry(m.channel_id)
                        .or_default()
                        .push((m.log_time, p as u64));
                    times = Some(match times {
                        None => (m.log_time, m.log_time),
                        Some((a, b)) => (a.min(m.log_time), b.max(m.log_time)),
                    });
                }
                _ => {
                    return Err(corrupt(f.at, here(), "does not belong inside a chunk"));
                }
            }
            p = inner.end();
        }
        if let Some((a, b)) = times {
            if (a, b) != (c.start_time, c.end_time) {
                return Err(corrupt(
                    f.at,
                    "chunk",
                    format!(
                        "its header gives message times {}–{} ns, its messages span {a}–{b} ns",
                        c.start_time, c.end_time
                    ),
                ));
            }
        }
        self.chunks.push(info);
        Ok(())
    }

    fn message_index(&mut self, f: &Framed<'_>) -> Result<(), RecordingError> {
        let (id, entries) =
            parse::message_index(f.body).map_err(|d| corrupt(f.at, "message index", d))?;
        let Some(c) = self.chunks.last_mut() else {
            return Err(corrupt(f.at, "message index", "no chunk before it"));
        };
        let want = c.entries.get(&id).map(Vec::as_slice).unwrap_or(&[]);
        if entries != want {
            let i = entries
                .iter()
                .zip(want)
                .position(|(a, b)| a != b)
                .unwrap_or(entries.len().min(want.len()));
            return Err(corrupt(
                f.at,
                "message index",
                format!(
                    "channel {id}: {} entries for the {} messages of the channel in the chunk at \
                     byte {}; entry {i} differs",
                    entries.len(),
                    want.len(),
                    c.at
                ),
            ));
        }
        if c.index_offsets.insert(id, f.at as u64).is_some() {
            return Err(corrupt(
                f.at,
                "message index",
                format!(
                    "a second message index for channel {id} after the chunk at byte {}",
                    c.at
                ),
            ));
        }
        c.index_len += (f.end() - f.at) as u64;
        Ok(())
    }

    fn metadata_rec(&mut self, f: &Framed<'_>) -> Result<(), RecordingError> {
        let (name, m) = parse::metadata(f.body).map_err(|d| corrupt(f.at, "metadata", d))?;
        if self.metadata.contains_key(&name) {
            return Err(corrupt(
                f.at,
                format!("metadata `{name}`"),
                "a second metadata record of this name",
            ));
        }
        self.metadata_recs
            .push((f.at as u64, (f.end() - f.at) as u64, name.clone()));
        self.metadata.insert(name, m);
        Ok(())
    }
}

/// The data section: records from the header to the data end. Returns the data end's offset,
/// CRC and end, or why the file ends before it.
fn walk_data(
    buf: &[u8],
    w: &mut Walk,
) -> Result<Result<(usize, u32, usize), String>, RecordingError> {
    let mut at = MAGIC.len();
    let mut index_run = false;
    loop {
        let f = match parse::frame(buf, at) {
            None => {
                return Ok(Err(format!(
                    "the file ends at byte {at}, before its data-end record"
                )));
            }
            Some(Err(e)) => return Ok(Err(frame_detail(e, at, buf.len()))),
            Some(Ok(f)) => f,
        };
        if at == MAGIC.len() && f.opcode != op::HEADER {
            return Err(corrupt(
                at,
                op_name(f.opcode),
                "the first record of an MCAP file must be its header",
            ));
        }
        let continues_run = f.opcode == op::MESSAGE_INDEX && index_run;
        match f.opcode {
            op::HEADER if at == MAGIC.len() => {
                let mut c = parse::Cur::new(f.body);
                c.string("profile")
                    .and_then(|_| c.string("library"))
                    .map_err(|d| corrupt(at, "header", d))?;
            }
            op::SCHEMA => w.schema(f.body).map_err(|d| corrupt(at, "schema", d))?,
            op::CHANNEL => w.channel(f.body).map_err(|d| corrupt(at, "channel", d))?,
            op::MESSAGE => {
                let m = parse::message(f.body).map_err(|d| corrupt(at, "message", d))?;
                w.message(m, at, &|| "message".to_string())?;
            }
            op::CHUNK => w.chunk(&f)?,
            op::MESSAGE_INDEX if index_run => w.message_index(&f)?,
            op::METADATA => w.metadata_rec(&f)?,
            op::ATTACHMENT => w.attachments += 1,
            op::DATA_END => {
                let crc = parse::Cur::new(f.body)
                    .u32("data_section_crc")
                    .map_err(|d| corrupt(at, "data end", d))?;
                return Ok(Ok((at, crc, f.end())));
            }
            other => {
                return Err(corrupt(
                    at,
                    op_name(other),
                    "does not belong in the data section of a recording",
                ));
            }
        }
        index_run = f.opcode == op::CHUNK || continues_run;
        at = f.end();
    }
}

/// What the summary section holds.
#[derive(Default)]
struct Summary {
    schemas: BTreeMap<u16, parse::Schema>,
    channels: BTreeMap<u16, parse::ChannelRec>,
    chunk_indexes: Vec<(usize, ChunkIndexRec)>,
    metadata_indexes: Vec<(usize, (u64, u64, String))>,
    attachment_indexes: u64,
    stats: Option<(usize, parse::Stats)>,
    offsets: Vec<(usize, (u8, u64, u64))>,
    /// Runs of records of one opcode: `(opcode, start, length)`.
    groups: Vec<(u8, u64, u64)>,
}

/// The summary section from `start` to the footer. Returns the footer's offset and fields, or
/// why the file ends before them.
#[allow(clippy::type_complexity)]
fn walk_summary(
    buf: &[u8],
    start: usize,
    s: &mut Summary,
) -> Result<Result<(usize, (u64, u64, u32)), String>, RecordingError> {
    let mut at = start;
    loop {
        let f = match parse::frame(buf, at) {
            None => {
                return Ok(Err(format!(
                    "the file ends at byte {at}, in its summary section (the data section is \
                     complete; the footer is missing)"
                )));
            }
            Some(Err(e)) => return Ok(Err(frame_detail(e, at, buf.len()))),
            Some(Ok(f)) => f,
        };
        let name = op_name(f.opcode);
        let err = |d: String| corrupt(at, format!("{name} (summary)"), d);
        match f.opcode {
            op::SCHEMA => {
                let x = parse::schema(f.body).map_err(err)?;
                s.schemas.insert(x.id, x);
            }
            op::CHANNEL => {
                let x = parse::channel(f.body).map_err(err)?;
                s.channels.insert(x.id, x);
            }
            op::CHUNK_INDEX => s
                .chunk_indexes
                .push((at, parse::chunk_index(f.body).map_err(err)?)),
            op::METADATA_INDEX => s
                .metadata_indexes
                .push((at, parse::metadata_index(f.body).map_err(err)?)),
            op::ATTACHMENT_INDEX => s.attachment_indexes += 1,
            op::STATISTICS => {
                if s.stats.is_some() {
                    return Err(err("a second statistics record".into()));
                }
                s.stats = Some((at, parse::statistics(f.body).map_err(err)?));
            }
            op::SUMMARY_OFFSET => s
                .offsets
                .push((at, parse::summary_offset(f.body).map_err(err)?)),
            op::FOOTER => {
                let ft = parse::footer(f.body).map_err(|d| corrupt(at, "footer", d))?;
                let end = f.end();
                return match buf.get(end..end + MAGIC.len()) {
                    None => Ok(Err(format!(
                        "the file ends at byte {}, inside its end magic after the footer",
                        buf.len()
                    ))),
                    Some(m) if m != MAGIC => Err(corrupt(
                        end,
                        "end magic",
                        "the file does not end with the MCAP magic bytes",
                    )),
                    Some(_) if buf.len() > end + MAGIC.len() => Err(corrupt(
                        end + MAGIC.len(),
                        "the end of the file",
                        format!(
                            "{} bytes follow the end magic",
                            buf.len() - end - MAGIC.len()
                        ),
                    )),
                    Some(_) => Ok(Ok((at, ft))),
                };
            }
            other => {
                return Err(corrupt(
                    at,
                    op_name(other),
                    "does not belong in the summary section",
                ));
            }
        }
        if f.opcode != op::SUMMARY_OFFSET {
            let len = (f.end() - at) as u64;
            match s.groups.last_mut() {
                Some(g) if g.0 == f.opcode && g.1 + g.2 == at as u64 => g.2 += len,
                _ => s.groups.push((f.opcode, at as u64, len)),
            }
        }
        at = f.end();
    }
}

fn mismatch<T: std::fmt::Display + PartialEq>(
    at: usize,
    record: &str,
    field: &str,
    summary: T,
    actual: T,
    what: &str,
) -> Result<(), RecordingError> {
    if summary == actual {
        Ok(())
    } else {
        Err(corrupt(
            at,
            record,
            format!("{field} = {summary}, {what} {actual}"),
        ))
    }
}

fn map_text(m: &BTreeMap<u16, u64>) -> String {
    let parts: Vec<String> = m.iter().map(|(k, v)| format!("{k}: {v}")).collect();
    format!("{{{}}}", parts.join(", "))
}

/// The summary against the records of the data section.
fn check_summary(w: &Walk, s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    let Some((sat, st)) = &s.stats else {
        return Err(corrupt(
            footer_at,
            "footer",
            "the summary has no statistics record",
        ));
    };
    let (sat, rec) = (*sat, "statistics");
    let held = "the data section holds";
    mismatch(
        sat,
        rec,
        "message_count",
        st.message_count,
        w.message_count,
        held,
    )?;
    mismatch(
        sat,
        rec,
        "schema_count",
        st.schema_count as usize,
        w.schemas.len(),
        held,
    )?;
    mismatch(
        sat,
        rec,
        "channel_count",
        st.channel_count as usize,
        w.channel_recs.len(),
        held,
    )?;
    mismatch(
        sat,
        rec,
        "attachment_count",
        u64::from(st.attachment_count),
        w.attachments,
        held,
    )?;
    mismatch(
        sat,
        rec,
        "metadata_count",
        st.metadata_count as usize,
        w.metadata_recs.len(),
        held,
    )?;
    mismatch(
        sat,
        rec,
        "chunk_count",
        st.chunk_count as usize,
        w.chunks.len(),
        held,
    )?;
    let (a, b) = w.time_range.unwrap_or((0, 0));
    mismatch(
        sat,
        rec,
        "message_start_time",
        st.start_time,
        a,
        "the earliest message is at",
    )?;
    mismatch(
        sat,
        rec,
        "message_end_time",
        st.end_time,
        b,
        "the latest message is at",
    )?;
    let counts: BTreeMap<u16, u64> = st
        .channel_message_counts
        .iter()
        .filter(|(_, n)| **n > 0)
        .map(|(k, v)| (*k, *v))
        .collect();
    mismatch(
        sat,
        rec,
        "channel_message_counts",
        map_text(&counts),
        map_text(&w.per_channel),
        held,
    )?;
    for (id, x) in &w.schemas {
        if s.schemas.get(id) != Some(x) {
            return Err(corrupt(
                footer_at,
                "summary",
                format!(
                    "schema {id} (`{}`) is missing from the summary or differs",
                    x.name
                ),
            ));
        }
    }
    for (id, x) in &w.channel_recs {
        if s.channels.get(id) != Some(x) {
            return Err(corrupt(
                footer_at,
                "summary",
                format!(
                    "channel {id} (`{}`) is missing from the summary or differs",
                    x.topic
                ),
            ));
        }
    }
    if s.schemas.len() != w.schemas.len() || s.channels.len() != w.channel_recs.len() {
        return Err(corrupt(
            footer_at,
            "summary",
            format!(
                "{} schemas and {} channels, the data section defines {} and {}",
                s.schemas.len(),
                s.channels.len(),
                w.schemas.len(),
                w.channel_recs.len()
            ),
        ));
    }
    if s.chunk_indexes.len() != w.chunks.len() {
        let at = s.chunk_indexes.first().map_or(footer_at, |c| c.0);
        return Err(corrupt(
            at,
            "chunk indexes",
            format!(
                "the summary indexes {} chunks, the data section holds {}",
                s.chunk_indexes.len(),
                w.chunks.len()
            ),
        ));
    }
    for (i, ((at, ci), c)) in s.chunk_indexes.iter().zip(&w.chunks).enumerate() {
        let rec = format!("chunk index {i}");
        let what = format!("the chunk at byte {} has", c.at);
        let what = what.as_str();
        let starts = format!("chunk {i} starts at byte");
        mismatch(
            *at,
            &rec,
            "chunk_start_offset",
            ci.chunk_start_offset,
            c.at as u64,
            &starts,
        )?;
        mismatch(*at, &rec, "chunk_length", ci.chunk_length, c.length, what)?;
        mismatch(
            *at,
            &rec,
            "message_start_time",
            ci.start_time,
            c.start_time,
            what,
        )?;
        mismatch(*at, &rec, "message_end_time", ci.end_time, c.end_time, what)?;
        mismatch(
            *at,
            &rec,
            "compression",
            ci.compression.as_str(),
            c.compression.as_str(),
            what,
        )?;
        mismatch(
            *at,
            &rec,
            "compressed_size",
            ci.compressed_size,
            c.compressed_size,
            what,
        )?;
        mismatch(
            *at,
            &rec,
            "uncompressed_size",
            ci.uncompressed_size,
            c.uncompressed_size,
            what,
        )?;
        mismatch(
            *at,
            &rec,
            "message_index_offsets",
            map_text(&ci.message_index_offsets),
            map_text(&c.index_offsets),
            what,
        )?;
        mismatch(
            *at,
            &rec,
            "message_index_length",
            ci.message_index_length,
            c.index_len,
            what,
        )?;
        if c.index_offsets.len() != c.entries.len() {
            return Err(corrupt(
                c.at,
                "chunk",
                format!(
                    "messages of {} channels, message indexes for {} after it",
                    c.entries.len(),
                    c.index_offsets.len()
                ),
            ));
        }
    }
    if s.metadata_indexes.len() != w.metadata_recs.len() {
        let at = s.metadata_indexes.first().map_or(footer_at, |c| c.0);
        return Err(corrupt(
            at,
            "metadata indexes",
            format!(
                "the summary indexes {} metadata records, the data section holds {}",
                s.metadata_indexes.len(),
                w.metadata_recs.len()
            ),
        ));
    }
    for ((at, (off, len, name)), (a_off, a_len, a_name)) in
        s.metadata_indexes.iter().zip(&w.metadata_recs)
    {
        if (off, len, name) != (a_off, a_len, a_name) {
            return Err(corrupt(
                *at,
                "metadata index",
                format!(
                    "`{name}` at byte {off}, {len} bytes; the data section has `{a_name}` at \
                     byte {a_off}, {a_len} bytes"
                ),
            ));
        }
    }
    mismatch(
        footer_at,
        "summary",
        "attachment indexes",
        s.attachment_indexes,
        w.attachments,
        "attachments in the data section:",
    )?;
    let mut offsets: Vec<(u8, u64, u64)> = s.offsets.iter().map(|o| o.1).collect();
    offsets.sort_unstable();
    let mut groups = s.groups.clone();
    groups.sort_unstable();
    if offsets != groups {
        let at = s.offsets.first().map_or(footer_at, |o| o.0);
        let text = |v: &[(u8, u64, u64)]| {
            let p: Vec<String> = v
                .iter()
                .map(|(o, a, l)| format!("{} at byte {a}, {l} bytes", op_name(*o)))
                .collect();
            p.join("; ")
        };
        return Err(corrupt(
            at,
            "summary offsets",
            format!(
                "they list [{}], the summary holds [{}]",
                text(&offsets),
                text(&groups)
            ),
        ));
    }
    Ok(())
}

/// Reads a recording from bytes, with every check of the module documentation. With `salvage`,
/// a truncated file gives its complete ticks (and `truncated` says why it ends); without, it is
/// an error, and so is a salvage that finds no complete tick. A damaged or inconsistent file is
/// an error either way.
pub fn read_recording(buf: &[u8], salvage: bool) -> Result<Recording, RecordingError> {
    if buf.len() < MAGIC.len() || buf[..MAGIC.len()] != MAGIC[..] {
        return Err(RecordingError::NotMcap);
    }
    let mut w = Walk::default();
    let mut truncated = None;
    match walk_data(buf, &mut w)? {
        Err(why) => truncated = Some(why),
        Ok((de_at, saved, de_end)) => {
            let calc = crc32fast::hash(&buf[..de_at]);
            if saved == 0 {
                return Err(corrupt(
                    de_at,
                    "data end",
                    "the data-section CRC is 0 (not written; nanohaptics writes it in every \
                     recording)",
                ));
            }
            if saved != calc {
                return Err(corrupt(
                    de_at,
                    "data end",
                    format!(
                        "the CRC-32 of bytes 0–{} is 0x{calc:08x}, the data-end record says \
                         0x{saved:08x} (the data section was changed)",
                        de_at - 1
                    ),
                ));
            }
            w.integrity.data_crc = true;
            if w.inputs != w.timings {
                return Err(corrupt(
                    de_at,
                    "data end",
                    format!(
                        "the last tick ({}) has no /loop/timing message",
                        w.inputs.saturating_sub(1)
                    ),
                ));
            }
            match w.metadata.get("session").map(|m| m.get("ticks")) {
                None => {
                    return Err(corrupt(
                        de_at,
                        "data end",
                        "the data section has no `session` metadata record (its tick count)",
                    ));
                }
                Some(n) => {
                    let at = w
                        .metadata_recs
                        .iter()
                        .find(|r| r.2 == "session")
                        .map_or(de_at, |r| r.0 as usize);
                    let n = n.map(String::as_str).unwrap_or("(missing)");
                    if n.parse::<u64>().ok() != Some(w.inputs) {
                        return Err(corrupt(
                            at,
                            "metadata `session`",
                            format!("ticks = {n}, the data section holds {} ticks", w.inputs),
                        ));
                    }
                    w.integrity.ticks_match_metadata = true;
                }
            }
            let mut s = Summary::default();
            match walk_summary(buf, de_end, &mut s)? {
                Err(why) => truncated = Some(why),
                Ok((footer_at, (summary_start, offsets_start, crc))) => {
                    mismatch(
                        footer_at,
                        "footer",
                        "summary_start",
                        summary_start,
                        de_end as u64,
                        "the summary section starts at byte",
                    )?;
                    let first = s.offsets.first().map_or(0, |o| o.0 as u64);
                    mismatch(
                        footer_at,
                        "footer",
                        "summary_offset_start",
                        offsets_start,
                        first,
                        "the first summary offset record is at byte",
                    )?;
                    let calc = crc32fast::hash(&buf[de_end..footer_at + 1 + 8 + 16]);
                    if crc == 0 {
                        return Err(corrupt(
                            footer_at,
                            "footer",
                            "the summary CRC is 0 (not written; nanohaptics writes it in every \
                             recording)",
                        ));
                    }
                    if crc != calc {
                        return Err(corrupt(
                            footer_at,
                            "footer",
                            format!(
                                "the CRC-32 of the summary section (bytes {de_end}–{}) is \
                                 0x{calc:08x}, the footer says 0x{crc:08x} (the summary was \
                                 changed)",
                                footer_at + 24
                            ),
                        ));
                    }
                    w.integrity.summary_crc = true;
                    check_summary(&w, &s, footer_at)?;
                    w.integrity.summary = true;
                }
            }
        }
    }
    if let Some(detail) = &truncated {
        // Keep whole ticks only (a tick ends with its /loop/timing message), and the
        // description.
        let tail = w.messages.split_off(w.complete);
        w.messages.extend(
            tail.into_iter()
                .filter(|m| m.channel == Channel::Description),
        );
        if !salvage {
            return Err(RecordingError::Truncated {
                ticks: w.timings,
                detail: detail.clone(),
            });
        }
        if w.timings == 0 {
            return Err(RecordingError::NothingToSalvage {
                detail: detail.clone(),
            });
        }
    }
    w.integrity.ticks = w.timings;
    let desc_msg = w
        .messages
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
    Ok(Recording {
        description,
        messages: w.messages,
        metadata: w.metadata,
        channels: w.channels,
        unknown_topics: w.unknown_topics,
        truncated,
        bytes: buf.len() as u64,
        integrity: w.integrity,
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
