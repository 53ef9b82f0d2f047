//! Two uses of a whole recording: its switch schedule (for the runner, on replay) and a rewrite
//! as a new complete file (the salvaged part of a truncated recording).

use crate::channels::messages::{Channel, SwitchMsg};
use crate::encode::{OutMsg, TickMessages};
use crate::reader::{Recording, RecordingError};
use crate::writer::{self, Recorder, RecorderSetup, WriteSummary};
use haptic_types::Switch;

/// The switches of a recording as a schedule (tick, switch) for the runner, from its
/// `/scene/switch` messages (log time `start + tick · period_ns`).
pub fn switch_schedule(
    rec: &Recording,
    period_ns: u64,
) -> Result<Vec<(u64, Switch)>, RecordingError> {
    let start = rec.description.start_time_ns;
    let mut out = Vec::new();
    for m in rec.messages.iter().filter(|m| m.channel == Channel::Switch) {
        let bad = |detail: String| RecordingError::BadMessage {
            topic: Channel::Switch.topic().to_string(),
            log_time_ns: m.log_time_ns,
            detail,
        };
        let d = SwitchMsg::decode(&m.data).map_err(|e| bad(e.to_string()))?;
        let at = start.saturating_add(d.tick.saturating_mul(period_ns));
        if m.log_time_ns != at {
            return Err(bad(format!(
                "tick {} belongs at {at} ns, found at {} ns",
                d.tick, m.log_time_ns
            )));
        }
        out.extend(d.switches().into_iter().map(|s| (d.tick, s)));
    }
    Ok(out)
}

/// Writes `rec` (e.g. the salvaged part of a truncated recording) as a new, complete MCAP
/// file; the metadata records are copied. Returns what the writer did.
pub fn rewrite(
    rec: &Recording,
    path: &std::path::Path,
) -> Result<WriteSummary, writer::RecordError> {
    let mut w = Recorder::create(
        path,
        RecorderSetup {
            description: rec.description.clone(),
            flush_every_ns: 1_000_000_000,
        },
    )?;
    let mut cur: Option<TickMessages> = None;
    for m in rec
        .messages
        .iter()
        .filter(|m| m.channel != Channel::Description)
    {
        if cur.as_ref().is_some_and(|c| c.log_time_ns != m.log_time_ns) {
            if let Some(c) = cur.take() {
                w.write(c)?;
            }
        }
        let c = cur.get_or_insert_with(|| TickMessages {
            tick: 0,
            log_time_ns: m.log_time_ns,
            msgs: Vec::new(),
        });
        c.msgs.push(OutMsg {
            channel: m.channel,
            data: m.data.clone(),
        });
    }
    if let Some(c) = cur {
        w.write(c)?;
    }
    // The copy holds the ticks read (a salvage holds fewer than the session ran): its `session`
    // record says so, as the reader checks.
    let ticks = rec
        .messages
        .iter()
        .filter(|m| m.channel == Channel::DeviceInput)
        .count();
    for (name, md) in &rec.metadata {
        let mut md = md.clone();
        if name == "session" {
            if let Some(t) = md.insert("ticks".into(), ticks.to_string()) {
                if t != ticks.to_string() {
                    md.insert("ticks_in_the_original".into(), t);
                }
            }
        }
        w.metadata(name, md)?;
    }
    if !rec.metadata.contains_key("session") {
        // A salvaged file ends before the session's closing record: say how much it holds.
        let mut md = std::collections::BTreeMap::new();
        md.insert("ticks".to_string(), ticks.to_string());
        md.insert("salvaged".to_string(), "true".to_string());
        w.metadata("session", md)?;
    }
    w.finish()
}
