//! # haptic-devices — a haptic device and the hand that holds it, as physics
//!
//! Every world of nanohaptics renders a force to a device; whether that rendering is *stable*
//! depends on what the device and the hand are: a moving mass with a little friction, an
//! encoder that reports positions in counts, a force held constant over each tick (zero-order
//! hold), and a hand that grips the stylus with some stiffness and damping. An ideal, massless
//! scripted hand cannot show instability; this crate is the model that can.
//!
//! What it is for:
//! - [`Mechanics`]: a device's moving mass (kg), viscous friction (N·s/m), encoder quantum (m),
//!   force resolution (N), servo rate (Hz) and [`Limits`](world_form::Limits), with presets for
//!   the Novint Falcon, the 3D Systems Touch, the Force Dimension delta.3 and the Haply Inverse3
//!   ([`Mechanics::preset`]), each figure cited in `docs/devices.md`;
//! - [`Grip`]: the hand as a spring-damper to the operator's intended path, from
//!   [`Grip::LOOSE`] (300 N/m, 2 N·s/m) to [`Grip::FIRM`] (1000 N/m, 8 N·s/m), parsed from
//!   `loose`, `firm` or `k=…,b=…[,m=…]`;
//! - [`Plant`]: the device and the hand integrated between two ticks of a haptic loop under a
//!   held force command, reporting encoder-quantized positions and the energy the device put
//!   into the hand.
//!
//! What it is not: no I/O, no scripts, no haptic loop, no worlds. The loop's device trait, the
//! scripted operator that feeds a [`Plant`] its intended path and the UDP bridge live in
//! `haptic-loop`; this crate knows nothing of them (arrows point one way).
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

mod grip;
mod mechanics;
mod plant;

pub use grip::{Grip, GripError};
pub use mechanics::{Mechanics, MechanicsError, PRESETS};
pub use plant::{Hold, Plant};

/// A 3-vector, SI units as named where it is used.
pub type Vec3 = [f64; 3];
