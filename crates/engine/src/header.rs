//! The session header: what a session is, as the engine knows it.
//!
//! The [`Runner`](crate::runner::Runner) and every [`Sink`](crate::sink::Sink) receive it before
//! the first tick. It belongs to the engine, not to the file format: the recorder converts it
//! to the recording's description ([`crate::record_sink::description_of`]) and a replay reads
//! it back ([`crate::record_sink::header_of`]), so the tick, the runner and the sinks never
//! name the format.

use haptic_types::device::DeviceSpecs;

/// What a session is: its scene, its device, how it is driven and when it started.
#[derive(Clone, Debug, PartialEq)]
pub struct SessionHeader {
    /// Scene name.
    pub scene_name: String,
    /// Scene kind (`wall`, `nanoworld`, `brickworld`, `optical_tweezers`, …).
    pub scene_kind: String,
    /// The whole scene file (a replay rebuilds the world from it).
    pub scene_toml: String,
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// `batch`, `realtime` or `stepped`.
    pub mode: String,
    /// Script name (information only; empty without a script).
    pub script_name: String,
    /// Script text (information only; empty without a script).
    pub script_toml: String,
    /// Who holds the device: `rigid`, the simulated hand's parameters, `person`, `python`.
    pub operator: String,
    /// Names of the scene's state fields, each with its unit.
    pub state_fields: Vec<String>,
    /// Wall-clock start of the session, ns since the Unix epoch (information only: it never
    /// reaches the physics).
    pub start_time_ns: u64,
    /// How the device is connected: `script`, `hand`, `replay`, `udp:HOST:PORT`, `python`,
    /// `page`.
    pub device_link: String,
    /// The device's specifications (a model's, or what a bridged device announced).
    pub device: DeviceSpecs,
}
