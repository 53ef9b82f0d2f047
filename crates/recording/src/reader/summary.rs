//! The summary section: its records from the data end to the footer, read by the bounded field
//! parser and kept with their offsets for [`super::check`]; then the footer's own fields (where
//! the summary and its offsets start, a CRC that was written — the MCAP reader compared it).

use super::framing::{Framer, Step, misplaced};
use super::{RecordingError, corrupt};
use crate::parse::{self, ChunkIndexRec, op, op_name};
use std::collections::BTreeMap;

/// What the summary section holds.
#[derive(Default)]
pub(super) struct Summary {
    pub schemas: BTreeMap<u16, parse::Schema>,
    pub channels: BTreeMap<u16, parse::ChannelRec>,
    pub chunk_indexes: Vec<(usize, ChunkIndexRec)>,
    pub metadata_indexes: Vec<(usize, (u64, u64, String))>,
    pub attachment_indexes: u64,
    pub stats: Option<(usize, parse::Stats)>,
    pub offsets: Vec<(usize, (u8, u64, u64))>,
    /// Runs of records of one opcode: `(opcode, start, length)`.
    pub groups: Vec<(u8, u64, u64)>,
}

/// The footer: its offset and fields.
pub(super) struct Footer {
    pub at: usize,
    pub summary_start: u64,
    pub summary_offset_start: u64,
    pub summary_crc: u32,
}

impl Summary {
    /// The summary section up to the footer and the end magic after it; `Err(why)` when the
    /// file ends before them.
    pub fn read(
        &mut self,
        records: &mut Framer<'_>,
    ) -> Result<Result<Footer, String>, RecordingError> {
        loop {
            let f = match records.next()? {
                Step::Record(f) => f,
                Step::Truncated(why) => return Ok(Err(why)),
                Step::End => return Ok(Err("the file ends before its footer".into())),
            };
            if let Some(e) = misplaced(false, f.at, f.opcode) {
                return Err(e);
            }
            let at = f.at;
            let name = op_name(f.opcode);
            let err = |d: String| corrupt(at, format!("{name} (summary)"), d);
            match f.opcode {
                op::SCHEMA => {
                    let x = parse::schema(f.body).map_err(err)?;
                    self.schemas.insert(x.id, x);
                }
                op::CHANNEL => {
                    let x = parse::channel(f.body).map_err(err)?;
                    self.channels.insert(x.id, x);
                }
                op::CHUNK_INDEX => self
                    .chunk_indexes
                    .push((at, parse::chunk_index(f.body).map_err(err)?)),
                op::METADATA_INDEX => self
                    .metadata_indexes
                    .push((at, parse::metadata_index(f.body).map_err(err)?)),
                op::ATTACHMENT_INDEX => self.attachment_indexes += 1,
                op::STATISTICS => {
                    if self.stats.is_some() {
                        return Err(err("a second statistics record".into()));
                    }
                    self.stats = Some((at, parse::statistics(f.body).map_err(err)?));
                }
                op::SUMMARY_OFFSET => self
                    .offsets
                    .push((at, parse::summary_offset(f.body).map_err(err)?)),
                op::FOOTER => {
                    let (summary_start, summary_offset_start, summary_crc) =
                        parse::footer(f.body).map_err(|d| corrupt(at, "footer", d))?;
                    // The end magic, and nothing after it.
                    return match records.next()? {
                        Step::Truncated(why) => Ok(Err(why)),
                        Step::Record(r) => Err(corrupt(
                            r.at,
                            op_name(r.opcode),
                            "follows the footer (the file must end with its magic bytes)",
                        )),
                        Step::End => Ok(Ok(Footer {
                            at,
                            summary_start,
                            summary_offset_start,
                            summary_crc,
                        })),
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
                match self.groups.last_mut() {
                    Some(g) if g.0 == f.opcode && g.1 + g.2 == at as u64 => g.2 += len,
                    _ => self.groups.push((f.opcode, at as u64, len)),
                }
            }
        }
    }
}

/// The footer's fields against the file: where the summary section and its first summary
/// offset record start, and a summary CRC that was written.
pub(super) fn check_footer(
    s: &Summary,
    footer: &Footer,
    summary_start: usize,
) -> Result<(), RecordingError> {
    let at = footer.at;
    if footer.summary_start != summary_start as u64 {
        return Err(corrupt(
            at,
            "footer",
            format!(
                "summary_start = {}, the summary section starts at byte {summary_start}",
                footer.summary_start
            ),
        ));
    }
    let first = s.offsets.first().map_or(0, |o| o.0 as u64);
    if footer.summary_offset_start != first {
        return Err(corrupt(
            at,
            "footer",
            format!(
                "summary_offset_start = {}, the first summary offset record is at byte {first}",
                footer.summary_offset_start
            ),
        ));
    }
    if footer.summary_crc == 0 {
        return Err(corrupt(
            at,
            "footer",
            "the summary CRC is 0 (not written; nanohaptics writes it in every recording)",
        ));
    }
    Ok(())
}
