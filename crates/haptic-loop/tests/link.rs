//! Every built-in scene on every device preset, loose grip and firm, behind a link (issue 31):
//! one-way latency {0, 0.5, 1, 2, 5, 10, 20, 50} ms, each also with 1 ms of jitter and 5 % loss
//! in both directions, the device side speaking bridge protocol 2 (the local model, the
//! two-port passivity layer). The criteria are issue 22's
//! ([`haptic_loop::closed_loop::Report::stable`]), measured on the force the device's motors
//! rendered: no undeclared jump above 1 N, at most 10 % of the power above 50 Hz, the observer
//! within its reserve.
//!
//! Asserted: every run up to 10 ms one way is stable (the target); the 20 and 50 ms runs (the
//! goal) are printed with their figures and must keep the energy the motors put into the hand
//! below 0.1 J. And the contrast that is the reason for protocol 2: the carried brick
//! on a loosely held Falcon buzzes behind 2 ms with protocol 1 and not with protocol 2.
#![allow(clippy::unwrap_used)]

use haptic_devices::link::LinkParams;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop::{Linked, Report, run_linked};

fn read(name: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    std::fs::read_to_string(root.join(name)).unwrap()
}

const SCENES: [(&str, &str); 5] = [
    ("wall.toml", "wall.script.toml"),
    ("brickworld.toml", "brickworld.script.toml"),
    ("nanoworld.toml", "nanoworld.script.toml"),
    ("optical_tweezers.toml", "optical_tweezers.script.toml"),
    (
        "optical_tweezers_10khz.toml",
        "optical_tweezers.script.toml",
    ),
];

const LATENCIES_MS: [f64; 8] = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];

fn link(ms: f64, bad: bool) -> LinkParams {
    LinkParams {
        latency_s: ms * 1e-3,
        jitter_s: if bad { 1e-3 } else { 0.0 },
        loss: if bad { 0.05 } else { 0.0 },
        seed: 7,
    }
}

fn line(label: &str, r: &Report) -> String {
    format!(
        "{label:<58} {} jumps {:>3}, max jump {:>6.3} N, above 50 Hz {:.4}, observer min {:+.4} J, \
         motors' work on the hand {:+.4} J, two-port {:>5}",
        if r.stable() { "stable  " } else { "UNSTABLE" },
        r.undeclared_jumps,
        r.max_jump_n,
        r.hf_fraction,
        r.min_observer_j,
        r.energy_to_hand_j,
        r.device_interventions
    )
}

#[test]
fn every_scene_on_every_device_is_stable_behind_a_link_of_up_to_10_ms() {
    // Every (scene, device, grip, latency, link) case, run on two threads.
    let mut cases = Vec::new();
    for (scene, script) in SCENES {
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                for ms in LATENCIES_MS {
                    for bad in [false, true] {
                        cases.push((scene, script, mech, grip, ms, bad));
                    }
                }
            }
        }
    }
    assert_eq!(cases.len(), 5 * 4 * 2 * 8 * 2);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&(scene, script, mech, grip, ms, bad)) = cases.get(i) else {
                        break;
                    };
                    let l = Linked {
                        link: link(ms, bad),
                        protocol: Protocol::V2,
                    };
                    let (r, _) = run_linked(&read(scene), &read(script), mech, grip, &l, None)
                        .unwrap_or_else(|e| panic!("{scene} on {}: {e}", mech.name));
                    let label =
                        format!("{scene} {} {} {}", mech.name, grip.label(), l.link.label());
                    results.lock().unwrap().push((i, ms, label, r));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    let mut unstable = Vec::new();
    let mut goal_unstable = 0;
    let mut worst_goal_energy: f64 = f64::NEG_INFINITY;
    for (_, ms, label, r) in &results {
        println!("{}", line(label, r));
        if *ms <= 10.0 && !r.stable() {
            unstable.push(label.clone());
        }
        if *ms > 10.0 {
            goal_unstable += u32::from(!r.stable());
            worst_goal_energy = worst_goal_energy.max(r.energy_to_hand_j);
        }
    }
    println!(
        "{goal_unstable} of {} runs unstable at 20 and 50 ms (the goal); the most energy the \
         motors put into a hand there: {worst_goal_energy:+.4} J",
        5 * 4 * 2 * 2 * 2
    );
    // Beyond the target the two-port layer still bounds the energy the motors can put into
    // the hand (protocol 1 pumps joules into it from 2 ms on).
    assert!(worst_goal_energy < 0.1, "{worst_goal_energy} J");
    assert!(unstable.is_empty(), "unstable up to 10 ms: {unstable:#?}");
}

/// Why protocol 2: the carried brick on a loosely held Falcon behind 2 ms each way. With
/// protocol 1 the device renders the answered force and stiffness (`F0 − K (p − p0)`), and the
/// brick's coupling reaches the hand a round trip late: it buzzes and pumps joules into the
/// hand. With protocol 2 the device integrates the brick itself: stable.
#[test]
fn the_carried_brick_buzzes_behind_2_ms_with_protocol_1_and_not_with_protocol_2() {
    let (scene, script) = (read("brickworld.toml"), read("brickworld.script.toml"));
    let run = |protocol| {
        let l = Linked {
            link: LinkParams::latency_ms(2.0),
            protocol,
        };
        run_linked(&scene, &script, Mechanics::FALCON, Grip::LOOSE, &l, None)
            .unwrap()
            .0
    };
    let (v1, v2) = (run(Protocol::V1), run(Protocol::V2));
    println!("{}", line("protocol 1, 2 ms", &v1));
    println!("{}", line("protocol 2, 2 ms", &v2));
    assert!(!v1.stable() && v1.undeclared_jumps > 100 && v1.energy_to_hand_j > 1.0);
    assert!(v2.stable() && v2.energy_to_hand_j < 0.0);
    // The house still gets built through the link.
    assert!(v2.house_complete_s.is_some_and(|t| t > 0.0));
}

/// A linked run is simulated in whole nanoseconds with seeded draws: it repeats to the bit,
/// every reading and every force the hand felt as well as the summary.
#[test]
fn a_run_behind_a_lossy_jittery_link_repeats_to_the_bit() {
    let (scene, script) = (read("wall.toml"), read("wall.script.toml"));
    let l = Linked {
        link: link(5.0, true),
        protocol: Protocol::V2,
    };
    let a = run_linked(&scene, &script, Mechanics::TOUCH, Grip::LOOSE, &l, None).unwrap();
    let b = run_linked(&scene, &script, Mechanics::TOUCH, Grip::LOOSE, &l, None).unwrap();
    assert_eq!(a.0, b.0);
    assert!(!a.1.felt.is_empty() && a.1.felt.len() == a.1.readings.len());
    let bits = |t: &haptic_loop::closed_loop::Trace| -> Vec<u64> {
        (t.readings.iter().chain(&t.felt))
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(bits(&a.1), bits(&b.1));
    // And an ideal link with protocol 1 is the closed loop of issue 22.
    let ideal = run_linked(
        &scene,
        &script,
        Mechanics::TOUCH,
        Grip::LOOSE,
        &Linked::IDEAL,
        None,
    )
    .unwrap()
    .0;
    assert!(ideal.stable());
}

#[test]
fn a_bad_link_is_refused_by_name() {
    let l = Linked {
        link: LinkParams {
            jitter_s: -1e-3,
            ..LinkParams::IDEAL
        },
        protocol: Protocol::V2,
    };
    let e = run_linked(
        &read("wall.toml"),
        &read("wall.script.toml"),
        Mechanics::FALCON,
        Grip::LOOSE,
        &l,
        None,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "link `jitter_s` = -0.001 is out of range: allowed 0 ≤ jitter_s ≤ 1 s"
    );
}
