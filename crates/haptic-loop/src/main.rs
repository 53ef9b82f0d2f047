//! `nanohaptics`: run scenes headless, record them to MCAP, replay and verify recordings.
//!
//! ```text
//! nanohaptics run SCENE [--script S] [--operator rigid|hand|hand:key=value,...] [--device M]
//!                 [--seconds T] [--out REC.mcap] [--realtime] [--json]
//! nanohaptics replay REC.mcap [--verify] [--salvage] [--json]
//! nanohaptics info REC.mcap [--salvage] [--json]
//! nanohaptics demo [--scenes DIR] [--out DIR] [--json]
//! nanohaptics render REC.mcap --out DIR [--every N] [--width W] [--gif FILE] [--view V]
//! nanohaptics render SCENE.toml --out FILE.png [--width W] [--view V]
//! ```
//! Exit status: 0 success, 1 error (bad input, unreadable file), 2 replay diverged.

mod render_cmd;

use clap::{Parser, Subcommand};
use haptic_loop::device::{DeviceModel, OperatorParams};
use haptic_loop::record::messages::Channel;
use haptic_loop::record::read_recording_file;
use haptic_loop::replay::verify;
use haptic_loop::session::{
    OperatorChoice, SceneSource, SessionArrays, SessionError, SessionOptions, SessionReport,
    run_session,
};
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "nanohaptics",
    version,
    about = "Deterministic haptic sessions: run, record, replay, verify"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a scene with a script (batch by default) and optionally record it.
    Run(RunArgs),
    /// Draw a recording (PNG frames, animated GIF) or a scene's initial state (PNG).
    Render(render_cmd::RenderArgs),
    /// Recompute a recording from its inputs and compare every output bit for bit.
    Replay {
        /// Recording (MCAP).
        rec: PathBuf,
        /// Exit with status 2 on the first divergence.
        #[arg(long)]
        verify: bool,
        /// Accept a truncated recording and replay its complete part.
        #[arg(long)]
        salvage: bool,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Channels, duration and tick statistics of a recording.
    Info {
        /// Recording (MCAP).
        rec: PathBuf,
        /// Accept a truncated recording.
        #[arg(long)]
        salvage: bool,
        /// Print as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run every scene with its default script, record, verify, and summarise.
    Demo {
        /// Folder of scene files.
        #[arg(long, default_value = "scenes")]
        scenes: PathBuf,
        /// Folder for the recordings.
        #[arg(long, default_value = "target/demo")]
        out: PathBuf,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
}

#[derive(clap::Args)]
struct RunArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Script file (TOML); default: the scene's default script.
    #[arg(long)]
    script: Option<PathBuf>,
    /// `rigid` (stylus follows the script exactly), `hand` (simulated hand with the script's
    /// parameters) or `hand:mass_kg=0.3,stiffness_n_per_m=300,damping_n_s_per_m=12`.
    #[arg(long, default_value = "hand")]
    operator: String,
    /// Device model overriding the scene's: falcon or touch.
    #[arg(long)]
    device: Option<String>,
    /// Session length, s (default: the script's duration).
    #[arg(long)]
    seconds: Option<f64>,
    /// Record to this MCAP file.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Pace ticks against the wall clock (zero force on a missed deadline).
    #[arg(long)]
    realtime: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

fn parse_operator(s: &str) -> Result<OperatorChoice, String> {
    match s {
        "rigid" => Ok(OperatorChoice::Rigid),
        "hand" => Ok(OperatorChoice::ScriptHand),
        _ => match s.strip_prefix("hand:") {
            Some(kv) => OperatorParams::default()
                .with_overrides(kv)
                .map(OperatorChoice::Hand)
                .map_err(|e| e.to_string()),
            None => Err(format!(
                "--operator `{s}` is not one of: rigid, hand, hand:key=value,..."
            )),
        },
    }
}

fn summary_json(r: &SessionReport) -> serde_json::Value {
    let a = &r.arrays;
    let peak = a
        .device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max);
    serde_json::json!({
        "scene": r.description.scene_name,
        "kind": r.description.scene_kind,
        "device": r.description.device_model,
        "script": r.description.script_name,
        "operator": r.description.operator,
        "mode": r.description.mode,
        "ticks": r.stats.ticks,
        "duration_s": r.stats.ticks as f64 / f64::from(r.description.rate_hz),
        "peak_device_force_n": peak,
        "clamped_ticks": a.status.iter().filter(|s| **s & 1 != 0).count(),
        "events": a.events.len(),
        "tick_stats": r.stats,
        "written": r.written,
    })
}

fn print_summary(r: &SessionReport) {
    let j = summary_json(r);
    let s = &r.stats;
    println!(
        "{} ({}, {} device, {} operator)",
        r.description.scene_name,
        r.description.mode,
        r.description.device_model,
        r.description.operator
    );
    println!(
        "  {} ticks ({:.3} s), peak force {:.3} N, {} clamped ticks, {} events",
        s.ticks,
        j["duration_s"].as_f64().unwrap_or(0.0),
        j["peak_device_force_n"].as_f64().unwrap_or(0.0),
        j["clamped_ticks"],
        j["events"]
    );
    println!(
        "  tick work p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; jitter p99 {:.1} µs; {} missed deadlines",
        s.compute.p50_ns as f64 / 1e3,
        s.compute.p99_ns as f64 / 1e3,
        s.compute.max_ns as f64 / 1e3,
        s.jitter.p99_ns as f64 / 1e3,
        s.missed
    );
    if let Some(w) = &r.written {
        println!(
            "  recorded {} messages, {} bytes ({:.0} bytes per minute)",
            w.messages,
            w.bytes,
            w.bytes as f64 * 60.0 / (s.ticks as f64 / f64::from(r.description.rate_hz))
        );
    }
}

fn progress_bar(len: u64, label: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    let style = ProgressStyle::with_template("{prefix:>16} [{bar:40}] {pos}/{len} ticks {eta}")
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_prefix(label.to_string());
    pb
}

fn cmd_run(args: RunArgs) -> Result<ExitCode, String> {
    let RunArgs {
        scene,
        script,
        operator,
        device,
        seconds,
        out,
        realtime,
        json,
    } = args;
    let mut opts = SessionOptions::new(SceneSource::from_path(&scene).map_err(|e| e.to_string())?);
    opts.operator = parse_operator(&operator)?;
    opts.device = device
        .as_deref()
        .map(DeviceModel::from_name)
        .transpose()
        .map_err(|e| e.to_string())?;
    opts.script = script
        .as_deref()
        .map(|p| {
            std::fs::read_to_string(p).map_err(|e| format!("cannot read {}: {e}", p.display()))
        })
        .transpose()?;
    opts.seconds = seconds;
    opts.realtime = realtime;
    opts.out = out;
    let pb = (!json).then(|| progress_bar(0, "run"));
    let report = run_session(&opts, &mut |done, total| {
        if let Some(pb) = &pb {
            pb.set_length(total);
            pb.set_position(done);
        }
    })
    .map_err(|e| e.to_string())?;
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    if json {
        println!("{}", summary_json(&report));
    } else {
        print_summary(&report);
    }
    Ok(ExitCode::SUCCESS)
}

fn cmd_replay(rec: &Path, strict: bool, salvage: bool, json: bool) -> Result<ExitCode, String> {
    let r = read_recording_file(rec, salvage).map_err(|e| format!("{}: {e}", rec.display()))?;
    let report = verify(&r).map_err(|e| format!("{}: replay failed: {e}", rec.display()))?;
    if json {
        println!(
            "{}",
            serde_json::json!({"recording": rec.display().to_string(), "truncated": r.truncated, "report": report})
        );
    } else {
        match &report.divergence {
            None => println!(
                "{}: {} ticks replayed, {} output messages identical bit for bit{}",
                rec.display(),
                report.ticks,
                report.messages_compared,
                if r.truncated.is_some() {
                    " (salvaged part of a truncated file)"
                } else {
                    ""
                }
            ),
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
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    })
}

fn cmd_info(rec: &Path, salvage: bool, json: bool) -> Result<ExitCode, String> {
    let r = read_recording_file(rec, salvage).map_err(|e| format!("{}: {e}", rec.display()))?;
    let mut counts: BTreeMap<&str, u64> = BTreeMap::new();
    for m in &r.messages {
        *counts.entry(m.channel.topic()).or_default() += 1;
    }
    let a = SessionArrays::from_recording(&r).map_err(|e| e.to_string())?;
    let d = &r.description;
    let ticks = a.tick.len() as u64;
    let duration = ticks as f64 / f64::from(d.rate_hz);
    let pct = haptic_loop::pacing::Percentiles::of(&a.compute_ns);
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
        return Ok(ExitCode::SUCCESS);
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
    Ok(ExitCode::SUCCESS)
}

fn cmd_demo(scenes: &Path, out: &Path, json: bool) -> Result<ExitCode, String> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes)
        .map_err(|e| format!("cannot list {}: {e}", scenes.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|x| x == "toml")
                && !p.to_string_lossy().ends_with(".script.toml")
        })
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(format!("no scene files (*.toml) in {}", scenes.display()));
    }
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut rows = Vec::new();
    let mut all_ok = true;
    for f in &files {
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let rec = out.join(format!("{stem}.mcap"));
        let mut opts = SessionOptions::new(
            SceneSource::from_path(f).map_err(|e: SessionError| e.to_string())?,
        );
        opts.out = Some(rec.clone());
        let pb = (!json).then(|| progress_bar(0, &stem));
        let report = run_session(&opts, &mut |done, total| {
            if let Some(pb) = &pb {
                pb.set_length(total);
                pb.set_position(done);
            }
        })
        .map_err(|e| format!("{}: {e}", f.display()))?;
        if let Some(pb) = pb {
            pb.finish_and_clear();
        }
        let r = read_recording_file(&rec, false).map_err(|e| format!("{}: {e}", rec.display()))?;
        let v = verify(&r).map_err(|e| e.to_string())?;
        all_ok &= v.ok();
        let png = out.join(format!("{stem}.png"));
        render_cmd::final_picture(&rec, &png, 800)
            .map_err(|e| format!("{}: {e}", png.display()))?;
        let mut j = summary_json(&report);
        j["recording"] = serde_json::json!(rec.display().to_string());
        j["replay_verified"] = serde_json::json!(v.ok());
        j["picture"] = serde_json::json!(png.display().to_string());
        j["divergence"] = serde_json::json!(v.divergence);
        if !json {
            print_summary(&report);
            println!(
                "  -> {} ; replay {}",
                rec.display(),
                if v.ok() { "bit-exact" } else { "DIVERGED" }
            );
            println!("  -> {}", png.display());
        }
        rows.push(j);
    }
    if json {
        println!(
            "{}",
            serde_json::json!({"scenes": rows, "all_verified": all_ok})
        );
    } else {
        println!(
            "{} scenes run, recorded and replay-verified: {}",
            rows.len(),
            if all_ok {
                "all bit-exact"
            } else {
                "DIVERGENCE"
            }
        );
    }
    Ok(if all_ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(2)
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let res = match cli.cmd {
        Cmd::Run(args) => cmd_run(args),
        Cmd::Render(args) => render_cmd::cmd(&args),
        Cmd::Replay {
            rec,
            verify,
            salvage,
            json,
        } => cmd_replay(&rec, verify, salvage, json),
        Cmd::Info { rec, salvage, json } => cmd_info(&rec, salvage, json),
        Cmd::Demo { scenes, out, json } => cmd_demo(&scenes, &out, json),
    };
    match res {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
