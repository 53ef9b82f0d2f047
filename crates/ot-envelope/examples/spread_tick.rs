//! Thread-CPU time of every step of the optical-tweezers world at the 10 kHz scene's settings,
//! spread rebuilds against whole rebuilds (the load-independent side of issue 25 item 6).
//!
//! The cursor follows the default script's waypoints (`scenes/optical_tweezers.script.toml`,
//! 1 mm of stylus = 1 µm, linear between waypoints, no hand model), grab from 0.3 s to 5.3 s,
//! at 10 kHz: 55,000 steps, 50,000 grabbed. Each step is timed by the thread's CPU clock and
//! the wall clock (`bench_harness::timer::span`); the steering counters are printed.
//!
//! `cargo run --release -p ot-envelope --example spread_tick -- [--rounds N]`
#![allow(clippy::unwrap_used)]

use bench_harness::machine::LoadAvg;
use bench_harness::timer::span;
use ot_envelope::world::{Input, Params, World};
use world_form::Limits;

/// The default script's waypoints: (t s, x mm, y mm).
const WAYPOINTS: [(f64, f64, f64); 8] = [
    (0.0, 0.0, 0.0),
    (0.5, 0.0, 0.0),
    (1.5, 4.0, 0.0),
    (2.5, 4.0, 4.0),
    (3.5, 0.0, 4.0),
    (4.5, 0.0, 0.0),
    (4.55, 20.0, 0.0),
    (5.5, 20.0, 0.0),
];

/// Cursor at `t` s, world m (1 mm of stylus = 1 µm).
fn cursor(t: f64) -> [f64; 2] {
    for w in WAYPOINTS.windows(2) {
        if t <= w[1].0 {
            let a = (t - w[0].0) / (w[1].0 - w[0].0);
            return [
                (w[0].1 + a * (w[1].1 - w[0].1)) * 1e-6,
                (w[0].2 + a * (w[1].2 - w[0].2)) * 1e-6,
            ];
        }
    }
    [20e-6, 0.0]
}

fn pct(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rounds: usize = args
        .iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .map_or(1, |s| s.parse().unwrap());
    let rate = 10_000.0;
    println!(
        "| settings | grabbed steps | CPU p50 µs | CPU p99 µs | CPU max µs | wall max µs | slowest (CPU) | builds (spread) | whole builds in grabbed steps | load |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for _ in 0..rounds {
        for (name, budget) in [
            ("spread, 256 evaluations per tick", Some(256)),
            ("whole rebuilds", None),
        ] {
            // the 10 kHz scene's world (scenes/optical_tweezers_10khz.toml)
            let mut p = Params::paper();
            p.stiffness_n_per_m = 0.8;
            p.cursor_radius_m = 150e-9;
            p.velocity_retain = 0.1;
            p.envelope_build_evals_per_tick = budget;
            let mut w = World::new(&p, &Limits::FALCON.in_world(1e6, 1e-3)).unwrap();
            let built_at_load = w.tick_stats().rebuilds;
            let (mut cpu, mut wall) = (Vec::new(), Vec::new());
            let mut slowest = (0.0, 0);
            // (CPU µs, step, what the step did)
            let mut top: Vec<(f64, usize, &'static str)> = Vec::new();
            for k in 0..55_000usize {
                let t = k as f64 / rate;
                let input = Input {
                    cursor_m: cursor(t),
                    grab: (0.3..5.3).contains(&t),
                };
                let before = w.tick_stats();
                let (_, s) = span(|| w.step(&input));
                if w.grabbed() {
                    let after = w.tick_stats();
                    let did = if after.spread_builds > before.spread_builds {
                        "last slice (geometry) + swap"
                    } else if after.rebuilds > before.rebuilds {
                        "whole build"
                    } else if after.build_slices > before.build_slices {
                        "slice"
                    } else {
                        "warm"
                    };
                    top.push((s.cpu_s * 1e6, k, did));
                    cpu.push(s.cpu_s * 1e6);
                    wall.push(s.wall_s * 1e6);
                    if s.cpu_s * 1e6 > slowest.0 {
                        slowest = (s.cpu_s * 1e6, k);
                    }
                }
            }
            let st = w.tick_stats();
            let n = cpu.len();
            println!(
                "| {name} | {n} | {:.1} | {:.1} | {:.1} | {:.1} | step {} | {} ({}) | {} | {} |",
                pct(&mut cpu, 0.5),
                pct(&mut cpu, 0.99),
                pct(&mut cpu, 1.0),
                pct(&mut wall, 1.0),
                slowest.1,
                st.rebuilds,
                st.spread_builds,
                st.rebuilds - st.spread_builds - built_at_load,
                LoadAvg::now().map_or("?".into(), |l| l.to_string()),
            );
            top.sort_by(|a, b| b.0.total_cmp(&a.0));
            let top: Vec<String> = top
                .iter()
                .take(6)
                .map(|(t, k, d)| format!("{k} {d} {t:.0} µs"))
                .collect();
            println!(
                "|   slowest steps (CPU): {} | | | | | | | | | |",
                top.join(", ")
            );
            println!("|   {st:?} | | | | | | | | | |");
        }
    }
}
