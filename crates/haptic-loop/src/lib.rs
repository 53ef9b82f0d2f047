//! # haptic-loop: a deterministic haptic loop with MCAP record and bit-exact replay
//!
//! What this crate is for:
//!
//! - **Devices** ([`device`]): a CHAI3D-like haptic device interface (position in metres in the
//!   device frame, buttons, force command in newtons, and specifications: maximum force, maximum
//!   stiffness, workspace radius), with specs for the Novint Falcon and the Touch/Omni class, and
//!   three headless implementations: a scripted device (TOML waypoints, smooth interpolation,
//!   button events), a simulated operator (a mass–spring–damper hand pulled toward the script
//!   and pushed by the rendered force) and a replay device (inputs read back from a recording).
//! - **The loop** ([`haptic`], [`pacing`]): a fixed tick (default 1 kHz) whose index is the only
//!   clock the physics sees; device↔world mapping, force clamping by vector scaling, stiffness
//!   cap, soft engagement, zero force on invalid input or a missed deadline.
//! - **Scenes** ([`scene`]): one small trait every world plugs into (cursor and buttons in;
//!   force, events and drawable primitives out), TOML scene files validated with typed errors,
//!   and a stiff-wall calibration scene.
//! - **Recording and replay** ([`record`], [`replay`]): every tick into MCAP from a writer
//!   thread (so writing never stalls a tick), and a replay that recomputes every output from the
//!   logged inputs alone and compares bit for bit.
//! - **The runner** ([`runner`]): one loop for every way a session is driven — a device source
//!   (script, simulated hand, replay, a device in another process over the UDP [`bridge`]), a
//!   pacing policy (batch, real time, the device's clock) and sinks (the MCAP recorder, the
//!   per-tick [`arrays`], the replay verifier, the frame renderer, the [`live`] Foxglove view).
//! - **Sessions** ([`session`]): "run a scene with a script and get per-tick arrays back" and
//!   "read a recording into arrays", the API the Python wheel wraps.
//!
//! What it is not: it holds no world physics (the worlds live in their own crates and are
//! adapted by a thin scene), no GPU renderer and no driver for real hardware: a real device's
//! driver runs in its own process and speaks the bridge protocol (the wheel's
//! `nanohaptics.bridge` has adapters for the Touch and Force Dimension / Falcon SDKs).

pub mod arrays;
pub mod builtin;
pub mod closed_loop;
pub mod encode;
pub mod error;
pub mod haptic;
pub mod header;
pub mod live;
pub mod media;
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
pub use haptic_types::{switch, textpos, vec3};

pub use haptic::{HapticLoop, LoopConfig, TickResult};
pub use haptic_types::{Buttons, DeviceModel, DeviceSample, DeviceSpecs, HapticDevice};
pub use scene::{Event, Primitive, Scene, SceneInput, SceneOutput};
pub use session::{SessionArrays, SessionOptions};
