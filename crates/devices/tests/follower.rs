//! Protocol 4's follower on the device side: a world that is a follower, answering a round
//! trip late, is rendered by the device as the world will answer the reading it holds now,
//! bit for bit; protocol 3 drops the follower and renders the answer's residual alone.
#![allow(clippy::unwrap_used)]

use haptic_devices::local::{DeviceSide, Protocol};
use haptic_types::device::ForceCommand;
use haptic_types::local::{Follower, LocalModel};

/// The hand's path, m, sample by sample: out along x faster than the particle can follow
/// (0.3 mm a sample against an envelope of 0.1 mm), back slowly (inside the envelope), then
/// round a circle.
fn path(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|s| {
            let t = s as f64;
            if s < 40 {
                [3e-4 * t, 0.0, 0.0]
            } else if s < 120 {
                [3e-4 * 40.0 - 5e-5 * (t - 40.0), 0.0, 1e-3]
            } else {
                let th = (t - 120.0) * 0.05;
                [8e-3 * th.cos(), 8e-3 * th.sin(), 0.0]
            }
        })
        .collect()
}

fn world() -> Follower {
    Follower {
        position_m: [0.0; 2],
        drift_m: [0.0; 2],
        reach_m: (0..24)
            .map(|k| {
                let th = std::f64::consts::TAU * f64::from(k) / 24.0;
                [1e-4 * th.cos(), 0.6e-4 * th.sin()]
            })
            .collect(),
        retain: 0.1,
        stiffness_n_per_m: 800.0,
    }
}

/// Runs the world and a device speaking `protocol` behind `delay` samples each way; returns
/// the device's rendered force and the world's own answer for each reading.
fn run(protocol: Protocol, delay: usize) -> Vec<([f64; 3], [f64; 3])> {
    let readings = path(400);
    let mut w = world();
    let mut answers: Vec<(ForceCommand, LocalModel)> = Vec::new();
    let mut truth = Vec::new();
    let mut dev = DeviceSide::new(protocol, 100.0, 1e-3);
    let mut out = Vec::new();
    for (s, &p) in readings.iter().enumerate() {
        // The world's tick for sample s: its force, its model (the follower as the sample
        // met it), then its step.
        let f = w.force(p);
        truth.push(f);
        let cmd = ForceCommand {
            tick: s as u64,
            seq: s as u64,
            force_n: f,
            stiffness_n_per_m: [800.0, 0.0, 0.0, 0.0, 800.0, 0.0, 0.0, 0.0, 800.0],
            status: 0,
        };
        let model = LocalModel {
            follower: Some(w.clone()),
            world_energy_j: 1e9,
            ..LocalModel::default()
        };
        answers.push((cmd, model));
        w.step(p);
        // The device: its reading sent, the answer a round trip old arrives, its force.
        dev.record_reading(s as u64, p);
        if let Some(k) = s.checked_sub(2 * delay) {
            let (cmd, model) = answers[k].clone();
            dev.receive(&cmd, Some(model));
            out.push((dev.render(p, 1e-3), truth[s]));
        }
    }
    out
}

#[test]
fn the_device_renders_the_follower_as_the_world_will_answer_the_reading_it_holds() {
    for delay in [0, 1, 5, 20] {
        let v4 = run(Protocol::V4, delay);
        assert!(v4.len() > 300);
        for (i, (felt, world)) in v4.iter().enumerate() {
            assert_eq!(felt, world, "round trip {} samples, reading {i}", 2 * delay);
        }
        // The path pushes past the envelope: the world's force is not zero everywhere.
        let peak = v4.iter().map(|r| r.1[0].abs()).fold(0.0, f64::max);
        assert!(peak > 1.0, "{peak} N");
    }
    // Protocol 3 drops the follower: the device renders the residual (zero here) while the
    // world pushes back.
    let v3 = run(Protocol::V3, 5);
    assert!(v3.iter().all(|r| r.0 == [0.0; 3]));
    assert!(v3.iter().any(|r| r.1[0].abs() > 1.0));
}
