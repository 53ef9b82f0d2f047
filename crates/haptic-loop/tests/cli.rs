//! The `nanohaptics` program: run, info, replay --verify (exit codes and messages), demo, bad
//! input, and a real crash (SIGKILL) mid-session losing at most the last second.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("haptic-loop-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn nh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn run_info_and_verify() {
    let rec = tmp("run.mcap");
    let r = rec.to_str().unwrap();
    let run = json(&nh(&[
        "run",
        "scenes/wall.toml",
        "--seconds",
        "1.5",
        "--out",
        r,
        "--json",
    ]));
    assert_eq!(run["ticks"], 1500);
    let info = json(&nh(&["info", r, "--json"]));
    assert_eq!(info["ticks"], 1500);
    assert_eq!(info["duration_s"], 1.5);
    assert_eq!(info["channels"].as_array().unwrap().len(), 9);
    let v = json(&nh(&["replay", r, "--verify", "--json"]));
    assert_eq!(v["report"]["ticks"], 1500);
    assert!(v["report"]["divergence"].is_null());
}

#[test]
fn replay_of_a_recording_of_another_scene_version_exits_2_naming_tick_and_channel() {
    // Re-record with a different scene text stored in the description: the file is internally
    // inconsistent, exactly what --verify must catch.
    let rec = tmp("edited.mcap");
    let scene = tmp("edited-wall.toml");
    let text = std::fs::read_to_string(root().join("scenes/wall.toml")).unwrap();
    std::fs::write(&scene, &text).unwrap();
    std::fs::copy(
        root().join("scenes/wall.script.toml"),
        scene.with_file_name("wall.script.toml"),
    )
    .unwrap();
    let r = rec.to_str().unwrap();
    assert!(
        nh(&["run", scene.to_str().unwrap(), "--out", r, "--json"])
            .status
            .success()
    );
    let mut rec_data = haptic_loop::record::read_recording_file(&rec, false).unwrap();
    rec_data.description.scene_toml = text.replace("engage_s = 0.25", "engage_s = 0.3");
    let v = haptic_loop::replay::verify(&rec_data).unwrap();
    let d = v.divergence.unwrap();
    // The ramps agree at tick 0 (both zero) and first differ at tick 1.
    assert_eq!((d.tick, d.channel.as_str()), (1, "/haptic/force"));

    // Through the program: the edited recording written back to a file.
    let edited = tmp("edited-rewritten.mcap");
    haptic_loop::record::rewrite(&rec_data, &edited).unwrap();
    let o = nh(&["replay", edited.to_str().unwrap(), "--verify"]);
    assert_eq!(o.status.code(), Some(2));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("DIVERGED at tick 1 on /haptic/force: recorded world"),
        "{out}"
    );
    // Without --verify the report is printed and the exit status is 0.
    assert!(nh(&["replay", edited.to_str().unwrap()]).status.success());

    // Through the program: a file whose bytes were damaged.
    let bytes = std::fs::read(&rec).unwrap();
    let bad = tmp("cut.mcap");
    std::fs::write(&bad, &bytes[..bytes.len() / 2]).unwrap();
    let o = nh(&["replay", bad.to_str().unwrap(), "--verify"]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("truncated recording"), "{err}");
    assert!(err.contains("complete ticks are readable"), "{err}");
    let o = nh(&["replay", bad.to_str().unwrap(), "--verify", "--salvage"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_input_is_an_error_naming_the_field() {
    let scene = tmp("bad.toml");
    std::fs::write(
        &scene,
        "[scene]\nname='x'\nkind='wall'\n[loop]\nrate_hz=1000\nengage_s=-1.0\n[wall]\nnormal=[0.0,0.0,1.0]\nstiffness_n_per_m=100.0\n",
    )
    .unwrap();
    let o = nh(&[
        "run",
        scene.to_str().unwrap(),
        "--script",
        "scenes/wall.script.toml",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: scene: `loop.engage_s` = -1 is out of range (allowed: 0 ≤ loop.engage_s ≤ 10)"
    );
    let o = nh(&["run", "scenes/wall.toml", "--operator", "hand:mass_kg=-2"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: script: `mass_kg` = -2 is out of range (allowed: 0.01 ≤ mass_kg ≤ 10)"
    );
    let o = nh(&["info", "Cargo.toml"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: Cargo.toml: not an MCAP file (bad magic bytes)"
    );
}

#[test]
fn demo_runs_every_scene_and_verifies() {
    let out = tmp("demo");
    let j = json(&nh(&["demo", "--out", out.to_str().unwrap(), "--json"]));
    assert_eq!(j["all_verified"], true);
    let scenes = j["scenes"].as_array().unwrap();
    assert!(!scenes.is_empty());
    for s in scenes {
        assert!(Path::new(s["recording"].as_str().unwrap()).exists());
        assert!(Path::new(s["picture"].as_str().unwrap()).exists());
    }
}

/// A real crash: the program is killed (SIGKILL) 2.5 s into a real-time session. Chunks are
/// flushed every session second, so the file holds whole seconds, at most one second behind.
#[test]
fn sigkill_mid_session_loses_at_most_the_last_second() {
    let rec = tmp("crash.mcap");
    let t0 = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args([
            "run",
            "scenes/wall.toml",
            "--seconds",
            "30",
            "--realtime",
            "--json",
            "--out",
            rec.to_str().unwrap(),
        ])
        .current_dir(root())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(2500));
    child.kill().unwrap();
    let elapsed = t0.elapsed().as_secs_f64();
    child.wait().unwrap();
    let e = haptic_loop::record::read_recording_file(&rec, false).unwrap_err();
    assert!(e.to_string().starts_with("truncated recording"), "{e}");
    let part = haptic_loop::record::read_recording_file(&rec, true).unwrap();
    let v = haptic_loop::replay::verify(&part).unwrap();
    assert!(v.ok());
    // At most `elapsed` seconds of ticks can have run; the file keeps all but the last second
    // (the process start-up, before tick 0, counts against us, so allow it 0.5 s).
    assert_eq!(v.ticks % 1000, 0);
    assert!(
        v.ticks as f64 >= (elapsed - 1.0 - 0.5).floor() * 1000.0,
        "{} ticks after {elapsed} s",
        v.ticks
    );
    assert!(v.ticks as f64 <= elapsed * 1000.0);
}

/// The scene: one terminal runs a bridged, live, recorded session; another runs the
/// fake device with 5% loss; the recording verifies.
#[test]
fn a_bridged_live_session_against_fake_device_replays_bit_for_bit() {
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let ws = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let rec = tmp("live.mcap");
    let sim = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args([
            "run",
            "scenes/wall.toml",
            "--device",
            &format!("udp:127.0.0.1:{port}"),
            "--realtime",
            "--live",
            &format!("ws:127.0.0.1:{ws}"),
            "--out",
            rec.to_str().unwrap(),
            "--wait-s",
            "30",
            "--json",
        ])
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let dev = nh(&[
        "fake-device",
        &format!("udp:127.0.0.1:{port}"),
        "--loss",
        "0.05",
        "--seconds",
        "2",
        "--json",
    ]);
    let d = json(&dev);
    let s = json(&sim.wait_with_output().unwrap());
    assert_eq!(s["end"], "device_ended");
    assert_eq!(s["device_link"], format!("udp:127.0.0.1:{port}"));
    let sent = d["sent"].as_u64().unwrap();
    assert_eq!(s["link"]["received"].as_u64().unwrap(), sent);
    assert!(d["dropped"].as_u64().unwrap() > 30, "{d}");
    assert!(s["live"]["scenes"].as_u64().unwrap() >= 90, "{s}");
    assert_eq!(d["forces_within_limits"], true);
    let o = nh(&["replay", rec.to_str().unwrap(), "--verify"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    assert!(String::from_utf8_lossy(&o.stdout).contains("identical bit for bit"));
}

/// From a folder with no scenes: built-in scenes by name, `scenes export`, and the exported
/// copy (a file on disk) overriding the built-in.
#[test]
fn builtin_scenes_work_from_any_directory_and_exported_copies_override_them() {
    let dir = tmp("elsewhere");
    std::fs::create_dir_all(&dir).unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap()
    };
    let j = json(&run(&["run", "wall", "--seconds", "0.2", "--json"]));
    assert_eq!(j["ticks"], 200);
    let j = json(&run(&[
        "run",
        "scenes/wall.toml",
        "--seconds",
        "0.2",
        "--json",
    ]));
    assert_eq!(j["scene"], "stiff wall (calibration)");
    let o = run(&["scenes", "export", "mine"]);
    assert!(o.status.success());
    // 5 scenes, 4 scripts (the 10 kHz scene shares the optical-tweezers script)
    assert_eq!(String::from_utf8_lossy(&o.stdout).lines().count(), 9);
    let edited = std::fs::read_to_string(dir.join("mine/wall.toml"))
        .unwrap()
        .replace("name = \"stiff wall (calibration)\"", "name = \"my wall\"");
    std::fs::write(dir.join("mine/wall.toml"), edited).unwrap();
    let j = json(&run(&[
        "run",
        "mine/wall.toml",
        "--seconds",
        "0.2",
        "--json",
    ]));
    assert_eq!(j["scene"], "my wall");
    let o = run(&["scenes", "export", "mine"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("exists: not overwriting it"));
    let o = run(&["run", "moon"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: cannot read moon: no such file, and not a built-in scene (built-in: brickworld, \
         nanoworld, optical_tweezers, optical_tweezers_10khz, wall; `nanohaptics scenes export \
         DIR` writes editable copies)"
    );
}
