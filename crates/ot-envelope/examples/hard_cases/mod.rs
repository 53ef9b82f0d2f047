//! The report's "Hard cases" (section 6 of `bench_report.rs`), shared with the test that holds
//! their printed figures (`tests/figures.rs`): the envelope of a 2D case against a 700×700
//! sampling of the same map, and the 3D case's mesh against 30³ sampled displacements.
#![allow(dead_code)]

use bench_harness::span;
use nalgebra::{Vector2, Vector3};
use ot_envelope::envelope3::working_envelope_3d;
use ot_envelope::reference::Reference;
use ot_envelope::{OffsetRegion, SampledMap, envelope_from_map};
use ot_physics::{Method, Propagator, TrapModel};

type BoxError = Box<dyn std::error::Error>;
type V2 = Vector2<f64>;
const NM: f64 = 1e-9;

/// The paper's trap with waists `w` (m): P0 = 1e-15 J, m = 1e-15 kg.
pub fn model(w: [f64; 2]) -> TrapModel<2> {
    TrapModel::builder(1e-15, w)
        .mass(1e-15)
        .build()
        .expect("model")
}

/// One 2D hard case's envelope.
pub struct HardCase {
    /// The case's tick map.
    pub prop: Propagator<2>,
    /// Fold curves found.
    pub fold_curves: usize,
    /// The polygon's vertices.
    pub vertices: usize,
    /// Whether the zero displacement is inside.
    pub inside: bool,
    /// Hausdorff distance (nm) from a 700×700 sampling of the same map.
    pub hausdorff_nm: f64,
}

/// The envelope of the trap with waists `w` at drift `v0` over `dt` with `meth`.
pub fn hard_case(w: [f64; 2], v0: V2, dt: f64, meth: Method) -> Result<HardCase, BoxError> {
    let prop = Propagator::new(model(w), meth, dt)?;
    let region = OffsetRegion::around_drift(&prop, &v0, 3.0)?;
    let map = SampledMap::build(&prop, &v0, &region, None)?;
    let we = envelope_from_map(&prop, &map, 0.5e-9)?;
    let r = Reference::sample(&prop, &v0, &we.region, 700)?;
    let e = r.errors(&prop, &we.polygon, 2.0 * NM)?;
    Ok(HardCase {
        fold_curves: we.fold_curves,
        vertices: we.polygon.len(),
        inside: we.contains(&V2::zeros()),
        hausdorff_nm: e.hausdorff() / NM,
        prop,
    })
}

/// The 3D hard case's mesh.
pub struct HardCase3d {
    /// The mesh's vertices and triangles.
    pub vertices: usize,
    pub triangles: usize,
    /// Wall-clock seconds of the build.
    pub build_s: f64,
    /// Worst distance (nm) outside the mesh of the displacements sampled at 30³ offsets.
    pub worst_nm: f64,
}

/// Waists 600/300/900 nm, v0 = (50, 0, 20) nm/µs, RK4 × 8 over 1 µs.
pub fn hard_case_3d() -> Result<HardCase3d, BoxError> {
    let m3 = TrapModel::builder(1e-15, [600e-9, 300e-9, 900e-9])
        .mass(1e-15)
        .build()?;
    let p3 = Propagator::new(m3, Method::Rk4 { substeps: 8 }, 1e-6)?;
    let v3 = Vector3::new(0.05, 0.0, 0.02);
    let (we3, s3) = span(|| working_envelope_3d(&p3, &v3, 4, 3.0, 0.1));
    let we3 = we3?;
    let mut worst: f64 = 0.0;
    let n = 30;
    let w3 = Vector3::new(600e-9, 300e-9, 900e-9);
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let z = Vector3::new(i as f64, j as f64, k as f64) / (n - 1) as f64 * 4.8
                    - Vector3::repeat(2.4);
                let (d, _, _) = p3.flow(&(z.component_mul(&w3) + v3 * 0.5e-6), &v3)?;
                if we3.mesh.winding(&d) < 0.5 {
                    worst = worst.max(we3.mesh.distance(&d));
                }
            }
        }
    }
    Ok(HardCase3d {
        vertices: we3.mesh.vertices.len(),
        triangles: we3.mesh.triangles.len(),
        build_s: s3.wall_s,
        worst_nm: worst / NM,
    })
}
