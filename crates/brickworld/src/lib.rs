//! # brickworld — the macro world of the haptic teaching game
//!
//! Bricks on a grassy ground under gravity, simulated with rapier (f64, enhanced determinism),
//! handled through a haptic cursor: a god-object proxy that never enters a brick or the ground
//! and renders the spring `F = -k d n`; hold the centre button to carry a brick (its weight
//! `M g` and inertia `-M a` are felt), release to drop or throw it, press the other three
//! buttons to turn it by 90°. A loading zone supplies bricks, and a blueprint of slots scores
//! how well a house is built. Gravity, restitution, friction, inertia and brick mass are
//! switched by parameters and at run time.
//!
//! What it is for: one [`World`] stepped at a fixed rate (1 kHz by default) by a haptic loop,
//! with [`World::step`] taking a validated [`CursorInput`] and returning a [`StepReport`]
//! (device force, events), plus read access to everything a renderer or recorder needs.
//!
//! What it is not: it knows nothing of devices, scene files, recordings, rendering or Python —
//! the `haptic-loop` crate wraps it. It models only rigid cuboid bricks and fixed boxes.
//!
//! Units: SI everywhere (m, kg, s, N); the world frame is right-handed with z up and the
//! ground at z = 0. Quaternions are `[x, y, z, w]`.
//!
//! ```
//! use brickworld::{Buttons, DeviceLimits, Params, World};
//! let mut world = World::new(Params::default(), DeviceLimits::NOVINT_FALCON).unwrap();
//! let input = world.input([0.0, 0.0, 0.2], Buttons::default()).unwrap();
//! let report = world.step(&input);
//! assert_eq!(report.force_n, [0.0, 0.0, 0.0]); // free space, nothing carried
//! ```

pub mod blueprint;
pub mod error;
pub mod estimator;
pub mod impact;
pub mod impacts;
pub mod input;
pub mod params;
pub mod proxy;
pub mod script;
pub mod world;

pub use blueprint::Score;
pub use error::{InputError, ParamError, WorldError};
pub use estimator::MotionEstimator;
pub use input::{Buttons, CursorInput};
pub use params::{
    AccelEstimator, Blueprint, BrickPlacement, BrickProps, DeviceLimits, LoadingZone, Obstacle,
    Params, ParamsFromTomlError,
};
pub use world::{
    Axis, Body, BoxView, BrickId, BrickView, Event, NEAREST_MAX_M, SLEEP_MAX_ACCEL_M_S2,
    SLEEP_SPEED_M_S, SlotView, StepReport, Touch, World,
};
