//! A chunk: its header read by our field parser (to bound its uncompressed size before
//! anything is allocated, and to refuse a CRC that was not written), then opened by the `mcap`
//! crate's sans-io [`LinearReader`] (one for the chunks of a file): it decompresses the
//! records (zstd, lz4), checks their CRC-32 before giving any of them, and frames them (a
//! record length over its limit, see [`REUSE_LIMIT`], is refused before it is buffered). Each
//! record is placed at its offset in the decompressed bytes, and walked like a record of the
//! data section.

use super::framing::{HEAD, Rec, mcap_detail};
use super::walk::{ChunkInfo, Walk};
use super::{RecordingError, corrupt};
use crate::parse::{self, ChunkRec, op, op_name};
use mcap::McapError;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// Largest uncompressed chunk accepted, bytes (the writer makes 8 MiB chunks).
const MAX_CHUNK: u64 = 1 << 30;

/// The record length limit of the chunk reader, bytes, unless a chunk needs more (its size):
/// a record inside a chunk announcing more is refused before it is buffered; one announcing
/// less but more than is left in its chunk is refused at the end of the chunk's records, after
/// a buffer of at most this size (the writer makes 8 MiB chunks).
const REUSE_LIMIT: usize = 16 << 20;

/// The bound of a chunk's uncompressed size for `compressed` bytes of records: 1000 times
/// them plus 1 MiB, at most [`MAX_CHUNK`].
fn bound(compressed: u64) -> u64 {
    MAX_CHUNK.min(compressed.saturating_mul(1000).saturating_add(1 << 20))
}

impl Walk {
    /// A chunk record of the data section.
    pub(super) fn chunk(&mut self, f: &Rec<'_>) -> Result<(), RecordingError> {
        let c = parse::chunk(f.body).map_err(|d| corrupt(f.at, "chunk", d))?;
        let bound = bound(c.records.len() as u64);
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
        if c.uncompressed_crc == 0 {
            return Err(corrupt(
                f.at,
                "chunk",
                "its CRC is 0 (not written; nanohaptics writes one for every chunk)",
            ));
        }
        if c.compression.is_empty() && c.records.len() as u64 != c.uncompressed_size {
            return Err(corrupt(
                f.at,
                "chunk",
                format!(
                    "its {} bytes of uncompressed records are not the {} bytes it announces",
                    c.records.len(),
                    c.uncompressed_size
                ),
            ));
        }
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
        let times = self.chunk_records(f, &c, &mut info)?;
        self.integrity.chunk_crcs += 1;
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

    /// The records of chunk `c` (record `f`) through the MCAP reader; returns the span of their
    /// log times.
    fn chunk_records(
        &mut self,
        f: &Rec<'_>,
        c: &ChunkRec<'_>,
        info: &mut ChunkInfo,
    ) -> Result<Option<(u64, u64)>, RecordingError> {
        let size = usize::try_from(c.uncompressed_size).unwrap_or(usize::MAX);
        let need = size.max(f.body.len());
        // One reader for the chunks of a file (its buffers and decoders are reused), while its
        // length limit covers the chunk.
        let (limit, mut reader) = match self.chunk_reader.take() {
            Some((limit, r)) if limit >= need => (limit, r),
            _ => {
                let limit = need.max(REUSE_LIMIT);
                let options = LinearReaderOptions::default()
                    .with_skip_start_magic(true)
                    .with_skip_end_magic(true)
                    .with_prevalidate_chunk_crcs(true)
                    .with_record_length_limit(limit);
                (limit, LinearReader::new_with_options(options))
            }
        };
        let mut given = false;
        let mut times: Option<(u64, u64)> = None;
        // Offset of the next record in the decompressed records.
        let mut p = 0usize;
        while let Some(event) = reader.next_event() {
            let (opcode, body) = match event {
                Err(e) => return Err(chunk_error(f, c, p, &e)),
                // Every record read: the reader asks for the next chunk, and is kept for it.
                Ok(LinearReadEvent::ReadRequest(_)) if given && p == size => break,
                // A record runs past the chunk's records: the reader fails at the end of its
                // input (it is not kept).
                Ok(LinearReadEvent::ReadRequest(_)) if given => {
                    reader.notify_read(0);
                    continue;
                }
                Ok(LinearReadEvent::ReadRequest(_)) => {
                    // The whole chunk record at once: the reader holds it all.
                    let n = f.end() - f.at;
                    let dst = reader.insert(n);
                    dst[0] = op::CHUNK;
                    dst[1..HEAD].copy_from_slice(&(f.body.len() as u64).to_le_bytes());
                    dst[HEAD..].copy_from_slice(f.body);
                    reader.notify_read(n);
                    given = true;
                    continue;
                }
                Ok(LinearReadEvent::Record { opcode, data }) => (opcode, data),
            };
            let here = || {
                format!(
                    "{} record at byte {p} of the decompressed records of the chunk",
                    op_name(opcode)
                )
            };
            match opcode {
                op::SCHEMA => self.schema(body).map_err(|d| corrupt(f.at, here(), d))?,
                op::CHANNEL => self.channel(body).map_err(|d| corrupt(f.at, here(), d))?,
                op::MESSAGE => {
                    let m = parse::message(body).map_err(|d| corrupt(f.at, here(), d))?;
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
                _ => return Err(corrupt(f.at, here(), "does not belong inside a chunk")),
            }
            p += HEAD + body.len();
        }
        self.chunk_reader = Some((limit, reader));
        Ok(times)
    }
}

/// The MCAP reader's error in chunk `c` (record `f`), the next record at byte `p` of its
/// decompressed records, as ours.
fn chunk_error(f: &Rec<'_>, c: &ChunkRec<'_>, p: usize, e: &McapError) -> RecordingError {
    let size = c.uncompressed_size;
    let left = usize::try_from(size)
        .unwrap_or(usize::MAX)
        .saturating_sub(p);
    let inside = |what: String| {
        format!("its decompressed records end inside the record at byte {p} of them ({what})")
    };
    let detail = match e {
        McapError::BadChunkCrc { saved, calculated } => format!(
            "the CRC-32 of its {size} decompressed bytes is 0x{calculated:08x}, the chunk says \
             0x{saved:08x} (the chunk was changed or damaged)"
        ),
        McapError::UnsupportedCompression(name) => {
            format!("compression `{name}` is not supported (allowed: zstd, lz4, none)")
        }
        // The MCAP reader's words for compressed data that ends before the announced size.
        McapError::DecompressionError(d) if d == "decompressor made no progress" => {
            format!("the records decompress to fewer bytes than the {size} the chunk announces")
        }
        McapError::DecompressionError(d) => {
            format!("the {} data does not decompress ({d})", c.compression)
        }
        McapError::Io(d) => format!("the {} data does not decompress ({d})", c.compression),
        McapError::RecordTooLarge { opcode, len } => inside(format!(
            "a {} record announcing {len} bytes, {} are left",
            op_name(*opcode),
            left.saturating_sub(HEAD)
        )),
        McapError::UnexpectedEoc | McapError::UnexpectedEof if left < HEAD => {
            inside(format!("{left} bytes of a 9-byte record header"))
        }
        McapError::UnexpectedEoc | McapError::UnexpectedEof => {
            // Uncompressed records are the chunk's own bytes: their header can be read here.
            let head = c
                .compression
                .is_empty()
                .then(|| c.records.get(p..p + HEAD))
                .flatten();
            match head {
                Some(h) => {
                    let mut l = [0u8; 8];
                    l.copy_from_slice(&h[1..]);
                    inside(format!(
                        "a {} record announcing {} bytes, {} are left",
                        op_name(h[0]),
                        u64::from_le_bytes(l),
                        left - HEAD
                    ))
                }
                None => inside(format!(
                    "a record announcing more than the {} bytes that are left",
                    left - HEAD
                )),
            }
        }
        other => mcap_detail(other),
    };
    corrupt(f.at, "chunk", detail)
}
