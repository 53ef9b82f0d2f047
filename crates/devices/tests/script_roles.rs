//! Scripts bind their button events by role (issue 41): the same script plays on every
//! preset's own buttons.
#![allow(clippy::unwrap_used)]

use haptic_devices::Script;
use haptic_types::device::{Buttons, FALCON};
use haptic_types::{ButtonRoles, Role};

const S: &str = r#"
[script]
name = "t"
[[waypoint]]
t_s = 0.0
position_mm = [0.0, 0.0, 0.0]
[[waypoint]]
t_s = 2.0
position_mm = [20.0, 0.0, -10.0]
[[button]]
t_s = 1.0
name = "centre"
down = true
[[button]]
t_s = 1.5
name = "centre"
down = false
"#;

#[test]
fn button_events_bind_by_role_on_every_preset() {
    use haptic_types::device::TOUCH;
    let by_role = S.replace("name = \"centre\"", "role = \"grip\"");
    for specs in [FALCON, TOUCH] {
        let s = Script::from_toml(&by_role, &specs).unwrap();
        assert_eq!((s.buttons(1.0), s.buttons(1.5)), (Buttons(1), Buttons(0)));
    }
    // turn_x: the Falcon's plus (bit 1); a Touch has no button for it, so it is left out.
    let turn = S.replace("name = \"centre\"", "role = \"turn_x\"");
    assert_eq!(
        Script::from_toml(&turn, &FALCON).unwrap().buttons(1.0),
        Buttons(2)
    );
    assert!(Script::from_toml(&turn, &TOUCH).unwrap().buttons.is_empty());
    // An override moves the role: grip on the Touch's button2.
    let roles = ButtonRoles::resolve(&TOUCH, &[(Role::Grip, "button2".into())]).unwrap();
    let s = Script::from_toml_with(&by_role, &TOUCH, &roles).unwrap();
    assert_eq!(s.buttons(1.0), Buttons(2));
    let bad = S.replace("name = \"centre\"", "role = \"hold\"");
    let e = Script::from_toml(&bad, &FALCON).unwrap_err();
    assert_eq!(
        e.to_string(),
        "script: `button[0].role` = \"hold\" is out of range: allowed a role: grip, turn_x, \
         turn_y, turn_z"
    );
    assert!(e.position(&bad).is_some());
    let both = S.replacen("name = \"centre\"", "name = \"centre\"\nrole = \"grip\"", 1);
    assert!(
        Script::from_toml(&both, &FALCON)
            .unwrap_err()
            .to_string()
            .contains(
                "`button[0]` = both or neither of `name` and `role` is out of range: allowed \
         exactly one"
            )
    );
}
