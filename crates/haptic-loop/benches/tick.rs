//! Criterion micro-benchmarks: one tick of the loop around the wall scene (with and without
//! encoding the tick's messages) and the CDR encoding of a force message.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use haptic_engine::haptic::HapticLoop;
use haptic_loop::encode::LoopEncoder;
use haptic_loop::scene::load_scene;
use haptic_types::Buttons;
use haptic_types::DeviceSample;
use recording::TickEncoder;
use recording::channels::messages::ForceMsg;
use std::hint::black_box;

const SCENE: &str = include_str!("../../../scenes/wall.toml");

fn bench(c: &mut Criterion) {
    let s = load_scene(SCENE, None).unwrap();
    let mut lp = HapticLoop::new(s.config, s.scene);
    let mut n = 0u64;
    c.bench_function("wall tick (loop only)", |b| {
        b.iter(|| {
            n += 1;
            let z = -0.004 + 0.002 * ((n % 100) as f64 / 100.0);
            let r = lp.tick(DeviceSample::new([0.001, 0.0, z], Buttons(1)), false);
            black_box(r.device_force_n)
        })
    });
    let s = load_scene(SCENE, None).unwrap();
    let mut lp = HapticLoop::new(s.config, s.scene);
    let mut enc = LoopEncoder::new(&lp, 0);
    let mut msgs = Vec::with_capacity(16);
    c.bench_function("wall tick + encode all channels", |b| {
        b.iter(|| {
            let sample = DeviceSample::new([0.001, 0.0, -0.004], Buttons(0));
            lp.tick(sample, false);
            msgs.clear();
            msgs.push(TickEncoder::input(lp.next_tick() - 1, &sample, false));
            enc.outputs(lp.last_result(), &lp, &mut msgs);
            black_box(msgs.len())
        })
    });
    let f = ForceMsg {
        tick: 12345,
        world_force_n: [0.1, 0.2, 0.3],
        device_force_n: [0.1, 0.2, 0.3],
        engagement: 1.0,
        status: 0,
        watchdog: 1.0,
        device_stiffness_n_per_m: [0.0; 9],
    };
    c.bench_function("CDR encode force message", |b| {
        b.iter(|| black_box(f.encode()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
