//! Prints one closed-loop run tick by tick as CSV (scene, preset, grip as arguments):
//! `cargo run --release -p haptic-loop --example haptic-loop-closed-loop-trace -- wall falcon firm
//! [counts|ideal] [safety|nosafety] [impedance scale]`.
#![allow(clippy::unwrap_used)]
use haptic_devices::{Grip, Mechanics};
use haptic_devices::{ModelledDevice, Script};
use haptic_engine::haptic::HapticLoop;
use haptic_loop::scene::load_scene_for;
use haptic_types::HapticDevice;
use haptic_types::TickTime;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let scene = &a[1];
    let mut mech = Mechanics::preset(&a[2]).unwrap();
    if a.get(4).is_some_and(|s| s == "ideal") {
        mech = mech.without_quantization();
    }
    let grip = Grip::parse(&a[3]).unwrap();
    let mut text = std::fs::read_to_string(root.join(format!("{scene}.toml"))).unwrap();
    if a.get(5).is_some_and(|s| s == "nosafety") {
        text = text.replace(
            "[loop]\n",
            "[loop]\npassivity = false\nforce_rate_limit = false\n",
        );
    }
    if let Some(scale) = a.get(6).and_then(|s| s.parse::<f64>().ok()) {
        // Scale the device-side impedance by `scale` (as the Z-width report's margins do).
        (text, mech) = haptic_loop::closed_loop::scale_impedance(&text, mech, scale);
    }
    let specs = haptic_devices::modelled::preset_specs(&mech);
    let l = load_scene_for(&text, specs.clone()).unwrap();
    let stext = std::fs::read_to_string(root.join(format!("{scene}.script.toml"))).unwrap();
    let script = Script::from_toml(&stext, &specs).unwrap();
    let ticks = (script.duration_s * f64::from(l.config.rate_hz)).round() as u64;
    let rate = l.config.rate_hz;
    let mut lp = HapticLoop::new(l.config, l.scene);
    let mut dev = ModelledDevice::new(script, mech, grip, &specs);
    println!("tick,x,y,z,fx,fy,fz,status,tank,events");
    for i in 0..ticks {
        let s = dev.sample(TickTime::new(i, rate)).unwrap();
        let r = lp.tick(s, false).clone();
        let ev: Vec<&str> = r.events.iter().map(|e| e.name.as_str()).collect();
        println!(
            "{i},{:.6},{:.6},{:.6},{:.4},{:.4},{:.4},{},{:.5},{}",
            s.position_m[0],
            s.position_m[1],
            s.position_m[2],
            r.device_force_n[0],
            r.device_force_n[1],
            r.device_force_n[2],
            r.status,
            lp.passivity_tank_j(),
            ev.join(" ")
        );
        dev.set_force(&lp.command(i)).unwrap();
    }
}
