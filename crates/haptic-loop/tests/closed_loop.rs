//! Every built-in scene's default script played through a hand holding a modelled device, in
//! closed loop (issue 22): four device presets × loose and firm grips × with and without
//! encoder counts and force resolution. In every run:
//! - force changes above 1 N in one tick happen only at declared events (grab, release,
//!   impact, snap, pull-off) or within 50 ms after one;
//! - at most 10 % of the felt force's power (about its mean) lies above 50 Hz;
//! - the passivity observer's tank stays above minus its reserve (the controller holds it).
//!
//! Issue 22 is not closed: the runs in [`UNSTABLE_TODAY`] fail these criteria (the stiff wall
//! and the optical tweezers with a firm grip, the carried brick on a Falcon with a loose grip
//! and encoder counts, the Inverse3 at the wall). The test asserts the measured map exactly.
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
    let text = std::fs::read_to_string(root().join("scenes").join(scene)).unwrap();
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
                &format!("[brickworld.params]\nproxy_stiffness_n_per_m = {}\n", 0.8 * cap),
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
    let reserve_j = loaded.config.safety.passivity_reserve_j.unwrap();
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
        let jump = ((f[0] - prev[0]).powi(2) + (f[1] - prev[1]).powi(2) + (f[2] - prev[2]).powi(2))
            .sqrt();
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

/// The runs that fail the criteria today (issue 22 is open): the stability map as measured,
/// so that a fix or a regression changes this test. Read with `--nocapture` for the figures.
const UNSTABLE_TODAY: &[&str] = &[
    "wall.toml falcon firm counts",
    "wall.toml falcon firm ideal",
    "wall.toml delta3 firm counts",
    "wall.toml delta3 firm ideal",
    "wall.toml inverse3 loose counts",
    "wall.toml inverse3 loose ideal",
    "wall.toml inverse3 firm counts",
    "wall.toml inverse3 firm ideal",
    "brickworld.toml falcon loose counts",
    "optical_tweezers.toml falcon loose counts",
    "optical_tweezers.toml falcon loose ideal",
    "optical_tweezers.toml falcon firm counts",
    "optical_tweezers.toml falcon firm ideal",
    "optical_tweezers.toml delta3 loose counts",
    "optical_tweezers.toml delta3 loose ideal",
    "optical_tweezers.toml delta3 firm counts",
    "optical_tweezers.toml delta3 firm ideal",
    "optical_tweezers.toml inverse3 firm ideal",
];

#[test]
fn every_scene_through_every_device_and_grip_matches_the_measured_stability_map() {
    let mut failures = Vec::new();
    for (scene, script) in SCENES {
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                for quantized in [true, false] {
                    let m = if quantized { mech } else { mech.without_quantization() };
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
                        r.undeclared_jumps, r.max_jump_n, r.hf_fraction, r.min_tank_j,
                        r.safety_ticks
                    );
                    if r.undeclared_jumps > 0 || r.hf_fraction > 0.10 || r.min_tank_j < -r.reserve_j
                    {
                        failures.push(label);
                    }
                }
            }
        }
    }
    assert_eq!(failures, UNSTABLE_TODAY, "unstable runs: {failures:#?}");
}
