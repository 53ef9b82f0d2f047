//! A bridged session against the fake device's modelled hand, for the real-link tests
//! (`bond_link.rs`, `trap_link.rs`): the scene served over loopback UDP, the fake device (a
//! preset held with a grip: moving mass, encoder counts, the force held over each servo
//! period) its samples delayed 10 ms with 1 ms of jitter and 5 % loss.
// Each real-link test binary uses its own part of this module.
#![allow(dead_code)]

use haptic_devices::bridge::BridgeConfig;
use haptic_devices::bridge::fake::{FakeConfig, FakeReport, run_fake};
use haptic_devices::local::Protocol;
use haptic_devices::modelled::preset_specs;
use haptic_devices::{Grip, Mechanics, Script};
use haptic_loop::session::{SceneSource, SessionOptions, SessionReport, run_session};
use haptic_types::DeviceModel;
use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A built-in scene or script's text.
pub fn read(name: &str) -> String {
    std::fs::read_to_string(root().join("scenes").join(name)).unwrap()
}

/// A file `name` in this test binary's folder under the target's temporary directory.
pub fn out(test: &str, name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// One bridged session of `scene` (a file of `scenes/`) driven by `script` for `seconds`
/// against the modelled `mech` held with `grip`, speaking `protocol`, its samples 10 ms late
/// with jitter and loss; recorded to `rec`.
pub fn bridged(
    scene: &str,
    script: &str,
    seconds: f64,
    (mech, grip): (Mechanics, Grip),
    protocol: Protocol,
    rec: &Path,
) -> (SessionReport, FakeReport) {
    let addr: SocketAddr = UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    let mut opts =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes").join(scene)).unwrap());
    let mut b = BridgeConfig::parse(&format!("udp:{addr}")).unwrap();
    b.wait_s = 20.0;
    opts.device = Some(haptic_devices::source::DeviceSource::Udp(b));
    opts.out = Some(rec.to_path_buf());
    let specs = preset_specs(&mech);
    let f = FakeConfig {
        target: addr,
        model: DeviceModel::Falcon,
        script: Script::from_toml(&read(script), &specs).unwrap(),
        hand: None,
        physical: Some((mech, grip)),
        loss: 0.05,
        jitter_s: 0.001,
        latency_s: 0.010,
        seed: 3,
        seconds: Some(seconds),
        outage: None,
        wait_s: 20.0,
        bye: true,
        protocol,
        fault: None,
    };
    let h = std::thread::spawn(move || run_session(&opts, &mut |_, _| {}));
    let dev = run_fake(&f, None).unwrap();
    (h.join().unwrap().unwrap(), dev)
}

/// What every real-link run must show whatever the scene: at most 0.01 J into the hand
/// (`line` says which run), every force within the device's limit, and a recording that
/// replays bit for bit.
pub fn assert_sound_and_replayed(dev: &FakeReport, rec: &Path, line: &str) {
    assert!(dev.energy_to_hand_j <= 0.01, "{line}");
    assert!(dev.forces_within_limits, "{line}");
    let v =
        haptic_loop::replay::verify(&recording::read_recording_file(rec, false).unwrap()).unwrap();
    assert!(v.ok(), "{line}: the recording does not replay");
}
