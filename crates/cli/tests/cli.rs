//! The `nanohaptics` program: run, info, replay --verify (exit codes and messages), demo, bad
//! input, and a real crash (SIGKILL) mid-session losing at most the last second.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// Real-time tests (a session paced by the wall clock, a bridged device) run alone: the other
/// tests of this file wait, so that a loaded 2-core machine does not make them late. The
/// others run beside each other.
static REALTIME: std::sync::RwLock<()> = std::sync::RwLock::new(());

fn alone() -> std::sync::RwLockWriteGuard<'static, ()> {
    REALTIME.write().unwrap_or_else(|e| e.into_inner())
}

fn beside_others() -> std::sync::RwLockReadGuard<'static, ()> {
    REALTIME.read().unwrap_or_else(|e| e.into_inner())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-cli-{}", std::process::id()));
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

/// `nanohaptics run SCENE` waiting for a bridged device on loopback `port`, in real time,
/// recording to `rec`, with `extra` arguments; stdout (its JSON summary) piped.
fn bridged_run(scene: &str, port: u16, rec: &Path, extra: &[&str]) -> std::process::Child {
    let device = format!("udp:127.0.0.1:{port}");
    let mut args = vec![
        "run",
        scene,
        "--device",
        &device,
        "--realtime",
        "--out",
        rec.to_str().unwrap(),
        "--wait-s",
        "30",
        "--json",
    ];
    args.extend_from_slice(extra);
    Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(args)
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn run_info_and_verify() {
    let _shared = beside_others();
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
    assert_eq!(info["channels"].as_array().unwrap().len(), 10);
    let v = json(&nh(&["replay", r, "--verify", "--json"]));
    assert_eq!(v["report"]["ticks"], 1500);
    assert!(v["report"]["divergence"].is_null());
}

/// The figures docs/recording-format.md quotes from the golden recordings.
#[test]
fn the_golden_recordings_hold_the_figures_the_format_doc_quotes() {
    let _shared = beside_others();
    // docs/recording-format.md: "`brickworld.mcap`, which now holds the whole 21.9 s house script"
    let info = json(&nh(&["info", "recordings/brickworld.mcap", "--json"]));
    let s = info["duration_s"].as_f64().expect("duration");
    assert!((21.85..21.95).contains(&s), "{info}"); // 21 932 ticks at 1 kHz
    // docs/recording-format.md: "`replay` prints what was checked: `checked: 5 chunk CRCs, the
    // data-section CRC, the summary CRC and the summary against the records, ticks 0–3999 in
    // sequence and as many as the session record says`"
    let o = nh(&["replay", "recordings/wall.mcap", "--verify"]);
    assert!(o.status.success(), "{o:?}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.lines().any(|l| l.trim()
            == "checked: 5 chunk CRCs, the data-section CRC, the summary CRC and the summary \
                against the records, ticks 0–3999 in sequence and as many as the session \
                record says"),
        "{out}"
    );
}

#[test]
fn replay_of_a_recording_of_another_scene_version_exits_2_naming_tick_and_channel() {
    let _shared = beside_others();
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
    let mut rec_data = recording::read_recording_file(&rec, false).unwrap();
    rec_data.description.scene_toml = text.replace("engage_s = 0.25", "engage_s = 0.3");
    let v = haptic_loop::replay::verify(&rec_data).unwrap();
    let d = v.divergence.unwrap();
    // The ramps agree at tick 0 (both zero) and first differ at tick 1.
    assert_eq!((d.tick, d.channel.as_str()), (1, "/haptic/force"));

    // Through the program: the edited recording written back to a file.
    let edited = tmp("edited-rewritten.mcap");
    recording::rewrite(&rec_data, &edited).unwrap();
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
    let _shared = beside_others();
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
        format!(
            "error: {}:6:10: scene: `loop.engage_s` = -1 is out of range: allowed 0 ≤ \
             loop.engage_s ≤ 10",
            scene.display()
        )
    );
    let o = nh(&["run", "scenes/wall.toml", "--operator", "hand:mass_kg=-2"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: script: `mass_kg` = -2 is out of range: allowed 0.01 ≤ mass_kg ≤ 10"
    );
    let o = nh(&["info", "Cargo.toml"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: Cargo.toml: not an MCAP file (bad magic bytes)"
    );
}

#[test]
fn demo_runs_every_scene_and_verifies() {
    let _shared = beside_others();
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
    let _quiet = alone();
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
    let e = recording::read_recording_file(&rec, false).unwrap_err();
    assert!(e.to_string().starts_with("truncated recording"), "{e}");
    let part = recording::read_recording_file(&rec, true).unwrap();
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
    let _quiet = alone();
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
    let sim = bridged_run(
        "scenes/wall.toml",
        port,
        &rec,
        &["--live", &format!("ws:127.0.0.1:{ws}")],
    );
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

/// `nanohaptics play` with a bridged device as the hand: it prints the page's address before
/// the device's hello, serves the page, records the session, keeps the end screen up until
/// Ctrl-C, and the recording replays bit for bit.
#[test]
fn play_serves_the_page_and_records_a_bridged_session() {
    let _quiet = alone();
    use std::io::{BufRead, Read, Write};
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let rec = tmp("play.mcap");
    let mut play = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args([
            "play",
            "brickworld",
            "--port",
            "0",
            "--seconds",
            "1",
            "--out",
        ])
        .arg(&rec)
        .args(["--device", &format!("udp:127.0.0.1:{port}")])
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = std::io::BufReader::new(play.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no address in {line:?}"));
    // The page is served before any device is there.
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut tcp = std::net::TcpStream::connect(addr).unwrap();
    write!(
        tcp,
        "GET / HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    // Read the head, then the body by its Content-Length (the server may keep the socket).
    tcp.set_read_timeout(Some(std::time::Duration::from_secs(10)))
        .unwrap();
    let mut resp = std::io::BufReader::new(tcp);
    let mut page = String::new();
    let mut len = 0;
    loop {
        let mut h = String::new();
        resp.read_line(&mut h).unwrap();
        if let Some(v) = h.to_ascii_lowercase().strip_prefix("content-length:") {
            len = v.trim().parse().unwrap();
        }
        page.push_str(&h);
        if h == "\r\n" {
            break;
        }
    }
    let mut body = vec![0; len];
    resp.read_exact(&mut body).unwrap();
    page.push_str(&String::from_utf8_lossy(&body));
    assert!(
        page.starts_with("HTTP/1.1 200"),
        "{}",
        &page[..page.len().min(200)]
    );
    assert!(page.contains("<canvas"), "the page has no canvas");
    let dev = nh(&[
        "fake-device",
        &format!("udp:127.0.0.1:{port}"),
        "--seconds",
        "3",
    ]);
    assert!(
        dev.status.success(),
        "{}",
        String::from_utf8_lossy(&dev.stderr)
    );
    // The end screen stays up until Ctrl-C; then the program says how the session went.
    std::thread::sleep(std::time::Duration::from_millis(300));
    assert!(
        play.try_wait().unwrap().is_none(),
        "play ended before Ctrl-C"
    );
    let pid = play.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .unwrap()
            .success()
    );
    assert!(play.wait().unwrap().success());
    line.clear();
    out.read_line(&mut line).unwrap();
    assert!(line.starts_with("completed: 1000 ticks"), "{line}");
    let o = nh(&["replay", rec.to_str().unwrap(), "--verify"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
}

/// Issue 22 over the bridge: a modelled Falcon held loosely carries the first brick of the
/// brick script for real (4 s, real time) with no force change above 1 N between periods,
/// the motors taking energy from the hand rather than giving it, and the session replays bit
/// for bit. Bad model and grip arguments are named.
#[test]
fn a_loosely_held_falcon_carries_a_brick_without_buzz_over_the_bridge() {
    let _quiet = alone();
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let rec = tmp("modelled.mcap");
    // Real time over UDP on a shared 2-core machine: a reply later than the watchdog's grace
    // (2.5 ms), or a sample the simulator saw late (its `watchdog_ticks`), makes the watchdog
    // ramp the force down and the soft engagement ramp it up again; a tick that misses its
    // deadline sends zero force. That is a jump the hand feels and energy the re-engagement
    // gives it, but neither is the rendering's buzz nor its passivity. A run whose claims
    // fail while the machine disturbed it is tried again (at most eight runs, waiting 1 s,
    // 2 s, ... between them); a jump over 1 N or energy into the hand in a run with every
    // reply on time is the rendering's fault, and fails at once. Measured under three CPU hogs
    // on 2 cores: disturbed runs gave 0.0002-0.014 J into the hand and up to 16 jumps; the
    // undisturbed runs of this test give none.
    let mut attempt = 0;
    let d = loop {
        attempt += 1;
        let sim = bridged_run("scenes/brickworld.toml", port, &rec, &[]);
        let dev = nh(&[
            "fake-device",
            &format!("udp:127.0.0.1:{port}"),
            "--script",
            "scenes/brickworld.script.toml",
            "--model",
            "falcon",
            "--grip",
            "loose",
            "--seconds",
            "4",
            "--json",
        ]);
        let d = json(&dev);
        let s = json(&sim.wait_with_output().unwrap());
        assert_eq!(s["end"], "device_ended");
        let late = d["round_trip"]["max_ns"].as_u64().unwrap() > 2_500_000
            || s["watchdog_ticks"].as_u64().unwrap() > 0;
        let held = d["jumps_over_1n"] == 0 && d["energy_to_hand_j"].as_f64().unwrap() < 0.0;
        if held || !late || attempt == 8 {
            break d;
        }
        // A disturbance on a shared machine lasts seconds (five disturbed runs in a row,
        // 20 s, were seen on a fresh clone): wait longer before each new try.
        std::thread::sleep(std::time::Duration::from_secs(attempt));
        eprintln!(
            "run {attempt}: the machine made a reply or sample later than the watchdog's \
             grace ({} watchdog ticks), tried again: {d}",
            s["watchdog_ticks"]
        );
    };
    assert_eq!(d["jumps_over_1n"], 0, "{d}");
    assert!(d["max_jump_n"].as_f64().unwrap() < 1.0);
    assert!(d["energy_to_hand_j"].as_f64().unwrap() < 0.0, "{d}");
    let o = nh(&["replay", rec.to_str().unwrap(), "--verify"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let forty: String = (0..40)
        .map(|i| format!("b{i}"))
        .collect::<Vec<_>>()
        .join(",");
    for (args, err) in [
        (
            vec!["--model", "omega"],
            "error: --model: unknown device model `omega` (allowed: falcon, touch, delta3, inverse3)",
        ),
        (
            vec!["--grip", "k=0"],
            "error: --grip: grip `k` = 0 is out of range: allowed 0 < k ≤ 10000 N/m",
        ),
        (
            vec!["--ideal"],
            "error: --ideal needs --grip (it removes a modelled device's encoder counts)",
        ),
        (
            vec!["--button-names", forty.as_str()],
            "error: --button-names: device specs: `button_names` = 40 buttons is out of range: \
             allowed at most 32 buttons",
        ),
        (
            vec!["--button-names", "a,b,a"],
            "error: --button-names: device specs: `button_names` = \"a\" (buttons 0 and 2) is out \
             of range: allowed distinct names (a role is bound to a button by its name)",
        ),
    ] {
        let mut a = vec!["fake-device", "udp:127.0.0.1:1"];
        a.extend(args);
        let o = nh(&a);
        assert_eq!(o.status.code(), Some(1));
        assert_eq!(String::from_utf8_lossy(&o.stderr).trim(), err);
    }
}

/// From a folder with no scenes: built-in scenes by name, `scenes export`, and the exported
/// copy (a file on disk) overriding the built-in.
#[test]
fn builtin_scenes_work_from_any_directory_and_exported_copies_override_them() {
    let _shared = beside_others();
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

/// Runs the program in `dir` and returns its error line (exit code 1 asserted).
fn error_in(dir: &Path, args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{args:?} should fail");
    String::from_utf8_lossy(&o.stderr).trim().to_string()
}

#[test]
fn file_errors_say_file_line_column_and_what_was_expected() {
    let _shared = beside_others();
    let dir = tmp("located");
    std::fs::create_dir_all(&dir).unwrap();
    let w = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
    // TOML syntax: the reader's own position.
    w("bad.toml", "garbage = [\n");
    assert_eq!(
        error_in(&dir, &["run", "bad.toml"]),
        "error: bad.toml:1:12: scene: unclosed array, expected `]`"
    );
    // A range error: the field's value.
    let wall = std::fs::read_to_string(root().join("scenes/wall.toml")).unwrap();
    let line = wall
        .lines()
        .position(|l| l.starts_with("stiffness_n_per_m"))
        .unwrap()
        + 1;
    w(
        "w.toml",
        &wall.replacen("stiffness_n_per_m = ", "stiffness_n_per_m = -", 1),
    );
    w(
        "wall.script.toml",
        &std::fs::read_to_string(root().join("scenes/wall.script.toml")).unwrap(),
    );
    assert_eq!(
        error_in(&dir, &["run", "w.toml"]),
        format!(
            "error: w.toml:{line}:21: scene: `wall.stiffness_n_per_m` = -5000 is out of range: \
             allowed 0 < wall.stiffness_n_per_m ≤ 1e12"
        )
    );
    // A world's own parameter check, located in the world's table.
    w(
        "b.toml",
        &std::fs::read_to_string(root().join("scenes/brickworld.toml"))
            .unwrap()
            .replacen(
                "position_tolerance_m = 0.01",
                "position_tolerance_m = -0.01",
                1,
            ),
    );
    let e = error_in(&dir, &["run", "b.toml", "--script", "wall.script.toml"]);
    assert!(
        e.starts_with("error: b.toml:")
            && e.ends_with(
                "scene: brickworld.params: parameter `blueprint.position_tolerance_m` = -0.01 \
                 is out of range: allowed (0, 1]"
            ),
        "{e}"
    );
    // Scripts: unknown field, and a range error in the second waypoint.
    w("s2.toml", "[script]\nname=\"x\"\nspeed=3\n");
    assert_eq!(
        error_in(&dir, &["run", "wall", "--script", "s2.toml"]),
        "error: s2.toml:3:1: script: unknown field `speed`, expected one of `name`, \
         `duration_s`, `operator`"
    );
    w(
        "s3.toml",
        "[script]\nname=\"x\"\n[[waypoint]]\nt_s=0.0\nposition_mm=[0.0,0.0,0.0]\n[[waypoint]]\n\
         t_s=-0.8\nposition_mm=[0.0,0.0,0.0]\n",
    );
    assert_eq!(
        error_in(&dir, &["run", "wall", "--script", "s3.toml"]),
        "error: s3.toml:7:5: script: `waypoint[1].t_s` = -0.8 is out of range: allowed 0 ≤ \
         t_s ≤ 3600"
    );
    // A recording or binary file given as a scene.
    let wall_rec = root().join("recordings/wall.mcap");
    assert_eq!(
        error_in(&dir, &["run", wall_rec.to_str().unwrap()]),
        format!(
            "error: cannot read {}: this is an MCAP recording, not a TOML file (recordings are \
             for `nanohaptics replay`, `info` and `render`)",
            wall_rec.display()
        )
    );
    std::fs::write(dir.join("bin.toml"), b"a = 1\n\xff\xfe").unwrap();
    assert_eq!(
        error_in(&dir, &["run", "bin.toml"]),
        "error: cannot read bin.toml: not UTF-8 text: byte 6 (line 2, column 1) is not valid \
         UTF-8 (a TOML file is text)"
    );
    // A scene copied without its default script.
    std::fs::create_dir_all(dir.join("alone")).unwrap();
    std::fs::write(dir.join("alone/wall.toml"), &wall).unwrap();
    let line = wall
        .lines()
        .position(|l| l.starts_with("default_script"))
        .unwrap()
        + 1;
    assert_eq!(
        error_in(&dir, &["run", "alone/wall.toml"]),
        format!(
            "error: alone/wall.toml:{line}:18: `scene.default_script` = \"wall.script.toml\": \
             cannot read alone/wall.script.toml: No such file or directory (os error 2) (pass \
             --script FILE, or keep the script next to the scene; `nanohaptics scenes export \
             DIR` writes the built-in scenes with their scripts)"
        )
    );
}

#[test]
fn a_session_shorter_than_one_tick_is_refused() {
    let _shared = beside_others();
    assert_eq!(
        error_in(&root(), &["run", "wall", "--seconds", "0.0004"]),
        "error: session length [s] = 4e-4 is out of range: allowed 5e-4 ≤ length ≤ 3600 s, one \
         tick or more (a tick is 1 ms at 1000 Hz)"
    );
    assert_eq!(
        error_in(&root(), &["run", "wall", "--seconds", "1e308"]),
        "error: session length [s] = 1e308 is out of range: allowed 0 < length ≤ 3600 s"
    );
    // Half a tick rounds to one tick.
    let run = json(&nh(&["run", "wall", "--seconds", "0.0005", "--json"]));
    assert_eq!(run["ticks"], 1);
}

/// Long work can be interrupted: Ctrl-C (SIGINT) stops a session after the current tick, the
/// recording is finished (not truncated) and verifies, and the exit code is 130.
#[test]
fn ctrl_c_stops_a_session_cleanly_with_a_complete_recording() {
    let _quiet = alone();
    let rec = tmp("interrupted.mcap");
    let child = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["run", "wall", "--seconds", "3600", "--realtime", "--out"])
        .arg(&rec)
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let k = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130));
    let r = recording::read_recording_file(&rec, false).expect("a complete file");
    let v = haptic_loop::replay::verify(&r).unwrap();
    assert!(v.ok());
    assert!(v.ticks > 0 && v.ticks < 3_600_000, "{} ticks", v.ticks);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!(
            "stopped by an interrupt after {} ticks; {} holds them, complete and verifiable",
            v.ticks,
            rec.display()
        )),
        "{err}"
    );
}

/// A reader that has closed the pipe (`nanohaptics scenes | head -0`) ends the program
/// quietly with status 141, as any Unix filter, never with a panic message.
#[test]
fn a_closed_pipe_ends_the_program_quietly() {
    let _shared = beside_others();
    for args in [&["scenes"][..], &["info", "recordings/wall.mcap"]] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
            .args(args)
            .current_dir(root())
            .stdout(writer)
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err, "", "{args:?}");
        assert_eq!(o.status.code(), Some(141), "{args:?}");
    }
}

/// `lesson` and `render --audio` from a directory with no `scenes/` (the built-in scenes), and
/// the house score in the run summary.
#[test]
fn lesson_audio_and_score_work_from_any_directory() {
    let _shared = beside_others();
    let dir = tmp("elsewhere");
    std::fs::create_dir_all(&dir).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args([
            "lesson",
            "--out",
            "my-lesson",
            "--width",
            "400",
            "--sample-rate",
            "8000",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("bricks: 4 of 4 slots"), "{out}");
    assert!(out.contains("pull-off 3.00 nN (10.00×)"), "{out}");
    for f in [
        "lesson.md",
        "hysteresis.png",
        "macro_house.wav",
        "nano_house.mcap",
        "lesson.json",
    ] {
        assert!(dir.join("my-lesson").join(f).is_file(), "{f}");
    }
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["lesson", "--width", "10"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: --width = 10 is out of range: allowed 200–4000 px"
    );
    let rec = dir.join("my-lesson/macro_house.mcap");
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args([
            "render",
            rec.to_str().unwrap(),
            "--audio",
            "b.wav",
            "--proximity",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("wrote WAV sound b.wav"));
    let run = json(&nh(&["run", "nanoworld", "--json"]));
    assert_eq!(run["house_score"]["score"], 100.0);
    assert_eq!(run["house_score"]["slots_filled"], 7.0);
    let wall = json(&nh(&["run", "wall", "--json", "--seconds", "0.1"]));
    assert!(wall["house_score"].is_null());
}

/// A device is named one way in every command (`DeviceSource::parse`): the same forms, the
/// same error listing them, and each command's own refusal of a form it cannot use.
#[test]
fn every_command_names_a_device_the_same_way() {
    let forms = "allowed falcon, touch, udp:HOST:PORT or udp:PORT";
    for (args, err) in [
        (
            vec!["run", "wall", "--device", "phantom"],
            format!("error: --device: device `phantom` is not known: {forms}"),
        ),
        (
            vec!["play", "wall", "--device", "phantom"],
            format!("error: --device: device `phantom` is not known: {forms}"),
        ),
        (
            vec!["fake-device", "phantom"],
            format!("error: device `phantom` is not known: {forms}"),
        ),
        (
            vec!["play", "wall", "--device", "touch"],
            "error: --device `touch`: play's own hand is the page; --device names a device in \
             another process (udp:HOST:PORT or udp:PORT)"
                .to_string(),
        ),
        (
            vec!["fake-device", "touch"],
            "error: `touch` is a device model: fake-device plays against the simulator's \
             address, udp:HOST:PORT or udp:PORT (the model is --model touch)"
                .to_string(),
        ),
        (
            vec!["run", "wall", "--device", "udp:host"],
            "error: --device: device `udp:host`: `host` is not an IP address and port \
             (e.g. 127.0.0.1:9870)"
                .to_string(),
        ),
    ] {
        let o = nh(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&o.stderr).trim(), err, "{args:?}");
    }
    // The loopback shorthand is accepted everywhere: `run` waits on it (here for no time).
    let o = nh(&[
        "run", "wall", "--device", "udp:1", "--wait-s", "0", "--json",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: device: device link: no device said hello on udp:127.0.0.1:1 within 0 s"
    );
}

/// `classroom --lesson FILE` refuses a lesson file with a mistake before it serves anything:
/// the file's line and column, the field and what is allowed, exit 1.
#[test]
fn classroom_lesson_refuses_a_bad_lesson_file_with_its_place() {
    let dir = tmp("class-lesson");
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.lesson.toml");
    std::fs::write(
        &bad,
        "[lesson]\ntitle = \"x\"\n[[step]]\nid = \"a\"\ntitle = \"A\"\nscene = \"brickworld\"\n\
         task = \"t\"\ndone = { when = \"atom_snapped\" }\n",
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .args(["classroom", "--port", "0", "--lesson", "bad.lesson.toml"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&o.stdout), "");
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: bad.lesson.toml:8:17: lesson: `step[0].done.when` = \"atom_snapped\" cannot \
         happen in scene \"brickworld\": it reads nano.snap, which a brickworld scene never \
         emits (allowed in a brickworld scene: house_complete, brick_lifted, brick_thrown, \
         brick_placed, time)"
    );
    assert!(
        !dir.join("class").exists(),
        "nothing served, no folder made"
    );
}

/// A flag that cannot apply to a lesson is refused, not ignored: `--seconds` (a step ends when
/// its condition is met) for `play --lesson` and `classroom --lesson`, `--device` for `play
/// --lesson` (each step's world takes the page as the hand).
#[test]
fn lesson_refuses_the_flags_it_cannot_apply() {
    let dir = tmp("lesson-flags");
    std::fs::create_dir_all(&dir).unwrap();
    for (args, said) in [
        (
            &["play", "--lesson", "--port", "0", "--seconds", "5"][..],
            "error: --seconds does not apply to a lesson: each step ends when its condition is \
             met, and the lesson when the student finishes it or ends it",
        ),
        (
            &["classroom", "--lesson", "--port", "0", "--seconds", "5"][..],
            "error: --seconds does not apply to a lesson: each step ends when its condition is \
             met, and the lesson when the student finishes it or is ended",
        ),
        (
            &[
                "play",
                "--lesson",
                "--port",
                "0",
                "--device",
                "udp:127.0.0.1:9",
            ][..],
            "error: --device does not apply to a lesson: each step's world takes the page as \
             the hand",
        ),
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&o.stderr).trim(), said, "{args:?}");
    }
}
