//! Issue 13, item 5: our single-trajectory integrator against ode_solvers'
//! Dop853 at equal error (≤ 0.01 nm on the paper problem), as a ratio of
//! CPU times measured in the same run, repeated `--runs` times (default 3).
//!
//! For each side the cheapest setting reaching 0.01 nm is taken: ours among
//! DOP853 with error control (rtol 1e-4 … 1e-10) and DOP853's formula with
//! fixed substeps (1 … 8); the peer's among rtol 1e-2 … 1e-11 (its tolerances
//! are in nm and nm/µs).
//!
//! `cargo run --release -p ot-physics --example dop853_ratio -- [--runs N]`

mod common;

use common::{Problem, Row, measure, peer};
use ot_physics::Method;

const TARGET_NM: f64 = 0.01;

fn cheapest(rows: &[Row]) -> Option<&Row> {
    rows.iter()
        .filter(|r| r.max_err_nm <= TARGET_NM)
        .min_by(|a, b| a.ns_per_traj.total_cmp(&b.ns_per_traj))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let runs: usize = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .map_or(Ok(3), |s| s.parse())?;
    let p = Problem::paper(21)?;
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("load: {}", load.trim());
    println!(
        "| run | ours (setting) | ours ns/traj | ours max err nm | Dop853 (rtol) | Dop853 ns/traj | Dop853 max err nm | ratio |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for run in 1..=runs {
        let mut ours = Vec::new();
        for k in 4..=10 {
            let rtol = 10f64.powi(-k);
            ours.push(measure(
                &p,
                Method::Adaptive { rtol },
                &format!("adaptive rtol 1e-{k}"),
                20.0,
            )?);
        }
        for n in 1..=8 {
            ours.push(measure(
                &p,
                Method::Rk8 { substeps: n },
                &format!("rk8 ×{n}"),
                20.0,
            )?);
        }
        let mut theirs = Vec::new();
        for k in 2..=11 {
            if let Some(r) = peer::measure(&p, 10f64.powi(-k), 20.0) {
                theirs.push(r);
            }
        }
        let (Some(a), Some(b)) = (cheapest(&ours), cheapest(&theirs)) else {
            println!("| {run} | no setting reached {TARGET_NM} nm | | | | | | |");
            continue;
        };
        println!(
            "| {run} | {} | {:.0} | {:.4} | {} | {:.0} | {:.4} | {:.2}× |",
            a.setting,
            a.ns_per_traj,
            a.max_err_nm,
            b.setting,
            b.ns_per_traj,
            b.max_err_nm,
            b.ns_per_traj / a.ns_per_traj
        );
    }
    Ok(())
}
