//! The nano-world scene through the loop: the default script builds the whole house, the
//! forces the device feels are the world's scaled by the mapping, replay is bit-exact, and
//! bad scene files are refused by field.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_loop::replay::verify;
use haptic_loop::scene::load_scene;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use recording::read_recording_file;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn default_script_builds_the_house_and_replays_bit_exactly() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-nano-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rec = dir.join("nano.mcap");
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes/nanoworld.toml")).unwrap());
    o.out = Some(rec.clone());
    let r = run_session(&o, &mut |_, _| {}).unwrap();
    assert_eq!(
        r.header.operator, "rigid",
        "the script asks for a rigid stylus"
    );
    let a = &r.arrays;
    let names: Vec<&str> = a.events.iter().map(|e| e.1.as_str()).collect();
    assert_eq!(
        names.iter().filter(|n| **n == "nano.slot_filled").count(),
        7
    );
    assert_eq!(
        names
            .iter()
            .filter(|n| **n == "nano.atom_transferred")
            .count(),
        7
    );
    assert!(names.contains(&"nano.house_complete"));
    let score = a.state_column("house_score").unwrap();
    assert_eq!(*score.last().unwrap(), 7.0);
    // Every tick, once engaged and unclamped, the device feels the world force × 1e9.
    for i in 0..a.tick.len() {
        if a.engagement[i] == 1.0 && a.status[i] == 0 {
            for k in 0..3 {
                assert_eq!(a.device_force_n[i][k], a.world_force_n[i][k] * 1e9);
            }
        }
    }
    // The pull-offs are felt at ten times the snap force: the tip–atom pull-off is 3 nN, so
    // the largest force on the device is about 3 N (within the last tick's overshoot).
    let peak = a
        .device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max);
    assert!((peak - 3.0).abs() < 0.05, "peak {peak} N");
    let v = verify(&read_recording_file(&rec, false).unwrap()).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
}

#[test]
fn scene_errors_name_the_field() {
    let text = std::fs::read_to_string(root().join("scenes/nanoworld.toml")).unwrap();
    let err = |t: String| match load_scene(&t, None) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    // 1 nN → 100 N: the 2 N/m adhesion spring would be 30 000 N/m on the Falcon.
    assert_eq!(
        err(text.replace("force_scale = 1.0e9", "force_scale = 1.0e11")),
        "scene: `nanoworld.params.interaction.game.pairs.tip_substrate.stiffness_n_per_m` = 2 is \
         out of range: allowed ≤ 0.2 N/m, the device's stiffness limit mapped \
         to the world (lower mapping.force_scale or mapping.workspace_scale)"
    );
    assert_eq!(
        err(text.replace("preset = \"game\"", "preset = \"lunar\"")),
        "scene: `nanoworld.preset` = \"lunar\" is out of range: allowed \"game\" or \"physical\""
    );
    assert!(
        err(text.replace("preset = \"game\"", "colour = 1")).contains("unknown field `colour`")
    );
}
