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
}
