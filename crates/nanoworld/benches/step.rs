//! Criterion benchmarks of one world tick: the tip hovering inside the activation range
//! (every tick sums the pair law over the substrate atoms in range via the cell list).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use nanoworld::{Params, TipInput, World};

/// Game-default world with an n × n substrate and nothing else.
fn world(n: usize) -> World {
    let mut p = Params::game_default();
    p.substrate.nx = n;
    p.substrate.ny = n;
    p.loading_zone = None;
    p.initial_atoms_xy_m.clear();
    p.house = None;
    let c = n as f64 * p.substrate.spacing_m / 2.0;
    World::new(&p, &p.default_limits(), Vector3::new(c, c, 2e-9)).expect("valid bench world")
}

/// A circle of radius 1 nm at 0.25 nm surface gap above the substrate centre, 1000 ticks.
fn hover_path(w: &World) -> Vec<TipInput> {
    let p = w.params();
    let n = p.substrate.nx as f64;
    let c = n * p.substrate.spacing_m / 2.0;
    let z = p.substrate.atom_radius_m + p.tip.radius_m + 0.25e-9;
    (0..1000)
        .map(|k| {
            let t = k as f64 / 1000.0 * std::f64::consts::TAU;
            TipInput {
                position_m: Vector3::new(c + 1e-9 * t.cos(), c + 1e-9 * t.sin(), z),
            }
        })
        .collect()
}

fn bench_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("step_hover");
    for n in [32usize, 100, 317, 1000] {
        let mut w = world(n);
        let path = hover_path(&w);
        let mut k = 0;
        g.bench_with_input(BenchmarkId::from_parameter(n * n), &n, |b, _| {
            b.iter(|| {
                k = (k + 1) % path.len();
                w.step(&path[k], 1e-3).expect("valid input").force_n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_step);
criterion_main!(benches);
