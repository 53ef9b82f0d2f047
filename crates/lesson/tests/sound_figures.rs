//! The teaching report's sound figures (BENCHMARKS.md, "Sound (`render --audio`)"), which do
//! not depend on the clock, to their printed digits: the golden brick recording sounds 10
//! times and peaks at 0.219 (0.281 as the report last printed it, before the golden was
//! re-recorded), the nano one 2 times at 0.798 (proximity tone on); the brick
//! recording's 5 impacts with silence before them start within 0.283 ms of their tick (the
//! target is ±1 ms).
#![allow(clippy::unwrap_used)]

#[path = "../examples/sound_figures/mod.rs"]
mod sound_figures;

use haptic_loop::session::SessionArrays;
use haptic_loop::sound::session_sound;
use recording::read_recording_file;

fn golden(name: &str) -> SessionArrays {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../recordings/{name}.mcap"));
    SessionArrays::from_recording(&read_recording_file(&path, false).unwrap()).unwrap()
}

#[test]
fn the_golden_recordings_sound_as_the_report_says() {
    for (name, sounds, peak) in [("brickworld", 10, "0.219"), ("nanoworld", 2, "0.798")] {
        let a = golden(name);
        let snd = session_sound(&a, name, true, 44_100).unwrap();
        let top = snd.samples.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        assert_eq!(
            (snd.sounds.len(), format!("{top:.3}").as_str()),
            (sounds, peak),
            "{name}"
        );
    }
    let a = golden("brickworld");
    let plain = session_sound(&a, "brickworld", false, 44_100).unwrap();
    let (worst, n) = sound_figures::onset_error(&a, &plain.samples, 44_100.0);
    assert_eq!(n, 5);
    assert_eq!(format!("{:.3}", worst * 1e3), "0.283", "{worst} s");
}
