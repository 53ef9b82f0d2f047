//! Every built-in scene through every device preset, loose and firm grip, behind a modelled
//! link of 0–50 ms one way (each also with 1 ms of jitter and 5 % loss), with the device side
//! speaking protocol 1 or 2: the closed-loop criteria of issue 22 at each latency.
//!
//! `cargo run --release -p haptic-loop --example link_grid -- [v1|v2] [scene-filter]`
#![allow(clippy::unwrap_used)]

use haptic_devices::link::LinkParams;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, PRESETS};
use haptic_loop::closed_loop::{Linked, run_linked};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let protocol = if args.get(1).is_some_and(|a| a == "v1") {
        Protocol::V1
    } else {
        Protocol::V2
    };
    let filter = args.get(2).cloned().unwrap_or_default();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let read = |n: &str| std::fs::read_to_string(root.join(n)).unwrap();
    for (scene, script) in [
        ("wall.toml", "wall.script.toml"),
        ("brickworld.toml", "brickworld.script.toml"),
        ("nanoworld.toml", "nanoworld.script.toml"),
        ("optical_tweezers.toml", "optical_tweezers.script.toml"),
    ] {
        if !scene.contains(&filter) {
            continue;
        }
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                for ms in [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0] {
                    for bad in [false, true] {
                        let link = LinkParams {
                            latency_s: ms * 1e-3,
                            jitter_s: if bad { 1e-3 } else { 0.0 },
                            loss: if bad { 0.05 } else { 0.0 },
                            seed: 7,
                        };
                        let l = Linked { link, protocol };
                        match run_linked(&read(scene), &read(script), mech, grip, &l, None) {
                            Ok(r) => println!(
                                "{scene:<24} {:<8} {:<5} {:<28} {} jumps {:>5} max {:6.2} N hf {:.3} obs {:+.3} J work {:+.3} J pc {}",
                                mech.name,
                                grip.label(),
                                link.label(),
                                if r.stable() { "ok      " } else { "UNSTABLE" },
                                r.undeclared_jumps,
                                r.max_jump_n,
                                r.hf_fraction,
                                r.min_observer_j,
                                r.energy_to_hand_j,
                                r.device_interventions
                            ),
                            Err(e) => println!(
                                "{scene:<24} {:<8} {:<5} refused: {e}",
                                mech.name,
                                grip.label()
                            ),
                        }
                    }
                }
            }
        }
    }
}
