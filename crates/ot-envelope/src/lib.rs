//! # ot-envelope — where to put the trap, and what moves are possible
//!
//! The control half of the optical-tweezers seed paper (Lee, Lyons & LeBrun,
//! §2.2–2.4): for a particle of velocity `v0` and a tick `Δt`,
//! * [`solve_trap`]: every trap offset (trap centre relative to the particle,
//!   m) that moves the particle by a target displacement in one tick, found
//!   in a stated bounded region, or a plain "no solution";
//! * [`working_envelope`]: the boundary of all reachable displacements, as a
//!   counter-clockwise polygon (m) with a stated tolerance; in 3D a closed
//!   surface mesh ([`envelope3`]);
//! * [`clip_command`]: a commanded displacement cut back to the envelope
//!   (radially, as in the paper, or to the nearest point) and the excess;
//! * [`steer::Controller`]: the pure per-tick steering law — cursor command in,
//!   new trap position and the reaction force of a spring on the excess out;
//! * [`tick::TickController`]: the same law warm-started from the previous
//!   tick's envelope (translate, check fold points, rebuild on failure),
//!   allocation-free in steady state — the haptic loop's tick;
//! * [`spread::EnvelopeBuild`]: a full envelope build split into slices of
//!   counted work (force evaluations), resumed tick after tick while the
//!   tick serves the last build translated; finished, it is the one-shot
//!   build bit for bit;
//! * [`world::World`]: the optical-tweezers world itself — SI [`world::Params`], built with
//!   the device's `world_form::Limits`, stepped with an [`world::Input`] (cursor, button) to a
//!   [`world::StepReport`] (force, stiffness felt, typed events);
//! * [`paper`]: the paper's own method (grid of targets, marching-squares
//!   seeds, Newton, subdivision, contour), kept as the benchmark baseline.
//!
//! It builds on `ot-physics`, whose [`ot_physics::Propagator`] is the tick
//! map (choose its method for the accuracy you need: `Rk4 { substeps: 8 }`
//! is within 0.21 nm of converged dynamics at the paper's constants).
//!
//! What it is not: no device, logging or rendering (that is `haptic-loop`),
//! no Python (the `ot-py` crate wraps these functions), no thermal noise
//! (the tick map is deterministic).
//!
//! ```
//! use ot_envelope::{working_envelope, solve_trap, Solutions};
//! use ot_physics::{Method, Propagator, TrapModel};
//! use nalgebra::Vector2;
//! let model = TrapModel::builder(1e-15, [600e-9, 300e-9]).mass(1e-15).build()?;
//! let tick = Propagator::new(model, Method::Rk4 { substeps: 8 }, 1e-6)?;
//! let we = working_envelope(&tick, &Vector2::zeros(), None)?;
//! assert!(we.contains(&Vector2::new(300e-9, 0.0)));
//! assert!(!we.contains(&Vector2::new(700e-9, 0.0)));
//! match solve_trap(&tick, &Vector2::zeros(), &Vector2::new(300e-9, 0.0))? {
//!     Solutions::Found(offsets) => assert!(!offsets.is_empty()),
//!     Solutions::None { .. } => unreachable!(),
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bounded;
pub mod clip;
pub mod envelope;
pub mod envelope3;
pub mod error;
mod folds;
pub mod geometry;
pub mod grid;
pub mod inverse;
pub mod paper;
pub mod reference;
pub mod region;
pub mod sample;
pub mod spread;
pub mod steer;
pub mod tick;
pub mod tick_length;
pub mod world;

pub use bounded::{Bounded, SteeringRange};
pub use clip::{ClipMode, Clipped, clip_command, clip_to_polygon};
pub use envelope::{
    DEFAULT_TOL, Envelope, EnvelopeOptions, envelope_from_map, working_envelope,
    working_envelope_with,
};
pub use error::{EnvelopeError, Result};
pub use inverse::{Solutions, solve_trap};
pub use region::OffsetRegion;
pub use sample::SampledMap;
pub use tick::{TickController, TickOutput, TickParams, TickStats};

/// The user guide's examples (`docs/ot-envelope.md`), compiled and run as doc-tests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/ot-envelope.md")]
pub struct UserGuide;
