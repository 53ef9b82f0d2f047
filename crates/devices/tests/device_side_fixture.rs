//! The device side's reference trace: what `haptic_devices::local::DeviceSide` renders for a
//! fixed sequence of readings and force packets (protocol 1 and 2: late and overtaken answers,
//! contact planes, a carried body with its contact planes, the two-port layer acting). The
//! trace is `tests/python/fixtures/device_side.json`; the Python reference client
//! (`nanohaptics.bridge`, tests/python/test_bridge_v2.py) must render the same forces from
//! the same bytes. This test fails when the Rust side's trace changes; regenerate with
//! `NANOHAPTICS_BLESS=1 cargo test -p haptic-devices --test device_side_fixture`.
#![allow(clippy::unwrap_used)]

use haptic_devices::bridge::protocol::{ForceReply, Packet};
use haptic_devices::local::{DeviceSide, Protocol};
use haptic_types::local::{Body, LocalModel, Plane};
use serde_json::{Value, json};

const PERIOD_S: f64 = 1e-3;
const SERVO_S: f64 = 2.5e-4;
const MAX_FORCE_N: f64 = 8.0;

/// The stylus at servo instant `i`: a slow circle dipping below z = 0, m.
fn stylus(i: u64) -> [f64; 3] {
    let t = i as f64 * SERVO_S;
    [
        0.01 * (3.0 * t).sin(),
        0.004 * (2.0 * t).cos(),
        -0.003 + 0.004 * (5.0 * t).cos(),
    ]
}

/// The answer to sample `seq`: a floor and a wall; a body carried from seq 80 to 220, with the
/// floor under it; the world's energy running low from seq 150 (the two-port layer acts).
fn answer(seq: u64, p0: [f64; 3], with_local: bool) -> ForceReply {
    let floor = Plane {
        normal: [0.0, 0.0, 1.0],
        offset_m: -0.002,
        stiffness_n_per_m: 2000.0,
    };
    let wall = Plane {
        normal: [-1.0, 0.0, 0.0],
        offset_m: -0.008,
        stiffness_n_per_m: 1500.0,
    };
    let carried = (80..220).contains(&seq);
    let body = carried.then(|| Body {
        position_m: [p0[0], p0[1], p0[2] - 0.001],
        velocity_m_per_s: [0.002, 0.0, -0.001],
        mass_kg: 1.25,
        stiffness_n_per_m: 900.0,
        series_stiffness_n_per_m: 900.0,
        damping_n_s_per_m: 60.0,
        damper_m: [0.0, 0.0, 0.0005],
        external_force_n: [0.0, 0.0, -0.6],
        substeps: 4,
        restitution: 0.2,
    });
    let local = LocalModel {
        residual_force_n: [0.05, -0.02, 0.1],
        residual_stiffness_n_per_m: if seq % 3 == 0 {
            [30.0, 0.0, 0.0, 0.0, 30.0, 0.0, 0.0, 0.0, 10.0]
        } else {
            [0.0; 9]
        },
        planes: vec![floor, wall],
        body,
        body_planes: if carried {
            vec![Plane {
                normal: [0.0, 0.0, 1.0],
                offset_m: -0.004,
                stiffness_n_per_m: 0.0,
            }]
        } else {
            Vec::new()
        },
        world_energy_j: if seq < 150 {
            0.0
        } else {
            -0.05 - 1e-4 * seq as f64
        },
        bond: None,
    };
    ForceReply {
        seq,
        tick: seq,
        force_n: [0.1, 0.2, 1.5],
        stiffness_n_per_m: [100.0, 0.0, 0.0, 0.0, 100.0, 0.0, 0.0, 0.0, 400.0],
        status: 0,
        local: with_local.then(|| Box::new(local)),
    }
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// One case: 300 loop periods of 4 servo instants; sample k is read at instant 4k; its answer
/// arrives 3 periods later (sample 7k + 3's 2 periods later still: it overtakes the one before).
fn case(protocol: Protocol) -> Value {
    let mut side = DeviceSide::new(protocol, MAX_FORCE_N, PERIOD_S);
    let mut steps = Vec::new();
    let mut readings = Vec::new();
    for k in 0..300u64 {
        let p = stylus(4 * k);
        readings.push(p);
        side.record_reading(k, p);
        steps.push(json!({"op": "reading", "seq": k, "p": p}));
        // Answers arriving now: for samples k − 3 (and k − 2 when it overtakes).
        let mut arriving: Vec<u64> = Vec::new();
        if k >= 3 && (k - 3) % 7 != 3 {
            arriving.push(k - 3);
        }
        if k >= 2 && (k - 2) % 7 == 3 {
            arriving.push(k - 2);
        }
        for seq in arriving {
            let reply = answer(
                seq,
                readings[usize::try_from(seq).unwrap()],
                protocol == Protocol::V2,
            );
            let bytes = Packet::Force(reply.clone()).encode();
            side.receive(&reply.command(), reply.local.as_deref().cloned());
            steps.push(json!({"op": "receive", "packet_hex": hex(&bytes)}));
        }
        for j in 0..4 {
            let q = stylus(4 * k + j);
            let f = side.render(q, SERVO_S);
            steps.push(json!({"op": "render", "p": q, "servo_s": SERVO_S, "f": f}));
        }
    }
    json!({
        "protocol": protocol.version(),
        "max_force_n": MAX_FORCE_N,
        "period_s": PERIOD_S,
        "interventions": side.interventions(),
        "work_j": side.work_j(),
        "steps": steps,
    })
}

#[test]
fn the_device_sides_reference_trace_is_unchanged() {
    let trace = json!({
        "about": "haptic_devices::local::DeviceSide rendering fixed readings and force packets; \
                  generated by crates/devices/tests/device_side_fixture.rs",
        "cases": [case(Protocol::V1), case(Protocol::V2)],
    });
    // The layer acts in the protocol-2 case, and not in protocol 1 (it has none).
    assert_eq!(trace["cases"][0]["interventions"], 0);
    assert!(trace["cases"][1]["interventions"].as_u64().unwrap() > 0);
    let text = serde_json::to_string_pretty(&trace).unwrap() + "\n";
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/python/fixtures/device_side.json");
    if std::env::var_os("NANOHAPTICS_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        stored == text,
        "{} differs from the device side's trace: regenerate it with NANOHAPTICS_BLESS=1",
        path.display()
    );
}
