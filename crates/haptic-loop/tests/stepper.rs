//! A session stepped from outside gives the same bits as the runner's session on the same
//! inputs, records, and replays bit for bit.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::source::OperatorChoice;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use haptic_loop::stepper::{Stepper, StepperOptions};
use haptic_types::Buttons;
use haptic_types::DeviceSample;
use recording::read_recording_file;
use std::path::Path;

#[test]
fn stepping_the_scripted_inputs_reproduces_the_scripted_session_and_replays() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = SceneSource::from_path(&root.join("scenes/wall.toml")).unwrap();
    let mut o = SessionOptions::new(scene.clone());
    o.operator = OperatorChoice::Rigid;
    let scripted = run_session(&o, &mut |_, _| {}).unwrap().arrays;

    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("stepped-{}.mcap", std::process::id()));
    let mut so = StepperOptions::new(scene);
    so.out = Some(out.clone());
    let mut s = Stepper::new(so).unwrap();
    for (p, b) in scripted
        .device_position_m
        .iter()
        .zip(&scripted.device_buttons)
    {
        let tick = s.tick(DeviceSample::new(*p, Buttons(*b))).unwrap().tick;
        assert_eq!(tick, s.haptic_loop().next_tick() - 1);
    }
    let c = s.command();
    assert_eq!(c.force_n, *scripted.device_force_n.last().unwrap());
    let report = s.finish().unwrap();
    let a = &report.arrays;
    assert_eq!(a.device_force_n, scripted.device_force_n);
    assert_eq!(a.state, scripted.state);
    assert_eq!(a.events, scripted.events);
    assert_eq!(
        a.device_stiffness_n_per_m,
        scripted.device_stiffness_n_per_m
    );
    // In contact the stiffness sent is the wall's k n nᵀ (capped at 3000 N/m), zero elsewhere.
    let k = a
        .device_stiffness_n_per_m
        .iter()
        .zip(&a.engagement)
        .zip(&a.status)
        .find(|((k, e), s)| k[8] > 0.0 && **e == 1.0 && **s == 0)
        .unwrap()
        .0
        .0;
    assert_eq!(*k, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3000.0]);
    let rec = read_recording_file(&out, false).unwrap();
    assert_eq!(rec.description.mode, "stepped");
    let v = verify(&rec).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
    assert_eq!(v.ticks, 4000);
}
