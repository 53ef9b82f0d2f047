//! BENCHMARKS.md's ot-envelope "Hard cases" table, held to its printed figures by the
//! report's own computation (`examples/bench_report.rs`, section 6): fold curves, polygon
//! vertices, whether the zero displacement is inside, and the Hausdorff distance (nm, to the
//! printed 3 decimals) from a 700×700 sampling of the same map; the 3D case's mesh size and
//! its worst sampled displacement outside the mesh (30³ offsets, 2 decimals).
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::{NM, paper_model};
use nalgebra::{Vector2, Vector3};
use ot_envelope::envelope3::working_envelope_3d;
use ot_envelope::reference::Reference;
use ot_envelope::{OffsetRegion, SampledMap, envelope_from_map};
use ot_physics::{Method, Propagator, TrapModel};

type V2 = Vector2<f64>;

/// `x` rounds to `printed` at `decimals` decimals (two-sided).
fn assert_printed(what: &str, x: f64, printed: f64, decimals: i32) {
    let half = 0.5 * 10f64.powi(-decimals);
    assert!(
        (x - printed).abs() <= half + 1e-12,
        "{what}: {x} does not print as {printed:.*}",
        decimals as usize
    );
}

/// One row of the table: (fold curves, vertices, zero displacement inside, Hausdorff nm).
fn hard_case(w: [f64; 2], v0: V2, dt: f64, meth: Method) -> (usize, usize, bool, f64) {
    let p = Propagator::new(paper_model(w), meth, dt).unwrap();
    let region = OffsetRegion::around_drift(&p, &v0, 3.0).unwrap();
    let map = SampledMap::build(&p, &v0, &region, None).unwrap();
    let we = envelope_from_map(&p, &map, 0.5e-9).unwrap();
    let r = Reference::sample(&p, &v0, &we.region, 700).unwrap();
    let e = r.errors(&p, &we.polygon, 2.0 * NM).unwrap();
    let row = (
        we.fold_curves,
        we.polygon.len(),
        we.contains(&V2::zeros()),
        e.hausdorff() / NM,
    );
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
    let m3 = TrapModel::builder(1e-15, [600e-9, 300e-9, 900e-9])
        .mass(1e-15)
        .build()
        .unwrap();
    let p3 = Propagator::new(m3, Method::Rk4 { substeps: 8 }, 1e-6).unwrap();
    let v3 = Vector3::new(0.05, 0.0, 0.02);
    let we3 = working_envelope_3d(&p3, &v3, 4, 3.0, 0.1).unwrap();
    let mut worst: f64 = 0.0;
    let n = 30;
    let w3 = Vector3::new(600e-9, 300e-9, 900e-9);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let z = Vector3::new(i as f64, j as f64, k as f64) / (n - 1) as f64 * 4.8
                    - Vector3::repeat(2.4);
                let (d, _, _) = p3.flow(&(z.component_mul(&w3) + v3 * 0.5e-6), &v3).unwrap();
                if we3.mesh.winding(&d) < 0.5 {
                    worst = worst.max(we3.mesh.distance(&d));
                }
            }
        }
    }
    eprintln!(
        "3D: {} vertices, {} triangles, worst {} nm",
        we3.mesh.vertices.len(),
        we3.mesh.triangles.len(),
        worst / NM
    );
    assert_eq!(
        (we3.mesh.vertices.len(), we3.mesh.triangles.len()),
        (2562, 5120)
    );
    assert_printed("3D worst outside (nm)", worst / NM, 0.83, 2);
}
