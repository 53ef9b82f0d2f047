//! # haptic-devices — every device that can drive a session, and the hand that holds it
//!
//! Every world of nanohaptics renders a force to a device; whether that rendering is *stable*
//! depends on what the device and the hand are: a moving mass with a little friction, an
//! encoder that reports positions in counts, a force held constant over each tick (zero-order
//! hold), and a hand that grips the stylus with some stiffness and damping. An ideal, massless
//! scripted hand cannot show instability; this crate holds the model that can, and every
//! device source the loop is driven by.
//!
//! What it is for:
//! - **device physics**: [`Mechanics`], a device's moving mass (kg), viscous friction (N·s/m),
//!   encoder quantum (m), force resolution (N), servo rate (Hz) and
//!   [`Limits`](world_form::Limits), with presets for the Novint Falcon, the 3D Systems Touch,
//!   the Force Dimension delta.3 and the Haply Inverse3 ([`Mechanics::preset`], each figure
//!   cited in `docs/devices.md`); [`Grip`], the hand as a spring-damper to the operator's
//!   intended path, from [`Grip::LOOSE`] (300 N/m, 2 N·s/m) to [`Grip::FIRM`] (1000 N/m,
//!   8 N·s/m); [`Plant`], the device and the hand integrated between two ticks under a held
//!   force command, reporting encoder-quantized positions;
//! - **devices** (each a [`HapticDevice`](haptic_types::HapticDevice)): [`script`], TOML
//!   waypoints played by a rigid stylus ([`ScriptedDevice`]); [`operator`], a simulated
//!   mass–spring–damper hand following the script ([`SimulatedOperator`]); [`modelled`], a
//!   [`Plant`] held by a [`Grip`] following the script ([`ModelledDevice`]); [`bridge`], a
//!   device in another process over UDP ([`UdpDevice`]) and the `fake-device` stand-in;
//! - [`source`]: the one list of device sources a session can be driven by;
//! - [`local`]: the device side of the bridge — what a device's servo thread renders between
//!   the simulator's answers (protocol 1's `F0 − K (p − p0)`, protocol 2's local model) and
//!   the two-port passivity layer — used by `fake-device`, [`linked`] and, ported line by
//!   line, the Python adapters;
//! - [`link`]: a network link as a deterministic model (latency, jitter, loss), and
//!   [`linked`], a modelled device held by a hand at its far end;
//!
//! What it is not: no haptic loop, no worlds, no recording, no pacing of ticks (the engine's,
//! `haptic_engine::timing` and `haptic_engine::realtime`). The device interface itself (the
//! trait, samples, force commands, specifications) is `haptic-types`'; the engine
//! (`haptic-engine`) drives these devices and knows them only through that interface.
//!
//! ```
//! use haptic_devices::{Grip, Mechanics, Plant, Hold};
//! let falcon = Mechanics::preset("falcon").unwrap();
//! let mut plant = Plant::new(falcon, Grip::LOOSE, [0.0; 3]);
//! // Hold the stylus still against a constant 1 N push along +z for 2 s of 1 ms ticks: the
//! // hand's spring yields 1 N / 300 N/m = 3.33 mm.
//! let hold = Hold::constant([0.0, 0.0, 1.0]);
//! for _ in 0..2000 {
//!     plant.advance(1e-3, |_| ([0.0; 3], [0.0; 3]), &hold);
//! }
//! assert!((plant.position_m()[2] - 1.0 / 300.0).abs() < 1e-5);
//! // The encoder reports whole counts of 0.0635 mm.
//! let counts = plant.reading_m()[2] / falcon.encoder_quantum_m;
//! assert_eq!(counts, counts.round());
//! ```

pub mod bridge;
mod grip;
pub mod link;
pub mod linked;
pub mod local;
mod mechanics;
pub mod modelled;
pub mod operator;
mod plant;
pub mod script;
pub mod source;

pub use grip::{Grip, GripError};
pub use mechanics::{Mechanics, MechanicsError, PRESETS};
pub use plant::{Hold, Plant};

pub use bridge::{BridgeConfig, UdpDevice};
pub use modelled::ModelledDevice;
pub use operator::SimulatedOperator;
pub use script::{OperatorParams, Script, ScriptError, ScriptedDevice};
pub use source::{DeviceSource, open_device};
