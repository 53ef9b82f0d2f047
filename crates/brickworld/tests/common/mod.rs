//! Helpers shared by the integration tests.
#![allow(dead_code)]

use brickworld::{BrickPlacement, Grip, Params, StepReport, World};
use world_form::Limits;

/// Parameters with no loading zone and no blueprint: only what a test adds. With
/// `BRICKWORLD_TEST_SOLVER=scene` in the environment, the shipped brick scene's solver setting
/// (its `solver_iterations` and `contact_frequency_hz`), to run a suite under it.
pub fn bare() -> Params {
    if std::env::var("BRICKWORLD_TEST_SOLVER").as_deref() == Ok("scene") {
        scene_solver()
    } else {
        Params::default()
    }
}

/// Whether the suite runs under the default solver (not `BRICKWORLD_TEST_SOLVER=scene`):
/// the figures docs/brickworld.md quotes from a suite are measured there, so the asserts that
/// hold them to the doc's printed precision run only then.
pub fn default_solver() -> bool {
    std::env::var("BRICKWORLD_TEST_SOLVER").as_deref() != Ok("scene")
}

/// The default parameters with the shipped scene's solver setting (its `solver_iterations`
/// and `contact_frequency_hz`, read from `scenes/brickworld.toml`).
pub fn scene_solver() -> Params {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/brickworld.toml");
    let text = std::fs::read_to_string(path).expect("scenes/brickworld.toml");
    let scene: toml::Value = toml::from_str(&text).expect("scene is TOML");
    let params = &scene["brickworld"]["params"];
    let d = Params::default();
    Params {
        solver_iterations: params
            .get("solver_iterations")
            .and_then(toml::Value::as_integer)
            .map_or(d.solver_iterations, |i| {
                usize::try_from(i).expect("a count")
            }),
        contact_frequency_hz: params
            .get("contact_frequency_hz")
            .and_then(toml::Value::as_float)
            .unwrap_or(d.contact_frequency_hz),
        ..d
    }
}

/// A brick at `c` (m), axis aligned.
pub fn at(c: [f64; 3]) -> BrickPlacement {
    BrickPlacement {
        center_m: c,
        rotation_deg: [0.0; 3],
    }
}

/// Builds a world with the Falcon limits.
pub fn world(p: Params) -> World {
    World::new(&p, &Limits::FALCON).expect("valid test params")
}

/// Steps with the cursor parked at `pos` (m), no buttons.
pub fn idle(w: &mut World, pos: [f64; 3]) -> StepReport {
    let i = w
        .input(pos, Grip::default())
        .expect("cursor inside workspace");
    w.step(&i)
}

/// Steps with the cursor at `pos` and the grip's `hold` command as given.
pub fn hold(w: &mut World, pos: [f64; 3], down: bool) -> StepReport {
    let b = Grip {
        hold: down,
        ..Grip::default()
    };
    let i = w.input(pos, b).expect("cursor inside workspace");
    w.step(&i)
}

/// The report example's scenes (`examples/common`), shared with the tests.
#[path = "../../examples/common/mod.rs"]
#[allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]
mod scenes;

#[allow(unused_imports)] // not every test file builds the wall
pub use scenes::running_bond_wall;

/// The largest distance, m, between the same brick's positions in `a` and `b`.
pub fn moved(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max)
}
