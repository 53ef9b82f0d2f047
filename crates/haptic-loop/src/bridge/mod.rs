//! The device bridge: a haptic device in another process (a driver for a Falcon, a Touch, a
//! Force Dimension device, a Python script, or `nanohaptics fake-device`) sends numbered
//! samples over UDP and gets a force and a local stiffness back for each.
//!
//! - [`protocol`]: the versioned wire format (`docs/device-bridge.md` has the byte layout);
//! - [`udp`]: the simulator's side, a [`HapticDevice`](crate::device::HapticDevice) with a
//!   watchdog-friendly sample clock and fault counters;
//! - [`fake`]: a stand-in device process with injectable loss, jitter, latency and an outage.

pub mod fake;
pub mod protocol;
pub mod udp;

pub use udp::{BridgeConfig, UdpDevice};
