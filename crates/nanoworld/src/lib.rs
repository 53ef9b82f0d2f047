//! # nanoworld — the nano world of the haptic teaching game
//!
//! The second world of Jackson, Pawluk & Taylor's teaching game (ASEE 2011): an AFM tip
//! (the cursor) over fixed teal substrate atoms, with movable orange atoms from a loading
//! zone. Van der Waals attraction is felt before contact, the tip or the less-bound atom
//! snaps into contact, adhesion holds until the pull reaches ten times the snap force
//! (approach–retract hysteresis), and an atom carried to another atom stays there because
//! the atom–atom bond is stronger than the tip–atom one. A blueprint scores a house.
//!
//! Two modes share the same state machine ([`Interaction`]):
//! - **game**: the paper's laws, F = A·(1/z² − 1/w²) inside an activation gap w, snap
//!   inside a snap gap, adhesion F = k·z, release at `pull_off_ratio` × snap force;
//! - **physical**: Hamaker sphere–plane and sphere–sphere forces (A ≈ 1e-19 J), a
//!   cantilever of stiffness k_c between cursor and tip with jump-to-contact at
//!   z_jtc = (A·R/(3·k_c))^{1/3}, and DMT pull-off 2π·R·W. With
//!   k_c = A·R/(3·10^{3/2}·z0³) ≈ A·R/(95·z0³) it reproduces the paper's tenfold pull-off.
//!
//! Parameters ([`Params`], what never changes during a step) are apart from the state
//! ([`World`]); the world is built from them and the device's [`world_form::Limits`] (largest
//! force N and stiffness N/m, in the world's units: [`GAME_FALCON_LIMITS`] /
//! [`PHYSICAL_FALCON_LIMITS`] when no device mapping is at hand); one [`World::step`] per
//! haptic tick reads both. SI units, f64, no wall
//! clock, no threads, no hash-map order: same inputs give the same bits.
//!
//! **Not here**: devices, the fixed-rate loop, scene files, recording and replay, drawing,
//! and Python bindings — `haptic-loop` and `ot-py` wrap this crate for those. Atom motion
//! is quasi-static (atoms rest, ride on the tip, or stay where they are put); there is no
//! thermal motion or atom dynamics.
//!
//! ```
//! use nalgebra::Vector3;
//! use nanoworld::{GAME_FALCON_LIMITS, Params, TipInput, World};
//!
//! let start = Vector3::new(3e-9, 3e-9, 2e-9);
//! let mut world = World::new(&Params::game_default(), &GAME_FALCON_LIMITS, start)?;
//! let report = world.step(&TipInput { position_m: Vector3::new(3e-9, 3e-9, 0.7e-9) }, 1e-3)?;
//! assert!(report.force_n.z < 0.0); // pulled towards the substrate before contact
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod contact;
mod curve;
mod error;
mod game;
mod house;
mod law;
mod params;
mod physical;
mod script;
mod substrate;
mod view;
mod world;

pub use curve::{CurveSpec, ForceCurve, force_distance_curve};
pub use error::{CurveError, ParamError, StepError};
pub use game::SubstrateForceCheck;
pub use house::HouseStatus;
pub use law::{PairKind, PairLaw, PairLaws};
pub use params::{
    AtomParams, GAME_FALCON_LIMITS, GamePair, GameParams, HouseParams, Interaction, LoadingZone,
    MAX_MOVABLE_ATOMS, MAX_SUBSTRATE_ATOMS, PHYSICAL_FALCON_LIMITS, Pairs, Params, PhysicalParams,
    SubstrateParams, TipParams,
};
pub use script::{
    MAX_SCRIPT_SAMPLES, ScriptError, house_script, house_waypoints, polyline, polyline_len,
};
pub use substrate::Substrate;
pub use view::{BodyContact, BodyKind, BodyView};
pub use world::{
    Anchor, BrokenLink, Event, MAX_POSITION_M, MIN_DT_S, Member, MovableAtom, StepReport, Target,
    TipContact, TipInput, World,
};
