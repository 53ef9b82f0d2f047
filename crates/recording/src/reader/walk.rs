//! The data section: its records from the header to the data end, each through the bounded
//! field parser, with the definitions (a schema or channel defined again must be the same), the
//! message indexes after each chunk and the metadata records kept for the summary check.

use super::framing::{Framer, Rec, Step, misplaced};
use super::ticks::Ticks;
use super::{Integrity, RecordedMessage, RecordingError, corrupt};
use crate::channels::messages::Channel;
use crate::parse::{self, MessageRec, op, op_name};
use std::collections::BTreeMap;

/// What the data section held about one chunk.
#[derive(Default)]
pub(super) struct ChunkInfo {
    pub at: usize,
    pub length: u64,
    pub start_time: u64,
    pub end_time: u64,
    pub compression: String,
    pub compressed_size: u64,
    pub uncompressed_size: u64,
    /// `(log time, offset in the decompressed records)` of each message, by channel.
    pub entries: BTreeMap<u16, Vec<(u64, u64)>>,
    /// Offsets of the message index records that follow the chunk, by channel.
    pub index_offsets: BTreeMap<u16, u64>,
    pub index_len: u64,
}

/// Everything read from the data section.
#[derive(Default)]
pub(super) struct Walk {
    pub schemas: BTreeMap<u16, parse::Schema>,
    pub channel_recs: BTreeMap<u16, parse::ChannelRec>,
    topics: BTreeMap<u16, Option<Channel>>,
    pub channels: Vec<(String, String, String)>,
    pub unknown_topics: Vec<String>,
    pub ticks: Ticks,
    pub metadata: BTreeMap<String, BTreeMap<String, String>>,
    /// `(offset, length, name)` of each metadata record.
    pub metadata_recs: Vec<(u64, u64, String)>,
    pub chunks: Vec<ChunkInfo>,
    pub attachments: u64,
    pub message_count: u64,
    pub per_channel: BTreeMap<u16, u64>,
    pub time_range: Option<(u64, u64)>,
    pub integrity: Integrity,
    /// The MCAP reader of the chunks and its record length limit, bytes ([`super::chunk`]).
    pub chunk_reader: Option<(usize, mcap::sans_io::LinearReader)>,
}

/// The data-end record: its offset, the data-section CRC it holds, and its end.
pub(super) struct DataEnd {
    pub at: usize,
    pub crc: u32,
    pub end: usize,
}

impl Walk {
    /// The data section, up to and including its data end; `Err(why)` when the file ends
    /// before it.
    pub fn data_section(
        &mut self,
        records: &mut Framer<'_>,
    ) -> Result<Result<DataEnd, String>, RecordingError> {
        let mut index_run = false;
        loop {
            let f = match records.next()? {
                Step::Record(f) => f,
                Step::Truncated(why) => return Ok(Err(why)),
                Step::End => {
                    return Ok(Err("the file ends before its data-end record".into()));
                }
            };
            if let Some(e) = misplaced(true, f.at, f.opcode) {
                return Err(e);
            }
            let at = f.at;
            match f.opcode {
                op::HEADER => {
                    let mut c = parse::Cur::new(f.body);
                    c.string("profile")
                        .and_then(|_| c.string("library"))
                        .map_err(|d| corrupt(at, "header", d))?;
                }
                op::SCHEMA => self.schema(f.body).map_err(|d| corrupt(at, "schema", d))?,
                op::CHANNEL => self
                    .channel(f.body)
                    .map_err(|d| corrupt(at, "channel", d))?,
                op::MESSAGE => {
                    let m = parse::message(f.body).map_err(|d| corrupt(at, "message", d))?;
                    self.message(m, at, &|| "message".to_string())?;
                }
                op::CHUNK => self.chunk(&f)?,
                op::MESSAGE_INDEX if index_run => self.message_index(&f)?,
                op::METADATA => self.metadata_rec(&f)?,
                op::ATTACHMENT => self.attachments += 1,
                op::DATA_END => {
                    let crc = parse::Cur::new(f.body)
                        .u32("data_section_crc")
                        .map_err(|d| corrupt(at, "data end", d))?;
                    return Ok(Ok(DataEnd {
                        at,
                        crc,
                        end: f.end(),
                    }));
                }
                other => {
                    return Err(corrupt(
                        at,
                        op_name(other),
                        "does not belong in the data section of a recording",
                    ));
                }
            }
            index_run = f.opcode == op::CHUNK || (f.opcode == op::MESSAGE_INDEX && index_run);
        }
    }

    /// The checks at the data end: its CRC was written (the MCAP reader compared it), the last
    /// tick is complete, and the tick count is the `session` metadata record's.
    pub fn data_end(&mut self, d: &DataEnd) -> Result<(), RecordingError> {
        if d.crc == 0 {
            return Err(corrupt(
                d.at,
                "data end",
                "the data-section CRC is 0 (not written; nanohaptics writes it in every \
                 recording)",
            ));
        }
        self.integrity.data_crc = true;
        self.ticks
            .last_is_complete()
            .map_err(|e| corrupt(d.at, "data end", e))?;
        let Some(session) = self.metadata.get("session") else {
            return Err(corrupt(
                d.at,
                "data end",
                "the data section has no `session` metadata record (its tick count)",
            ));
        };
        let at = self
            .metadata_recs
            .iter()
            .find(|r| r.2 == "session")
            .map_or(d.at, |r| r.0 as usize);
        self.ticks
            .match_metadata(session.get("ticks").map(String::as_str))
            .map_err(|e| corrupt(at, "metadata `session`", e))?;
        self.integrity.ticks_match_metadata = true;
        Ok(())
    }

    /// A schema record (in the data section or a chunk).
    pub fn schema(&mut self, b: &[u8]) -> Result<(), String> {
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

    /// A channel record (in the data section or a chunk).
    pub fn channel(&mut self, b: &[u8]) -> Result<(), String> {
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

    /// One message (in the data section or a chunk); `at` and `record` place errors.
    pub fn message(
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
        self.ticks
            .message(ch, m.log_time, m.data)
            .map_err(|e| e.place(at, record))?;
        self.ticks.messages.push(RecordedMessage {
            channel: ch,
            log_time_ns: m.log_time,
            data: m.data.to_vec(),
        });
        if ch == Channel::Timing {
            self.ticks.complete = self.ticks.messages.len();
        }
        Ok(())
    }

    /// A message index record, after a chunk: it must list that chunk's messages of its
    /// channel, in order.
    fn message_index(&mut self, f: &Rec<'_>) -> Result<(), RecordingError> {
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

    /// A metadata record (one per name).
    fn metadata_rec(&mut self, f: &Rec<'_>) -> Result<(), RecordingError> {
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
