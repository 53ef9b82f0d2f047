//! Soak: a real-time bridged brick-world session, the device in another process over the UDP
//! bridge with 5 % of its samples lost and up to 1 ms of jitter, held by a loose hand on a
//! modelled Falcon that replays the wall-building script over and over.
//!
//! Behind an environment flag, because it runs in real time: `NANOHAPTICS_SOAK_S=120` runs the
//! two-minute version, `NANOHAPTICS_SOAK_S=3600` the hour of BENCHMARKS.md:
//!
//! ```text
//! NANOHAPTICS_SOAK_S=120 cargo test --release -p nanohaptics-cli --test soak -- --nocapture
//! ```
//!
//! It checks that the resident memory of the simulator stays flat (the last tenth of the
//! session within 4 MiB of the level after the first tenth), that the tick compute time does
//! not drift (the lower quartile of the last tenth within 50 % + 10 µs of the first tenth's,
//! after the first 5 s: a shared machine's load moves the median), that every tick the simulator ran is in the recording (at least 95 % of
//! the planned ones: a bridged session ticks on the device's samples), and that the recording
//! replays bit for bit. The figures are printed and written to `target/soak/soak-<seconds>s.json`.
//! Without the flag the test says how to run it and returns. `NANOHAPTICS_BIN` runs another
//! build of the program (e.g. a copy kept aside while the tree changes during an hour's soak).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use recording::channels::messages::{Channel, TimingMsg};
use recording::reader::read_recording_file;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The brick-world script repeated back to back (with a 1 s move back to the start between
/// plays) until it covers `seconds` (a script ends by 3600 s: later entries are left out).
fn repeated_script(seconds: f64) -> String {
    let text = std::fs::read_to_string(root().join("scenes/brickworld.script.toml")).unwrap();
    let mut v: toml::Table = toml::from_str(&text).unwrap();
    let waypoints = v["waypoint"].as_array().unwrap().clone();
    let buttons = v["button"].as_array().unwrap().clone();
    let last_t = |a: &Vec<toml::Value>| {
        a.iter()
            .map(|w| w["t_s"].as_float().unwrap())
            .fold(0.0, f64::max)
    };
    let period = last_t(&waypoints).max(last_t(&buttons)) + 1.0;
    let plays = (seconds / period).ceil() as usize + 1;
    let shift = |a: &[toml::Value], k: usize| -> Vec<toml::Value> {
        a.iter()
            .map(|w| {
                let mut w = w.as_table().unwrap().clone();
                let t = w["t_s"].as_float().unwrap() + k as f64 * period;
                // Rounded to the µs so the shifted times print short and stay ordered.
                w.insert("t_s".into(), ((t * 1e6).round() / 1e6).into());
                toml::Value::Table(w)
            })
            .filter(|w| w["t_s"].as_float().unwrap() <= seconds.min(3600.0))
            .collect()
    };
    let mut all_w = Vec::new();
    let mut all_b = Vec::new();
    for k in 0..plays {
        // Each play starts where the previous one ended: a 1 s move back to the start.
        all_w.extend(shift(&waypoints, k));
        all_b.extend(shift(&buttons, k));
    }
    v.insert("waypoint".into(), toml::Value::Array(all_w));
    v.insert("button".into(), toml::Value::Array(all_b));
    v["script"].as_table_mut().unwrap().insert(
        "name".into(),
        "soak: the wall, built again and again".into(),
    );
    toml::to_string(&v).unwrap()
}

fn program() -> PathBuf {
    std::env::var_os("NANOHAPTICS_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_nanohaptics")))
}

fn rss_kib(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = s.lines().find(|l| l.starts_with("VmRSS:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The `q` quantile (0–1) of `v` by the project's one percentile (nearest rank).
fn quantile(v: &mut [u64], q: f64) -> u64 {
    v.sort_unstable();
    world_form::numbers::percentile(v, q).unwrap_or(0)
}

#[test]
fn soak_bridged_session_with_loss_and_jitter() {
    let Ok(flag) = std::env::var("NANOHAPTICS_SOAK_S") else {
        eprintln!(
            "soak not run: set NANOHAPTICS_SOAK_S=120 (two minutes) or 3600 (the hour) to run it"
        );
        return;
    };
    let seconds: f64 = flag
        .parse()
        .ok()
        .filter(|s: &f64| s.is_finite() && *s >= 20.0)
        .expect("NANOHAPTICS_SOAK_S: seconds, at least 20");
    let dir = root().join("target/soak");
    std::fs::create_dir_all(&dir).unwrap();
    let script = dir.join("soak.script.toml");
    std::fs::write(&script, repeated_script(seconds)).unwrap();
    let rec = dir.join(format!("soak-{seconds}s.mcap"));
    let port = 47_300 + (std::process::id() % 500) as u16;
    let device = format!("udp:127.0.0.1:{port}");
    let secs = format!("{seconds}");
    let started = Instant::now();
    let mut sim = Command::new(program())
        .args(["run", "scenes/brickworld.toml", "--device", &device])
        .args(["--realtime", "--seconds", &secs, "--wait-s", "30", "--json"])
        .arg("--out")
        .arg(&rec)
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let fake = Command::new(program())
        .args(["fake-device", &device, "--grip", "loose", "--loss", "0.05"])
        .args(["--jitter-ms", "1", "--seed", "7", "--json"])
        .args(["--seconds", &format!("{}", seconds + 2.0)])
        .arg("--script")
        .arg(&script)
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Resident memory of the simulator, once a second, until it exits.
    let mut rss: Vec<(f64, u64)> = Vec::new();
    let pid = sim.id();
    loop {
        if sim.try_wait().unwrap().is_some() {
            break;
        }
        if let Some(kib) = rss_kib(pid) {
            rss.push((started.elapsed().as_secs_f64(), kib));
        }
        std::thread::sleep(Duration::from_secs(1));
        assert!(
            started.elapsed().as_secs_f64() < seconds + 120.0,
            "the session overran"
        );
    }
    let mut out = String::new();
    sim.stdout.take().unwrap().read_to_string(&mut out).unwrap();
    let mut err = String::new();
    sim.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    assert!(sim.wait().unwrap().success(), "simulator failed: {err}");
    let fake_out = fake.wait_with_output().unwrap();
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    let fake_report: serde_json::Value = serde_json::from_slice(&fake_out.stdout).unwrap();

    // Memory: flat after the first tenth of the session.
    let at = |frac: f64| {
        let t = frac * seconds;
        rss.iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .map(|r| r.1)
            .unwrap()
    };
    let early = at(0.1);
    let late_max = rss
        .iter()
        .filter(|r| r.0 >= 0.9 * seconds)
        .map(|r| r.1)
        .max()
        .unwrap_or(early);
    let peak = rss.iter().map(|r| r.1).max().unwrap();

    // Tick compute time from the recording's /loop/timing, by tenths of the session.
    let recording = read_recording_file(&rec, false).unwrap();
    let ticks = recording.integrity.ticks;
    let compute: Vec<u64> = recording
        .messages
        .iter()
        .filter(|m| m.channel == Channel::Timing)
        .map(|m| TimingMsg::decode(&m.data).unwrap().compute_ns)
        .collect();
    let n = compute.len();
    let skip = 5_000.min(n / 10); // the first 5 s: caches, allocations, the first bricks
    let tenth = (n - skip) / 10;
    let (mut deciles, mut quartiles) = (Vec::new(), Vec::new());
    for k in 0..10 {
        let a = skip + k * tenth;
        deciles.push(quantile(&mut compute[a..a + tenth].to_vec(), 0.5));
        quartiles.push(quantile(&mut compute[a..a + tenth].to_vec(), 0.25));
    }
    let p99_all = {
        let mut c = compute[skip..].to_vec();
        c.sort_unstable();
        c[(c.len() * 99) / 100]
    };
    drop(recording);

    // Replay, bit for bit.
    let replay = Command::new(program())
        .args(["replay", "--verify", "--json"])
        .arg(&rec)
        .current_dir(root())
        .output()
        .unwrap();
    let replay_ok = replay.status.success();
    let replay_report: serde_json::Value =
        serde_json::from_slice(&replay.stdout).unwrap_or(serde_json::Value::Null);

    let report = serde_json::json!({
        "seconds": seconds,
        "ticks": ticks,
        "missed_deadlines": summary["tick_stats"]["missed"],
        "compute_p99_ns": p99_all,
        "compute_median_by_tenth_ns": deciles,
        "compute_lower_quartile_by_tenth_ns": quartiles,
        "rss_kib_at_10pct": early,
        "rss_kib_last_tenth_max": late_max,
        "rss_kib_peak": peak,
        "rss_samples": rss.len(),
        "link": summary["link"],
        "watchdog_ticks": summary["watchdog_ticks"],
        "device_dropped": fake_report["dropped"],
        "device_sent": fake_report["sent"],
        "recording_bytes": std::fs::metadata(&rec).unwrap().len(),
        "replay_verified": replay_ok,
        "replay": replay_report,
        "load_average": std::fs::read_to_string("/proc/loadavg").unwrap_or_default().trim(),
    });
    let text = serde_json::to_string_pretty(&report).unwrap();
    println!("{text}");
    std::fs::write(dir.join(format!("soak-{seconds}s.json")), &text).unwrap();

    // The device really lost 5 % and the link saw it.
    let sent = fake_report["sent"].as_f64().unwrap();
    let dropped = fake_report["dropped"].as_f64().unwrap();
    let loss = dropped / (sent + dropped);
    assert!((0.04..0.06).contains(&loss), "device loss {loss}");
    // Every tick the simulator ran is in the recording. A bridged session ticks on the
    // device's samples: on a loaded machine a late tick takes the newest sample (the others
    // are superseded), so it may run a little fewer ticks than the device's seconds.
    assert_eq!(Some(ticks), summary["ticks"].as_u64(), "ticks recorded");
    let planned = (seconds * 1000.0).round() as u64;
    assert!(
        ticks * 100 >= planned * 95,
        "{ticks} ticks of {planned} planned"
    );
    assert!(
        late_max <= early + 4 * 1024,
        "resident memory grew: {early} KiB at 10 %, {late_max} KiB in the last tenth"
    );
    // The lower quartile: what a tick costs when the other jobs of a shared machine leave it
    // alone (the median follows their load). A leak of work per tick moves it too.
    let (first, last) = (quartiles[0] as f64, quartiles[9] as f64);
    assert!(
        last <= first * 1.5 + 10_000.0,
        "tick compute drifted: lower quartile {first} ns in the first tenth, {last} ns in the \
         last (medians {deciles:?})"
    );
    assert!(
        replay_ok,
        "replay diverged: {}",
        String::from_utf8_lossy(&replay.stdout)
    );
    std::fs::remove_file(&rec).ok();
}
