//! Criterion micro-benchmarks: envelope, inverse solve, steering
//! continuation and the paper-method baseline (paper constants, RK4 × 8).
//! Errors of each are measured by `examples/bench_report.rs`.

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector2;
use ot_envelope::inverse::TrapSolver;
use ot_envelope::paper::paper_envelope;
use ot_envelope::working_envelope;
use ot_physics::{Method, Propagator, TrapModel};
use std::hint::black_box;

fn benches(c: &mut Criterion) {
    let m = TrapModel::builder(1e-15, [600e-9, 300e-9])
        .mass(1e-15)
        .build()
        .expect("model");
    let p = Propagator::new(m, Method::Rk4 { substeps: 8 }, 1e-6).expect("prop");
    let v0 = Vector2::new(0.1, 0.1);
    c.bench_function("envelope paper v0=(100,100) nm/us", |b| {
        b.iter(|| working_envelope(&p, black_box(&v0), None))
    });
    c.bench_function("envelope paper v0=0", |b| {
        b.iter(|| working_envelope(&p, black_box(&Vector2::zeros()), None))
    });
    let solver = TrapSolver::new(&p, &v0, None, None).expect("solver");
    let target = Vector2::new(250e-9, 120e-9);
    c.bench_function("solve all branches (map ready)", |b| {
        b.iter(|| solver.solve(black_box(&target)))
    });
    let prev = solver.solve(&target).expect("solve").0.offsets()[0] + Vector2::new(8e-9, -5e-9);
    c.bench_function("steer: continue previous branch", |b| {
        b.iter(|| solver.steer(black_box(&target), Some(&prev)))
    });
    let region = solver.map().region;
    let mut g = c.benchmark_group("baseline");
    g.sample_size(10);
    g.bench_function("paper method, targets every 32 nm", |b| {
        b.iter(|| {
            paper_envelope(
                &p,
                &v0,
                &region,
                0.3,
                Vector2::new(-520e-9, -740e-9),
                Vector2::new(700e-9, 840e-9),
                32e-9,
            )
        })
    });
    g.finish();
}

criterion_group!(group, benches);
criterion_main!(group);
