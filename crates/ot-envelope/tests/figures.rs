//! BENCHMARKS.md's ot-envelope "Hard cases" table, held to its printed figures by the
//! report's own computation (`examples/bench_report.rs`, section 6, through
//! `examples/hard_cases`): fold curves, polygon vertices, whether the zero displacement is
//! inside, and the Hausdorff distance (nm, to the printed 3 decimals) from a 700×700 sampling
//! of the same map; the 3D case's mesh size and its worst sampled displacement outside the mesh
//! (30³ offsets, 2 decimals).
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
#[path = "../examples/hard_cases/mod.rs"]
mod hard_cases;

use common::assert_printed;
use nalgebra::Vector2;
use ot_physics::Method;

type V2 = Vector2<f64>;

/// One row of the table (`examples/hard_cases`): (fold curves, vertices, zero displacement
/// inside, Hausdorff nm).
fn hard_case(w: [f64; 2], v0: V2, dt: f64, meth: Method) -> (usize, usize, bool, f64) {
    let c = hard_cases::hard_case(w, v0, dt, meth).unwrap();
    let row = (c.fold_curves, c.vertices, c.inside, c.hausdorff_nm);
    eprintln!("{row:?}");
    row
}

fn check(row: (usize, usize, bool, f64), folds: usize, vertices: usize, inside: bool, h: f64) {
    assert_eq!((row.0, row.1, row.2), (folds, vertices, inside), "{row:?}");
    assert_printed("Hausdorff (nm)", row.3, h, 3);
}

const PAPER_W: [f64; 2] = [600e-9, 300e-9];

#[test]
fn hard_case_paper_one_step_model() {
    let row = hard_case(PAPER_W, V2::zeros(), 1e-6, Method::PaperRk4);
    check(row, 4, 364, true, 0.030);
}

#[test]
fn hard_case_five_microsecond_tick() {
    let row = hard_case(PAPER_W, V2::zeros(), 5e-6, Method::Rk4 { substeps: 48 });
    check(row, 7, 788, true, 0.030);
}

#[test]
fn hard_case_fast_particle() {
    let row = hard_case(
        PAPER_W,
        V2::new(3.0, 1.0),
        1e-6,
        Method::Rk4 { substeps: 8 },
    );
    check(row, 1, 238, false, 0.406);
}

#[test]
fn hard_case_line_trap() {
    let row = hard_case(
        [30e-6, 300e-9],
        V2::zeros(),
        1e-6,
        Method::Rk4 { substeps: 8 },
    );
    check(row, 1, 96, true, 0.063);
}

#[test]
fn hard_case_fig7() {
    let row = hard_case(
        PAPER_W,
        V2::new(0.1, 0.1),
        1.3e-6,
        Method::Rk4 { substeps: 12 },
    );
    check(row, 1, 392, true, 0.083);
}

#[test]
fn hard_case_3d() {
    let c = hard_cases::hard_case_3d().unwrap();
    eprintln!(
        "3D: {} vertices, {} triangles, worst {} nm",
        c.vertices, c.triangles, c.worst_nm
    );
    assert_eq!((c.vertices, c.triangles), (2562, 5120));
    assert_printed("3D worst outside (nm)", c.worst_nm, 0.83, 2);
}
