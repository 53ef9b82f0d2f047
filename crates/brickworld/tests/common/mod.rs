//! Helpers shared by the integration tests.
#![allow(dead_code)]

use brickworld::{BrickPlacement, Grip, Params, StepReport, World};
use world_form::Limits;

/// Parameters with no loading zone and no blueprint: only what a test adds.
pub fn bare() -> Params {
    Params::default()
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
