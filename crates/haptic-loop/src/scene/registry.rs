//! The worlds a scene file can name: `scene.kind` → the world's adapter.
//!
//! Adding a world is one new adapter file under `scene/` defining `pub const WORLD: WorldKind`,
//! its `pub mod` line in `scene/mod.rs`, and one line here.

use super::{WorldKind, brick, nano, optical, wall};

/// Every world this build knows, in the order error messages list them.
pub const WORLDS: &[WorldKind] = &[wall::WORLD, nano::WORLD, brick::WORLD, optical::WORLD];

/// The world named `kind`.
pub fn find(kind: &str) -> Option<&'static WorldKind> {
    WORLDS.iter().find(|w| w.kind == kind)
}

/// The kind names, in order.
pub fn kinds() -> Vec<&'static str> {
    WORLDS.iter().map(|w| w.kind).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_listed_once() {
        assert_eq!(
            kinds(),
            ["wall", "nanoworld", "brickworld", "optical_tweezers"]
        );
    }

    /// A menu reads every switch with its value now, a switch set through the scene
    /// included; a scene without switches lists none.
    #[test]
    fn a_menu_reads_each_switch_with_its_value_now() {
        let scene_file = |name: &str| {
            let p = format!("{}/../../scenes/{name}", env!("CARGO_MANIFEST_DIR"));
            std::fs::read_to_string(p).unwrap()
        };
        let mut bricks = crate::scene::load_scene(&scene_file("brickworld.toml"), None)
            .unwrap()
            .scene;
        bricks.set_switch("gravity_m_per_s2", 0.0).unwrap();
        bricks.set_switch("inertia", 0.0).unwrap();
        let values = bricks.switch_values();
        let names: Vec<&str> = values.iter().map(|(n, _)| n.as_str()).collect();
        let menu: Vec<&str> = bricks.switches().iter().map(|s| s.name).collect();
        assert_eq!(names, menu);
        let value = |n: &str| values.iter().find(|(m, _)| m == n).map(|(_, v)| *v);
        assert_eq!(value("gravity_m_per_s2"), Some(0.0));
        assert_eq!(value("inertia"), Some(0.0));
        assert_eq!(value("friction"), bricks.switch_value("friction"));
        let wall = crate::scene::load_scene(&scene_file("wall.toml"), None)
            .unwrap()
            .scene;
        assert!(wall.switch_values().is_empty());
    }
}
