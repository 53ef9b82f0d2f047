//! `nanohaptics replay` and `info`: a recording re-simulated and compared bit for bit, and
//! what a recording holds.

use crate::status;
use haptic_loop::replay::verify;
use haptic_loop::session::SessionArrays;
use recording::channels::messages::Channel;
use recording::read_recording_file;
use std::collections::BTreeMap;
use std::path::Path;

/// `replay FILE --serve`: re-simulates the recording into the replay page's frames, serves
/// them on 127.0.0.1:`port` until Ctrl-C.
pub(crate) fn serve(rec: &Path, port: u16) -> Result<u8, String> {
    eprintln!(
        "{}: re-simulating the session for the page ...",
        rec.display()
    );
    let t = std::time::Instant::now();
    let book =
        play::replay::ReplayBook::from_file(rec).map_err(|e| format!("{}: {e}", rec.display()))?;
    let (ticks, frames) = (book.ticks, book.frames.len());
    let stop = crate::run_cmd::interrupt_flag()?;
    let mut server =
        play::replay::ReplayServer::start(book, rec.to_path_buf(), port).map_err(|e| {
            format!(
                "cannot serve the page on 127.0.0.1:{port}: {e} (choose another with --port, or \
                 --port 0 for any free port)"
            )
        })?;
    println!(
        "{}: {ticks} ticks in {frames} frames ({:.1} s); open {} in a browser (Ctrl-C ends)",
        rec.display(),
        t.elapsed().as_secs_f64(),
        server.url()
    );
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    server.stop();
    Ok(status::SUCCESS)
}

pub(crate) fn replay(rec: &Path, strict: bool, salvage: bool, json: bool) -> Result<u8, String> {
    let r = read_recording_file(rec, salvage).map_err(|e| format!("{}: {e}", rec.display()))?;
    let report = verify(&r).map_err(|e| format!("{}: replay failed: {e}", rec.display()))?;
    if json {
        println!(
            "{}",
            serde_json::json!({"recording": rec.display().to_string(), "truncated": r.truncated,
                "integrity": r.integrity, "report": report})
        );
    } else {
        match &report.divergence {
            None => {
                println!(
                    "{}: {} ticks replayed, {} output messages identical bit for bit{}",
                    rec.display(),
                    report.ticks,
                    report.messages_compared,
                    if r.truncated.is_some() {
                        " (salvaged part of a truncated file)"
                    } else {
                        ""
                    }
                );
                let i = &r.integrity;
                let mut checked = vec![format!("{} chunk CRCs", i.chunk_crcs)];
                if i.data_crc {
                    checked.push("the data-section CRC".into());
                }
                if i.summary {
                    checked.push("the summary CRC and the summary against the records".into());
                }
                checked.push(format!(
                    "ticks 0–{} in sequence{}",
                    i.ticks.saturating_sub(1),
                    if i.ticks_match_metadata {
                        " and as many as the session record says"
                    } else {
                        ""
                    }
                ));
                println!("  checked: {}", checked.join(", "));
            }
            Some(d) => println!(
                "{}: DIVERGED at tick {} on {}: {}",
                rec.display(),
                d.tick,
                d.channel,
                d.detail
            ),
        }
    }
    Ok(if report.ok() || !strict {
        status::SUCCESS
    } else {
        status::DIVERGED
    })
}

pub(crate) fn info(rec: &Path, salvage: bool, json: bool) -> Result<u8, String> {
    let r = read_recording_file(rec, salvage).map_err(|e| format!("{}: {e}", rec.display()))?;
    let mut counts: BTreeMap<&str, u64> = BTreeMap::new();
    for m in &r.messages {
        *counts.entry(m.channel.topic()).or_default() += 1;
    }
    let a = SessionArrays::from_recording(&r).map_err(|e| e.to_string())?;
    let d = &r.description;
    let ticks = a.tick.len() as u64;
    let duration = ticks as f64 / f64::from(d.rate_hz);
    let pct = haptic_engine::timing::Percentiles::of(&a.compute_ns);
    let session = r.metadata.get("session").cloned().unwrap_or_default();
    let channels: Vec<_> = r
        .channels
        .iter()
        .map(|(t, s, e)| {
            serde_json::json!({"topic": t, "schema": s, "encoding": e,
                "messages": counts.get(t.as_str()).copied().unwrap_or(0),
                "verified_by_replay": Channel::from_topic(t).map(|c| c.verified())})
        })
        .collect();
    if json {
        println!(
            "{}",
            serde_json::json!({
                "recording": rec.display().to_string(), "bytes": r.bytes,
                "scene": d.scene_name, "kind": d.scene_kind, "device": d.device_model,
                "script": d.script_name, "operator": d.operator, "mode": d.mode,
                "rate_hz": d.rate_hz, "ticks": ticks, "duration_s": duration,
                "events": a.events.len(), "truncated": r.truncated,
                "channels": channels, "tick_compute": pct, "session_metadata": session,
            })
        );
        return Ok(status::SUCCESS);
    }
    println!("{} ({} bytes)", rec.display(), r.bytes);
    println!(
        "  scene: {} [{}], device {}, script \"{}\", operator {}, {} mode",
        d.scene_name, d.scene_kind, d.device_model, d.script_name, d.operator, d.mode
    );
    println!(
        "  {ticks} ticks at {} Hz = {duration:.3} s, {} events",
        d.rate_hz,
        a.events.len()
    );
    if let Some(t) = &r.truncated {
        println!("  TRUNCATED: {t}");
    }
    println!(
        "  tick work: p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs",
        pct.p50_ns as f64 / 1e3,
        pct.p99_ns as f64 / 1e3,
        pct.p999_ns as f64 / 1e3,
        pct.max_ns as f64 / 1e3
    );
    if let (Some(j), Some(m)) = (
        session.get("jitter_p99_ns"),
        session.get("missed_deadlines"),
    ) {
        println!("  jitter p99 {j} ns, missed deadlines {m}");
    }
    // Recordings since issue 33 say what scheduling the tick thread had and how late it woke.
    if let Some(policy) = session.get("rt_policy") {
        let get = |k: &str| session.get(k).map_or("?", String::as_str);
        let ns = |k: &str| {
            session
                .get(k)
                .and_then(|v| v.parse::<f64>().ok())
                .map_or("?".to_string(), |v| format!("{:.1}", v / 1e3))
        };
        println!(
            "  real time: {policy} (priority {}, memory locked {}, CPU {}, refused: {}); wake-up \
             p50 {} µs, p99 {} µs, p99.9 {} µs, max {} µs",
            get("rt_priority"),
            get("rt_memory_locked"),
            get("rt_cpu"),
            get("rt_refused"),
            ns("wakeup_p50_ns"),
            ns("wakeup_p99_ns"),
            ns("wakeup_p999_ns"),
            ns("wakeup_max_ns")
        );
    }
    println!("  channels:");
    for c in &channels {
        println!(
            "    {:<20} {:<42} {:<9} {:>7} messages",
            c["topic"].as_str().unwrap_or(""),
            c["schema"].as_str().unwrap_or(""),
            c["encoding"].as_str().unwrap_or(""),
            c["messages"]
        );
    }
    Ok(status::SUCCESS)
}
