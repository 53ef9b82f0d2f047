//! Issue 13's measurements of the optical-tweezers tick, old settings against new in one run:
//!
//! * a 60 s session of `scenes/optical_tweezers.toml` with logging on, batch pacing, once with
//!   the old settings (RK4×8 tick map, a full envelope build every tick) and once with the new
//!   defaults (error-budget tick map, warm start), alternating `--rounds` times: tick compute
//!   p50/p99/max;
//! * the envelope's Hausdorff distance from converged dynamics at sampled ticks of the new
//!   session, reconstructed from the recorded particle states (the reconstruction is checked
//!   bit for bit against the recorded trap);
//! * `--realtime`: `scenes/optical_tweezers_10khz.toml` paced in real time for 60 s: missed
//!   deadlines;
//! * `--hausdorff-every N`: check every N-th grabbed tick (default 50; 1 = every tick);
//! * `--only old|new --seconds S`: one session and nothing else (for `valgrind --tool=callgrind`);
//! * `--scene PATH`: the batch sessions' scene, relative to the repository (default
//!   `scenes/optical_tweezers.toml`; the Hausdorff check replays the world's steering: the
//!   envelope built at load, kept fresh between grabs, spread rebuilds, and checks every tick
//!   served while a spread build is under way).
//!
//! `cargo run --release -p haptic-loop --example ot_tick -- [--rounds N] [--realtime]`

mod ot_replay;

use bench_harness::Summary;
use bench_harness::machine::LoadAvg;
use haptic_loop::session::{SceneSource, SessionOptions, SessionReport, run_session};
use std::path::{Path, PathBuf};

type BoxError = Box<dyn std::error::Error>;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn old_text(text: &str) -> String {
    text.replace(
        "tick_map_tol_nm = 0.01",
        "rk4_substeps = 8\ntick_map_tol_nm_unused = 0",
    )
    .replace("tick_map_tol_nm_unused = 0", "")
    .replace(
        "warm_start = true",
        "warm_start = false\nenvelope_margin_waists = 3.0\nenvelope_cell_waists = 0.3",
    )
}

fn session(text: &str, seconds: f64, realtime: bool, tag: &str) -> Result<SessionReport, BoxError> {
    let mut src = SceneSource::from_text(text, "optical_tweezers.toml");
    src.dir = Some(root().join("scenes"));
    let mut o = SessionOptions::new(src);
    o.seconds = Some(seconds);
    o.realtime = realtime;
    o.out = Some(std::env::temp_dir().join(format!("ot_tick_{tag}_{}.mcap", std::process::id())));
    let r = run_session(&o, &mut |_, _| {})?;
    if let Some(p) = &o.out {
        let _ = std::fs::remove_file(p);
    }
    Ok(r)
}

fn us(ns: u64) -> f64 {
    ns as f64 / 1e3
}

/// The load average now (1, 5, 15 min), from the shared harness.
fn load() -> String {
    LoadAvg::now().map_or("?".to_string(), |l| l.to_string())
}

/// Replays the new session's steering from its recorded states and measures the envelope's
/// Hausdorff distance from converged dynamics every `every` grabbed ticks.
fn hausdorff_check(text: &str, r: &SessionReport, every: u64) -> Result<String, BoxError> {
    let f = ot_replay::replay(text, r, every)?;
    Ok(format!(
        "envelope Hausdorff from converged dynamics (tol 0.02 nm reference), {} of {} grabbed ticks: \
         tick envelope (warm or rebuilt) {:.3} nm, a full rebuild at the same tick {:.3} nm; \
         of which the {} ticks served during a spread build (all checked): {:.3} nm; \
         most force evaluations of a build slice in a grabbed tick: {}; \
         reconstruction mismatches with the recorded trap: {}; {:?}",
        f.checked,
        f.grabbed,
        f.worst_nm,
        f.worst_cold_nm,
        f.checked_spread,
        f.worst_spread_nm,
        f.max_slice,
        f.mismatches,
        f.stats
    ))
}

fn main() -> Result<(), BoxError> {
    let args: Vec<String> = std::env::args().collect();
    let flag = |f: &str| {
        args.iter()
            .position(|a| a == f)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    // the batch sessions' scene (`--scene scenes/optical_tweezers_10khz.toml`: the 10 kHz one)
    let scene = flag("--scene").unwrap_or_else(|| "scenes/optical_tweezers.toml".into());
    let text = std::fs::read_to_string(root().join(scene))?;
    let old = old_text(&text);
    let seconds: f64 = flag("--seconds").map_or(Ok(60.0), |s| s.parse())?;
    if let Some(which) = flag("--only") {
        let t = if which == "old" { &old } else { &text };
        let r = session(t, seconds, false, &which)?;
        println!(
            "{which}: {} ticks, {} events",
            r.stats.ticks,
            r.arrays.events.len()
        );
        return Ok(());
    }
    let rounds: usize = flag("--rounds").map_or(Ok(1), |s| s.parse())?;
    println!("load before: {}", load());
    println!(
        "| settings | ticks | p50 µs | p99 µs | max µs | grabbed ticks | grabbed p50 µs | grabbed p99 µs | grabbed max µs | load (1 min) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut last_new = None;
    let mut last_old = None;
    for _ in 0..rounds {
        for (name, t) in [
            ("old: RK4×8, full build every tick", &old),
            ("new: budget map, warm start", &text),
        ] {
            let r = session(t, seconds, false, "bench")?;
            let s = &r.stats;
            let g = r
                .arrays
                .state_column("grabbed")
                .ok_or("no grabbed column")?;
            // grabbed ticks' work, µs, nearest-rank percentiles (0 when none was grabbed)
            let gt = Summary::of(
                r.arrays
                    .compute_ns
                    .iter()
                    .zip(&g)
                    .filter(|(_, g)| **g == 1.0)
                    .map(|(t, _)| us(*t)),
            );
            let pct = |q: f64| gt.as_ref().and_then(|s| s.percentile(q)).unwrap_or(0.0);
            println!(
                "| {name} | {} | {:.1} | {:.1} | {:.1} | {} | {:.1} | {:.1} | {:.1} | {} |",
                s.ticks,
                us(s.compute.p50_ns),
                us(s.compute.p99_ns),
                us(s.compute.max_ns),
                gt.as_ref().map_or(0, Summary::len),
                pct(0.5),
                pct(0.99),
                pct(1.0),
                load().split(' ').next().unwrap_or("?")
            );
            let mut slow: Vec<(u64, usize)> = r
                .arrays
                .compute_ns
                .iter()
                .copied()
                .enumerate()
                .map(|(i, t)| (t, i))
                .collect();
            slow.sort_unstable_by(|a, b| b.cmp(a));
            let slow: Vec<String> = slow
                .iter()
                .take(5)
                .map(|(t, i)| format!("tick {i}: {:.0} µs", us(*t)))
                .collect();
            println!("|   slowest: {} | | | | | | | | | |", slow.join(", "));
            if name.starts_with("new") {
                last_new = Some(r);
            } else {
                last_old = Some(r);
            }
        }
    }
    if let Some(r) = &last_new {
        for e in r
            .arrays
            .events
            .iter()
            .filter(|e| e.1 == "ot.tick_map")
            .take(1)
        {
            println!("{}", e.2);
        }
        let every: u64 = flag("--hausdorff-every").map_or(Ok(50), |s| s.parse())?;
        println!("new: {}", hausdorff_check(&text, r, every.max(1))?);
        if let Some(ro) = &last_old {
            println!("old: {}", hausdorff_check(&old, ro, every.max(1))?);
        }
    }
    if args.iter().any(|a| a == "--realtime") {
        let t10 = std::fs::read_to_string(root().join("scenes/optical_tweezers_10khz.toml"))?;
        let r = session(&t10, seconds, true, "rt10k")?;
        let s = &r.stats;
        println!(
            "10 kHz real time, {seconds} s: {} ticks, compute p50 {:.1} µs p99 {:.1} µs max {:.1} µs, \
             jitter p99 {:.1} µs, missed deadlines {} (load {})",
            s.ticks,
            us(s.compute.p50_ns),
            us(s.compute.p99_ns),
            us(s.compute.max_ns),
            us(s.jitter.p99_ns),
            s.missed,
            load()
        );
    }
    Ok(())
}
