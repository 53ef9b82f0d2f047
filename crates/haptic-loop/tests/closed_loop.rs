//! Every built-in scene's default script played through a hand holding a modelled device, in
//! closed loop (issue 22): four device presets × loose and firm grips × with and without
//! encoder counts and force resolution. In every run:
//! - force changes above 1 N in one tick happen only at declared events (grab, release,
//!   impact, snap, pull-off) or within 50 ms after one;
//! - at most 10 % of the felt force's power (about its mean) lies above 50 Hz;
//! - the passivity observer's tank stays above minus its reserve (the controller holds it).
//!
//! And the case issue 22 was filed for: the paper's `F = −M a` buzzes on a Falcon held loosely,
//! the coupling does not; with the safety layer off, the coupling alone still holds.
#![allow(clippy::unwrap_used)]

use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::device::{HapticDevice, ModelledDevice, Script, TickTime};
use haptic_loop::haptic::HapticLoop;
use haptic_loop::scene::load_scene_for;
use rustfft::{FftPlanner, num_complex::Complex};

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const SCENES: [(&str, &str); 4] = [
    ("wall.toml", "wall.script.toml"),
    ("nanoworld.toml", "nanoworld.script.toml"),
    ("brickworld.toml", "brickworld.script.toml"),
    ("optical_tweezers.toml", "optical_tweezers.script.toml"),
];

/// Events after which a jump of the felt force is expected.
const DECLARED: [&str; 9] = [
    "brick.grabbed",
    "brick.released",
    "brick.impact",
    "brick.thrown",
    "nano.snap",
    "nano.pull_off",
    "nano.atom_transferred",
    "nano.atom_picked_up",
    "nano.atom_attached",
];

/// What one closed-loop run showed.
#[derive(Debug)]
struct Run {
    /// Ticks whose force changed by more than 1 N, not within 50 ms of a declared event.
    undeclared_jumps: usize,
    /// Largest force change in one tick, N.
    max_jump_n: f64,
    /// Fraction of the felt force's power above 50 Hz.
    hf_fraction: f64,
    /// Lowest passivity tank, J.
    min_tank_j: f64,
    /// The reserve, J.
    reserve_j: f64,
    /// Ticks where the safety layer acted.
    safety_ticks: usize,
}

fn run(scene: &str, script: &str, mech: Mechanics, grip: Grip) -> Option<Run> {
    run_with(scene, script, mech, grip, |t| t)
}

fn run_with(
    scene: &str,
    script: &str,
    mech: Mechanics,
    grip: Grip,
    edit: impl Fn(String) -> String,
) -> Option<Run> {
    let text = edit(std::fs::read_to_string(root().join("scenes").join(scene)).unwrap());
    let falcon = haptic_loop::device::DeviceModel::Falcon.specs().clone();
    let specs = haptic_loop::device::modelled::specs_of(&mech, &falcon);
    // A device softer than the scene was written for gets the scene's proxy spring at 80 % of
    // its own cap (the brick world's 1000 N/m proxy exceeds a Touch's 160 N/m in the world).
    let loaded = match load_scene_for(&text, specs.clone()) {
        Ok(l) => l,
        Err(_) => {
            let cap = specs.limits.max_stiffness_n_per_m / (0.125 * 20.0);
            let t = text.replace(
                "[brickworld.params]\n",
                &format!(
                    "[brickworld.params]\nproxy_stiffness_n_per_m = {}\n",
                    0.8 * cap
                ),
            );
            match load_scene_for(&t, specs.clone()) {
                Ok(l) => l,
                Err(e) => {
                    println!("{scene} refuses {}: {e}", mech.name);
                    return None;
                }
            }
        }
    };
    let stext = std::fs::read_to_string(root().join("scenes").join(script)).unwrap();
    let script = Script::from_toml(&stext, &specs).unwrap();
    let ticks = (script.duration_s * f64::from(loaded.config.rate_hz)).round() as u64;
    let rate = loaded.config.rate_hz;
    let reserve_j = loaded
        .config
        .safety
        .passivity_reserve_j
        .unwrap_or(haptic_loop::scene::loop_config::DEFAULT_PASSIVITY_RESERVE_J);
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let mut dev = ModelledDevice::new(script, mech, grip, &falcon);
    let mut forces: Vec<[f64; 3]> = Vec::with_capacity(ticks as usize);
    let mut last_declared: Option<u64> = None;
    let (mut undeclared_jumps, mut max_jump_n, mut min_tank_j, mut safety_ticks) =
        (0, 0.0f64, f64::INFINITY, 0);
    let mut prev = [0.0; 3];
    for i in 0..ticks {
        let s = dev.sample(TickTime::new(i, rate)).unwrap();
        let r = lp.tick(s, false);
        if r.events.iter().any(|e| DECLARED.contains(&e.name.as_str())) {
            last_declared = Some(i);
        }
        if r.status & (64 | 128) != 0 {
            safety_ticks += 1;
        }
        let f = r.device_force_n;
        let jump =
            ((f[0] - prev[0]).powi(2) + (f[1] - prev[1]).powi(2) + (f[2] - prev[2]).powi(2)).sqrt();
        max_jump_n = max_jump_n.max(jump);
        let near_event = last_declared.is_some_and(|t| i - t <= u64::from(rate) / 20);
        if jump > 1.0 && !near_event {
            undeclared_jumps += 1;
        }
        prev = f;
        forces.push(f);
        min_tank_j = min_tank_j.min(lp.passivity_tank_j());
        dev.set_force(&lp.command(i)).unwrap();
    }
    Some(Run {
        undeclared_jumps,
        max_jump_n,
        hf_fraction: hf_fraction(&forces, f64::from(rate), 50.0),
        min_tank_j,
        reserve_j,
        safety_ticks,
    })
}

/// Fraction of the power of `f` (each axis, its mean removed) above `cut_hz`.
fn hf_fraction(f: &[[f64; 3]], rate_hz: f64, cut_hz: f64) -> f64 {
    let n = f.len();
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(n);
    let (mut total, mut high) = (0.0, 0.0);
    for a in 0..3 {
        let mean = f.iter().map(|v| v[a]).sum::<f64>() / n as f64;
        let mut buf: Vec<Complex<f64>> = f.iter().map(|v| Complex::new(v[a] - mean, 0.0)).collect();
        fft.process(&mut buf);
        for (k, c) in buf.iter().enumerate().take(n / 2 + 1).skip(1) {
            let p = c.norm_sqr();
            total += p;
            if k as f64 * rate_hz / n as f64 > cut_hz {
                high += p;
            }
        }
    }
    if total > 0.0 { high / total } else { 0.0 }
}

#[test]
fn every_scene_is_stable_through_every_device_and_grip() {
    let mut failures = Vec::new();
    for (scene, script) in SCENES {
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                for quantized in [true, false] {
                    let m = if quantized {
                        mech
                    } else {
                        mech.without_quantization()
                    };
                    let Some(r) = run(scene, script, m, grip) else {
                        continue;
                    };
                    let label = format!(
                        "{scene} {} {} {}",
                        mech.name,
                        grip.label(),
                        if quantized { "counts" } else { "ideal" }
                    );
                    println!(
                        "{label:<50} jumps>1N outside events {:>4}, max jump {:.3} N, \
                         power above 50 Hz {:.4}, tank min {:+.4} J, safety ticks {}",
                        r.undeclared_jumps,
                        r.max_jump_n,
                        r.hf_fraction,
                        r.min_tank_j,
                        r.safety_ticks
                    );
                    if unstable(&r) {
                        failures.push(label);
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "unstable runs: {failures:#?}");
}

fn unstable(r: &Run) -> bool {
    r.undeclared_jumps > 0 || r.hf_fraction > 0.10 || r.min_tank_j < -r.reserve_j
}

/// Issue 22's case: a brick carried on a Falcon held loosely, with encoder counts. The paper's
/// `F = −M a` buzzes (with or without the safety layer, which can only damp it); the coupling
/// is smooth, and smooth even with the safety layer off.
#[test]
fn the_papers_inertia_buzzes_where_the_coupling_does_not() {
    let (scene, script) = ("brickworld.toml", "brickworld.script.toml");
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
    let cases: [(&str, Box<dyn Fn(String) -> String>, bool); 4] = [
        (
            "paper, safety off",
            Box::new(move |t| paper(no_safety(t))),
            true,
        ),
        ("paper, safety on", Box::new(paper), true),
        ("coupling, safety off", Box::new(no_safety), false),
        ("coupling, safety on", Box::new(|t| t), false),
    ];
    for (label, edit, buzzes) in cases {
        let r = run_with(scene, script, Mechanics::FALCON, Grip::LOOSE, edit).unwrap();
        println!(
            "{label:<22} jumps>1N outside events {:>5}, max jump {:.3} N, power above 50 Hz \
             {:.4}, tank min {:+.4} J, safety ticks {}",
            r.undeclared_jumps, r.max_jump_n, r.hf_fraction, r.min_tank_j, r.safety_ticks
        );
        assert_eq!(unstable(&r), buzzes, "{label}: {r:?}");
    }
}
