//! Criterion micro-benchmarks: one paper-problem flow per method, each
//! labelled with the displacement error it reaches against a converged
//! reference (DOP853, rtol 1e-13) on the same start.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use ot_physics::{Composition, Method, Propagator, paper};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let model = paper::model().expect("paper constants are valid");
    // the example: particle 100 nm right of and 50 nm above the trap,
    // moving at (100, 100) nm/µs
    let offset = Vector2::new(-100e-9, -50e-9);
    let v0 = Vector2::from(paper::V0_MOVING);
    let reference = Propagator::new(model, Method::Adaptive { rtol: 1e-13 }, paper::DT)
        .and_then(|p| p.flow(&offset, &v0))
        .expect("reference")
        .0;
    let methods = [
        Method::PaperRk4,
        Method::Rk4 { substeps: 16 },
        Method::Rk8 { substeps: 4 },
        Method::Dopri5 { rtol: 1e-6 },
        Method::default(),
        Method::Symplectic {
            substeps: 16,
            composition: Composition::Yoshida4,
        },
    ];
    let mut g = c.benchmark_group("flow");
    for m in methods {
        let p = Propagator::new(model, m, paper::DT).expect("valid method");
        let (d, _, evals) = p.flow(&offset, &v0).expect("flow");
        let err_nm = (d - reference).norm() / 1e-9;
        g.bench_function(
            format!("{} err={err_nm:.1e}nm evals={evals}", m.name()),
            |b| b.iter(|| p.flow(black_box(&offset), black_box(&v0))),
        );
    }
    g.finish();
    let p = Propagator::new(model, Method::default(), paper::DT).expect("valid");
    let f = p.flow_jacobian(&offset, &v0).expect("flow");
    let err_nm = (f.displacement - reference).norm() / 1e-9;
    c.bench_function(&format!("flow_jacobian/adaptive err={err_nm:.1e}nm"), |b| {
        b.iter(|| p.flow_jacobian(black_box(&offset), black_box(&v0)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
