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
    // Named by the flag, not by a line of the scene as the flag rewrote it (which the user
    // never saw: it pointed at line 40 of a 68-line file that has no `[device]` table).
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: `--buttons grip` = \"zz\" is out of range: allowed a button of device `falcon`: \
         centre, plus, minus, forward"
    );
    let o = run(&[&base[..], &["--buttons", "grip=centre,turn_z=zz"]].concat());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: `--buttons turn_z` = \"zz\" is out of range: allowed a button of device \
         `falcon`: centre, plus, minus, forward"
    );
    // Any other error in the rewritten scene says where it is in that text.
    let lone = Path::new(env!("CARGO_TARGET_TMPDIR")).join("buttons_flag_lone.toml");
    std::fs::copy(root().join("scenes/brickworld.toml"), &lone).unwrap();
    let o = run(&["run", lone.to_str().unwrap(), "--buttons", "grip=centre"]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.starts_with(&format!(
            "error: {}:56:18 (the scene as --buttons grip=centre rewrote it): \
             `scene.default_script` = \"brickworld.script.toml\": cannot read ",
            lone.display()
        )),
        "{e}"
    );
    let o = run(&[&base[..], &["--buttons", "hold=centre"]].concat());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: `--buttons` = \"hold\" is out of range: allowed a role: grip, turn_x, turn_y, \
         turn_z"
    );
}
