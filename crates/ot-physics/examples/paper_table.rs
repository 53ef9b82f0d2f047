//! The paper problem: each integrator's displacement error against a
//! converged reference, with its CPU time — the project's main job until
//! the haptic loop's `demo` lands.
//!
//! `cargo run --release -p ot-physics --example paper_table`

mod common;

use common::{Problem, measure, peer};
use ot_physics::{Composition, DEFAULT_RTOL, Method, paper};

fn main() -> Result<(), ot_physics::PhysicsError> {
    let p = Problem::paper(21)?;
    println!(
        "Paper problem: a = 600 nm, b = 300 nm, P0 = 1e-6 nJ, m = 1e-12 g, Δt = 1 µs;\n\
         {} starts (21×21 offsets in ±1.5 µm, v0 = 0 and (100,100) nm/µs);\n\
         reference DOP853 rtol 1e-14 (agrees with rtol 1e-13 to {:.1e} nm).\n",
        p.starts.len(),
        p.reference_error / 1e-9
    );
    let methods = [
        (Method::PaperRk4, "one RK4 step (the paper)"),
        (Method::Rk4 { substeps: 16 }, "16 substeps"),
        (Method::Dopri5 { rtol: 1e-8 }, "rtol 1e-8"),
        (Method::Adaptive { rtol: DEFAULT_RTOL }, "default"),
        (
            Method::Symplectic {
                substeps: 16,
                composition: Composition::Yoshida4,
            },
            "16 substeps",
        ),
    ];
    println!(
        "{:<22} {:<26} {:>14} {:>14} {:>12} {:>10}",
        "method", "setting", "max err (nm)", "mean err (nm)", "ns / traj", "evals"
    );
    let mut rows = Vec::new();
    for (m, s) in methods {
        rows.push(measure(&p, m, s, 30.0)?);
    }
    if let Some(r) = peer::measure(&p, 1e-8, 30.0) {
        rows.push(r);
    }
    for r in &rows {
        println!(
            "{:<22} {:<26} {:>14.3e} {:>14.3e} {:>12.0} {:>10.1}",
            r.method, r.setting, r.max_err_nm, r.mean_err_nm, r.ns_per_traj, r.evals_per_traj
        );
    }
    let _ = paper::DT;
    println!(
        "\nFull work-precision sweep: cargo run --release -p ot-physics --example ot-physics-report"
    );
    Ok(())
}
