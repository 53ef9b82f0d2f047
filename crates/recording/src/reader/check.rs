//! The summary against the records of the data section, one named check per part: the
//! statistics, the schema and channel definitions, the chunk indexes (and the message indexes
//! after each chunk), the metadata indexes, the attachment indexes and the summary offsets.
//! Each error names the summary record, its byte offset and the field that differs.

use super::summary::Summary;
use super::walk::{ChunkInfo, Walk};
use super::{RecordingError, corrupt};
use crate::parse::{ChunkIndexRec, Stats, op_name};
use std::collections::BTreeMap;

/// The summary against the records of the data section (the footer at `footer_at`).
pub(super) fn check_summary(w: &Walk, s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    let Some((at, stats)) = &s.stats else {
        return Err(corrupt(
            footer_at,
            "footer",
            "the summary has no statistics record",
        ));
    };
    statistics(w, *at, stats)?;
    definitions(w, s, footer_at)?;
    chunk_indexes(w, s, footer_at)?;
    metadata_indexes(w, s, footer_at)?;
    mismatch(
        footer_at,
        "summary",
        "attachment indexes",
        s.attachment_indexes,
        w.attachments,
        "attachments in the data section:",
    )?;
    summary_offsets(s, footer_at)
}

/// `Ok` when the summary's `field` equals the data section's, else
/// `"{field} = {summary}, {what} {actual}"` at the record `record` at byte `at`.
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

/// The statistics record (at byte `at`): counts, time range, messages per channel.
fn statistics(w: &Walk, at: usize, st: &Stats) -> Result<(), RecordingError> {
    let (rec, held) = ("statistics", "the data section holds");
    let m =
        |field: &str, summary: u64, actual: u64| mismatch(at, rec, field, summary, actual, held);
    m("message_count", st.message_count, w.message_count)?;
    m(
        "schema_count",
        st.schema_count.into(),
        w.schemas.len() as u64,
    )?;
    m(
        "channel_count",
        st.channel_count.into(),
        w.channel_recs.len() as u64,
    )?;
    m(
        "attachment_count",
        st.attachment_count.into(),
        w.attachments,
    )?;
    m(
        "metadata_count",
        st.metadata_count.into(),
        w.metadata_recs.len() as u64,
    )?;
    m("chunk_count", st.chunk_count.into(), w.chunks.len() as u64)?;
    let (a, b) = w.time_range.unwrap_or((0, 0));
    mismatch(
        at,
        rec,
        "message_start_time",
        st.start_time,
        a,
        "the earliest message is at",
    )?;
    mismatch(
        at,
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
        at,
        rec,
        "channel_message_counts",
        map_text(&counts),
        map_text(&w.per_channel),
        held,
    )
}

/// Every schema and channel of the data section, the same in the summary, and no other.
fn definitions(w: &Walk, s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    in_summary(&w.schemas, &s.schemas, footer_at, "schema", |x| &x.name)?;
    in_summary(&w.channel_recs, &s.channels, footer_at, "channel", |x| {
        &x.topic
    })?;
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
    Ok(())
}

/// Every `kind` record of the data section (`name` says what it is called), the same in the
/// summary.
fn in_summary<T: PartialEq>(
    data: &BTreeMap<u16, T>,
    summary: &BTreeMap<u16, T>,
    footer_at: usize,
    kind: &str,
    name: impl Fn(&T) -> &str,
) -> Result<(), RecordingError> {
    match data.iter().find(|(id, x)| summary.get(id) != Some(x)) {
        None => Ok(()),
        Some((id, x)) => Err(corrupt(
            footer_at,
            "summary",
            format!(
                "{kind} {id} (`{}`) is missing from the summary or differs",
                name(x)
            ),
        )),
    }
}

/// The summary's `kind` indexes (each at its byte) number the `held` records of the data
/// section (`records` names them in the error); the error is at the first index, or at the
/// footer when there is none.
fn one_index_each<T>(
    indexes: &[(usize, T)],
    held: usize,
    footer_at: usize,
    kind: &str,
    records: &str,
) -> Result<(), RecordingError> {
    if indexes.len() == held {
        return Ok(());
    }
    let at = indexes.first().map_or(footer_at, |c| c.0);
    Err(corrupt(
        at,
        format!("{kind} indexes"),
        format!(
            "the summary indexes {} {records}, the data section holds {held}",
            indexes.len()
        ),
    ))
}

/// One chunk index per chunk, in order, each equal to its chunk.
fn chunk_indexes(w: &Walk, s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    one_index_each(
        &s.chunk_indexes,
        w.chunks.len(),
        footer_at,
        "chunk",
        "chunks",
    )?;
    for (i, ((at, ci), c)) in s.chunk_indexes.iter().zip(&w.chunks).enumerate() {
        chunk_index(i, *at, ci, c)?;
    }
    Ok(())
}

/// Chunk index `i` (at byte `at`) against chunk `c`, and the message indexes after the chunk.
fn chunk_index(
    i: usize,
    at: usize,
    ci: &ChunkIndexRec,
    c: &ChunkInfo,
) -> Result<(), RecordingError> {
    let rec = format!("chunk index {i}");
    let rec = rec.as_str();
    let what = format!("the chunk at byte {} has", c.at);
    let what = what.as_str();
    let starts = format!("chunk {i} starts at byte");
    let m =
        |field: &str, summary: u64, actual: u64| mismatch(at, rec, field, summary, actual, what);
    mismatch(
        at,
        rec,
        "chunk_start_offset",
        ci.chunk_start_offset,
        c.at as u64,
        &starts,
    )?;
    m("chunk_length", ci.chunk_length, c.length)?;
    m("message_start_time", ci.start_time, c.start_time)?;
    m("message_end_time", ci.end_time, c.end_time)?;
    mismatch(
        at,
        rec,
        "compression",
        ci.compression.as_str(),
        c.compression.as_str(),
        what,
    )?;
    m("compressed_size", ci.compressed_size, c.compressed_size)?;
    m(
        "uncompressed_size",
        ci.uncompressed_size,
        c.uncompressed_size,
    )?;
    mismatch(
        at,
        rec,
        "message_index_offsets",
        map_text(&ci.message_index_offsets),
        map_text(&c.index_offsets),
        what,
    )?;
    m("message_index_length", ci.message_index_length, c.index_len)?;
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
    Ok(())
}

/// One metadata index per metadata record, in order, each naming its record's place.
fn metadata_indexes(w: &Walk, s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    one_index_each(
        &s.metadata_indexes,
        w.metadata_recs.len(),
        footer_at,
        "metadata",
        "metadata records",
    )?;
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
    Ok(())
}

/// The summary offset records list exactly the groups of records the summary holds.
fn summary_offsets(s: &Summary, footer_at: usize) -> Result<(), RecordingError> {
    let mut offsets: Vec<(u8, u64, u64)> = s.offsets.iter().map(|o| o.1).collect();
    offsets.sort_unstable();
    let mut groups = s.groups.clone();
    groups.sort_unstable();
    if offsets == groups {
        return Ok(());
    }
    let at = s.offsets.first().map_or(footer_at, |o| o.0);
    let text = |v: &[(u8, u64, u64)]| {
        let p: Vec<String> = v
            .iter()
            .map(|(o, a, l)| format!("{} at byte {a}, {l} bytes", op_name(*o)))
            .collect();
        p.join("; ")
    };
    Err(corrupt(
        at,
        "summary offsets",
        format!(
            "they list [{}], the summary holds [{}]",
            text(&offsets),
            text(&groups)
        ),
    ))
}
