//! The reader's errors on small hand-made files: what the `mcap` crate detects (CRCs, framing,
//! decompression) worded as ours, at the right byte offsets. The golden recordings' flips and
//! cuts are tested in `crates/cli/tests/recording_integrity.rs`.
#![allow(clippy::unwrap_used)]

use super::{RecordingError, read_recording};
use crate::parse::op;

/// A record: opcode, length, body.
fn rec(opcode: u8, body: &[u8]) -> Vec<u8> {
    let mut v = vec![opcode];
    v.extend_from_slice(&(body.len() as u64).to_le_bytes());
    v.extend_from_slice(body);
    v
}

/// The MCAP magic and a header record (profile "", library "t"): 8 + 9 + 9 bytes.
fn start() -> Vec<u8> {
    let mut v = mcap::MAGIC.to_vec();
    let mut h = 0u32.to_le_bytes().to_vec();
    h.extend_from_slice(&1u32.to_le_bytes());
    h.push(b't');
    v.extend(rec(op::HEADER, &h));
    v
}

/// A chunk record holding `records` compressed as `compression` (`z`: the compressed bytes).
fn chunk(records: &[u8], compression: &str, z: &[u8], crc: u32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&1u64.to_le_bytes());
    b.extend_from_slice(&1u64.to_le_bytes());
    b.extend_from_slice(&(records.len() as u64).to_le_bytes());
    b.extend_from_slice(&crc.to_le_bytes());
    b.extend_from_slice(&(compression.len() as u32).to_le_bytes());
    b.extend_from_slice(compression.as_bytes());
    b.extend_from_slice(&(z.len() as u64).to_le_bytes());
    b.extend_from_slice(z);
    rec(op::CHUNK, &b)
}

fn err(b: &[u8]) -> String {
    read_recording(b, false).unwrap_err().to_string()
}

#[test]
fn cuts_are_truncations_at_the_record_they_cut() {
    let mut f = start();
    assert_eq!(f.len(), 26);
    assert_eq!(
        err(&f),
        "truncated recording: the file ends at byte 26, before its data-end record; 0 complete \
         ticks are readable (salvage them with --salvage)"
    );
    let schema = rec(op::SCHEMA, &[0; 30]);
    f.extend_from_slice(&schema[..5]);
    assert_eq!(
        err(&f),
        "truncated recording: the file ends at byte 31, 5 bytes into the record header at byte \
         26; 0 complete ticks are readable (salvage them with --salvage)"
    );
    f.extend_from_slice(&schema[5..20]);
    assert_eq!(
        err(&f),
        "truncated recording: the schema record at byte 26 announces 30 bytes, the file ends 11 \
         bytes into it; 0 complete ticks are readable (salvage them with --salvage)"
    );
    // A length longer than the file: the same, not an allocation.
    let mut g = start();
    g.extend(rec(op::MESSAGE, &[0; 4]));
    g[27..35].copy_from_slice(&u64::MAX.to_le_bytes());
    assert_eq!(
        read_recording(&g, true).unwrap_err().to_string(),
        "nothing to salvage: the message record at byte 26 announces 18446744073709551615 \
         bytes, the file ends 4 bytes into it, before the end of its first tick"
    );
}

#[test]
fn a_changed_data_section_names_both_crcs_and_a_zero_crc_is_refused() {
    let mut f = start();
    let calc = crc32fast::hash(&f);
    f.extend(rec(op::DATA_END, &(calc ^ 1).to_le_bytes()));
    assert_eq!(
        err(&f),
        format!(
            "corrupt recording: data end at byte 26: the CRC-32 of bytes 0–25 is 0x{calc:08x}, \
             the data-end record says 0x{:08x} (the data section was changed)",
            calc ^ 1
        )
    );
    let mut f = start();
    f.extend(rec(op::DATA_END, &0u32.to_le_bytes()));
    assert_eq!(
        err(&f),
        "corrupt recording: data end at byte 26: the data-section CRC is 0 (not written; \
         nanohaptics writes it in every recording)"
    );
    // Too short for its field: the field is named.
    let mut f = start();
    f.extend(rec(op::DATA_END, &[1, 2]));
    assert_eq!(
        err(&f),
        "corrupt recording: data end at byte 26: `data_section_crc` needs 4 bytes at byte 0 of \
         the record, only 2 are left"
    );
    // A footer in the data section is refused for its place, not for its CRC.
    let mut f = start();
    f.extend(rec(op::FOOTER, &[7; 20]));
    assert_eq!(
        err(&f),
        "corrupt recording: footer at byte 26: does not belong in the data section of a \
         recording"
    );
}

#[test]
fn chunk_records_are_placed_in_the_decompressed_bytes() {
    // An uncompressed chunk whose one record announces 40 bytes with 3 left (within the
    // chunk's size: the MCAP reader runs out of records) and 100 bytes (over it: refused
    // before it is buffered).
    for (len, c) in [(40u64, 26), (100, 26)] {
        let mut records = vec![op::MESSAGE];
        records.extend_from_slice(&len.to_le_bytes());
        records.extend_from_slice(&[1, 2, 3]);
        let mut f = start();
        f.extend(chunk(&records, "", &records, crc32fast::hash(&records)));
        assert_eq!(
            err(&f),
            format!(
                "corrupt recording: chunk at byte {c}: its decompressed records end inside the \
                 record at byte 0 of them (a message record announcing {len} bytes, 3 are left)"
            )
        );
    }
}

#[test]
fn chunk_crc_and_decompression_errors_are_ours() {
    let mut records = rec(op::SCHEMA, &[0; 14]);
    records.extend(rec(op::SCHEMA, &[0; 14]));
    let z = zstd::bulk::compress(&records, 3).unwrap();
    let crc = crc32fast::hash(&records);
    let mut f = start();
    f.extend(chunk(&records, "zstd", &z, crc ^ 0x10));
    assert_eq!(
        err(&f),
        format!(
            "corrupt recording: chunk at byte 26: the CRC-32 of its 46 decompressed bytes is \
             0x{crc:08x}, the chunk says 0x{:08x} (the chunk was changed or damaged)",
            crc ^ 0x10
        )
    );
    let mut f = start();
    f.extend(chunk(&records, "zstd", &z[..z.len() - 3], crc));
    assert_eq!(
        err(&f),
        "corrupt recording: chunk at byte 26: the records decompress to fewer bytes than the 46 \
         the chunk announces"
    );
    let mut bad = z.clone();
    bad[..4].copy_from_slice(b"junk");
    let mut f = start();
    f.extend(chunk(&records, "zstd", &bad, crc));
    assert_eq!(
        err(&f),
        "corrupt recording: chunk at byte 26: the zstd data does not decompress (Unknown frame \
         descriptor)"
    );
    let mut f = start();
    f.extend(chunk(&records, "brotli", &z, crc));
    assert_eq!(
        err(&f),
        "corrupt recording: chunk at byte 26: compression `brotli` is not supported (allowed: \
         zstd, lz4, none)"
    );
    let mut f = start();
    f.extend(chunk(&records, "zstd", &z, 0));
    assert_eq!(
        err(&f),
        "corrupt recording: chunk at byte 26: its CRC is 0 (not written; nanohaptics writes \
         one for every chunk)"
    );
    // The records decompress and check: the first schema (id 0) is refused at its place.
    let mut f = start();
    f.extend(chunk(&records, "zstd", &z, crc));
    assert_eq!(
        err(&f),
        "corrupt recording: schema record at byte 0 of the decompressed records of the chunk \
         at byte 26: schema id 0 is reserved (no schema)"
    );
    let e = read_recording(&f, true).unwrap_err();
    assert!(
        matches!(e, RecordingError::Corrupt { offset: 26, .. }),
        "{e}"
    );
}

/// A chunk record announcing `size` uncompressed bytes for the records `z`.
fn chunk_sized(size: u64, compression: &str, z: &[u8], crc: u32) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&1u64.to_le_bytes());
    b.extend_from_slice(&1u64.to_le_bytes());
    b.extend_from_slice(&size.to_le_bytes());
    b.extend_from_slice(&crc.to_le_bytes());
    b.extend_from_slice(&(compression.len() as u32).to_le_bytes());
    b.extend_from_slice(compression.as_bytes());
    b.extend_from_slice(&(z.len() as u64).to_le_bytes());
    b.extend_from_slice(z);
    rec(op::CHUNK, &b)
}

/// docs/recording-format.md: a chunk's uncompressed size is bounded "≤ 1 GiB and ≤ 1000 × its
/// compressed size + 1 MiB": each bound is accepted (the file then fails further on) and one
/// byte past it is refused before anything is allocated.
#[test]
fn a_chunk_size_at_its_bound_passes_it_and_one_byte_more_is_refused() {
    // 1000 × the compressed size + 1 MiB (zstd)
    let mut records = rec(op::SCHEMA, &[0; 14]);
    records.extend(rec(op::SCHEMA, &[0; 14]));
    let z = zstd::bulk::compress(&records, 3).unwrap();
    let crc = crc32fast::hash(&records);
    let bound = 1000 * z.len() as u64 + (1 << 20);
    let body = 40 + "zstd".len() + z.len();
    let mut f = start();
    f.extend(chunk_sized(bound, "zstd", &z, crc));
    assert_eq!(
        err(&f),
        format!(
            "corrupt recording: chunk at byte 26: the records decompress to fewer bytes than the \
             {bound} the chunk announces"
        )
    );
    let mut f = start();
    f.extend(chunk_sized(bound + 1, "zstd", &z, crc));
    assert_eq!(
        err(&f),
        format!(
            "corrupt recording: chunk at byte 26: uncompressed size {} bytes is over the bound \
             of {bound} bytes for a {body}-byte chunk (a damaged size field)",
            bound + 1
        )
    );
    // 1 GiB: 1 100 000 bytes of records would allow 1.1 GB by the first rule
    let records = vec![0u8; 1_100_000];
    let gib = 1u64 << 30;
    let body = 40 + records.len();
    let mut f = start();
    f.extend(chunk_sized(gib, "", &records, 1));
    assert_eq!(
        err(&f),
        "corrupt recording: chunk at byte 26: its 1100000 bytes of uncompressed records are not \
         the 1073741824 bytes it announces"
    );
    let mut f = start();
    f.extend(chunk_sized(gib + 1, "", &records, 1));
    assert_eq!(
        err(&f),
        format!(
            "corrupt recording: chunk at byte 26: uncompressed size 1073741825 bytes is over the \
             bound of 1073741824 bytes for a {body}-byte chunk (a damaged size field)"
        )
    );
}
