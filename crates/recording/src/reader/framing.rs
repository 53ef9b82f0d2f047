//! The file's top-level records, framed by the `mcap` crate's sans-io
//! [`LinearReader`]: it checks the magic bytes at both ends, frames each record (refusing a
//! length longer than the file), checks the data-section CRC at the data-end record and the
//! summary-section CRC at the footer, and refuses bytes after the end magic. Chunks come out
//! whole ([`super::chunk`] opens them).
//!
//! The reader reports no offsets, so it is fed exactly the bytes it asks for: after each record
//! it holds nothing unread, and the record ends at the count of bytes fed. Its errors become
//! ours here, placed at the record being read (a record cut by the end of the file is a
//! truncation, not a corruption).

use super::{RecordingError, corrupt};
use crate::parse::{self, op, op_name};
use mcap::McapError;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// Bytes of a record's opcode and length.
pub(super) const HEAD: usize = 1 + 8;

/// One record of the file.
#[derive(Clone, Copy)]
pub(super) struct Rec<'a> {
    /// Opcode.
    pub opcode: u8,
    /// Offset of the opcode byte in the file.
    pub at: usize,
    /// The body (after the opcode and length).
    pub body: &'a [u8],
}

impl Rec<'_> {
    /// Offset just past the record.
    pub fn end(&self) -> usize {
        self.at + HEAD + self.body.len()
    }
}

/// What reading on gives.
pub(super) enum Step<'a> {
    /// The next record.
    Record(Rec<'a>),
    /// The end magic after the footer, and nothing after it.
    End,
    /// The file ends early: where and how.
    Truncated(String),
}

/// The top-level records of a file, in order.
pub(super) struct Framer<'a> {
    buf: &'a [u8],
    reader: LinearReader,
    /// Bytes given to the reader.
    fed: usize,
    /// Offset of the record being read (just past the last one returned).
    next: usize,
    /// Offset just past the data-end record, once read.
    summary_start: Option<usize>,
    /// Offset just past the footer, once read.
    footer_end: Option<usize>,
}

impl<'a> Framer<'a> {
    /// The records of `buf` (which starts with the MCAP magic).
    pub fn new(buf: &'a [u8]) -> Self {
        let options = LinearReaderOptions::default()
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(buf.len());
        Framer {
            buf,
            reader: LinearReader::new_with_options(options),
            fed: 0,
            next: mcap::MAGIC.len(),
            summary_start: None,
            footer_end: None,
        }
    }

    /// The next record, the clean end of the file, or why it ends early.
    pub fn next(&mut self) -> Result<Step<'a>, RecordingError> {
        loop {
            let event = match self.reader.next_event() {
                None => return Ok(Step::End),
                Some(Err(e)) => return self.failure(&e),
                Some(Ok(event)) => event,
            };
            match event {
                LinearReadEvent::ReadRequest(n) => {
                    let n = n.min(self.buf.len() - self.fed);
                    if n > 0 {
                        self.reader
                            .insert(n)
                            .copy_from_slice(&self.buf[self.fed..self.fed + n]);
                    }
                    self.reader.notify_read(n);
                    self.fed += n;
                }
                LinearReadEvent::Record { opcode, data } => {
                    let len = data.len();
                    let at = self.next;
                    if at + HEAD + len != self.fed {
                        return Err(corrupt(
                            at,
                            op_name(opcode),
                            format!(
                                "the MCAP reader framed {len} bytes ending at byte {}, not at \
                                 byte {at} + 9 + {len}",
                                self.fed
                            ),
                        ));
                    }
                    self.next = self.fed;
                    match opcode {
                        op::DATA_END => self.summary_start = Some(self.fed),
                        op::FOOTER => self.footer_end = Some(self.fed),
                        _ => {}
                    }
                    let buf: &'a [u8] = self.buf;
                    return Ok(Step::Record(Rec {
                        opcode,
                        at,
                        body: &buf[at + HEAD..self.fed],
                    }));
                }
            }
        }
    }

    /// The MCAP reader's error at the record at `self.next`, as ours.
    fn failure(&self, e: &McapError) -> Result<Step<'a>, RecordingError> {
        let at = self.next;
        let opcode = self.buf.get(at).copied().unwrap_or(0);
        let body = self.buf.get(at + HEAD..).unwrap_or(&[]);
        if let Some(end) = self.footer_end {
            return match e {
                McapError::BadMagic => Err(corrupt(
                    end,
                    "end magic",
                    "the file does not end with the MCAP magic bytes",
                )),
                McapError::BytesAfterEndMagic => Err(corrupt(
                    end + mcap::MAGIC.len(),
                    "the end of the file",
                    format!(
                        "{} bytes follow the end magic",
                        self.buf.len().saturating_sub(end + mcap::MAGIC.len())
                    ),
                )),
                _ => Ok(Step::Truncated(format!(
                    "the file ends at byte {}, inside its end magic after the footer",
                    self.buf.len()
                ))),
            };
        }
        match e {
            McapError::UnexpectedEof | McapError::RecordTooLarge { .. } => {
                return Ok(Step::Truncated(self.cut(at)));
            }
            _ => {}
        }
        // The data end and the footer are the records the MCAP reader checks before it gives
        // them: one in the wrong section is refused for its place first.
        if let Some(e) = misplaced(self.summary_start.is_none(), at, opcode) {
            return Err(e);
        }
        Err(match e {
            McapError::BadDataCrc { saved, calculated } => corrupt(
                at,
                "data end",
                format!(
                    "the CRC-32 of bytes 0–{} is 0x{calculated:08x}, the data-end record says \
                     0x{saved:08x} (the data section was changed)",
                    at - 1
                ),
            ),
            McapError::BadSummaryCrc { saved, calculated } => corrupt(
                at,
                "footer",
                format!(
                    "the CRC-32 of the summary section (bytes {}–{}) is 0x{calculated:08x}, the \
                     footer says 0x{saved:08x} (the summary was changed)",
                    self.summary_start.unwrap_or(at),
                    at + HEAD + 16 - 1
                ),
            ),
            // A data end or footer too short for its fields: our parser names the field.
            McapError::Parse(_) if opcode == op::FOOTER => {
                let len = body.len().min(header_len(self.buf, at));
                let detail = parse::footer(&body[..len])
                    .err()
                    .unwrap_or_else(|| "its fields do not parse".into());
                corrupt(at, "footer", detail)
            }
            McapError::Parse(_) => {
                let len = body.len().min(header_len(self.buf, at));
                let detail = parse::Cur::new(&body[..len])
                    .u32("data_section_crc")
                    .err()
                    .unwrap_or_else(|| "its fields do not parse".into());
                corrupt(at, op_name(opcode), detail)
            }
            other => corrupt(at, op_name(opcode), mcap_detail(other)),
        })
    }

    /// Where and how the file ends, cut inside or before the record at `at`.
    fn cut(&self, at: usize) -> String {
        let total = self.buf.len();
        let left = total.saturating_sub(at);
        if left == 0 {
            return if self.summary_start.is_none() {
                format!("the file ends at byte {at}, before its data-end record")
            } else {
                format!(
                    "the file ends at byte {at}, in its summary section (the data section is \
                     complete; the footer is missing)"
                )
            };
        }
        if left < HEAD {
            return format!(
                "the file ends at byte {total}, {left} bytes into the record header at byte {at}"
            );
        }
        format!(
            "the {} record at byte {at} announces {} bytes, the file ends {} bytes into it",
            op_name(self.buf[at]),
            header_len(self.buf, at),
            left - HEAD
        )
    }
}

/// The length field of the record header at `at` (0 when the header is cut).
fn header_len(buf: &[u8], at: usize) -> usize {
    buf.get(at + 1..at + HEAD)
        .and_then(|l| l.try_into().ok())
        .map(u64::from_le_bytes)
        .map_or(0, |l| usize::try_from(l).unwrap_or(usize::MAX))
}

/// The error for a record of `opcode` at `at` in a section where it does not belong (the data
/// section when `in_data`), if it does not. A message index is placed by its own rule (after a
/// chunk, see [`super::walk`]).
pub(super) fn misplaced(in_data: bool, at: usize, opcode: u8) -> Option<RecordingError> {
    let first = at == mcap::MAGIC.len();
    if in_data && first && opcode != op::HEADER {
        return Some(corrupt(
            at,
            op_name(opcode),
            "the first record of an MCAP file must be its header",
        ));
    }
    let fits = if in_data {
        matches!(
            opcode,
            op::SCHEMA
                | op::CHANNEL
                | op::MESSAGE
                | op::CHUNK
                | op::MESSAGE_INDEX
                | op::METADATA
                | op::ATTACHMENT
                | op::DATA_END
        ) || (opcode == op::HEADER && first)
    } else {
        matches!(
            opcode,
            op::SCHEMA
                | op::CHANNEL
                | op::CHUNK_INDEX
                | op::METADATA_INDEX
                | op::ATTACHMENT_INDEX
                | op::STATISTICS
                | op::SUMMARY_OFFSET
                | op::FOOTER
        )
    };
    (!fits).then(|| {
        let place = if in_data {
            "does not belong in the data section of a recording"
        } else {
            "does not belong in the summary section"
        };
        corrupt(at, op_name(opcode), place)
    })
}

/// Our text for an error of the MCAP reader that our own checks do not catch first (no Rust
/// Debug text: each kind is worded here).
pub(super) fn mcap_detail(e: &McapError) -> String {
    match e {
        McapError::BadChunkCrc { saved, calculated } => {
            format!("the CRC-32 of its records is 0x{calculated:08x}, the chunk says 0x{saved:08x}")
        }
        McapError::BadChunkLength { header, available } => {
            format!("its header needs {header} bytes, the record has {available}")
        }
        McapError::UnsupportedCompression(c) => {
            format!("compression `{c}` is not supported (allowed: zstd, lz4, none)")
        }
        McapError::DecompressionError(d) => format!("its records do not decompress ({d})"),
        McapError::Io(e) => format!("its records do not decompress ({e})"),
        McapError::ChunkTooLarge(n) => format!("{n} bytes of chunk data are over the bound"),
        McapError::RecordTooLarge { opcode, len } => format!(
            "a {} record announces {len} bytes, more than the bytes that hold it",
            op_name(*opcode)
        ),
        McapError::UnexpectedEoc => "its records end inside a record".into(),
        McapError::UnexpectedEof => "the file ends inside the record".into(),
        McapError::Parse(_) => "its fields do not parse".into(),
        _ => "the MCAP reader refuses it".into(),
    }
}
