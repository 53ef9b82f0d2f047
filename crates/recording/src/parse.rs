//! A bounded MCAP record parser: every length read from a file is checked against the bytes
//! that hold it before anything is allocated, and a chunk is decompressed into a buffer that
//! grows with the bytes the decoder actually produces (never with a size the file announces).
//!
//! The MCAP crate's readers trust record lengths found inside a decompressed chunk and reserve
//! them up front, so a damaged chunk could abort the process (`memory allocation of … bytes
//! failed`) or panic (`capacity overflow`). This module reads our own files instead: its errors
//! are plain text that [`super::reader`] places at a byte offset and a record.

use std::collections::BTreeMap;
use std::io::Read;

/// Record opcodes (MCAP specification).
pub mod op {
    /// Header.
    pub const HEADER: u8 = 0x01;
    /// Footer.
    pub const FOOTER: u8 = 0x02;
    /// Schema.
    pub const SCHEMA: u8 = 0x03;
    /// Channel.
    pub const CHANNEL: u8 = 0x04;
    /// Message.
    pub const MESSAGE: u8 = 0x05;
    /// Chunk.
    pub const CHUNK: u8 = 0x06;
    /// Message index.
    pub const MESSAGE_INDEX: u8 = 0x07;
    /// Chunk index.
    pub const CHUNK_INDEX: u8 = 0x08;
    /// Attachment.
    pub const ATTACHMENT: u8 = 0x09;
    /// Attachment index.
    pub const ATTACHMENT_INDEX: u8 = 0x0A;
    /// Statistics.
    pub const STATISTICS: u8 = 0x0B;
    /// Metadata.
    pub const METADATA: u8 = 0x0C;
    /// Metadata index.
    pub const METADATA_INDEX: u8 = 0x0D;
    /// Summary offset.
    pub const SUMMARY_OFFSET: u8 = 0x0E;
    /// Data end.
    pub const DATA_END: u8 = 0x0F;
}

/// The name of a record type, for messages.
pub fn op_name(opcode: u8) -> String {
    match opcode {
        op::HEADER => "header".into(),
        op::FOOTER => "footer".into(),
        op::SCHEMA => "schema".into(),
        op::CHANNEL => "channel".into(),
        op::MESSAGE => "message".into(),
        op::CHUNK => "chunk".into(),
        op::MESSAGE_INDEX => "message index".into(),
        op::CHUNK_INDEX => "chunk index".into(),
        op::ATTACHMENT => "attachment".into(),
        op::ATTACHMENT_INDEX => "attachment index".into(),
        op::STATISTICS => "statistics".into(),
        op::METADATA => "metadata".into(),
        op::METADATA_INDEX => "metadata index".into(),
        op::SUMMARY_OFFSET => "summary offset".into(),
        op::DATA_END => "data end".into(),
        other => format!("record of unknown opcode 0x{other:02x}"),
    }
}

/// One record framed by its opcode and length.
#[derive(Clone, Copy, Debug)]
pub struct Framed<'a> {
    /// Opcode.
    pub opcode: u8,
    /// Offset of the opcode byte in the buffer that holds the record.
    pub at: usize,
    /// The body (after the 9-byte opcode and length).
    pub body: &'a [u8],
}

impl Framed<'_> {
    /// Offset just past the record.
    pub fn end(&self) -> usize {
        self.at + 9 + self.body.len()
    }
}

/// Why a record could not be framed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrameError {
    /// Fewer than 9 bytes left for the opcode and length.
    ShortHeader {
        /// Bytes left.
        left: usize,
    },
    /// The announced length runs past the end of the buffer.
    PastEnd {
        /// Opcode.
        opcode: u8,
        /// Announced body length, bytes.
        len: u64,
        /// Bytes left after the opcode and length.
        left: usize,
    },
}

/// Frames the record at `at` of `buf` (none when `at` is the end of `buf`).
pub fn frame(buf: &[u8], at: usize) -> Option<Result<Framed<'_>, FrameError>> {
    let rest = buf.get(at..)?;
    if rest.is_empty() {
        return None;
    }
    let Some((head, tail)) = rest.split_first_chunk::<9>() else {
        return Some(Err(FrameError::ShortHeader { left: rest.len() }));
    };
    let opcode = head[0];
    let mut l = [0u8; 8];
    l.copy_from_slice(&head[1..]);
    let len = u64::from_le_bytes(l);
    match usize::try_from(len).ok().filter(|&n| n <= tail.len()) {
        Some(n) => Some(Ok(Framed {
            opcode,
            at,
            body: &tail[..n],
        })),
        None => Some(Err(FrameError::PastEnd {
            opcode,
            len,
            left: tail.len(),
        })),
    }
}

/// A little-endian reader over one record body; every length is checked against what is left.
pub struct Cur<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Cur<'a> {
    /// A reader at the start of `b`.
    pub fn new(b: &'a [u8]) -> Self {
        Cur { b, pos: 0 }
    }

    /// Bytes not read yet.
    pub fn left(&self) -> usize {
        self.b.len() - self.pos
    }

    /// Position in the body, bytes.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// The next `n` bytes.
    pub fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        let left = self.left();
        match usize::try_from(n).ok().filter(|&n| n <= left) {
            Some(n) => {
                let s = &self.b[self.pos..self.pos + n];
                self.pos += n;
                Ok(s)
            }
            None => Err(format!(
                "`{what}` needs {n} bytes at byte {} of the record, only {left} are left",
                self.pos
            )),
        }
    }

    fn arr<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        let s = self.take(N as u64, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    /// A `u8`.
    pub fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.arr::<1>(what)?[0])
    }

    /// A `u16`.
    pub fn u16(&mut self, what: &str) -> Result<u16, String> {
        Ok(u16::from_le_bytes(self.arr(what)?))
    }

    /// A `u32`.
    pub fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.arr(what)?))
    }

    /// A `u64`.
    pub fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.arr(what)?))
    }

    /// A string (`u32` length, UTF-8 bytes).
    pub fn string(&mut self, what: &str) -> Result<String, String> {
        let n = self.u32(what)?;
        let b = self.take(u64::from(n), what)?;
        String::from_utf8(b.to_vec()).map_err(|_| format!("`{what}` is not UTF-8 text"))
    }

    /// Bytes with a `u32` length.
    pub fn bytes32(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)?;
        self.take(u64::from(n), what)
    }

    /// Bytes with a `u64` length.
    pub fn bytes64(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u64(what)?;
        self.take(n, what)
    }

    /// The rest of the body.
    pub fn rest(&mut self) -> &'a [u8] {
        let s = &self.b[self.pos..];
        self.pos = self.b.len();
        s
    }

    /// A map of strings (`u32` byte length, then key/value pairs). A repeated key is an error.
    pub fn string_map(&mut self, what: &str) -> Result<BTreeMap<String, String>, String> {
        let mut c = Cur::new(self.bytes32(what)?);
        let mut m = BTreeMap::new();
        while c.left() > 0 {
            let k = c.string(what)?;
            let v = c.string(what)?;
            if m.contains_key(&k) {
                return Err(format!("`{what}` repeats the key `{k}`"));
            }
            m.insert(k, v);
        }
        Ok(m)
    }

    /// A map `u16 → u64` (`u32` byte length, then pairs). A repeated key is an error.
    pub fn u16_u64_map(&mut self, what: &str) -> Result<BTreeMap<u16, u64>, String> {
        let mut c = Cur::new(self.bytes32(what)?);
        let mut m = BTreeMap::new();
        while c.left() > 0 {
            let k = c.u16(what)?;
            let v = c.u64(what)?;
            if m.insert(k, v).is_some() {
                return Err(format!("`{what}` repeats channel {k}"));
            }
        }
        Ok(m)
    }
}

/// A schema record.
#[derive(Clone, Debug, PartialEq)]
pub struct Schema {
    /// Id.
    pub id: u16,
    /// Name.
    pub name: String,
    /// Encoding of the schema text.
    pub encoding: String,
    /// Schema data.
    pub data: Vec<u8>,
}

/// Parses a schema record.
pub fn schema(b: &[u8]) -> Result<Schema, String> {
    let mut c = Cur::new(b);
    Ok(Schema {
        id: c.u16("id")?,
        name: c.string("name")?,
        encoding: c.string("encoding")?,
        data: c.bytes32("data")?.to_vec(),
    })
}

/// A channel record.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelRec {
    /// Id.
    pub id: u16,
    /// Schema id.
    pub schema_id: u16,
    /// Topic.
    pub topic: String,
    /// Message encoding.
    pub message_encoding: String,
    /// Metadata.
    pub metadata: BTreeMap<String, String>,
}

/// Parses a channel record.
pub fn channel(b: &[u8]) -> Result<ChannelRec, String> {
    let mut c = Cur::new(b);
    Ok(ChannelRec {
        id: c.u16("id")?,
        schema_id: c.u16("schema_id")?,
        topic: c.string("topic")?,
        message_encoding: c.string("message_encoding")?,
        metadata: c.string_map("metadata")?,
    })
}

/// A message record.
#[derive(Clone, Copy, Debug)]
pub struct MessageRec<'a> {
    /// Channel id.
    pub channel_id: u16,
    /// Sequence number.
    pub sequence: u32,
    /// Log time, ns.
    pub log_time: u64,
    /// Data.
    pub data: &'a [u8],
}

/// Parses a message record.
pub fn message(b: &[u8]) -> Result<MessageRec<'_>, String> {
    let mut c = Cur::new(b);
    let channel_id = c.u16("channel_id")?;
    let sequence = c.u32("sequence")?;
    let log_time = c.u64("log_time")?;
    let _publish = c.u64("publish_time")?;
    Ok(MessageRec {
        channel_id,
        sequence,
        log_time,
        data: c.rest(),
    })
}

/// A chunk record.
#[derive(Clone, Debug)]
pub struct ChunkRec<'a> {
    /// Earliest message log time, ns.
    pub start_time: u64,
    /// Latest message log time, ns.
    pub end_time: u64,
    /// Uncompressed size of the records, bytes.
    pub uncompressed_size: u64,
    /// CRC-32 of the uncompressed records.
    pub uncompressed_crc: u32,
    /// Compression (`""`, `zstd`, `lz4`).
    pub compression: String,
    /// The compressed records.
    pub records: &'a [u8],
}

/// Parses a chunk record.
pub fn chunk(b: &[u8]) -> Result<ChunkRec<'_>, String> {
    let mut c = Cur::new(b);
    let r = ChunkRec {
        start_time: c.u64("message_start_time")?,
        end_time: c.u64("message_end_time")?,
        uncompressed_size: c.u64("uncompressed_size")?,
        uncompressed_crc: c.u32("uncompressed_crc")?,
        compression: c.string("compression")?,
        records: c.bytes64("records")?,
    };
    if c.left() != 0 {
        return Err(format!(
            "{} bytes follow the chunk's records inside the chunk record",
            c.left()
        ));
    }
    Ok(r)
}

/// Decompresses a chunk's records into a buffer that grows with the decoder's output, up to
/// `size` bytes (the announced uncompressed size, already checked against a bound). Fails when
/// the data does not decode or decodes to another size.
pub fn decompress(compression: &str, src: &[u8], size: u64) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(usize::try_from(size.min(1 << 22)).unwrap_or(0));
    let read = |r: &mut dyn Read, out: &mut Vec<u8>| {
        r.take(size.saturating_add(1))
            .read_to_end(out)
            .map_err(|e| format!("the {compression} data does not decompress ({e})"))
    };
    match compression {
        "" => out.extend_from_slice(src),
        "zstd" => {
            let mut d = zstd::stream::read::Decoder::with_buffer(src)
                .map_err(|e| format!("the zstd decoder cannot start ({e})"))?;
            read(&mut d, &mut out)?;
        }
        "lz4" => {
            let mut d = lz4::Decoder::new(src)
                .map_err(|e| format!("the lz4 decoder cannot start ({e})"))?;
            read(&mut d, &mut out)?;
        }
        other => {
            return Err(format!(
                "compression `{other}` is not supported (allowed: zstd, lz4, none)"
            ));
        }
    }
    if out.len() as u64 != size {
        return Err(format!(
            "the records decompress to {}{} bytes, the chunk announces {size}",
            if out.len() as u64 > size {
                "more than "
            } else {
                ""
            },
            out.len().min(usize::try_from(size).unwrap_or(usize::MAX))
        ));
    }
    Ok(out)
}

/// A message index record.
pub fn message_index(b: &[u8]) -> Result<(u16, Vec<(u64, u64)>), String> {
    let mut c = Cur::new(b);
    let id = c.u16("channel_id")?;
    let mut e = Cur::new(c.bytes32("records")?);
    let mut v = Vec::with_capacity(e.left() / 16);
    while e.left() > 0 {
        v.push((e.u64("records")?, e.u64("records")?));
    }
    Ok((id, v))
}

/// A chunk index record.
#[derive(Clone, Debug, PartialEq)]
pub struct ChunkIndexRec {
    /// Earliest message log time, ns.
    pub start_time: u64,
    /// Latest message log time, ns.
    pub end_time: u64,
    /// Offset of the chunk record.
    pub chunk_start_offset: u64,
    /// Length of the chunk record (opcode and length included).
    pub chunk_length: u64,
    /// Offsets of the chunk's message index records by channel.
    pub message_index_offsets: BTreeMap<u16, u64>,
    /// Bytes of the message index records.
    pub message_index_length: u64,
    /// Compression.
    pub compression: String,
    /// Compressed size, bytes.
    pub compressed_size: u64,
    /// Uncompressed size, bytes.
    pub uncompressed_size: u64,
}

/// Parses a chunk index record.
pub fn chunk_index(b: &[u8]) -> Result<ChunkIndexRec, String> {
    let mut c = Cur::new(b);
    Ok(ChunkIndexRec {
        start_time: c.u64("message_start_time")?,
        end_time: c.u64("message_end_time")?,
        chunk_start_offset: c.u64("chunk_start_offset")?,
        chunk_length: c.u64("chunk_length")?,
        message_index_offsets: c.u16_u64_map("message_index_offsets")?,
        message_index_length: c.u64("message_index_length")?,
        compression: c.string("compression")?,
        compressed_size: c.u64("compressed_size")?,
        uncompressed_size: c.u64("uncompressed_size")?,
    })
}

/// A statistics record.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Stats {
    /// Messages.
    pub message_count: u64,
    /// Schemas.
    pub schema_count: u16,
    /// Channels.
    pub channel_count: u32,
    /// Attachments.
    pub attachment_count: u32,
    /// Metadata records.
    pub metadata_count: u32,
    /// Chunks.
    pub chunk_count: u32,
    /// Earliest message log time, ns.
    pub start_time: u64,
    /// Latest message log time, ns.
    pub end_time: u64,
    /// Messages per channel.
    pub channel_message_counts: BTreeMap<u16, u64>,
}

/// Parses a statistics record.
pub fn statistics(b: &[u8]) -> Result<Stats, String> {
    let mut c = Cur::new(b);
    Ok(Stats {
        message_count: c.u64("message_count")?,
        schema_count: c.u16("schema_count")?,
        channel_count: c.u32("channel_count")?,
        attachment_count: c.u32("attachment_count")?,
        metadata_count: c.u32("metadata_count")?,
        chunk_count: c.u32("chunk_count")?,
        start_time: c.u64("message_start_time")?,
        end_time: c.u64("message_end_time")?,
        channel_message_counts: c.u16_u64_map("channel_message_counts")?,
    })
}

/// Parses a metadata record: name and map.
pub fn metadata(b: &[u8]) -> Result<(String, BTreeMap<String, String>), String> {
    let mut c = Cur::new(b);
    Ok((c.string("name")?, c.string_map("metadata")?))
}

/// Parses a metadata index record: offset, length, name.
pub fn metadata_index(b: &[u8]) -> Result<(u64, u64, String), String> {
    let mut c = Cur::new(b);
    Ok((c.u64("offset")?, c.u64("length")?, c.string("name")?))
}

/// Parses a summary offset record: group opcode, start, length.
pub fn summary_offset(b: &[u8]) -> Result<(u8, u64, u64), String> {
    let mut c = Cur::new(b);
    Ok((
        c.u8("group_opcode")?,
        c.u64("group_start")?,
        c.u64("group_length")?,
    ))
}

/// Parses a footer record: summary start, summary offset start, summary CRC.
pub fn footer(b: &[u8]) -> Result<(u64, u64, u32), String> {
    let mut c = Cur::new(b);
    let f = (
        c.u64("summary_start")?,
        c.u64("summary_offset_start")?,
        c.u32("summary_crc")?,
    );
    if c.left() != 0 {
        return Err(format!("the footer is {} bytes, not 20", b.len()));
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn lengths_beyond_the_record_are_errors_not_allocations() {
        // A string announcing 4 GiB inside a 12-byte record.
        let mut b = vec![1, 0];
        b.extend_from_slice(&u32::MAX.to_le_bytes());
        b.extend_from_slice(b"abcdef");
        assert_eq!(
            schema(&b).unwrap_err(),
            "`name` needs 4294967295 bytes at byte 6 of the record, only 6 are left"
        );
        // A record announcing u64::MAX bytes.
        let mut f = vec![0x05];
        f.extend_from_slice(&u64::MAX.to_le_bytes());
        f.extend_from_slice(&[0; 4]);
        assert_eq!(
            frame(&f, 0).unwrap().unwrap_err(),
            FrameError::PastEnd {
                opcode: 5,
                len: u64::MAX,
                left: 4
            }
        );
        assert_eq!(
            frame(&f[..5], 0).unwrap().unwrap_err(),
            FrameError::ShortHeader { left: 5 }
        );
        assert!(frame(&f, f.len()).is_none());
    }

    #[test]
    fn decompression_stops_at_the_announced_size() {
        let data = vec![7u8; 100_000];
        let z = zstd::bulk::compress(&data, 3).unwrap();
        assert_eq!(decompress("zstd", &z, 100_000).unwrap(), data);
        assert_eq!(
            decompress("zstd", &z, 1000).unwrap_err(),
            "the records decompress to more than 1000 bytes, the chunk announces 1000"
        );
        assert_eq!(
            decompress("zstd", &z, 200_000).unwrap_err(),
            "the records decompress to 100000 bytes, the chunk announces 200000"
        );
        assert_eq!(
            decompress("brotli", &z, 1).unwrap_err(),
            "compression `brotli` is not supported (allowed: zstd, lz4, none)"
        );
    }
}
