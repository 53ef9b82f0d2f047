//! # haptic-loop: sessions — the worlds as scenes, set-up, record and replay
//!
//! The engine (`haptic-engine`) ticks a [`Scene`](haptic_engine::Scene) from a device and
//! knows no world; this crate is what sits on it to make a session:
//!
//! - **Scenes** ([`scene`]): each world's adapter to the engine's `Scene` trait (optical
//!   tweezers, bricks, atoms, the calibration wall), TOML scene files validated with typed
//!   errors located by line and column, the registry of worlds and the house-task score.
//! - **Sinks** ([`sinks`]): the MCAP recorder ([`record_sink`], the only module that turns the
//!   header into the file's description), the per-tick [`arrays`], the replay verifier
//!   ([`replay`]), frames and pictures ([`media`]), the [`live`] Foxglove view.
//! - **Sessions** ([`setup`], [`session`]): the one set-up (scene, device made ready for it,
//!   header, sinks) and "run a scene with a script or a device and get a report and per-tick
//!   arrays back" — what `nanohaptics run`, `play` and the Python wheel call; [`stepper`] one
//!   tick per call.
//! - **Checks in closed loop** ([`closed_loop`]): a scene played through a modelled device held
//!   by a hand, over an ideal or a modelled link, judged on what the hand felt.
//!
//! What it is not: it holds no world physics (worlds live in their own crates and are adapted
//! by a thin scene), no tick and no pacing (`haptic-engine`), no device and no device protocol
//! (those are `haptic-devices`, named and opened by `haptic_devices::source`), no file format
//! (`nanohaptics-recording`), no command line (`nanohaptics-cli`) and no browser page
//! (`nanohaptics-play`).

pub mod arrays;
pub mod builtin;
pub mod closed_loop;
pub mod encode;
pub mod error;
pub mod live;
pub mod media;
pub mod mwidth;
pub mod record_sink;
pub mod replay;
pub mod replay_device;
pub mod scene;
pub mod session;
pub mod setup;
pub mod sinks;
pub mod sound;
pub mod stepper;

pub use session::{SessionArrays, SessionOptions};
