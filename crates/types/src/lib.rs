//! # haptic-types: what every part of nanohaptics shares
//!
//! The vocabulary the recording format, the devices, the engine, the renderer and the wheel
//! all speak, with no behaviour behind it:
//!
//! - [`vec3`]: `[f64; 3]` vectors (m, N, m/s) and the few operations on them;
//! - [`primitive`]: what a scene draws ([`Primitive`], [`Rgba`]), world frame, metres;
//! - [`event`]: what happened during a tick ([`Event`]);
//! - [`switch`]: the teaching game's menu, set during a session ([`Switch`], [`SwitchSpec`]);
//! - [`device`]: the haptic device interface ([`HapticDevice`], [`DeviceSample`],
//!   [`DeviceSpecs`], [`ForceCommand`], [`TickTime`]);
//! - [`tick`]: what one tick of the loop produced ([`TickResult`], its [`tick::status`] bits);
//! - [`local`]: the local model a device renders between answers (bridge protocol 2): contact
//!   planes, a carried body on its coupling, the residual and the world's energy;
//! - [`textpos`]: line and column of a field in a TOML file, for errors;
//! - [`value`]: the one form of a bad number (`field = v is out of range: allowed …`).
//!
//! What it is not: no physics, no I/O, no devices (those live in `haptic-devices`), no
//! recording (`nanohaptics-recording`), no loop (`haptic-loop`). It depends only on
//! `world-form`, serde, toml (for positions) and thiserror, so any tool can read our data.
//!
//! ```
//! use haptic_types::{Event, tick::{TickResult, status}};
//! let mut r = TickResult::default();
//! r.status |= status::CLAMPED | status::WATCHDOG;
//! r.events.push(Event::new("force.clamped", "9.1 N > 8 N"));
//! assert_eq!(status::names(r.status), ["clamped", "watchdog"]);
//! ```

pub mod buttons;
pub mod device;
pub mod event;
pub mod local;
pub mod primitive;
pub mod switch;
pub mod textpos;
pub mod tick;
pub mod value;
pub mod vec3;

pub use buttons::{ButtonRoles, Role};
pub use device::{
    Buttons, DeviceError, DeviceModel, DeviceSample, DeviceSpecs, ForceCommand, HapticDevice,
    TickTime,
};
pub use event::Event;
pub use primitive::{Ball, OrientedBox, Primitive, Rgba};
pub use switch::{Switch, SwitchError, SwitchSpec};
pub use tick::TickResult;
pub use value::ValueError;
pub use vec3::Vec3;
