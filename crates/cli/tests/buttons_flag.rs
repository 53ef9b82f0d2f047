//! `nanohaptics run --buttons` (issue 41): the command line moves a role; the summary states
//! the mapping in force; a button the device lacks is refused naming the role and the buttons.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_nanohaptics"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn the_command_line_moves_a_role_and_the_summary_says_so() {
    let base = [
        "run",
        "scenes/brickworld.toml",
        "--seconds",
        "0.1",
        "--json",
    ];
    let o = run(&base);
    assert!(o.status.success());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        j["buttons"],
        "grip = centre, turn_x = plus, turn_y = minus, turn_z = forward (the falcon preset)"
    );
    let o = run(&[
        &base[..],
        &["--device", "touch", "--buttons", "grip=button2"],
    ]
    .concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        j["buttons"],
        "grip = button2, turn_x = none, turn_y = none, turn_z = none (the touch preset, \
         overridden)"
    );
    let o = run(&[&base[..], &["--buttons", "grip=zz"]].concat());
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains(
            "scene: `device.buttons.grip` = \"zz\" is out of range: allowed a button of device \
             `falcon`: centre, plus, minus, forward"
        ),
        "{e}"
    );
    let o = run(&[&base[..], &["--buttons", "hold=centre"]].concat());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("`--buttons` = \"hold\" is out of range: allowed a role: grip, turn_x"),
        "{e}"
    );
}
