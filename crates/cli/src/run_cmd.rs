//! `nanohaptics run`: a scene with a script or a device, batch or real time, recorded and
//! served live, with its summary.

use crate::status;
use haptic_devices::source::DeviceSource;
use haptic_devices::source::OperatorChoice;
use haptic_engine::totals::Totals;
use haptic_loop::live::LiveConfig;
use haptic_loop::session::{
    SceneSource, SessionError, SessionOptions, SessionReport, run_session_until,
};
use haptic_types::value::ValueError;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

#[derive(clap::Args)]
pub(crate) struct RunArgs {
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
    /// over the UDP bridge, `udp:HOST:PORT` or `udp:PORT` on loopback (listen there; waits for
    /// its hello; always real time; see docs/device-bridge.md).
    #[arg(long)]
    device: Option<String>,
    /// Which button plays which role, overriding the device's preset or the default by index:
    /// `grip=a,turn_z=b` (roles: grip, turn_x, turn_y, turn_z; docs/devices.md). Recorded as
    /// the scene's `[device] buttons`, so a replay maps them the same.
    #[arg(long)]
    buttons: Option<String>,
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
    #[command(flatten)]
    rt: crate::rt_args::RtArgs,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

/// The scene `text` with `--buttons ROLE=BUTTON,...` set as its `[device] buttons` (each role
/// name checked; each button is checked against the device when the session starts).
pub(crate) fn with_buttons(text: &str, buttons: &str) -> Result<String, String> {
    let pairs = haptic_types::buttons::parse_overrides(buttons).map_err(|e| e.to_string())?;
    haptic_loop::scene::overrides::override_buttons(text, &pairs)
        .map_err(|e| format!("--buttons: {e}"))
}

/// `--operator`: the one operator parser, shared with the wheel.
pub(crate) fn parse_operator(s: &str) -> Result<OperatorChoice, String> {
    haptic_loop::session::parse_operator(s).map_err(|e| match e {
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
pub(crate) fn summary_json(r: &SessionReport) -> serde_json::Value {
    let t = &r.totals;
    serde_json::json!({
        "scene": r.header.scene_name,
        "kind": r.header.scene_kind,
        "device": r.header.device.name,
        "script": r.header.script_name,
        "operator": r.header.operator,
        "mode": r.header.mode,
        "ticks": r.stats.ticks,
        "duration_s": r.stats.ticks as f64 / f64::from(r.header.rate_hz),
        "peak_device_force_n": t.peak_device_force_n,
        "clamped_ticks": t.clamped_ticks,
        "events": t.events,
        "tick_stats": r.stats,
        "written": r.written,
        "end": r.end,
        "device_link": r.header.device_link,
        "link": r.link.iter().map(|(k, v)| (k.to_string(), *v)).collect::<BTreeMap<String, u64>>(),
        "watchdog_ticks": t.watchdog_ticks,
        "live": r.live,
        "sinks": r.sinks,
        "house_score": house_score(t),
        "buttons": buttons_in_force(r),
    })
}

/// The button roles the session ran with, as people read them (`grip = centre, turn_x = plus,
/// … (the falcon preset)`): the recorded device's buttons and the recorded scene's overrides.
fn buttons_in_force(r: &SessionReport) -> String {
    let d = &r.header.device;
    match haptic_loop::scene::device::roles_in(&r.header.scene_toml, d) {
        Ok(roles) => roles.describe(&d.button_strs()),
        Err(e) => e.to_string(),
    }
}

pub(crate) fn print_summary(r: &SessionReport) {
    let j = summary_json(r);
    let s = &r.stats;
    println!(
        "{} ({}, {} device, {} operator)",
        r.header.scene_name, r.header.mode, r.header.device.name, r.header.operator
    );
    println!("  buttons: {}", buttons_in_force(r));
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
    if r.header.mode == "realtime" {
        println!(
            "  real time: {}; wake-up p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs",
            s.realtime.describe(),
            s.wakeup.p50_ns as f64 / 1e3,
            s.wakeup.p99_ns as f64 / 1e3,
            s.wakeup.p999_ns as f64 / 1e3,
            s.wakeup.max_ns as f64 / 1e3
        );
    }
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
            w.bytes as f64 * 60.0 / (s.ticks as f64 / f64::from(r.header.rate_hz))
        );
    }
}

pub(crate) fn progress_bar(len: u64, label: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    let style = ProgressStyle::with_template("{prefix:>16} [{bar:40}] {pos}/{len} ticks {eta}")
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_prefix(label.to_string());
    pb
}

pub(crate) fn cmd(args: RunArgs) -> Result<u8, String> {
    let RunArgs {
        scene,
        script,
        operator,
        device,
        buttons,
        live,
        live_hz,
        wait_s,
        seconds,
        out,
        realtime,
        rt,
        json,
    } = args;
    let mut source = SceneSource::resolve(&scene).map_err(|e| e.to_string())?;
    if let Some(b) = buttons.as_deref() {
        source.text = with_buttons(&source.text, b)?;
    }
    let mut opts = SessionOptions::new(source);
    opts.operator = parse_operator(&operator)?;
    if let Some(d) = device.as_deref() {
        let mut d = DeviceSource::parse(d).map_err(|e| format!("--device: {e}"))?;
        if let DeviceSource::Udp(b) = &mut d {
            if !(wait_s.is_finite() && (0.0..=86400.0).contains(&wait_s)) {
                return Err(ValueError::out_of_range("--wait-s", wait_s, "0–86400 s").to_string());
            }
            b.wait_s = wait_s;
            if !json {
                eprintln!(
                    "waiting for a device on udp:{} (nanohaptics fake-device udp:{} in another terminal) ...",
                    b.bind, b.bind
                );
            }
        }
        opts.device = Some(d);
    }
    if let Some(l) = live.as_deref() {
        let mut c = LiveConfig::parse(l).map_err(|e| e.to_string())?;
        if !(1..=1000).contains(&live_hz) {
            return Err(
                ValueError::out_of_range("--live-hz", f64::from(live_hz), "1–1000 Hz").to_string(),
            );
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
    opts.rt = rt.request()?;
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
    .map_err(|e| session_error(e, buttons.as_deref()))?;
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
        return Ok(status::INTERRUPTED);
    }
    Ok(status::SUCCESS)
}

/// A session's error as the user reads it. With `--buttons` the scene the session read is the
/// file rewritten with the flag's roles, so a button the device lacks is named by the flag
/// (`--buttons grip`), not by a line of a text the user never saw; any other error in the
/// rewritten scene says so beside its place.
fn session_error(e: SessionError, buttons: Option<&str>) -> String {
    use haptic_engine::check::SceneError;
    let Some(flag) = buttons else {
        return e.to_string();
    };
    match e {
        SessionError::SceneFile { at, error } => match *error {
            SceneError::OutOfRange {
                field,
                value,
                allowed,
            } if field.starts_with("device.buttons.")
                && haptic_types::buttons::parse_overrides(flag).is_ok_and(|pairs| {
                    pairs
                        .iter()
                        .any(|(r, _)| field == format!("device.buttons.{}", r.name()))
                }) =>
            {
                let role = field.trim_start_matches("device.buttons.");
                world_form::value::out_of_range(&format!("`--buttons {role}`"), value, &allowed)
            }
            error => format!("{at} (the scene as --buttons {flag} rewrote it): {error}"),
        },
        SessionError::DefaultScript { ref at, .. } => {
            let at = at.to_string();
            let text = e.to_string();
            let rest = text.strip_prefix(&at).unwrap_or(&text);
            format!("{at} (the scene as --buttons {flag} rewrote it){rest}")
        }
        other => other.to_string(),
    }
}

/// A flag raised by the first Ctrl-C (SIGINT) or SIGTERM: the session stops cleanly after
/// the current tick and the recording is finished. A second one ends the program at once.
pub(crate) fn interrupt_flag() -> Result<Arc<AtomicBool>, String> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM] {
        signal_hook::flag::register_conditional_shutdown(
            sig,
            i32::from(status::INTERRUPTED),
            Arc::clone(&stop),
        )
        .and_then(|_| signal_hook::flag::register(sig, Arc::clone(&stop)))
        .map_err(|e| format!("cannot watch for Ctrl-C: {e}"))?;
    }
    Ok(stop)
}
