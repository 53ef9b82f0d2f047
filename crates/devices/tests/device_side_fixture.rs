//! The device side's reference trace: what `haptic_devices::local::DeviceSide` renders for a
//! fixed sequence of readings and force packets (protocols 1 to 4: late and overtaken
//! answers, contact planes, a carried body with its contact planes, the two-port layer acting,
//! a bond that holds and breaks, a follower stepped through its envelope). The
//! trace is `tests/python/fixtures/device_side.json`; the Python reference client
//! (`nanohaptics.bridge`, tests/python/test_bridge_v2.py) must render the same forces from
//! the same bytes. This test fails when the Rust side's trace changes; regenerate with
//! `NANOHAPTICS_BLESS=1 cargo test -p haptic-devices --test device_side_fixture`.
#![allow(clippy::unwrap_used)]

use haptic_devices::bridge::protocol::{ForceReply, Packet};
use haptic_devices::local::{DeviceSide, Protocol};
use haptic_types::local::{Body, Bond, Follower, LocalModel, Plane};
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
/// floor under it; the world's energy running low from seq 150 (the two-port layer acts); with
/// `protocol` 3 or 4, from seq 30 to 120 a bond anchored just below the answered reading that
/// the stylus stretches past its 0.1 mm in some answers' life (it holds, then breaks); with
/// `protocol` 4, from seq 40 to 200 a follower 20 µm behind the answered reading whose
/// envelope (26 by 13 µm a sample, about a drift of 2 µm) the stylus, moving up to 30 µm a
/// sample, outruns at times: its spring acts, its particle is stepped with every reading.
fn answer(seq: u64, p0: [f64; 3], protocol: Protocol) -> ForceReply {
    let with_local = protocol != Protocol::V1;
    let follower = (protocol == Protocol::V4 && (40..200).contains(&seq)).then(|| Follower {
        position_m: [p0[0] - 2e-5, p0[1] + 1e-5],
        drift_m: [2e-6, -1e-6],
        reach_m: (0..24)
            .map(|k| {
                let th = std::f64::consts::TAU * f64::from(k) / 24.0;
                [2.6e-5 * th.cos(), 1.3e-5 * th.sin()]
            })
            .collect(),
        retain: 0.1,
        stiffness_n_per_m: 600.0,
    });
    let has_bond = matches!(protocol, Protocol::V3 | Protocol::V4);
    let bond = (has_bond && (30..120).contains(&seq)).then_some(Bond {
        anchor_m: [p0[0], p0[1], p0[2] - 0.00002],
        normal: [0.0, 0.0, 1.0],
        stiffness_n_per_m: 700.0,
        break_m: 0.0001,
    });
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
        bond,
        follower,
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
            let reply = answer(seq, readings[usize::try_from(seq).unwrap()], protocol);
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
        "cases": [
            case(Protocol::V1),
            case(Protocol::V2),
            case(Protocol::V3),
            case(Protocol::V4)
        ],
    });
    // The layer acts in the protocol-2 case, and not in protocol 1 (it has none).
    assert_eq!(trace["cases"][0]["interventions"], 0);
    assert!(trace["cases"][1]["interventions"].as_u64().unwrap() > 0);
    // Protocol 3's bond holds in some of its renders and has broken in others: while bonds
    // are answered (samples 30–119, arriving 3 periods later), the forces differ from
    // protocol 2's where it holds and equal them where it broke (207 and 137 of 344).
    let renders = |c: usize| -> Vec<Value> {
        let steps = trace["cases"][c]["steps"].as_array().unwrap();
        steps
            .iter()
            .filter(|s| s["op"] == "render")
            .map(|s| s["f"].clone())
            .collect()
    };
    let (v2, v3, v4) = (renders(1), renders(2), renders(3));
    let held = (4 * 34..4 * 120).filter(|&i| v2[i] != v3[i]).count();
    assert_eq!((held, 4 * 86 - held), (207, 137));
    // Protocol 4's follower (answered for samples 40–199, arriving 3 periods later): its
    // spring acts in 516 of the 624 renders meanwhile and not in 108 (the stylus inside the
    // envelope); before it, protocol 4 renders as protocol 3.
    assert_eq!(&v3[..4 * 43], &v4[..4 * 43]);
    let pushed = (4 * 44..4 * 200).filter(|&i| v3[i] != v4[i]).count();
    assert_eq!((pushed, 4 * 156 - pushed), (516, 108));
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

/// The bond as the device side renders it: `k (a − p)` while it holds at the position read
/// now, nothing once stretched past its breaking stretch (the residual then alone), and never
/// under protocol 2, which drops it.
#[test]
fn a_version_3_device_renders_the_bond_until_it_breaks_and_a_version_2_device_never() {
    let bond = Bond {
        anchor_m: [0.0, 0.0, 0.0],
        normal: [0.0, 0.0, 1.0],
        stiffness_n_per_m: 500.0,
        break_m: 0.002,
    };
    let reply = ForceReply {
        seq: 0,
        tick: 0,
        force_n: [0.0; 3],
        stiffness_n_per_m: [0.0; 9],
        status: 0,
        local: Some(Box::new(LocalModel {
            residual_force_n: [0.0, 0.1, 0.0],
            bond: Some(bond),
            world_energy_j: 1.0,
            ..LocalModel::default()
        })),
    };
    let render = |protocol, p: [f64; 3]| {
        let mut side = DeviceSide::new(protocol, MAX_FORCE_N, PERIOD_S);
        side.record_reading(0, [0.0; 3]);
        side.receive(&reply.command(), reply.local.as_deref().cloned());
        side.render(p, SERVO_S)
    };
    // 1.5 mm of pull: it holds, 0.75 N back towards the anchor.
    assert_eq!(render(Protocol::V3, [0.0, 0.0, 0.0015]), [0.0, 0.1, -0.75]);
    // 2.5 mm of pull, or 2.5 mm of shear while pressed in: broken, the residual alone.
    assert_eq!(render(Protocol::V3, [0.0, 0.0, 0.0025]), [0.0, 0.1, 0.0]);
    assert_eq!(render(Protocol::V3, [0.0025, 0.0, -0.001]), [0.0, 0.1, 0.0]);
    // 3 mm pressed in without shear: still bonded, pushing back out.
    assert_eq!(render(Protocol::V3, [0.0, 0.0, -0.003]), [0.0, 0.1, 1.5]);
    // Protocol 2 drops the bond: the residual alone wherever the stylus is.
    assert_eq!(render(Protocol::V2, [0.0, 0.0, 0.0015]), [0.0, 0.1, 0.0]);
}
