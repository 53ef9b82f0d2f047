//! # haptic-engine: the deterministic haptic tick and the one step of a session's time
//!
//! What this crate is for:
//!
//! - **The tick** ([`haptic`]): [`HapticLoop`], a fixed tick (default 1 kHz) whose index is the
//!   only clock the physics sees; device↔world mapping, force clamping by vector scaling,
//!   stiffness cap, soft engagement, the passivity layer at the device port, zero force on
//!   invalid input or a missed deadline, and the local model a protocol-2 device renders.
//! - **The interface every world plugs into** ([`scene`]): the [`Scene`] trait, with the loop's
//!   configuration ([`loop_config`]) and its checks ([`check`], typed errors that a scene file's
//!   reader locates by line and column).
//! - **Time** ([`runner`]): [`runner::TickEngine::cycle`] is the one step of a session — one
//!   tick from a device under a clock ([`runner::TickClock`]: batch, a wall-clock pacer, the
//!   device's own clock, recorded deadline flags, a shared worker's cycle);
//!   [`runner::Runner`] is the loop around it (stop flag, real-time guard, progress). Every
//!   tick goes to [`sink::Sink`]s with the [`header::SessionHeader`]; [`totals`] is the sink
//!   every session keeps.
//! - **Pacing** ([`timing`], [`realtime`], [`wakeup`]): sleeping to absolute deadlines,
//!   constant-memory tick-time statistics, the tick thread's real-time set-up, and how
//!   promptly this machine wakes a sleeping thread.
//!
//! What it is not: it knows no world (the worlds' adapters are `haptic-loop`'s `scene`), no
//! device but through [`haptic_types::HapticDevice`] (devices are `haptic-devices`), no file
//! format (the recorder is a sink above it), no renderer and no server. `scripts/layering.py`
//! holds it to `haptic-types` and `world-form`.

pub mod check;
pub mod clock;
pub mod haptic;
pub mod header;
pub mod loop_config;
pub mod pacing;
pub mod realtime;
pub mod runner;
pub mod scene;
pub mod sink;
pub mod timing;
pub mod totals;
pub mod wakeup;

pub use haptic::{HapticLoop, LoopConfig};
pub use scene::{Scene, SceneInput, SceneOutput};
