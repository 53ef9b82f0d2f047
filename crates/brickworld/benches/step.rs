//! Criterion benchmarks of one world tick (1 ms) with 100 bricks, 50 of them in stacks.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use brickworld::{BrickPlacement, Grip, Params, World};
use criterion::{Criterion, criterion_group, criterion_main};
use world_form::Limits;

/// 5 stacks of 10 bricks plus 50 loose bricks on a grid, settled for 2 s.
fn scene(sleeping: bool) -> World {
    let mut p = Params {
        loading_zone: None,
        sleeping,
        ..Params::default()
    };
    let h = p.brick_half_extents_m;
    for s in 0..5 {
        for i in 0..10 {
            p.bricks.push(BrickPlacement {
                center_m: [-0.8 + 0.4 * s as f64, 0.8, h[2] * (2 * i + 1) as f64],
                rotation_deg: [0.0; 3],
            });
        }
    }
    for i in 0..50 {
        p.bricks.push(BrickPlacement {
            center_m: [
                -1.0 + 0.25 * (i % 10) as f64,
                -0.8 + 0.2 * (i / 10) as f64,
                h[2],
            ],
            rotation_deg: [0.0, 0.0, 0.0],
        });
    }
    let mut w = World::new(&p, &Limits::FALCON).expect("valid scene");
    for _ in 0..2000 {
        let i = w.input([0.0, 0.0, 0.5], Grip::default()).unwrap();
        w.step(&i);
    }
    w
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("tick_100_bricks");
    for (name, sleeping) in [("resting_asleep", true), ("resting_no_sleep", false)] {
        let mut w = scene(sleeping);
        let mut t = 0u64;
        g.bench_function(name, |b| {
            b.iter(|| {
                t += 1;
                let x = 0.2 * ((t as f64) * 1e-3).sin();
                let i = w.input([x, 0.0, 0.5], Grip::default()).unwrap();
                w.step(&i)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
