//! Real-time quality of live sessions against `fake-device` on loopback at 1 kHz: bridge round
//! trip, tick jitter, missed deadlines, what the watchdog did under 5% loss and 2 ms jitter, how
//! fast the force reaches zero when the device vanishes, and what the live view costs the tick.
//!
//! ```text
//! cargo run --release -p haptic-loop --example haptic-loop-live-report -- [--seconds 60] [--out docs/bench/live.md]
//! ```
//! Each session runs the wall scene in real time with the recorder on (as a lab would) and the
//! fake device (rigid stylus playing the wall script, then holding still) in a thread of this
//! process; both sides pace themselves by the wall clock.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_loop::bridge::BridgeConfig;
use haptic_loop::bridge::fake::{FakeConfig, FakeReport, run_fake};
use haptic_loop::device::{DeviceModel, FALCON, Script};
use haptic_loop::haptic::status;
use haptic_loop::live::LiveConfig;
use haptic_loop::session::{SceneSource, SessionOptions, SessionReport, run_session};
use std::fmt::Write as _;
use std::net::{TcpListener, UdpSocket};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

struct Case {
    name: &'static str,
    loss: f64,
    jitter_s: f64,
    live: bool,
    outage: Option<(f64, f64)>,
    seconds: f64,
}

fn run_case(c: &Case) -> (SessionReport, FakeReport) {
    let addr = UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes/wall.toml")).unwrap());
    let mut b = BridgeConfig::parse(&format!("udp:{addr}")).unwrap();
    b.wait_s = 30.0;
    o.bridge = Some(b);
    o.out = Some(std::env::temp_dir().join(format!("live-report-{}.mcap", std::process::id())));
    if c.live {
        let port = TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        o.live = Some(LiveConfig::parse(&format!("ws:127.0.0.1:{port}")).unwrap());
    }
    let text = std::fs::read_to_string(root().join("scenes/wall.script.toml")).unwrap();
    let f = FakeConfig {
        target: addr,
        model: DeviceModel::Falcon,
        script: Script::from_toml(&text, &FALCON).unwrap(),
        hand: None,
        loss: c.loss,
        jitter_s: c.jitter_s,
        latency_s: 0.0,
        seed: 7,
        seconds: Some(c.seconds),
        outage: c.outage,
        wait_s: 30.0,
        bye: true,
    };
    let h = std::thread::spawn(move || run_session(&o, &mut |_, _| {}).unwrap());
    let dev = run_fake(&f, None).unwrap();
    (h.join().unwrap(), dev)
}

fn us(ns: u64) -> String {
    format!("{:.1}", ns as f64 / 1e3)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |k: &str| {
        args.iter()
            .position(|a| a == k)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let secs: f64 = arg("--seconds").map_or(60.0, |s| s.parse().expect("--seconds"));
    let out = arg("--out").map(PathBuf::from);
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let cases = [
        Case {
            name: "clean loopback, live view on",
            loss: 0.0,
            jitter_s: 0.0,
            live: true,
            outage: None,
            seconds: secs,
        },
        Case {
            name: "clean loopback, live view off",
            loss: 0.0,
            jitter_s: 0.0,
            live: false,
            outage: None,
            seconds: secs,
        },
        Case {
            name: "5% loss + 2 ms jitter",
            loss: 0.05,
            jitter_s: 0.002,
            live: false,
            outage: None,
            seconds: secs,
        },
        Case {
            name: "device silent 100 ms at t = 2 s",
            loss: 0.0,
            jitter_s: 0.0,
            live: false,
            outage: Some((2.0, 0.1)),
            seconds: 3.0,
        },
    ];
    let mut md = String::new();
    writeln!(md, "Wall scene at 1 kHz against `fake-device` (rigid stylus) on loopback, recorder on; load average at start: {}", load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")).unwrap();
    writeln!(md).unwrap();
    writeln!(md, "| session | s | round trip p50 / p99 / max (µs) | tick work p99 (µs) | tick jitter p99 (µs) | missed deadlines | stale ticks | watchdog ticks | link lost | live view per tick p99 (µs) |").unwrap();
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|").unwrap();
    let mut outage_line = String::new();
    for c in &cases {
        eprintln!("{} ({} s) ...", c.name, c.seconds);
        let (r, d) = run_case(c);
        let a = &r.arrays;
        let watchdog = a
            .status
            .iter()
            .filter(|s| **s & status::WATCHDOG != 0)
            .count();
        let lost = a.events.iter().filter(|e| e.1 == "device.lost").count();
        let stale = r
            .link
            .iter()
            .find(|(k, _)| *k == "stale_ticks")
            .map_or(0, |x| x.1);
        let live = r
            .sinks
            .iter()
            .find(|s| s.sink == "live")
            .map_or("–".to_string(), |s| us(s.tick.p99_ns));
        writeln!(
            md,
            "| {} | {:.0} | {} / {} / {} | {} | {} | {} | {} | {} | {} | {} |",
            c.name,
            r.stats.ticks as f64 / 1000.0,
            us(d.round_trip.p50_ns),
            us(d.round_trip.p99_ns),
            us(d.round_trip.max_ns),
            us(r.stats.compute.p99_ns),
            us(r.stats.jitter.p99_ns),
            r.stats.missed,
            stale,
            watchdog,
            lost,
            live
        )
        .unwrap();
        assert!(d.forces_within_limits);
        if c.outage.is_some() {
            // In ticks (the recorded, replayable truth) and on the device's wall clock.
            let first = a.device_age_ticks.iter().position(|&g| g >= 9).unwrap();
            let zero_at = first;
            let last_fresh = (0..first)
                .rev()
                .find(|&i| a.device_age_ticks[i] == 0)
                .unwrap();
            let f0 = haptic_loop::vec3::norm(a.device_force_n[last_fresh]);
            let dev_zero = d
                .outage_force
                .iter()
                .find(|x| x.1 == 0.0)
                .map_or(f64::NAN, |x| x.0);
            outage_line = format!(
                "Device silent for 100 ms while pressing the wall with {f0:.2} N: the force sent reached 0 N at the stale tick of age {} (scheduled {}.5 ms after the last sample: full force through 1.5 ms, then a linear ramp); the device received its first zero-force packet {dev_zero:.2} ms after it sent its last sample (wall clock, including the loopback trip). On return: `device.resumed`, soft engagement from 0 over 0.25 s.",
                zero_at - last_fresh,
                zero_at - last_fresh
            );
        }
    }
    writeln!(md).unwrap();
    writeln!(md, "{outage_line}").unwrap();
    print!("{md}");
    if let Some(p) = out {
        std::fs::write(&p, &md).unwrap();
        eprintln!("wrote {}", p.display());
    }
}
