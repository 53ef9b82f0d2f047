//! The optical-tweezers scene through the loop: grab on touch + button, the particle follows a
//! command inside the working envelope exactly, a command outside is clipped and felt as the
//! spring on the excess, release on button up, replay is bit-exact; bad parameters are refused.
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
fn steering_inside_the_envelope_is_exact_and_outside_is_felt() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-ot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rec = dir.join("ot.mcap");
    let mut o = SessionOptions::new(
        SceneSource::from_path(&root().join("scenes/optical_tweezers.toml")).unwrap(),
    );
    o.out = Some(rec.clone());
    let r = run_session(&o, &mut |_, _| {}).unwrap();
    let a = &r.arrays;
    let names: Vec<&str> = a.events.iter().map(|e| e.1.as_str()).collect();
    assert!(names.contains(&"ot.grab") && names.contains(&"ot.release"));
    assert!(names.contains(&"ot.clipped"));
    let col = |n: &str| a.state_column(n).unwrap();
    let (px, py, excess, lag, grabbed) = (
        col("particle_x_m"),
        col("particle_y_m"),
        col("excess_m"),
        col("lag_m"),
        col("grabbed"),
    );
    // The slow square (t = 0.5 – 4.5 s) stays inside the envelope: no excess, and the particle
    // is where the cursor is (the clipped command is reached by the trap's flow map).
    for i in 500..4500 {
        assert_eq!(grabbed[i], 1.0);
        assert_eq!(excess[i], 0.0, "tick {i}");
        assert!(lag[i] < 1e-9, "tick {i}: lag {} m", lag[i]);
        assert!((px[i] - a.cursor_m[i][0]).abs() < 1e-9 && (py[i] - a.cursor_m[i][1]).abs() < 1e-9);
    }
    // The fast drag is clipped: the cursor runs ahead and the stylus feels −k·excess (×1e6),
    // pointing back toward the particle, within the Falcon's 8 N.
    let i = (4500..5300)
        .max_by(|&i, &j| excess[i].total_cmp(&excess[j]))
        .unwrap();
    assert!(excess[i] > 1e-6, "excess {} m", excess[i]);
    let f = a.device_force_n[i];
    assert!(f[0] < 0.0, "force points back: {f:?}");
    let expected = (0.8 * excess[i] * 1e6).min(8.0);
    assert!(
        ((f[0] * f[0] + f[1] * f[1]).sqrt() - expected).abs() < 1e-9,
        "{f:?} vs {expected}"
    );
    // Released at 5.3 s: no force afterwards.
    assert!(a.device_force_n[5400..].iter().all(|f| *f == [0.0; 3]));
    let v = verify(&read_recording_file(&rec, false).unwrap()).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
}

#[test]
fn scene_errors_name_the_field() {
    let text = std::fs::read_to_string(root().join("scenes/optical_tweezers.toml")).unwrap();
    let err = |t: String| match load_scene(&t, None) {
        Ok(_) => panic!("accepted"),
        Err(e) => e.to_string(),
    };
    assert_eq!(
        err(text.replace("waist_y_nm = 300.0", "waist_y_nm = -300.0")),
        "scene: `optical_tweezers.waist_y_nm` = -300 is out of range: allowed 0 < \
         optical_tweezers.waist_y_nm ≤ 1e6"
    );
    assert_eq!(
        err(text.replace("stiffness_n_per_m = 0.8", "stiffness_n_per_m = 5.0")),
        "scene: `optical_tweezers.stiffness_n_per_m` = 5 is out of range: allowed 0 < \
         stiffness ≤ 3 N/m, the device's limit mapped to the world"
    );
    assert!(
        err(text.replace("clip = \"radial\"", "clip = \"sideways\""))
            .contains("unknown variant `sideways`")
    );
}

/// The paper's experiment in miniature: dragging faster than the trap can follow, force
/// feedback keeps the cursor much closer to the particle than no feedback, and a hand that
/// slows down under the force keeps it closer still.
#[test]
fn feedback_keeps_the_cursor_near_the_particle() {
    use haptic_devices::OperatorParams;
    use haptic_devices::source::OperatorChoice;
    let drag = "[script]\nname = 'drag'\nduration_s = 1.2\n\
                [[button]]\nt_s = 0.3\nname = 'centre'\ndown = true\n\
                [[waypoint]]\nt_s = 0.5\nposition_mm = [0.0, 0.0, 0.0]\n\
                [[waypoint]]\nt_s = 0.75\nposition_mm = [10.0, 0.0, 0.0]\n";
    let text = std::fs::read_to_string(root().join("scenes/optical_tweezers.toml")).unwrap();
    let run = |feedback: bool, op: OperatorParams| {
        let t = if feedback {
            text.clone()
        } else {
            text.replace("feedback = true", "feedback = false")
        };
        let mut o = SessionOptions::new(SceneSource::from_text(t, "optical_tweezers.toml"));
        o.script = Some(drag.to_string());
        o.operator = OperatorChoice::Hand(op);
        let a = run_session(&o, &mut |_, _| {}).unwrap().arrays;
        let f = a
            .device_force_n
            .iter()
            .map(|f| f[0].abs())
            .fold(0.0, f64::max);
        (
            a.state_column("lag_m")
                .unwrap()
                .into_iter()
                .fold(0.0, f64::max),
            f,
        )
    };
    let passive = OperatorParams::default();
    let (off, f_off) = run(false, passive);
    let (on, f_on) = run(true, passive);
    let (on_y, _) = run(
        true,
        OperatorParams {
            yield_force_n: 0.5,
            ..passive
        },
    );
    assert_eq!(f_off, 0.0, "no feedback, no force");
    assert!(f_on > 1.0, "the wall is felt: {f_on} N");
    assert!(
        off > 4e-6,
        "without feedback the cursor runs ahead: {off} m"
    );
    assert!(on < 0.4 * off, "feedback: {on} m vs {off} m");
    assert!(on_y < 0.6 * on, "yielding hand: {on_y} m vs {on} m");
}
