//! # ot-physics — a particle in an optical trap
//!
//! The dynamics half of the optical-tweezers seed paper (Lee, Lyons & LeBrun):
//! a particle in the elliptic Gaussian well
//! `P = −P0·exp(−ln2·(x²/a² + y²/b²))` (2D, or 3D with an axial waist),
//! with only the effects a scene switches on — inertia (the paper's
//! Lagrangian dynamics), Stokes drag, thermal noise, an external force.
//!
//! What it gives:
//! * [`GaussianWell`]: potential, force and force Jacobian (SI: J, N, N/m);
//! * [`TrapModel`]: the validated parameters (`mjModel`-style), built with
//!   [`TrapModel::builder`];
//! * [`Method`] and [`Propagator`]: named integrators — the paper's single
//!   RK4 step, RK4 with substeps, Dormand–Prince 5(4), DOP853 (default),
//!   Störmer–Verlet and Yoshida compositions — bound to a model and a Δt;
//! * the flow map of a tick ([`Propagator::flow`],
//!   [`Propagator::flow_jacobian`]): displacement after Δt for a trap offset
//!   and its exact derivatives from the variational equations;
//! * [`budget`]: the cheapest fixed-step tick map within a stated error (m)
//!   of converged dynamics, chosen and reported ([`choose_tick_map`]);
//! * [`langevin`]: thermal noise (BAOAB; overdamped exact-OU local
//!   linearisation) with seeded, reproducible random numbers;
//! * [`analysis`]: variance, autocorrelation and corner-frequency fits.
//!
//! What it is not: the inverse trap solver and working envelope live in
//! `ot-envelope`; devices, logging and scenes in `haptic-loop`.
//!
//! ```
//! use ot_physics::{Method, Propagator, TrapModel};
//! use nalgebra::Vector2;
//! // The paper's constants: P0 = 1e-6 nJ, a = 600 nm, b = 300 nm, m = 1e-12 g.
//! let model = TrapModel::builder(1e-15, [600e-9, 300e-9]).mass(1e-15).build()?;
//! let tick = Propagator::new(model, Method::default(), 1e-6)?;
//! // Particle at rest, 100 nm right of and 50 nm above the trap centre:
//! let (d, _v, _evals) = tick.flow(&Vector2::new(-100e-9, -50e-9), &Vector2::zeros())?;
//! assert!((d.x * 1e9 + 136.1).abs() < 0.1 && (d.y * 1e9 + 86.7).abs() < 0.1);
//! # Ok::<(), ot_physics::PhysicsError>(())
//! ```

pub mod analysis;
pub mod budget;
pub mod cancel;
pub mod dynamics;
pub mod error;
pub mod fastexp;
pub mod flow;
pub mod integrate;
pub mod langevin;
pub mod model;
pub mod paper;
pub mod state;
pub mod well;

pub use budget::{MapChoice, choose_tick_map};
pub use error::{PhysicsError, Result, ValueError};
pub use flow::{Flow, OffsetFlow};
pub use integrate::{Composition, DEFAULT_RTOL, DEFAULT_TOL_M, Method, Propagator};
pub use model::{BOLTZMANN, TrapBuilder, TrapModel};
pub use state::{Partials, Phase, PhaseJac, PhaseSens, PhaseVar};
pub use well::{GaussianWell, Well2, Well3};
