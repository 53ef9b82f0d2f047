//! The cost of a world where everything is awake: one and two layers of 100 bricks with
//! sleeping off, a 200-brick wall knocked over, and a standing one swept by the hand. Prints thread-CPU p50 / p99 / max per tick.
//! Run: `cargo run --release -p brickworld --example brickworld-awake [-- ticks [scene]]`.
//! `BRICKWORLD_SOLVER=scene` times the shipped brick scene's solver setting; it may also hold
//! `[brickworld.params]` lines (`solver_iterations = 1`, ...); unset, the defaults.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

mod common;

use brickworld::Params;
use common::{PARK, Timing, layers, step_idle, time_parked, time_sweep, tower};

fn line(name: &str, t: &Timing) {
    println!(
        "{name:<48} awake {:>3}  CPU p50 {:>7.1}  p99 {:>7.1}  max {:>7.1} µs",
        t.awake,
        t.cpu.median(),
        t.cpu.p99(),
        t.cpu.max()
    );
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(3000);
    // Optional second argument: run only the scenes whose name contains it.
    let only = std::env::args().nth(2).unwrap_or_default();
    let base = common::solver_from_env();
    println!(
        "solver: {} iterations, contacts {} Hz",
        base.solver_iterations, base.contact_frequency_hz
    );
    let off = Params {
        sleeping: false,
        ..base.clone()
    };
    for (name, k) in [
        ("100 bricks, one layer, sleeping off", 1),
        ("200 bricks, two layers, sleeping off", 2),
    ] {
        if !name.contains(&only) {
            continue;
        }
        let mut w = layers(&off, k, 0.005);
        for _ in 0..500 {
            step_idle(&mut w, PARK);
        }
        line(name, &time_parked(&mut w, n));
    }
    for (name, p) in [
        ("200-brick wall knocked over, sleeping on", base.clone()),
        ("200-brick wall knocked over, sleeping off", off.clone()),
    ] {
        if !name.contains(&only) {
            continue;
        }
        let mut w = tower(&p, 20, 10, 1.0);
        line(name, &time_parked(&mut w, n));
    }
    // The hand sweeps at 1 m/s through a standing 200-brick wall (settled 0.5 s first), at
    // 0.3 m, its fifth course: everything it pushes is awake.
    let name = "200-brick wall swept by the hand at 1 m/s";
    if name.contains(&only) {
        let mut w = tower(&base, 20, 0, 0.0);
        for _ in 0..500 {
            step_idle(&mut w, PARK);
        }
        line(name, &time_sweep(&mut w, n, 0.3, 1.0));
    }
}
