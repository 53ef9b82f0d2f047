//! The 3D working envelope mesh against brute-force forward sampling.

mod common;
use common::NM;
use nalgebra::Vector3;
use ot_envelope::envelope3::{icosphere, working_envelope_3d};
use ot_physics::{Method, Propagator, TrapModel};
use std::collections::BTreeMap;

#[test]
fn icosphere_is_closed_and_outward() {
    let m = icosphere(2);
    assert_eq!(m.vertices.len(), 162);
    let mut edges: BTreeMap<(u32, u32), i32> = BTreeMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    // every edge used once in each direction: closed and consistently oriented
    assert!(edges.values().all(|&c| c == 0));
    assert!((m.volume() - 4.0 / 3.0 * std::f64::consts::PI).abs() < 0.15);
    assert!((m.winding(&Vector3::zeros()) - 1.0).abs() < 1e-9);
}

#[test]
fn paper_trap_in_3d_contains_every_sampled_displacement() {
    // lateral waists as the paper, axial 900 nm; Δt = 1 µs; RK4 × 8.
    let model = TrapModel::builder(1e-15, [600e-9, 300e-9, 900e-9])
        .mass(1e-15)
        .build()
        .expect("model");
    let p = Propagator::new(model, Method::Rk4 { substeps: 8 }, 1e-6).expect("prop");
    let v0 = Vector3::new(0.05, 0.0, 0.02);
    let we = working_envelope_3d(&p, &v0, 4, 3.0, 0.1).expect("envelope");
    let mesh = &we.mesh;
    assert!(mesh.volume() > 0.0);
    // brute force: 24³ offsets within ±2.4 waists; images inside the mesh,
    // or within 1.5 nm of it (the flat triangles. chord error at 2562 vertices)
    let w = Vector3::new(600e-9, 300e-9, 900e-9);
    let n = 24;
    let mut worst_out: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let z = Vector3::new(i as f64, j as f64, k as f64) / (n - 1) as f64 * 4.8
                    - Vector3::repeat(2.4);
                let (d, _, _) = p
                    .flow(&(z.component_mul(&w) + v0 * 0.5e-6), &v0)
                    .expect("flow");
                if mesh.winding(&d) < 0.5 {
                    let dist = mesh.distance(&d);
                    worst_out = worst_out.max(dist);
                }
            }
        }
    }
    assert!(worst_out < 1.5 * NM, "worst outside {} nm", worst_out / NM);
    // the mesh is not too big: every vertex is a reachable displacement by construction
    assert!(mesh.winding(&Vector3::zeros()) > 0.99);
}
