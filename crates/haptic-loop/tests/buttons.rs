//! Buttons by role (issue 41): every built-in script runs on every preset, locally and over the
//! bridge, and a device named like the Haply adapter's default (`a`, `b`, `c`), a Touch and a
//! delta.3 grab, carry and place a brick in the brick world over the bridge; the welcome states
//! the roles in force, the scene or the command line can move them, and a hello the simulator
//! cannot accept is answered with a refusal naming the field.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::Script;
use haptic_devices::bridge::BridgeConfig;
use haptic_devices::bridge::fake::{FakeConfig, FakeReport, fake_specs, run_fake_as};
use haptic_devices::bridge::protocol::{Packet, Refusal};
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionOptions, SessionReport, run_session};
use haptic_types::DeviceModel;
use haptic_types::device::FALCON;
use recording::read_recording_file;
use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The real-time sessions of this file run one at a time.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn out(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("buttons");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn read(rel: &str) -> String {
    std::fs::read_to_string(root().join(rel)).unwrap()
}

fn free_port() -> SocketAddr {
    UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
}

/// The built-in scenes and their scripts.
const BUILTIN: [(&str, &str); 4] = [
    ("scenes/wall.toml", "scenes/wall.script.toml"),
    ("scenes/brickworld.toml", "scenes/brickworld.script.toml"),
    (
        "scenes/optical_tweezers.toml",
        "scenes/optical_tweezers.script.toml",
    ),
    ("scenes/nanoworld.toml", "scenes/nanoworld.script.toml"),
];

/// Each built-in script, its buttons by role, plays on each preset's own buttons (the closed
/// loop: the preset's mechanics held by a firm hand), its first 2 s.
#[test]
fn every_builtin_script_runs_on_every_preset_locally() {
    for (scene, script) in BUILTIN {
        let (scene, script) = (read(scene), read(script));
        for mech in PRESETS {
            let r = closed_loop::run(&scene, &script, mech, Grip::FIRM, Some(2.0))
                .unwrap_or_else(|e| panic!("{} on {}: {e}", script.lines().count(), mech.name));
            assert!(r.ticks > 0, "{}", mech.name);
        }
    }
}

/// Each built-in script, by role, on each preset's own buttons over the bridge: `fake-device`
/// as the modelled preset (protocol 2, a firm hand), 1 s of each scene, welcomed with the
/// preset's roles; the session runs to the device's bye.
#[test]
fn every_builtin_script_runs_on_every_preset_over_the_bridge() {
    let _serial = serial();
    for (scene, script) in BUILTIN {
        for mech in PRESETS {
            let addr = free_port();
            let mut dev = brick_device(addr, Some(mech), None);
            let specs = fake_specs(&dev, None);
            dev.script = Script::from_toml(&read(script), &specs).unwrap();
            dev.seconds = Some(1.0);
            let roles = haptic_types::ButtonRoles::resolve(&specs, &[]).unwrap();
            let mut o = bridged(read(scene), addr, &out("every.mcap"));
            o.out = None;
            let (r, f) = session_with(o, move || run_fake_as(&dev, None, None).unwrap());
            let who = format!("{scene} on {}", mech.name);
            assert_eq!(f.welcome.roles, Some(roles.wire()), "{who}");
            assert_eq!(r.end, "device_ended", "{who}");
            assert!(f.replies > 500, "{who}: {} replies", f.replies);
        }
    }
}

/// The brick world's script on a local Touch: button1 grips, the first brick is carried to its
/// slot (before issue 41 the script was refused by button name).
#[test]
fn the_brick_script_builds_on_a_local_touch() {
    let mut o = SessionOptions::new(
        SceneSource::from_path(&root().join("scenes/brickworld.toml")).unwrap(),
    );
    o.device = Some(haptic_devices::source::DeviceSource::Model(
        DeviceModel::Touch,
    ));
    o.seconds = Some(4.5);
    let r = run_session(&o, &mut |_, _| {}).unwrap();
    assert_placed(&r, "touch");
}

/// The session grabbed a brick, let it go and filled a slot.
fn assert_placed(r: &SessionReport, who: &str) {
    let e = &r.arrays.events;
    for kind in ["brick.grabbed", "brick.released", "brick.slot_filled"] {
        assert!(e.iter().any(|x| x.1 == kind), "{who}: no {kind}");
    }
    let filled = r.arrays.state_column("slots_filled").unwrap();
    assert_eq!(filled.last().copied(), Some(1.0), "{who}");
}

/// The brick world's script, its first 4.5 s (one brick grabbed, carried, placed), played by
/// `physical` (a modelled preset) or a rigid Falcon-limited stylus announcing `names`.
fn brick_device(
    addr: SocketAddr,
    physical: Option<Mechanics>,
    names: Option<&[String]>,
) -> FakeConfig {
    let mut cfg = FakeConfig {
        target: addr,
        model: DeviceModel::Falcon,
        script: Script::from_toml(&read("scenes/wall.script.toml"), &FALCON).unwrap(),
        hand: None,
        physical: physical.map(|m| (m, Grip::FIRM)),
        loss: 0.0,
        jitter_s: 0.0,
        latency_s: 0.0,
        seed: 1,
        seconds: Some(4.5),
        outage: None,
        wait_s: 20.0,
        bye: true,
        protocol: haptic_devices::local::Protocol::V2,
        fault: None,
    };
    let specs = fake_specs(&cfg, names);
    cfg.script = Script::from_toml(&read("scenes/brickworld.script.toml"), &specs).unwrap();
    cfg
}

fn bridged(scene_text: String, addr: SocketAddr, out: &Path) -> SessionOptions {
    let mut source = SceneSource::from_path(&root().join("scenes/brickworld.toml")).unwrap();
    source.text = scene_text;
    let mut o = SessionOptions::new(source);
    let mut b = BridgeConfig::parse(&format!("udp:{addr}")).unwrap();
    b.wait_s = 20.0;
    o.device = Some(haptic_devices::source::DeviceSource::Udp(b));
    o.out = Some(out.to_path_buf());
    o
}

fn session_with(
    opts: SessionOptions,
    device: impl FnOnce() -> FakeReport,
) -> (SessionReport, FakeReport) {
    let h = std::thread::spawn(move || run_session(&opts, &mut |_, _| {}));
    let f = device();
    (h.join().unwrap().unwrap(), f)
}

/// Who says hello, its mechanics (`None`: a rigid stylus), the button names it announces
/// instead of its own, and the welcome's role bytes it expects.
type Case<'a> = (&'a str, Option<Mechanics>, Option<&'a [String]>, [u8; 4]);

/// Done when (issue 41): a hello named like the Haply adapter's default (`a`, `b`, `c`), a
/// Touch's and a delta.3's grabs, carries and places a brick in the brick world over the
/// bridge; each welcome states the roles in force, and each recording replays bit for bit.
#[test]
fn haply_touch_and_delta3_hellos_build_in_the_brick_world_over_the_bridge() {
    let _serial = serial();
    let abc: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let cases: [Case; 3] = [
        // a grips, b turns about z, c about x.
        ("haply", None, Some(&abc), [0, 2, 255, 1]),
        ("touch", Some(Mechanics::TOUCH), None, [0, 255, 255, 1]),
        ("delta3", Some(Mechanics::DELTA3), None, [0, 255, 255, 1]),
    ];
    for (who, physical, names, roles) in cases {
        let addr = free_port();
        let rec = out(&format!("{who}.mcap"));
        let dev = brick_device(addr, physical, names);
        let (r, f) = session_with(
            bridged(read("scenes/brickworld.toml"), addr, &rec),
            move || run_fake_as(&dev, names, None).unwrap(),
        );
        assert_eq!(f.welcome.roles, Some(roles), "{who}");
        assert_placed(&r, who);
        let rec = read_recording_file(&rec, false).unwrap();
        let v = verify(&rec).unwrap();
        assert!(v.ok(), "{who}: {:?}", v.divergence);
        // The recording states the mapping in force (its metadata record `buttons`).
        let grip = if who == "haply" {
            "a"
        } else if who == "touch" {
            "button1"
        } else {
            "button0"
        };
        assert_eq!(rec.metadata["buttons"]["grip"], grip, "{who}");
        assert!(rec.metadata["buttons"]["mapping"].starts_with(&format!("grip = {grip},")));
    }
}

/// A scene's `[device] buttons` moves a role (the welcome says so); a device lacking the named
/// button is refused with the field and its buttons, and the simulator's own message counts
/// and names what it refused.
#[test]
fn a_scene_override_moves_a_role_and_a_device_without_the_button_is_refused() {
    let _serial = serial();
    let scene = read("scenes/brickworld.toml").replace(
        "[device]\nmodel = \"falcon\"",
        "[device]\nmodel = \"falcon\"\nbuttons = { grip = \"c\" }",
    );
    // The override: c grips (and no longer turns about x).
    let addr = free_port();
    let abc: Vec<String> = ["a", "b", "c"].map(String::from).to_vec();
    let mut dev = brick_device(addr, None, Some(&abc));
    dev.seconds = Some(0.3);
    let names = abc.clone();
    let (_, f) = session_with(
        bridged(scene.clone(), addr, &out("override.mcap")),
        move || run_fake_as(&dev, Some(&names), None).unwrap(),
    );
    assert_eq!(f.welcome.roles, Some([2, 255, 255, 1]));

    // A device with buttons x, y only: refused, naming `buttons.grip` and its buttons.
    let addr = free_port();
    let mut o = bridged(scene, addr, &out("refused.mcap"));
    if let Some(haptic_devices::source::DeviceSource::Udp(b)) = &mut o.device {
        b.wait_s = 1.0;
    }
    let h = std::thread::spawn(move || run_session(&o, &mut |_, _| {}));
    let xy: Vec<String> = ["x", "y"].map(String::from).to_vec();
    let mut dev = brick_device(addr, None, Some(&xy));
    dev.wait_s = 5.0;
    let e = run_fake_as(&dev, Some(&xy), None).unwrap_err().to_string();
    assert_eq!(
        e,
        format!(
            "device link: the simulator at {addr} refused the hello: hello refused: \
             `buttons.grip` = \"c\" is out of range: allowed a button of device `falcon`: x, y"
        )
    );
    let e = h.join().unwrap().err().unwrap().to_string();
    assert!(
        e.contains(&format!("no device said hello on udp:{addr} within 1 s; ")),
        "{e}"
    );
    assert!(
        e.contains("hello refused: `buttons.grip` = \"c\" is out of range"),
        "{e}"
    );
}

/// A hello the simulator cannot accept gets a refusal (version byte 1, type 6) naming the
/// field and the allowed values, at most one per 100 ms however often it is repeated; a
/// version-3 hello is welcomed with version 2 and the roles in force.
#[test]
fn refusals_are_rate_limited_and_a_newer_hello_negotiates_down() {
    let _serial = serial();
    let addr = free_port();
    let mut b = BridgeConfig::parse(&format!("udp:{addr}")).unwrap();
    b.wait_s = 3.0;
    let mut dev = haptic_devices::bridge::UdpDevice::new(b);
    let opened = std::thread::spawn(move || {
        use haptic_types::HapticDevice;
        let r = dev.open().map_err(|e| e.to_string());
        let counters = dev.link_counters();
        let _ = dev.close();
        (r, counters)
    });
    // The simulator binds at once; give its thread time to start before the first hello.
    std::thread::sleep(Duration::from_millis(300));
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    sock.set_read_timeout(Some(Duration::from_millis(5)))
        .unwrap();
    let mut bad = FALCON;
    bad.limits.max_force_n = 5000.0;
    let hello = |version: u8, specs| {
        Packet::Hello {
            version,
            rate_hz: 1000,
            specs,
        }
        .encode()
    };
    let refused = hello(2, bad);
    let mut refusals = Vec::new();
    let mut buf = [0u8; 2048];
    let start = std::time::Instant::now();
    // 40 refused hellos in about 0.4 s.
    for _ in 0..40 {
        sock.send_to(&refused, addr).unwrap();
        while let Ok((n, _)) = sock.recv_from(&mut buf) {
            if let Ok(Packet::Refusal(r)) = Packet::decode(&buf[..n]) {
                assert_eq!(&buf[4..6], &[1, 6]);
                refusals.push(r);
            }
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let elapsed = start.elapsed().as_secs_f64();
    assert!(!refusals.is_empty());
    assert!(
        refusals.len() as f64 <= elapsed / 0.1 + 1.0,
        "{} refusals in {elapsed} s",
        refusals.len()
    );
    assert_eq!(
        refusals[0],
        Refusal::new(
            "max_force_n",
            "0.001 ≤ max_force_n ≤ 1000",
            "hello refused: device specs: `max_force_n` = 5000 is out of range: allowed 0.001 \
             ≤ max_force_n ≤ 1000"
                .into()
        )
    );
    // A version-5 hello (a newer device): welcomed with 4, the Falcon's roles.
    sock.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    let welcome = loop {
        sock.send_to(&hello(5, FALCON), addr).unwrap();
        if let Ok((n, _)) = sock.recv_from(&mut buf) {
            if let Ok(w @ Packet::Welcome { .. }) = Packet::decode(&buf[..n]) {
                break w;
            }
        }
    };
    match welcome {
        Packet::Welcome { version, roles, .. } => {
            assert_eq!((version, roles), (4, Some([0, 1, 2, 3])));
        }
        other => panic!("{other:?}"),
    }
    let (r, counters) = opened.join().unwrap();
    assert!(r.is_ok(), "{r:?}");
    let get = |k: &str| counters.iter().find(|c| c.0 == k).unwrap().1;
    assert_eq!(
        (get("refused"), get("hellos"), get("malformed")),
        (40, 1, 0)
    );
}
