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
use haptic_loop::closed_loop::{Report, run};

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

/// Runs a scene on a device: every built-in scene plays on every preset (a softer device than
/// the scene's Falcon gets the mapping fitted to it, issue 31).
fn play(
    scene: &str,
    script: &str,
    mech: Mechanics,
    grip: Grip,
    edit: &dyn Fn(String) -> String,
) -> Report {
    let text = edit(read(scene));
    match run(&text, &read(script), mech, grip, None) {
        Ok(r) => r,
        Err(e) => panic!("{scene} refuses {}: {e}", mech.name),
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
                    let r = play(scene, script, m, grip, &|t| t);
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
                    // docs/haptic-loop.md: the safety layer acts on no tick of any run (the
                    // renderings are stable on their own).
                    if r.safety_ticks != 0 {
                        failures.push(format!("{label}: {} safety ticks", r.safety_ticks));
                    }
                    // Both house tasks still complete with a hand in the loop.
                    if r.house_complete_s.is_some_and(|t| t < 0.0) {
                        unbuilt.push(label);
                    }
                }
            }
        }
    }
    // 5 scenes × 4 devices × 2 grips × 2 sensings: no device is refused.
    assert_eq!(runs, 80);
    assert!(failures.is_empty(), "unstable runs: {failures:#?}");
    // Both house tasks complete on every device and grip: a Touch plays the brick world with
    // its mapping fitted (force_scale × 400/3000), so the world's coupling is the Falcon's.
    assert!(unbuilt.is_empty(), "houses not completed: {unbuilt:?}");
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
    // docs/devices.md quotes each run: the jumps above 1 N outside events (exact: the run is
    // deterministic), the share of the force's power above 50 Hz (to 0.1 %) and the motors'
    // work on the hand (to 0.01 J).
    let cases: [(&str, Edit, bool, u64, f64, f64); 4] = [
        (
            "paper, safety off",
            &|t| paper(no_safety(t)),
            false,
            7549,
            0.997,
            0.15,
        ),
        ("paper, safety on", &paper, false, 5269, 0.834, 0.07),
        ("coupling, safety off", &no_safety, true, 0, 0.006, -0.02),
        ("coupling, safety on", &|t| t, true, 0, 0.006, -0.02),
    ];
    for (label, edit, smooth, jumps, hf, work_j) in cases {
        let r = play(
            "brickworld.toml",
            "brickworld.script.toml",
            Mechanics::FALCON,
            Grip::LOOSE,
            edit,
        );
        println!("{}", line(label, &r));
        assert_eq!(r.stable(), smooth, "{label}: {r:?}");
        assert_eq!(r.undeclared_jumps, jumps, "{label}");
        assert!(
            (r.hf_fraction - hf).abs() < 0.0005,
            "{label}: {}",
            r.hf_fraction
        );
        assert!(
            (r.energy_to_hand_j - work_j).abs() < 0.005,
            "{label}: {} J",
            r.energy_to_hand_j
        );
        if !smooth {
            assert!(
                r.undeclared_jumps > 1000 && r.hf_fraction > 0.5,
                "{label}: a buzz"
            );
        }
    }
}

/// A scene may keep its mapping as written (`mapping.fit_device = false`): a device that cannot
/// render one of its springs is then refused, with the value and the cap.
#[test]
fn a_scene_that_refuses_to_be_fitted_names_the_spring_and_the_cap() {
    let text = read("brickworld.toml").replace("[mapping]\n", "[mapping]\nfit_device = false\n");
    let script = read("brickworld.script.toml");
    let e = run(&text, &script, Mechanics::TOUCH, Grip::LOOSE, Some(0.1)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene: brickworld.params: parameter `proxy_stiffness_n_per_m` = 1000 is out of range: \
         allowed (0, 160]"
    );
}

/// A device that announces odd limits (a bridged device: 1.7 N, 137 N/m, a Touch's
/// mechanics) plays every built-in scene: each scene fits its mapping to it and stays stable,
/// and both houses complete.
#[test]
fn a_device_with_odd_limits_plays_every_built_in_scene() {
    let mut odd = Mechanics::TOUCH;
    odd.limits.max_force_n = 1.7;
    odd.limits.max_stiffness_n_per_m = 137.0;
    for (scene, script) in SCENES {
        for grip in [Grip::LOOSE, Grip::FIRM] {
            let r = play(scene, script, odd, grip, &|t| t);
            println!("{}", line(&format!("{scene} odd {}", grip.label()), &r));
            assert!(r.stable(), "{scene}: {r:?}");
            assert!(r.peak_force_n <= 1.7, "{scene}: {}", r.peak_force_n);
            assert!(r.max_stiffness_n_per_m <= 137.0 * (1.0 + 1e-9), "{scene}");
            assert!(
                r.house_complete_s.is_none_or(|t| t > 0.0),
                "{scene}: house not built"
            );
        }
    }
}
