//! `nanohaptics`: run scenes headless, record them to MCAP, replay and verify recordings.
//!
//! ```text
//! nanohaptics run SCENE [--script S] [--operator rigid|hand|hand:key=value,...]
//!                 [--device falcon|touch|udp:HOST:PORT] [--seconds T] [--out REC.mcap]
//!                 [--realtime] [--live ws:HOST:PORT] [--json]
//! nanohaptics fake-device udp:HOST:PORT [--script S] [--hand|--hand key=value,...|--rigid]
//!                 [--model M] [--loss P] [--jitter-ms J] [--latency-ms L] [--seed N]
//!                 [--seconds T] [--outage START:SECONDS] [--json]
//! nanohaptics replay REC.mcap [--verify] [--salvage] [--json]
//! nanohaptics info REC.mcap [--salvage] [--json]
//! nanohaptics demo [--scenes DIR] [--out DIR] [--json]
//! nanohaptics render REC.mcap --out DIR [--every N] [--width W] [--gif FILE] [--view V]
//! nanohaptics render SCENE.toml --out FILE.png [--width W] [--view V]
//! ```
//! Exit status: 0 success, 1 error (bad input, unreadable file), 2 replay diverged.

mod lesson_cmd;
mod play_cmd;
mod render_cmd;

use clap::{Parser, Subcommand};
use haptic_devices::DeviceModel;
use haptic_devices::bridge::BridgeConfig;
use haptic_loop::live::LiveConfig;
use haptic_loop::replay::verify;
use haptic_loop::session::{
    OperatorChoice, SceneSource, SessionArrays, SessionError, SessionOptions, SessionReport,
    run_session, run_session_until,
};
use haptic_loop::totals::Totals;
use indicatif::{ProgressBar, ProgressStyle};
use recording::channels::messages::Channel;
use recording::read_recording_file;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

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
    /// List the built-in scenes, or `scenes export DIR` to write editable copies.
    Scenes {
        /// `export` to write the scenes and their scripts.
        action: Option<String>,
        /// Folder for `export`.
        dir: Option<PathBuf>,
    },
    /// A stand-in haptic device process: plays a script over the UDP bridge to `nanohaptics run
    /// --device udp:HOST:PORT`, with injectable loss, jitter, latency and an outage.
    FakeDevice(FakeArgs),
    /// The macro-vs-nano lesson: run both house tasks and the lesson's experiments, write a
    /// Markdown report with figures (`--out DIR`).
    Lesson(lesson_cmd::LessonArgs),
    /// Play the teaching game in a browser: serves one page on loopback (pointer, keyboard or
    /// gamepad as the hand, live sound, the menu, the score) and records the session.
    Play(play_cmd::PlayArgs),
    /// Run every scene with its default script, record, verify, and summarise.
    Demo {
        /// Folder of scene files (default: `./scenes` if it exists, else the built-in scenes,
        /// which `scenes export DIR` writes out for editing).
        #[arg(long)]
        scenes: Option<PathBuf>,
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
    /// Device: a model overriding the scene's (falcon, touch), or a device in another process
    /// over the UDP bridge, `udp:HOST:PORT` (listen there; waits for its hello; always real
    /// time; see docs/device-bridge.md).
    #[arg(long)]
    device: Option<String>,
    /// Serve a live Foxglove view at `ws:HOST:PORT` while the session runs (open
    /// ws://HOST:PORT in Foxglove; layout in docs/foxglove/).
    #[arg(long)]
    live: Option<String>,
    /// Rate of the live 3D scene, Hz (default 50).
    #[arg(long, default_value_t = 50)]
    live_hz: u32,
    /// How long to wait for a bridged device's hello, s.
    #[arg(long, default_value_t = 120.0)]
    wait_s: f64,
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

#[derive(clap::Args)]
struct FakeArgs {
    /// The simulator's bridge address, `udp:HOST:PORT`.
    target: String,
    /// Script file (TOML) the stylus plays (default: the built-in wall-press script).
    #[arg(long)]
    script: Option<PathBuf>,
    /// `hand` (default: a simulated hand pushed by the force), `rigid`, or
    /// `hand:mass_kg=0.3,stiffness_n_per_m=300,...` (also spelled `--hand`).
    #[arg(long, alias = "hand", default_value = "hand")]
    operator: String,
    /// Device model: falcon, touch, delta3 or inverse3 (delta3 and inverse3 are always
    /// modelled devices; see --grip).
    #[arg(long, default_value = "falcon")]
    model: String,
    /// Play a modelled device (moving mass, encoder counts, force held over each period) held
    /// by a hand: `loose` (300 N/m, 2 N·s/m), `firm` (1000 N/m, 8 N·s/m) or
    /// `k=N/m,b=N·s/m[,m=kg]` (docs/devices.md). Replaces --operator.
    #[arg(long)]
    grip: Option<String>,
    /// With --grip: an ideal device (no encoder counts, no force resolution).
    #[arg(long)]
    ideal: bool,
    /// Probability that a sample is lost, 0–1.
    #[arg(long, default_value_t = 0.0)]
    loss: f64,
    /// Extra delay of each sample, uniform in 0–J ms (samples may overtake each other).
    #[arg(long, default_value_t = 0.0)]
    jitter_ms: f64,
    /// Fixed delay of each sample, ms.
    #[arg(long, default_value_t = 0.0)]
    latency_ms: f64,
    /// Seed of the loss and jitter draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// How long to play, s (default: the script's duration).
    #[arg(long)]
    seconds: Option<f64>,
    /// Go silent from START s for SECONDS s, then come back (`--outage 1.0:0.05`).
    #[arg(long)]
    outage: Option<String>,
    /// How long to wait for the simulator's welcome, s.
    #[arg(long, default_value_t = 30.0)]
    wait_s: f64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The default script of `fake-device`: press the wall scene's surface, as its own script does.
const FAKE_SCRIPT: &str = include_str!("../../../scenes/wall.script.toml");

fn cmd_fake(a: FakeArgs) -> Result<ExitCode, String> {
    use haptic_devices::bridge::fake::{FakeConfig, run_fake};
    let target = a
        .target
        .strip_prefix("udp:")
        .and_then(|t| t.parse().ok())
        .ok_or_else(|| {
            format!(
                "fake-device `{}`: expected udp:HOST:PORT, e.g. udp:127.0.0.1:9870",
                a.target
            )
        })?;
    let mech = haptic_devices::Mechanics::preset(&a.model).map_err(|e| format!("--model: {e}"))?;
    // Scripts name the buttons of the device they were written for: a Falcon's, or a Touch's.
    let model = DeviceModel::from_name(&a.model).unwrap_or(DeviceModel::Falcon);
    let grip = match (&a.grip, DeviceModel::from_name(&a.model).is_ok()) {
        (Some(g), _) => Some(haptic_devices::Grip::parse(g).map_err(|e| format!("--grip: {e}"))?),
        (None, false) => Some(haptic_devices::Grip::LOOSE),
        (None, true) => None,
    };
    if a.ideal && grip.is_none() {
        return Err("--ideal needs --grip (it removes a modelled device's encoder counts)".into());
    }
    let physical = grip.map(|g| {
        let m = if a.ideal {
            mech.without_quantization()
        } else {
            mech
        };
        (m, g)
    });
    let (text, origin) = match &a.script {
        Some(p) => (
            haptic_loop::session::read_toml_text(p).map_err(|e| format!("--script: {e}"))?,
            p.display().to_string(),
        ),
        None => (
            FAKE_SCRIPT.to_string(),
            "built-in fake-device script".into(),
        ),
    };
    let script = haptic_devices::Script::from_toml(&text, model.specs()).map_err(|e| {
        let at = haptic_loop::session::Location {
            file: origin,
            at: e.position(&text),
        };
        format!("--script: {at}: {e}")
    })?;
    let hand = match parse_operator(&a.operator)? {
        OperatorChoice::Rigid => None,
        OperatorChoice::Hand(p) => Some(p),
        OperatorChoice::ScriptHand => Some(script.operator.unwrap_or_default()),
    };
    let check = |flag: &str, v: f64, lo: f64, hi: f64| {
        if v.is_finite() && (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("--{flag} = {v} is out of range: allowed {lo}–{hi}"))
        }
    };
    let loss = check("loss", a.loss, 0.0, 1.0)?;
    let jitter = check("jitter-ms", a.jitter_ms, 0.0, 1000.0)?;
    let latency = check("latency-ms", a.latency_ms, 0.0, 1000.0)?;
    let outage = a
        .outage
        .as_deref()
        .map(|o| {
            let bad = || format!("--outage `{o}`: expected START:SECONDS, e.g. 1.0:0.05");
            let (s, d) = o.split_once(':').ok_or_else(bad)?;
            let s: f64 = s.parse().map_err(|_| bad())?;
            let d: f64 = d.parse().map_err(|_| bad())?;
            Ok::<_, String>((
                check("outage start", s, 0.0, 86400.0)?,
                check("outage seconds", d, 0.0, 86400.0)?,
            ))
        })
        .transpose()?;
    if let Some(s) = a.seconds {
        // Up to a day: a soak plays for hours.
        check("seconds", s, 1e-3, 86400.0)?;
    }
    let cfg = FakeConfig {
        target,
        model,
        script,
        hand,
        physical,
        loss,
        jitter_s: jitter * 1e-3,
        latency_s: latency * 1e-3,
        seed: a.seed,
        seconds: a.seconds,
        outage,
        wait_s: check("wait-s", a.wait_s, 0.0, 86400.0)?,
        bye: true,
    };
    if !a.json {
        eprintln!("fake-device: saying hello to {target} ...");
    }
    let r = run_fake(&cfg, None).map_err(|e| e.to_string())?;
    if a.json {
        println!("{}", serde_json::json!(r));
    } else {
        println!(
            "fake-device: {} periods, {} samples sent, {} dropped (loss), {} silent (outage), {} replies",
            r.ticks, r.sent, r.dropped, r.silent, r.replies
        );
        println!(
            "  round trip p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; peak force {:.3} N (within limits: {})",
            r.round_trip.p50_ns as f64 / 1e3,
            r.round_trip.p99_ns as f64 / 1e3,
            r.round_trip.max_ns as f64 / 1e3,
            r.max_force_n,
            if r.forces_within_limits { "yes" } else { "NO" }
        );
        println!(
            "  force changes above 1 N between periods: {} (largest {:.3} N)",
            r.jumps_over_1n, r.max_jump_n
        );
        if let Some((m, g)) = physical {
            println!(
                "  modelled {} held {} ({} N/m, {} N·s/m){}: the motors did {:+.4} J of work on the hand",
                m.name,
                g.label(),
                g.stiffness_n_per_m,
                g.damping_n_s_per_m,
                if a.ideal { ", ideal sensing" } else { "" },
                r.energy_to_hand_j
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `--operator`: the one operator parser, shared with the wheel.
fn parse_operator(s: &str) -> Result<OperatorChoice, String> {
    OperatorChoice::parse(s).map_err(|e| match e {
        // An unknown name is the flag's error; a bad `hand:k=v` names its key.
        SessionError::Option(m) => format!("--{m}"),
        e => e.to_string(),
    })
}

/// The house task's score at the end of a session (brick and nano worlds), from the last
/// tick's state: `score`, slots filled, `dropped`, `comfort_exceeded_s`, `complete_s`.
fn house_score(t: &Totals) -> serde_json::Value {
    let Some(score) = t.last("score") else {
        return serde_json::Value::Null;
    };
    let filled = t.last("slots_filled").or_else(|| t.last("house_score"));
    serde_json::json!({
        "score": score,
        "slots_filled": filled,
        "dropped": t.last("dropped"),
        "comfort_exceeded_s": t.last("comfort_exceeded_s"),
        "complete_s": t.last("complete_s"),
        "rule": "100 × filled / slots − 10 per dropped brick or atom − 5 per second above half \
                 the device's largest force; never below 0",
    })
}

/// The run summary, from the session's running totals (constant memory: the run keeps no
/// per-tick arrays).
fn summary_json(r: &SessionReport) -> serde_json::Value {
    let t = &r.totals;
    serde_json::json!({
        "scene": r.description.scene_name,
        "kind": r.description.scene_kind,
        "device": r.description.device_model,
        "script": r.description.script_name,
        "operator": r.description.operator,
        "mode": r.description.mode,
        "ticks": r.stats.ticks,
        "duration_s": r.stats.ticks as f64 / f64::from(r.description.rate_hz),
        "peak_device_force_n": t.peak_device_force_n,
        "clamped_ticks": t.clamped_ticks,
        "events": t.events,
        "tick_stats": r.stats,
        "written": r.written,
        "end": r.end,
        "device_link": r.description.device_link,
        "link": r.link.iter().map(|(k, v)| (k.to_string(), *v)).collect::<BTreeMap<String, u64>>(),
        "watchdog_ticks": t.watchdog_ticks,
        "live": r.live,
        "sinks": r.sinks,
        "house_score": house_score(t),
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
    let h = &j["house_score"];
    if let Some(score) = h["score"].as_f64() {
        let complete = h["complete_s"].as_f64().unwrap_or(-1.0);
        println!(
            "  house score {score:.1}: {:.0} slots filled, {:.0} dropped, {:.2} s above the \
             comfort force, {}",
            h["slots_filled"].as_f64().unwrap_or(0.0),
            h["dropped"].as_f64().unwrap_or(0.0),
            h["comfort_exceeded_s"].as_f64().unwrap_or(0.0),
            if complete >= 0.0 {
                format!("complete at {complete:.2} s")
            } else {
                "not complete".to_string()
            }
        );
    }
    if !r.sinks.is_empty() {
        let parts: Vec<String> = r
            .sinks
            .iter()
            .map(|t| format!("{} {:.1} µs", t.sink, t.tick.p99_ns as f64 / 1e3))
            .collect();
        println!("  sink time per tick, p99: {}", parts.join(", "));
    }
    if !r.link.is_empty() {
        let parts: Vec<String> = r.link.iter().map(|(k, v)| format!("{k} {v}")).collect();
        println!("  device link: {}", parts.join(", "));
    }
    if let Some(l) = &r.live {
        println!(
            "  live view: {} scenes, {} states, {} log lines published, {} dropped",
            l.scenes, l.states, l.logs, l.dropped
        );
    }
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
        live,
        live_hz,
        wait_s,
        seconds,
        out,
        realtime,
        json,
    } = args;
    let mut opts = SessionOptions::new(SceneSource::resolve(&scene).map_err(|e| e.to_string())?);
    opts.operator = parse_operator(&operator)?;
    match device.as_deref() {
        Some(d) if d.starts_with("udp:") => {
            let mut b = BridgeConfig::parse(d).map_err(|e| e.to_string())?;
            if !(wait_s.is_finite() && (0.0..=86400.0).contains(&wait_s)) {
                return Err(format!(
                    "--wait-s = {wait_s} is out of range: allowed 0–86400"
                ));
            }
            b.wait_s = wait_s;
            if !json {
                eprintln!(
                    "waiting for a device on udp:{} (nanohaptics fake-device udp:{} in another terminal) ...",
                    b.bind, b.bind
                );
            }
            opts.bridge = Some(b);
        }
        Some(d) => {
            opts.device = Some(DeviceModel::from_name(d).map_err(|e| {
                format!("--device: {e}; or udp:HOST:PORT for a device in another process")
            })?);
        }
        None => {}
    }
    if let Some(l) = live.as_deref() {
        let mut c = LiveConfig::parse(l).map_err(|e| e.to_string())?;
        if !(1..=1000).contains(&live_hz) {
            return Err(format!(
                "--live-hz = {live_hz} is out of range: allowed 1–1000"
            ));
        }
        c.display_hz = live_hz;
        if !json {
            eprintln!(
                "live view on ws://{} (Foxglove: Open connection → Foxglove WebSocket)",
                c.bind
            );
        }
        opts.live = Some(c);
    }
    if let Some(p) = script.as_deref() {
        opts.script =
            Some(haptic_loop::session::read_toml_text(p).map_err(|e| format!("--script: {e}"))?);
        opts.script_origin = Some(p.display().to_string());
    }
    opts.seconds = seconds;
    opts.realtime = realtime;
    opts.out = out;
    // The summary comes from the running totals: no per-tick arrays, so memory stays flat
    // however long the session runs.
    opts.arrays = false;
    let pb = (!json).then(|| progress_bar(0, "run"));
    let stop = interrupt_flag()?;
    let report = run_session_until(
        &opts,
        &mut |done, total| {
            if let Some(pb) = &pb {
                pb.set_length(total);
                pb.set_position(done);
            }
        },
        Some(&stop),
    )
    .map_err(|e| e.to_string())?;
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    if json {
        println!("{}", summary_json(&report));
    } else {
        print_summary(&report);
    }
    if report.end == "stopped" {
        eprintln!(
            "stopped by an interrupt after {} ticks{}",
            report.stats.ticks,
            match &opts.out {
                Some(p) => format!("; {} holds them, complete and verifiable", p.display()),
                None => String::new(),
            }
        );
        return Ok(ExitCode::from(130));
    }
    Ok(ExitCode::SUCCESS)
}

/// A flag raised by the first Ctrl-C (SIGINT) or SIGTERM: the session stops cleanly after
/// the current tick and the recording is finished. A second one ends the program at once.
fn interrupt_flag() -> Result<Arc<AtomicBool>, String> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(sig, 130, Arc::clone(&stop))
            .and_then(|_| signal_hook::flag::register(sig, Arc::clone(&stop)))
            .map_err(|e| format!("cannot watch for Ctrl-C: {e}"))?;
    }
    Ok(stop)
}

fn cmd_replay(rec: &Path, strict: bool, salvage: bool, json: bool) -> Result<ExitCode, String> {
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
    let pct = haptic_devices::pacing::Percentiles::of(&a.compute_ns);
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

fn cmd_scenes(action: Option<&str>, dir: Option<&Path>) -> Result<ExitCode, String> {
    match (action, dir) {
        (None, _) => {
            for b in haptic_loop::builtin::SCENES {
                let name = haptic_loop::scene::SceneFile::parse(b.scene)
                    .map(|f| f.scene.name)
                    .unwrap_or_default();
                println!("{:<18} {name} (script: {})", b.name, b.script_file);
            }
            Ok(ExitCode::SUCCESS)
        }
        (Some("export"), Some(d)) => {
            let files = haptic_loop::builtin::export(d)?;
            for f in &files {
                println!("{}", f.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        (Some("export"), None) => {
            Err("scenes export: give the folder, e.g. `nanohaptics scenes export my-scenes`".into())
        }
        (Some(other), _) => Err(format!("scenes `{other}`: the only action is `export DIR`")),
    }
}

fn cmd_demo(scenes: Option<&Path>, out: &Path, json: bool) -> Result<ExitCode, String> {
    // Scene files on disk (`--scenes`, or `./scenes` when it exists: files on disk override),
    // or else the built-in scenes.
    let local = Path::new("scenes");
    let scenes = scenes.or_else(|| local.is_dir().then_some(local));
    let files: Vec<PathBuf> = match scenes {
        Some(dir) => {
            let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
                .map_err(|e| format!("cannot list {}: {e}", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().is_some_and(|x| x == "toml")
                        && !p.to_string_lossy().ends_with(".script.toml")
                })
                .collect();
            files.sort();
            if files.is_empty() {
                return Err(format!("no scene files (*.toml) in {}", dir.display()));
            }
            files
        }
        None => haptic_loop::builtin::SCENES
            .iter()
            .map(|b| PathBuf::from(b.name))
            .collect(),
    };
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut rows = Vec::new();
    let mut all_ok = true;
    for f in &files {
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let rec = out.join(format!("{stem}.mcap"));
        let source = match scenes {
            Some(_) => SceneSource::from_path(f),
            None => SceneSource::resolve(f),
        };
        let mut opts = SessionOptions::new(source.map_err(|e: SessionError| e.to_string())?);
        opts.out = Some(rec.clone());
        opts.arrays = false;
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
    // A closed pipe (`nanohaptics info REC | head`) ends the program quietly with the shell's
    // status 141, as for any Unix filter, instead of a panic on the next print.
    let _ = signal_hook::flag::register_conditional_shutdown(
        signal_hook::consts::SIGPIPE,
        141,
        Arc::new(AtomicBool::new(true)),
    );
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
        Cmd::Lesson(a) => lesson_cmd::cmd(&a),
        Cmd::Play(a) => play_cmd::cmd(&a),
        Cmd::Demo { scenes, out, json } => cmd_demo(scenes.as_deref(), &out, json),
        Cmd::Scenes { action, dir } => cmd_scenes(action.as_deref(), dir.as_deref()),
        Cmd::FakeDevice(a) => cmd_fake(a),
    };
    match res {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}
