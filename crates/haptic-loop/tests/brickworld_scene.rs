//! The brick-world scene through the loop: the default script builds the wall (4/4 slots),
//! the device feels the world force × force_scale within its limits, replay is bit-exact
//! (rapier f64 with enhanced determinism), and bad scene files are refused by field.
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
fn default_script_builds_the_wall_and_replays_bit_exactly() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-brick-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rec = dir.join("brick.mcap");
    let mut o = SessionOptions::new(
        SceneSource::from_path(&root().join("scenes/brickworld.toml")).unwrap(),
    );
    o.out = Some(rec.clone());
    let r = run_session(&o, &mut |_, _| {}).unwrap();
    let a = &r.arrays;
    let names: Vec<&str> = a.events.iter().map(|e| e.1.as_str()).collect();
    assert_eq!(names.iter().filter(|n| **n == "brick.grabbed").count(), 4);
    assert!(names.contains(&"brick.rotated"));
    assert_eq!(
        *a.state_column("slots_filled").unwrap().last().unwrap(),
        4.0
    );
    // Carrying a brick level, the vertical force is its weight: −M g scaled by 0.125 =
    // −0.613 N, through the coupling (the brick rings on its spring after each grab and each
    // change of height; on average over the level ticks, within 1 %).
    let holding = a.state_column("holding").unwrap();
    let level: Vec<usize> = (4..a.tick.len())
        .filter(|&i| {
            holding[i] == 1.0
                && a.engagement[i] == 1.0
                && a.cursor_m[i][2] > 0.3
                && (1..=4).all(|k| a.cursor_m[i - k][2] == a.cursor_m[i][2])
        })
        .collect();
    assert!(level.len() > 1000, "{} level ticks", level.len());
    let mean = level.iter().map(|&i| a.device_force_n[i][2]).sum::<f64>() / level.len() as f64;
    let weight: f64 = 0.5 * 9.81 * 0.125;
    // docs/haptic-loop.md quotes it: −0.613 N.
    assert!((weight - 0.613).abs() < 0.0005);
    assert!((mean + weight).abs() < 0.01 * weight, "mean Fz {mean} N");
    for i in 0..a.tick.len() {
        let f = a.device_force_n[i];
        assert!((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() <= 8.0);
        if a.engagement[i] == 1.0 && a.status[i] == 0 {
            for (fk, wk) in f.iter().zip(a.world_force_n[i]) {
                assert_eq!(*fk, wk * 0.125);
            }
        }
    }
    let v = verify(&read_recording_file(&rec, false).unwrap()).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
}

#[test]
fn scene_errors_name_the_field() {
    let text = std::fs::read_to_string(root().join("scenes/brickworld.toml")).unwrap();
    let err = |t: String| match load_scene(&t, None) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    assert_eq!(
        err(text.replace("dt_s = 0.001", "dt_s = 0.002")),
        "scene: `brickworld.params.dt_s` = 0.002 is out of range: allowed 0.001 s, the loop's \
         tick (1 / loop.rate_hz)"
    );
    // 1 N → 1 N: the 1000 N/m proxy would be 20 000 N/m on the Falcon.
    let e = err(text.replace("force_scale = 0.125", "force_scale = 1.0"));
    assert!(e.starts_with("scene: brickworld.params: "), "{e}");
    assert!(e.contains("proxy_stiffness_n_per_m"), "{e}");
    assert!(
        err(text.replace("draw_ground_half_m = 1.0", "ground = 1.0"))
            .contains("unknown field `ground`")
    );
}
