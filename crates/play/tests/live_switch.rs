//! A switch applied live through `Runner::with_live` is recorded as its tick's input, and the
//! replay (which applies recorded switches as scheduled ones) reproduces the session bit for
//! bit; a switch the world refuses is reported and not recorded.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::ScriptedDevice;
use haptic_devices::script::Script;
use haptic_engine::HapticLoop;
use haptic_engine::pacing::Pacing;
use haptic_engine::runner::Runner;
use haptic_engine::sink::Sink;
use haptic_loop::record_sink::RecorderSink;
use haptic_loop::scene::load_scene_for;
use haptic_loop::session::SceneSource;
use haptic_types::HapticDevice;
use haptic_types::device::FALCON;
use recording::{read_recording_file, switch_schedule};

#[test]
fn live_switches_are_recorded_on_their_tick_and_replay_bit_for_bit() {
    let scene = SceneSource::builtin("brickworld").unwrap();
    let script_text = &scene.scripts[0].1;
    let script = Script::from_toml(script_text, &FALCON).unwrap();
    let loaded = load_scene_for(&scene.text, FALCON.clone()).unwrap();
    let header = loaded.header(&scene.text, "batch", "page", 1_000_000_000);
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let mut dev = ScriptedDevice::new(script, FALCON.clone());
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-live-switch-{}.mcap", std::process::id()));
    let mut rec = RecorderSink::new(out.clone());
    let mut refused = Vec::new();
    let mut hook = |tick: u64, lp: &mut HapticLoop| {
        if tick == 700 {
            lp.switch("gravity_m_per_s2", 2.5).unwrap();
            lp.switch("friction", 0.2).unwrap();
        }
        if tick == 1500 {
            refused.push(lp.switch("brick_mass_kg", 1e9).unwrap_err().to_string());
        }
    };
    {
        let sinks: Vec<&mut dyn Sink> = vec![&mut rec];
        let mut runner = Runner::new(sinks).with_live(&mut hook);
        let (stats, _) = runner
            .run(
                &mut lp,
                &mut dev as &mut dyn HapticDevice,
                &header,
                Some(3000),
                Pacing::Batch,
                &mut |_, _| {},
            )
            .unwrap();
        assert_eq!(stats.ticks, 3000);
    }
    assert_eq!(
        refused,
        ["switch `brick_mass_kg` = 1e9 is out of range: allowed 0.001 ≤ value ≤ 100"]
    );
    let r = read_recording_file(&out, false).unwrap();
    let sched = switch_schedule(&r, 1_000_000).unwrap();
    let got: Vec<(u64, &str, f64)> = sched
        .iter()
        .map(|(t, s)| (*t, s.name.as_str(), s.value))
        .collect();
    assert_eq!(
        got,
        [(700, "gravity_m_per_s2", 2.5), (700, "friction", 0.2)]
    );
    let v = haptic_loop::replay::verify(&r).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
    assert_eq!(v.ticks, 3000);
    let _ = std::fs::remove_file(&out);
}
