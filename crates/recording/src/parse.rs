//! The field parser of the reader: the body of each record (framed, decompressed and
//! CRC-checked by the `mcap` crate's sans-io reader, see [`super::reader`]) read field by
//! field, every length checked against the bytes that hold it before anything is allocated.
//!
//! Why not `mcap::parse_record`: its string and byte fields reserve the length they announce
//! before reading (a damaged `u32` length reserves up to 4 GiB), a repeated map key silently
//! replaces the first, and its errors (`Record parse failed`) name no field. These parsers name
//! the field (`` `name` needs N bytes at byte K of the record ``) and refuse repeated keys;
//! [`super::reader`] places their errors at a byte offset and a record.

use std::collections::BTreeMap;

/// Record opcodes (MCAP specification), from the `mcap` crate.
pub use mcap::records::op;

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
        // A records field announcing u64::MAX bytes inside a chunk record.
        let mut c = vec![0u8; 8 + 8 + 8 + 4];
        c.extend_from_slice(&4u32.to_le_bytes());
        c.extend_from_slice(b"zstd");
        c.extend_from_slice(&u64::MAX.to_le_bytes());
        c.extend_from_slice(&[0; 4]);
        assert_eq!(
            chunk(&c).unwrap_err(),
            "`records` needs 18446744073709551615 bytes at byte 44 of the record, only 4 are left"
        );
    }

    #[test]
    fn repeated_keys_and_short_footers_are_named() {
        let mut m = Vec::new();
        for _ in 0..2 {
            m.extend_from_slice(&1u32.to_le_bytes());
            m.extend_from_slice(b"k");
            m.extend_from_slice(&1u32.to_le_bytes());
            m.extend_from_slice(b"v");
        }
        let mut b = 4u32.to_le_bytes().to_vec();
        b.extend_from_slice(b"name");
        b.extend_from_slice(&(m.len() as u32).to_le_bytes());
        b.extend_from_slice(&m);
        assert_eq!(metadata(&b).unwrap_err(), "`metadata` repeats the key `k`");
        assert_eq!(
            footer(&[0; 18]).unwrap_err(),
            "`summary_crc` needs 4 bytes at byte 16 of the record, only 2 are left"
        );
        assert_eq!(
            footer(&[0; 21]).unwrap_err(),
            "the footer is 21 bytes, not 20"
        );
        assert_eq!(op_name(0x42), "record of unknown opcode 0x42");
        assert_eq!(op_name(op::DATA_END), "data end");
    }
}
