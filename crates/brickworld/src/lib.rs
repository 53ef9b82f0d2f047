//! # brickworld — the macro world of the haptic teaching game
//!
//! Bricks on a grassy ground under gravity, simulated with rapier (f64, enhanced determinism),
//! handled through a haptic cursor: a god-object proxy that never enters a brick or the ground
//! and renders the spring `F = -k d n`; hold the grip to carry a brick (its weight `M g` and
//! inertia `-M a` are felt), let go to drop or throw it, turn it by 90° about x, y or z
//! ([`Grip`]: the hand's commands, which the haptic loop maps from a device's buttons). A
//! loading zone supplies bricks, and a blueprint of slots scores how well a house is built.
//! Gravity, restitution, friction, inertia and brick mass are
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
//! The world is split the rapier way, one job per module: [`bricks`] (the rigid bodies and
//! colliders of ground, obstacles and bricks; placement checks; views), [`hand`] (cursor proxy,
//! grab / release / throw / turn, the felt force with weight and inertia, scaled to the
//! device's [`world_form::Limits`]), [`blueprint`] (slots and score), [`spawner`] (the loading zone),
//! [`impact`] (what an impact is; its restitution in the solver and its events), [`rest`] (quiet
//! steps: resting contacts reused while nothing moves), [`event`] (what a step reports) and
//! [`world`], which holds the [`World`] (parameters, limits and those sets)
//! and orchestrates [`World::step`].
//!
//! ```
//! use brickworld::{Grip, Params, World};
//! use world_form::Limits;
//! let mut world = World::new(&Params::default(), &Limits::FALCON).unwrap();
//! let input = world.input([0.0, 0.0, 0.2], Grip::default()).unwrap();
//! let report = world.step(&input);
//! assert_eq!(report.force_n, [0.0, 0.0, 0.0]); // free space, nothing carried
//! ```

pub mod blueprint;
pub mod bricks;
pub mod error;
pub mod estimator;
pub mod event;
pub mod hand;
pub mod impact;
pub mod input;
pub mod local;
pub mod params;
pub mod proxy;
pub mod rest;
pub mod script;
pub mod spawner;
pub mod world;

pub use blueprint::{RESTING_SPEED_M_PER_S, Score, SlotView};
pub use bricks::{
    BoxView, BrickView, GROUND_HALF_EXTENT_M, SLEEP_MAX_ACCEL_M_PER_S2, SLEEP_SPEED_M_PER_S,
};
pub use error::{InputError, ParamError, WorldError};
pub use estimator::{AdaptiveWindow, MotionEstimator};
pub use event::{Axis, Body, BrickId, Event, Touch};
pub use hand::NEAREST_MAX_M;
pub use input::{CursorInput, Grip};
pub use params::{
    AccelEstimator, Blueprint, BrickPlacement, BrickProps, Coupling, Inertia, LoadingZone,
    Obstacle, Params, ParamsFromTomlError,
};
pub use world::{StepReport, World};
