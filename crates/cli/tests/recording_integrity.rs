//! Damaged, changed, cut and unwritable recordings (issue 11, items 16–19): the reader never
//! aborts or panics, `replay --verify` refuses every change a CRC or the summary can see, a
//! salvage that recovers nothing is an error, and a full disk keeps the OS error.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use recording::{RecordingError, read_recording, read_recording_file};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-integrity-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// A 4-second wall session: chunks [description], [ticks 0–999], …, [3000–3999].
fn wall_bytes() -> &'static [u8] {
    static B: OnceLock<Vec<u8>> = OnceLock::new();
    B.get_or_init(|| {
        let p = tmp("wall4s.mcap");
        let mut o =
            SessionOptions::new(SceneSource::from_path(&root().join("scenes/wall.toml")).unwrap());
        o.start_time_ns = Some(1_795_000_000_000_000_000);
        o.out = Some(p.clone());
        run_session(&o, &mut |_, _| {}).unwrap();
        std::fs::read(&p).unwrap()
    })
}

/// Top-level records: (opcode, start, end).
fn records(b: &[u8]) -> Vec<(u8, usize, usize)> {
    let mut v = Vec::new();
    let mut at = 8;
    while at + 9 <= b.len() {
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap()) as usize;
        v.push((b[at], at, at + 9 + len));
        if b[at] == 0x02 {
            break;
        }
        at += 9 + len;
    }
    v
}

fn of(b: &[u8], op: u8) -> Vec<(usize, usize)> {
    records(b)
        .into_iter()
        .filter(|r| r.0 == op)
        .map(|r| (r.1, r.2))
        .collect()
}

/// Chunk `k` with the message indexes that follow it: (start, end).
fn chunk_with_indexes(b: &[u8], k: usize) -> (usize, usize) {
    let recs = records(b);
    let i = recs
        .iter()
        .enumerate()
        .filter(|r| r.1.0 == 0x06)
        .nth(k)
        .unwrap()
        .0;
    let mut end = recs[i].2;
    for r in &recs[i + 1..] {
        if r.0 != 0x07 {
            break;
        }
        end = r.2;
    }
    (recs[i].1, end)
}

/// Rewrites the data-section CRC (so a test reaches the checks behind it).
fn fix_data_crc(b: &mut [u8]) {
    let (at, _) = of(b, 0x0F)[0];
    let crc = crc32fast::hash(&b[..at]);
    b[at + 9..at + 13].copy_from_slice(&crc.to_le_bytes());
}

/// Rewrites the summary CRC.
fn fix_summary_crc(b: &mut [u8]) {
    let (de, de_end) = of(b, 0x0F)[0];
    let _ = de;
    let (f, _) = of(b, 0x02)[0];
    let crc = crc32fast::hash(&b[de_end..f + 25]);
    b[f + 25..f + 29].copy_from_slice(&crc.to_le_bytes());
}

fn err(b: &[u8]) -> String {
    read_recording(b, false).unwrap_err().to_string()
}

/// The reader's error for file `m` whose summary section no longer matches the footer's
/// CRC: it names the footer's byte, the summary's bytes and both CRCs.
fn summary_crc_error(m: &[u8]) -> String {
    let (_, de_end) = of(m, 0x0F)[0];
    let (f, _) = of(m, 0x02)[0];
    let calc = crc32fast::hash(&m[de_end..f + 25]);
    let saved = u32::from_le_bytes(m[f + 25..f + 29].try_into().unwrap());
    format!(
        "corrupt recording: footer at byte {f}: the CRC-32 of the summary section (bytes \
         {de_end}–{}) is 0x{calc:08x}, the footer says 0x{saved:08x} (the summary was \
         changed)",
        f + 24
    )
}

#[test]
fn byte_flips_and_cuts_of_golden_recordings_are_errors_never_aborts() {
    // Every golden recording, 200 single-bit flips each (spread over the whole file, so inside
    // compressed chunk data, chunk headers, message indexes, the summary and the footer) and 40
    // cuts. The reader runs in this process: an abort would kill the test.
    let mut n = 0;
    for e in std::fs::read_dir(root().join("recordings")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "mcap") {
            continue;
        }
        let bytes = std::fs::read(&p).unwrap();
        let good = read_recording(&bytes, false).unwrap();
        assert!(
            good.integrity.summary && good.integrity.data_crc,
            "{}",
            p.display()
        );
        let len = bytes.len();
        for k in 0..200u64 {
            // A deterministic spread: golden-ratio steps over the file, bit k % 8.
            let i = ((k as f64 * 0.618_033_988_75).fract() * len as f64) as usize;
            let mut b = bytes.clone();
            b[i] ^= 1 << (k % 8);
            let e = read_recording(&b, false).expect_err(&format!(
                "{}: flipping bit {} of byte {i} read without error",
                p.display(),
                k % 8
            ));
            match &e {
                RecordingError::Corrupt { offset, .. } => assert!(*offset as usize <= len),
                RecordingError::NotMcap | RecordingError::Truncated { .. } => {}
                RecordingError::BadMessage { .. } => {}
                other => panic!("{}: byte {i}: unexpected {other}", p.display()),
            }
            // With salvage the damage is still an error (or, for a flip that makes the file look
            // cut, the complete ticks before it).
            if k % 4 != 0 {
                n += 1;
                continue;
            }
            if let Ok(r) = read_recording(&b, true) {
                assert!(r.truncated.is_some());
                assert!(r.integrity.ticks <= good.integrity.ticks);
            }
            n += 1;
        }
        for k in 1..=40 {
            let cut = &bytes[..len * k / 41];
            let e = read_recording(cut, false).unwrap_err();
            assert!(
                matches!(e, RecordingError::Truncated { .. }),
                "{}: cut at {}: {e}",
                p.display(),
                len * k / 41
            );
            match read_recording(cut, true) {
                Ok(r) => assert!(r.integrity.ticks > 0),
                Err(e) => assert!(
                    matches!(e, RecordingError::NothingToSalvage { .. }),
                    "{}: cut at {}: {e}",
                    p.display(),
                    len * k / 41
                ),
            }
        }
    }
    assert!(n >= 800, "{n} flips");
}

#[test]
fn a_damaged_chunk_length_inside_compressed_data_is_an_error_naming_the_record() {
    // A record length inside a chunk's decompressed records set to 2^62, the chunk re-compressed
    // with a matching CRC: the MCAP crate reserved such lengths up front and aborted.
    let b = wall_bytes();
    let (c, _) = of(b, 0x06)[1];
    let body = &b[c + 9..];
    let csize_at = 8 + 8 + 8 + 4;
    let clen = u32::from_le_bytes(body[csize_at..csize_at + 4].try_into().unwrap()) as usize;
    let data_at = csize_at + 4 + clen + 8;
    let comp = u64::from_le_bytes(body[data_at - 8..data_at].try_into().unwrap()) as usize;
    let mut recs = zstd::bulk::decompress(&body[data_at..data_at + comp], 1 << 26).unwrap();
    // The first record of the chunk: a message; its length field at bytes 1..9.
    recs[1..9].copy_from_slice(&(1u64 << 62).to_le_bytes());
    let z = zstd::bulk::compress(&recs, 3).unwrap();
    let mut chunk = Vec::new();
    chunk.extend_from_slice(&body[..16]);
    chunk.extend_from_slice(&(recs.len() as u64).to_le_bytes());
    chunk.extend_from_slice(&crc32fast::hash(&recs).to_le_bytes());
    chunk.extend_from_slice(&body[csize_at..csize_at + 4 + clen]);
    chunk.extend_from_slice(&(z.len() as u64).to_le_bytes());
    chunk.extend_from_slice(&z);
    let (_, end) = of(b, 0x06)[1];
    let mut m = b[..c].to_vec();
    m.push(0x06);
    m.extend_from_slice(&(chunk.len() as u64).to_le_bytes());
    m.extend_from_slice(&chunk);
    m.extend_from_slice(&b[end..]);
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: chunk at byte {c}: its decompressed records end inside the record \
             at byte 0 of them (a message record announcing 4611686018427387904 bytes, {} are \
             left)",
            recs.len() - 9
        )
    );
    assert_eq!(read_recording(&m, true).unwrap_err().to_string(), err(&m));
}

#[test]
fn verify_refuses_a_removed_duplicated_or_cut_chunk_with_the_first_difference() {
    let b = wall_bytes();
    let good = read_recording(b, false).unwrap();
    assert_eq!(good.integrity.chunk_crcs, 5);
    assert_eq!(good.integrity.ticks, 4000);
    assert!(good.integrity.ticks_match_metadata);
    assert!(verify(&good).unwrap().ok());

    // A whole chunk (ticks 1000–1999) and its message indexes removed.
    let (s, e) = chunk_with_indexes(b, 2);
    let mut m = b[..s].to_vec();
    m.extend_from_slice(&b[e..]);
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: message record at byte 0 of the decompressed records of the \
             chunk at byte {s}: /device/input tick 2000 follows tick 999: ticks 1000–1999 are \
             missing"
        )
    );
    // A chunk repeated.
    let mut m = b[..e].to_vec();
    m.extend_from_slice(&b[s..]);
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: message record at byte 0 of the decompressed records of the \
             chunk at byte {e}: /device/input tick 1000 follows tick 1999: tick 1000 repeats"
        )
    );
    // The last chunk removed: the ticks are in sequence, but the data section changed.
    let (s, e) = chunk_with_indexes(b, 4);
    let mut m = b[..s].to_vec();
    m.extend_from_slice(&b[e..]);
    let (de, _) = of(&m, 0x0F)[0];
    let calc = crc32fast::hash(&m[..de]);
    let saved = u32::from_le_bytes(m[de + 9..de + 13].try_into().unwrap());
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: data end at byte {de}: the CRC-32 of bytes 0–{} is \
             0x{calc:08x}, the data-end record says 0x{saved:08x} (the data section was changed)",
            de - 1
        )
    );
    // ... and with its CRC made to match, the session's tick count tells.
    fix_data_crc(&mut m);
    let (meta, _) = of(&m, 0x0C)[0];
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: metadata `session` at byte {meta}: ticks = 4000, the data \
             section holds 3000 ticks"
        )
    );
    // Cut right after the data end: complete data, no summary, no footer.
    let (_, de_end) = of(b, 0x0F)[0];
    let cut = &b[..de_end];
    assert_eq!(
        err(cut),
        format!(
            "truncated recording: the file ends at byte {de_end}, in its summary section (the \
             data section is complete; the footer is missing); 4000 complete ticks are readable \
             (salvage them with --salvage)"
        )
    );
    let part = read_recording(cut, true).unwrap();
    assert!(part.integrity.data_crc && !part.integrity.summary_crc);
    // Bytes after the end magic.
    let mut m = b.to_vec();
    m.extend_from_slice(b"junk");
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: the end of the file at byte {}: 4 bytes follow the end magic",
            b.len()
        )
    );
}

#[test]
fn a_change_in_any_crc_covered_byte_does_not_verify() {
    let b = wall_bytes();
    // The library name in the header (covered by the data-section CRC only).
    let mut m = b.to_vec();
    let profile_len = u32::from_le_bytes(b[17..21].try_into().unwrap()) as usize;
    m[8 + 9 + 4 + profile_len + 4] ^= 1;
    let (de, _) = of(&m, 0x0F)[0];
    let calc = crc32fast::hash(&m[..de]);
    let saved = u32::from_le_bytes(m[de + 9..de + 13].try_into().unwrap());
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: data end at byte {de}: the CRC-32 of bytes 0–{} is \
             0x{calc:08x}, the data-end record says 0x{saved:08x} (the data section was changed)",
            de - 1
        )
    );
    // A message index entry: it no longer matches its chunk (found before the data end).
    let (mi, _) = of(b, 0x07)[0];
    let mut m = b.to_vec();
    m[mi + 9 + 2 + 4] ^= 1;
    let (c1, _) = of(b, 0x06)[0];
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: message index at byte {mi}: channel 1: 1 entries for the 1 \
             messages of the channel in the chunk at byte {c1}; entry 0 differs"
        )
    );

    // The statistics in the summary.
    let (st, _) = of(b, 0x0B)[0];
    let mut m = b.to_vec();
    m[st + 9] ^= 1; // message_count
    assert_eq!(err(&m), summary_crc_error(&m));
    fix_summary_crc(&mut m);
    let n = u64::from_le_bytes(b[st + 9..st + 17].try_into().unwrap());
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: statistics at byte {st}: message_count = {}, the data section \
             holds {n}",
            n ^ 1
        )
    );
    // A chunk index pointing elsewhere.
    let (ci, _) = of(b, 0x08)[1];
    let mut m = b.to_vec();
    m[ci + 9 + 16] ^= 4; // chunk_start_offset
    fix_summary_crc(&mut m);
    let (c1, _) = of(b, 0x06)[1];
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: chunk index 1 at byte {ci}: chunk_start_offset = {}, chunk 1 \
             starts at byte {c1}",
            c1 ^ 4
        )
    );
    // The data end's own CRC field, and the footer's.
    let (de, _) = of(b, 0x0F)[0];
    let (f, _) = of(b, 0x02)[0];
    let mut m = b.to_vec();
    m[de + 9] ^= 0x80;
    assert!(err(&m).contains("(the data section was changed)"));
    let mut m = b.to_vec();
    m[f + 25] ^= 0x80;
    assert!(err(&m).contains("(the summary was changed)"));
}

#[test]
fn a_salvage_that_recovers_no_tick_is_an_error() {
    let b = wall_bytes();
    // Cut inside the first chunk of ticks: the description is readable, no tick is.
    let (c, _) = of(b, 0x06)[1];
    let cut = &b[..c + 100];
    let len = u64::from_le_bytes(b[c + 1..c + 9].try_into().unwrap());
    let want = format!(
        "nothing to salvage: the chunk record at byte {c} announces {len} bytes, the file ends \
         91 bytes into it, before the end of its first tick"
    );
    assert_eq!(read_recording(cut, true).unwrap_err().to_string(), want);
    // Through the program: exit status 1 and the message.
    let p = tmp("no-tick.mcap");
    std::fs::write(&p, cut).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["replay", p.to_str().unwrap(), "--salvage", "--verify"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        format!("error: {}: {want}", p.display())
    );
    // Cut before any message at all: the same error, not "no description".
    let e = read_recording(&b[..200], true).unwrap_err();
    assert!(matches!(e, RecordingError::NothingToSalvage { .. }), "{e}");
    // A salvage that recovers ticks replays them, and its rewrite reads back whole.
    let cut = &b[..of(b, 0x06)[3].0 + 10];
    let part = read_recording(cut, true).unwrap();
    assert_eq!(part.integrity.ticks, 2000);
    assert!(verify(&part).unwrap().ok());
    let q = tmp("salvaged.mcap");
    recording::rewrite(&part, &q).unwrap();
    let back = read_recording_file(&q, false).unwrap();
    assert_eq!(back.integrity.ticks, 2000);
    assert!(back.integrity.ticks_match_metadata && back.integrity.summary);
    assert_eq!(back.metadata["session"]["salvaged"], "true");
}

#[test]
fn a_full_disk_keeps_the_os_error_the_path_and_the_ticks_on_disk() {
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes/wall.toml")).unwrap());
    o.out = Some(PathBuf::from("/dev/full"));
    let e = run_session(&o, &mut |_, _| {}).unwrap_err();
    let want =
        "recording /dev/full: No space left on device (os error 28); 0 ticks reached the disk";
    assert_eq!(e.to_string(), want);
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["run", "wall", "--out", "/dev/full"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        format!("error: {want}")
    );
}

#[test]
fn a_summary_record_removed_fails_the_summary_crc_first_then_the_footer_offsets() {
    // The mcap crate's reader compares the summary CRC as the footer is read, so a summary
    // record removed is refused for the CRC before the footer's offsets are compared (the
    // reader of issue 11 compared `summary_offset_start` first). With the CRC rewritten, the
    // footer's offset is the error, at the footer's byte offset.
    let b = wall_bytes();
    let (st, st_end) = of(b, 0x0B)[0];
    let mut m = b[..st].to_vec();
    m.extend_from_slice(&b[st_end..]);
    assert_eq!(err(&m), summary_crc_error(&m));
    let (f, _) = of(&m, 0x02)[0];
    fix_summary_crc(&mut m);
    let first = u64::from_le_bytes(
        b[f + (st_end - st) + 17..f + (st_end - st) + 25]
            .try_into()
            .unwrap(),
    );
    let moved = of(&m, 0x0E)[0].0;
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: footer at byte {f}: summary_offset_start = {first}, the first \
             summary offset record is at byte {moved}"
        )
    );
}

/// docs/recording-format.md's two example messages, on the golden wall recording (4000 ticks;
/// chunks: the description, then ticks 0–999, …, 3000–3999): a chunk's CRC field changed, and
/// the file cut inside its last chunk.
#[test]
fn the_documented_corrupt_and_truncated_messages() {
    let b = std::fs::read(root().join("recordings/wall.mcap")).unwrap();
    let chunks = of(&b, 0x06);
    assert_eq!(chunks.len(), 5);
    let (at, _) = chunks[2];
    assert_eq!(at, 111_404);
    let size = u64::from_le_bytes(b[at + 25..at + 33].try_into().unwrap());
    assert_eq!(size, 459_217);
    let crc = u32::from_le_bytes(b[at + 33..at + 37].try_into().unwrap());
    let mut m = b.clone();
    m[at + 33..at + 37].copy_from_slice(&(crc ^ 1).to_le_bytes());
    assert_eq!(
        err(&m),
        format!(
            "corrupt recording: chunk at byte 111404: the CRC-32 of its 459217 decompressed \
             bytes is 0x{crc:08x}, the chunk says 0x{:08x} (the chunk was changed or damaged)",
            crc ^ 1
        )
    );
    // cut 1000 bytes into the last chunk (ticks 3000–3999)
    let (last, _) = chunks[4];
    let e = err(&b[..last + 1000]);
    assert!(
        e.starts_with("truncated recording: ")
            && e.ends_with("; 3000 complete ticks are readable (salvage them with --salvage)"),
        "{e}"
    );
    let part = read_recording(&b[..last + 1000], true).unwrap();
    let ticks = part
        .messages
        .iter()
        .filter(|m| matches!(m.channel, recording::Channel::Timing))
        .count();
    assert_eq!(ticks, 3000);
}
