//! Every built-in scene's default script played through a hand holding a modelled device, in
//! closed loop (issue 22): four device presets × loose and firm grips × with and without
//! encoder counts and force resolution. Every run must be stable
//! ([`haptic_loop::closed_loop::Report::stable`]):
//! - force changes above 1 N in one tick happen only at declared events (grab, release,
//!   impact, snap, pull-off) or within 50 ms after one;
//! - at most 10 % of the felt force's power (about its mean) lies above 50 Hz;
//! - the passivity observer stays above minus its reserve.
//!
//! And the case issue 22 was filed for: the paper's `F = −M a` buzzes on a Falcon held loosely,
//! with or without the safety layer; the coupling does not, with or without it.
#![allow(clippy::unwrap_used)]

use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop::{ClosedLoopError, Report, run};

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(name: &str) -> String {
    std::fs::read_to_string(root().join("scenes").join(name)).unwrap()
}

const SCENES: [(&str, &str); 5] = [
    ("wall.toml", "wall.script.toml"),
    ("nanoworld.toml", "nanoworld.script.toml"),
    ("brickworld.toml", "brickworld.script.toml"),
    ("optical_tweezers.toml", "optical_tweezers.script.toml"),
    // The 10 kHz loop on devices whose servo runs at 1 or 4 kHz: they sample its answers.
    (
        "optical_tweezers_10khz.toml",
        "optical_tweezers.script.toml",
    ),
];

/// Runs a scene; a device softer than the brick world was written for gets its proxy spring
/// at 80 % of its own cap (the 1000 N/m proxy exceeds a Touch's 160 N/m in that world).
/// `None` when the scene refuses the device (the optical tweezers' 0.8 N/m spring on a Touch).
fn play(
    scene: &str,
    script: &str,
    mech: Mechanics,
    grip: Grip,
    edit: &dyn Fn(String) -> String,
) -> Option<Report> {
    let text = edit(read(scene));
    let script = read(script);
    match run(&text, &script, mech, grip, None) {
        Ok(r) => Some(r),
        Err(ClosedLoopError::Scene(_)) if scene == "brickworld.toml" => {
            let cap = mech.limits.max_stiffness_n_per_m / (0.125 * 20.0);
            let t = text.replace(
                "[brickworld.params]\n",
                &format!(
                    "[brickworld.params]\nproxy_stiffness_n_per_m = {}\n",
                    0.8 * cap
                ),
            );
            Some(run(&t, &script, mech, grip, None).unwrap())
        }
        Err(e) => {
            println!("{scene} refuses {}: {e}", mech.name);
            None
        }
    }
}

fn line(label: &str, r: &Report) -> String {
    format!(
        "{label:<48} jumps>1N outside events {:>5}, max jump {:.3} N, power above 50 Hz {:.4}, \
         observer min {:+.4} J, safety ticks {:>5}, motors' work on the hand {:+.4} J",
        r.undeclared_jumps,
        r.max_jump_n,
        r.hf_fraction,
        r.min_observer_j,
        r.safety_ticks,
        r.energy_to_hand_j
    )
}

#[test]
fn every_scene_is_stable_through_every_device_and_grip() {
    let mut failures = Vec::new();
    let mut unbuilt = Vec::new();
    let mut runs = 0;
    for (scene, script) in SCENES {
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                for quantized in [true, false] {
                    let m = if quantized {
                        mech
                    } else {
                        mech.without_quantization()
                    };
                    let Some(r) = play(scene, script, m, grip, &|t| t) else {
                        continue;
                    };
                    runs += 1;
                    let label = format!(
                        "{scene} {} {} {}",
                        mech.name,
                        grip.label(),
                        if quantized { "counts" } else { "ideal" }
                    );
                    println!(
                        "{}, house complete at {:?} s",
                        line(&label, &r),
                        r.house_complete_s
                    );
                    if !r.stable() {
                        failures.push(label.clone());
                    }
                    // Both house tasks still complete with a hand in the loop.
                    if r.house_complete_s.is_some_and(|t| t < 0.0) {
                        unbuilt.push(label);
                    }
                }
            }
        }
    }
    // 5 scenes × 4 devices × 2 grips × 2 sensings, less the optical tweezers on a Touch.
    assert_eq!(runs, 72);
    assert!(failures.is_empty(), "unstable runs: {failures:#?}");
    // The one exception: a Touch renders 400 N/m, so the brick world's coupling is 48 N/m in
    // the world and the 0.5 kg brick hangs 10 cm under a hand whose script was written for a
    // Falcon; held loosely, its set-downs miss the slots (held firmly, the house completes).
    assert_eq!(
        unbuilt,
        [
            "brickworld.toml touch loose counts",
            "brickworld.toml touch loose ideal"
        ],
        "houses not completed"
    );
}

/// Issue 22's case: a brick carried on a Falcon held loosely, with encoder counts. The paper's
/// `F = −M a` buzzes (with or without the safety layer, which can only damp it); the coupling
/// is smooth, and smooth even with the safety layer off.
#[test]
fn the_papers_inertia_buzzes_where_the_coupling_does_not() {
    let no_safety = |t: String| {
        t.replace(
            "[loop]\n",
            "[loop]\npassivity = false\nforce_rate_limit = false\n",
        )
    };
    let paper = |t: String| {
        t.replace(
            "[brickworld.params]\n",
            "[brickworld.params]\ninertia = \"paper\"\n",
        )
    };
    type Edit<'a> = &'a dyn Fn(String) -> String;
    let cases: [(&str, Edit, bool); 4] = [
        ("paper, safety off", &|t| paper(no_safety(t)), false),
        ("paper, safety on", &paper, false),
        ("coupling, safety off", &no_safety, true),
        ("coupling, safety on", &|t| t, true),
    ];
    for (label, edit, smooth) in cases {
        let r = play(
            "brickworld.toml",
            "brickworld.script.toml",
            Mechanics::FALCON,
            Grip::LOOSE,
            edit,
        )
        .unwrap();
        println!("{}", line(label, &r));
        assert_eq!(r.stable(), smooth, "{label}: {r:?}");
        if !smooth {
            assert!(
                r.undeclared_jumps > 1000 && r.hf_fraction > 0.5,
                "{label}: a buzz"
            );
        }
    }
}
