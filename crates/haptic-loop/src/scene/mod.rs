//! The worlds as scenes: each world's adapter to the engine's [`Scene`] trait, the scene
//! files (TOML, validated with typed errors located by line and column), the registry of
//! worlds, the house-task score, and the stiff-wall calibration scene.

pub mod brick;
pub mod device;
pub mod file;
pub mod nano;
pub mod optical;
pub mod overrides;
pub mod registry;
pub mod score;
pub mod table;
pub mod wall;

use haptic_engine::check::SceneError;
use haptic_engine::loop_config::LoopConfig;
use haptic_engine::scene::Scene;

pub use file::{SceneFile, load_scene, load_scene_for};

/// A world constructor: a scene file's text and the checked loop configuration → the world.
pub type BuildWorld = fn(&str, &LoopConfig) -> Result<Box<dyn Scene>, SceneError>;

/// A world as the scene registry knows it: its `scene.kind` name (also the name of its table in
/// a scene file), a check of its table and its constructor. Each adapter defines one
/// (`pub const WORLD: WorldKind`) and [`registry::WORLDS`] lists them.
pub struct WorldKind {
    /// The kind name, e.g. `wall`; the world's table in a scene file is `[<kind>]`.
    pub kind: &'static str,
    /// Checks the world's table in a scene file's text (unknown fields, types) when present.
    pub check: fn(&str) -> Result<(), SceneError>,
    /// Builds the world from a scene file's text and the checked loop configuration.
    pub build: BuildWorld,
}

/// Reads world table `kind` from a scene's text for [`WorldKind::build`]; an error when the
/// file has none.
pub fn world_table<T: serde::de::DeserializeOwned>(
    text: &str,
    kind: &str,
) -> Result<T, SceneError> {
    table::pick(text, kind)?.ok_or_else(|| SceneError::Kind {
        kind: kind.to_string(),
        problem: format!("needs a `[{kind}]` table"),
    })
}
