//! # haptic-loop: the engine — a deterministic haptic loop, its sessions, record and replay
//!
//! What this crate is for:
//!
//! - **The tick** ([`haptic`]): [`HapticLoop`], a fixed tick (default 1 kHz) whose index is the
//!   only clock the physics sees; device↔world mapping, force clamping by vector scaling,
//!   stiffness cap, soft engagement, the passivity layer at the device port, zero force on
//!   invalid input or a missed deadline, and the local model a protocol-2 device renders.
//! - **Scenes** ([`scene`]): the one trait every world plugs into (cursor and buttons in; force,
//!   events and drawable primitives out), TOML scene files validated with typed errors located
//!   by line and column, the loop configuration, and the calibration wall.
//! - **Time** ([`runner`]): [`runner::TickEngine::tick`] is the one way a session's time
//!   advances; [`runner::Runner`] drives it from a device with a pacing policy (batch, real
//!   time, the device's clock, recorded deadlines), [`stepper::Stepper`] one tick per call.
//!   Both hand every tick to [`sink::Sink`]s with the engine's [`header::SessionHeader`].
//! - **Sinks** ([`sinks`]): the MCAP recorder ([`record_sink`], the only module that turns the
//!   header into the file's description), the per-tick [`arrays`], running [`totals`], the
//!   replay verifier ([`replay`]), frames and pictures ([`media`]), the [`live`] Foxglove view.
//! - **Sessions** ([`setup`], [`session`]): the one set-up (scene, device made ready for it,
//!   header, sinks) and "run a scene with a script or a device and get a report and per-tick
//!   arrays back" — what `nanohaptics run`, `play` and the Python wheel call.
//! - **Checks in closed loop** ([`closed_loop`]): a scene played through a modelled device held
//!   by a hand, over an ideal or a modelled link, judged on what the hand felt.
//!
//! What it is not: it holds no world physics (worlds live in their own crates and are adapted
//! by a thin scene), no device and no device protocol (those are `haptic-devices`, named and
//! opened by `haptic_devices::source`), no file format (`nanohaptics-recording`), no command
//! line (`nanohaptics-cli`) and no browser page (`nanohaptics-play`).

pub mod arrays;
pub mod builtin;
pub mod closed_loop;
pub mod encode;
pub mod error;
pub mod haptic;
pub mod header;
pub mod live;
pub mod media;
pub mod pacing;
pub mod record_sink;
pub mod replay;
pub mod replay_device;
pub mod runner;
pub mod scene;
pub mod session;
pub mod setup;
pub mod sink;
pub mod sinks;
pub mod sound;
pub mod stepper;
pub mod totals;

pub use haptic::{HapticLoop, LoopConfig};
pub use scene::{Scene, SceneInput, SceneOutput};
pub use session::{SessionArrays, SessionOptions};
