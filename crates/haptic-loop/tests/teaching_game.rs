//! The teaching game as a whole: switches during a session (recorded as inputs, replayed bit
//! for bit), collision and contact events with their JSON details, the proximity state, and
//! the house score.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::source::OperatorChoice;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionArrays, SessionOptions, run_session};
use recording::channels::messages::Channel;
use recording::read_recording_file;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-game-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn scene(name: &str) -> SceneSource {
    SceneSource::from_path(&root().join("scenes").join(name)).unwrap()
}

/// The scene's default script with `extra` TOML appended.
fn script_plus(name: &str, extra: &str) -> String {
    let t = std::fs::read_to_string(root().join("scenes").join(name)).unwrap();
    format!("{t}\n{extra}")
}

fn run(scene_file: &str, script: Option<String>, secs: f64, out: Option<PathBuf>) -> SessionArrays {
    let mut o = SessionOptions::new(scene(scene_file));
    o.script = script;
    o.operator = OperatorChoice::Rigid;
    o.seconds = Some(secs);
    o.out = out;
    run_session(&o, &mut |_, _| {}).unwrap().arrays
}

fn json(detail: &str) -> serde_json::Value {
    serde_json::from_str(detail).unwrap_or_else(|e| panic!("detail {detail:?}: {e}"))
}

#[test]
fn switching_gravity_off_mid_carry_removes_the_weight_and_replays_bit_exactly() {
    // The default script carries the first brick from 1.529 s to 3.575 s; from 2.104 s to
    // 3.004 s it moves horizontally. Gravity goes off at 2.5 s and back on at 2.8 s (the second
    // switch by its old name, `gravity_m_s2`: accepted, recorded under the new one).
    let extra = "[[switch]]\nt_s = 2.5\nname = \"gravity_m_per_s2\"\nvalue = 0.0\n\n\
                 [[switch]]\nt_s = 2.8\nname = \"gravity_m_s2\"\nvalue = 9.81\n";
    let p = tmp("gravity.mcap");
    let a = run(
        "brickworld.toml",
        Some(script_plus("brickworld.script.toml", extra)),
        3.2,
        Some(p.clone()),
    );
    let sets: Vec<_> = a.events.iter().filter(|e| e.1 == "switch.set").collect();
    assert_eq!(sets.len(), 2);
    assert_eq!(sets[0].0, 2500);
    assert_eq!(sets[1].0, 2800);
    assert_eq!(
        json(&sets[0].2),
        serde_json::json!({"name": "gravity_m_per_s2", "value": 0.0})
    );
    assert_eq!(
        json(&sets[1].2),
        serde_json::json!({"name": "gravity_m_per_s2", "value": 9.81})
    );
    // The weight of the 0.5 kg brick, −M g = −4.905 N, goes away and comes back. Compared with
    // the same run without the switches: identical to the bit before 2.5 s; then the coupling
    // lets the weight go as a step response (the brick rings on its spring at 4.3 Hz with an
    // effective damping ratio ≈ 0.2: this rigid operator adds none), so over the last 100 ms
    // before the second change, and 200–300 ms after it, the difference is the weight, then
    // nothing, within 25 %.
    let plain = run("brickworld.toml", None, 3.2, None);
    let diff = |t: usize| a.world_force_n[t][2] - plain.world_force_n[t][2];
    assert!(
        (0..2500).all(|t| diff(t) == 0.0),
        "before the switch: the same bits"
    );
    let mean = |a0: usize, a1: usize| (a0..a1).map(diff).sum::<f64>() / (a1 - a0) as f64;
    let w = 0.5 * 9.81;
    let (off, on) = (mean(2700, 2800), mean(3000, 3100));
    assert!(
        (off - w).abs() < 0.25 * w,
        "gravity off: the weight is gone ({off} N)"
    );
    assert!(on.abs() < 0.25 * w, "back on: the weight is back ({on} N)");
    // The switch is an input of the recording, and replay applies it on the same tick.
    let rec = read_recording_file(&p, false).unwrap();
    let sw: Vec<_> = rec
        .messages
        .iter()
        .filter(|m| m.channel == Channel::Switch)
        .collect();
    assert_eq!(sw.len(), 2);
    let v = verify(&rec).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
    // Without its switches the same inputs give another session: replay notices.
    let mut stripped = rec.clone();
    stripped.messages.retain(|m| m.channel != Channel::Switch);
    let d = verify(&stripped).unwrap().divergence.unwrap();
    assert_eq!(d.tick, 2500);
}

#[test]
fn halving_adhesion_halves_the_snap_force_felt() {
    let snaps = |a: &SessionArrays| -> Vec<f64> {
        a.events
            .iter()
            .filter(|e| e.1 == "nano.snap")
            .map(|e| json(&e.2)["snap_force_n"].as_f64().unwrap())
            .collect()
    };
    let base = run("nanoworld.toml", None, 3.0, None);
    let extra = "[[switch]]\nt_s = 0.0\nname = \"adhesion_scale\"\nvalue = 0.5\n";
    let half = run(
        "nanoworld.toml",
        Some(script_plus("nanoworld.script.toml", extra)),
        3.0,
        None,
    );
    let (a, b) = (snaps(&base), snaps(&half));
    assert!(!a.is_empty() && !b.is_empty());
    assert!((b[0] / a[0] - 0.5).abs() < 1e-12, "{} vs {}", b[0], a[0]);
}

#[test]
fn a_script_switch_the_scene_lacks_is_refused_with_its_line() {
    let extra = "[[switch]]\nt_s = 1.0\nname = \"gravity\"\nvalue = 0.0\n";
    let mut o = SessionOptions::new(scene("brickworld.toml"));
    o.script = Some(script_plus("brickworld.script.toml", extra));
    o.script_origin = Some("s.toml".into());
    let e = run_session(&o, &mut |_, _| {}).unwrap_err().to_string();
    let line = script_plus("brickworld.script.toml", extra)
        .lines()
        .position(|l| l == "name = \"gravity\"")
        .unwrap()
        + 1;
    assert_eq!(
        e,
        format!(
            "s.toml:{line}:8: script: `switch[0].name`: the brickworld scene has no switch \
             `gravity` (its switches: gravity_m_per_s2, restitution, friction, inertia, brick_mass_kg)"
        )
    );
    let extra = "[[switch]]\nt_s = 1.0\nname = \"restitution\"\nvalue = 1.5\n";
    o.script = Some(script_plus("brickworld.script.toml", extra));
    let e = run_session(&o, &mut |_, _| {}).unwrap_err().to_string();
    assert!(
        e.ends_with(
            "script: `switch[0].value`: switch `restitution` = 1.5 is out of range: \
             allowed 0 ≤ value ≤ 1"
        ),
        "{e}"
    );
}

#[test]
fn collisions_carry_their_impulse_and_the_house_is_scored() {
    let a = run("brickworld.toml", None, 21.937, None);
    let impacts: Vec<serde_json::Value> = a
        .events
        .iter()
        .filter(|e| e.1 == "brick.impact")
        .map(|e| json(&e.2))
        .collect();
    // The bricks' landings on the ground: the ground's impulse is M v (1 + e) plus the
    // weight's impulse over the tick, M g dt (e = 0.2, M = 0.5 kg), within 0.2 %. (This loop
    // used to look only at landings above 0.5 m/s, of which today's script has none: it
    // checked nothing.) docs/brickworld.md quotes the six landings' range to the printed
    // digits: 0.065–0.119 N·s at 0.101–0.190 m/s.
    let ground: Vec<_> = impacts
        .iter()
        .filter(|i| i["b"] == "ground" || i["a"] == "ground")
        .collect();
    let f = |i: &serde_json::Value, k: &str| i[k].as_f64().unwrap();
    let seen: Vec<(f64, f64)> = ground
        .iter()
        .map(|i| (f(i, "speed_m_per_s"), f(i, "impulse_n_s")))
        .collect();
    assert_eq!(seen.len(), 6, "{ground:?}");
    for (v, got) in &seen {
        let want = 0.5 * v * 1.2 + 0.5 * 9.81 * 1e-3;
        assert!(
            (got / want - 1.0).abs() < 2e-3,
            "impulse {got} N s, M v (1+e) + M g dt = {want}"
        );
    }
    let range = |k: usize| {
        let x = seen.iter().map(|s| if k == 0 { s.0 } else { s.1 });
        (x.clone().fold(f64::MAX, f64::min), x.fold(0.0, f64::max))
    };
    let ((v_lo, v_hi), (j_lo, j_hi)) = (range(0), range(1));
    assert!(
        (v_lo - 0.101).abs() < 0.0005 && (v_hi - 0.190).abs() < 0.0005,
        "{seen:?}"
    );
    assert!(
        (j_lo - 0.065).abs() < 0.0005 && (j_hi - 0.119).abs() < 0.0005,
        "{seen:?}"
    );
    for i in &impacts {
        assert_eq!(i["type"], "impact");
        assert!(i["impulse_n_s"].as_f64().unwrap() > 0.0);
        assert!(i["speed_m_per_s"].as_f64().unwrap() >= 0.05);
    }
    let n = a.state_fields.len();
    let col = |name: &str| a.state_fields.iter().position(|f| f == name).unwrap();
    let last = &a.state[a.state.len() - n..];
    assert_eq!(last[col("slots_filled")], 4.0);
    // Nothing dropped: bricks set down and let go, then struck by the next brick, have not
    // fallen (the rule reads heights, not the speed of an impact they did not make).
    let dropped = last[col("dropped")];
    assert_eq!(dropped, 0.0);
    // The score's rule: 100 × 4/4 − 10 per drop − 5 × seconds above the comfort limit (half
    // of 8 N).
    let over = last[col("comfort_exceeded_s")];
    assert!((last[col("score")] - (100.0 - 10.0 * dropped - 5.0 * over).max(0.0)).abs() < 1e-9);
    assert!(last[col("complete_s")] > 0.0);
    // Proximity: 0 while touching, positive in free space.
    let near = a.state_column("nearest_m").unwrap();
    println!(
        "nearest min {}",
        near.iter().cloned().fold(f64::INFINITY, f64::min)
    );
    assert!(near.iter().all(|d| *d >= 0.0));
    // (the cursor sphere rests within its 2 µm contact skin of what it touches)
    assert!(near.iter().any(|d| *d < 1e-5));
    assert!(near.iter().any(|d| *d > 0.05));
}

/// The loading-zone brick grabbed as the house script does, lifted `lift_mm` (device mm; the
/// brick world maps 1 mm to 2 cm), held until it hangs still, let go at 3 s: the events and the
/// session's `dropped` count at the end.
fn release_from(lift_mm: f64) -> (Vec<(u64, String, String)>, f64) {
    let (x, y, z) = (-22.5, 2.5, -6.8);
    let mut s = String::from("[script]\nname = \"drop test\"\noperator = \"rigid\"\n");
    for (t, zz) in [
        (0.0, 7.5),
        (0.6, z),
        (0.7, z),
        (1.3, z + lift_mm),
        (4.0, z + lift_mm),
    ] {
        s.push_str(&format!(
            "\n[[waypoint]]\nt_s = {t:?}\nposition_mm = [{x:?}, {y:?}, {zz:?}]\n"
        ));
    }
    for (t, down) in [(0.65, true), (3.0, false)] {
        s.push_str(&format!(
            "\n[[button]]\nt_s = {t:?}\nname = \"centre\"\ndown = {down}\n"
        ));
    }
    let a = run("brickworld.toml", Some(s), 4.0, None);
    let n = a.state_fields.len();
    let col = a.state_fields.iter().position(|f| f == "dropped").unwrap();
    let dropped = a.state[a.state.len() - n + col];
    (a.events, dropped)
}

/// The drop rule (`haptic_loop::scene::score::DROP_HEIGHT_M`, docs/lesson.md "The score"): a
/// brick the hand lets go counts as dropped when its centre is 1 cm or more below where it was
/// let go at its first impact. Let go still, hanging 2 cm above its rest, it is dropped; 5 mm
/// above, it is not. The height is measured from the fall itself: released at rest, the brick
/// falls freely until it first touches the ground, so its height above its rest is v² / 2g of
/// the impact's approach speed and g t² / 2 of the ticks it fell (1 ms each).
#[test]
fn a_brick_let_go_2_cm_above_its_rest_is_dropped_and_5_mm_above_is_not() {
    assert_eq!(haptic_loop::scene::score::DROP_HEIGHT_M, 0.01);
    let g = 9.81;
    // Device mm lifted (20 mm in the world per mm, less the brick's sag on the coupling).
    for (lift_mm, height_m, dropped_want) in [(1.12, 0.020, 1.0), (0.325, 0.005, 0.0)] {
        let (ev, dropped) = release_from(lift_mm);
        let released = ev.iter().find(|e| e.1 == "brick.released").unwrap().0;
        assert_eq!(released, 3000);
        let first = ev
            .iter()
            .find(|e| e.1 == "brick.impact" && e.0 > released)
            .unwrap();
        let j = json(&first.2);
        assert_eq!(
            (&j["a"], &j["b"]),
            (
                &serde_json::json!("ground"),
                &serde_json::json!({"brick": 0})
            )
        );
        let v = j["speed_m_per_s"].as_f64().unwrap();
        let t = (first.0 - released) as f64 * 1e-3;
        let (by_speed, by_time) = (v * v / (2.0 * g), 0.5 * g * t * t);
        for h in [by_speed, by_time] {
            assert!(
                (h - height_m).abs() < 0.5e-3,
                "lift {lift_mm} mm: fell {h} m"
            );
        }
        assert_eq!(dropped, dropped_want, "let go {height_m} m above its rest");
    }
}
