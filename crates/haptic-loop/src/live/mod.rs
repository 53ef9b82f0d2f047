//! The live view: a Foxglove WebSocket server (the `foxglove` crate's `websocket` feature) that
//! publishes a running session, as a sink of the runner.
//!
//! The servo tick never waits on it. At plot rate (default 200 Hz) the tick copies a small
//! snapshot (cursor, forces, factors, status) and, at display rate (default 50 Hz), the scene's
//! primitives, into a local buffer that it hands to a publisher thread with `try_lock` (never
//! blocking, never waking a thread). The publisher thread wakes every 5 ms, turns the snapshots
//! into Foxglove messages and logs them to the server's channels:
//!
//! | topic             | schema                     | rate          |
//! |-------------------|----------------------------|---------------|
//! | `/foxglove/scene` | `foxglove.SceneUpdate`     | display rate  |
//! | `/foxglove/tf`    | `foxglove.FrameTransform`  | display rate  |
//! | `/foxglove/log`   | `foxglove.Log`             | on events     |
//! | `/live/state`     | `nanohaptics.LiveState` (JSON) | plot rate |
//!
//! Timestamps are the session's start (wall clock, from the description) plus the tick time,
//! so Foxglove shows the real date. When the publisher falls behind, the oldest snapshots are
//! dropped and counted (`dropped` in `/live/state` and in the summary).

#[cfg(feature = "live")]
pub mod guard;
#[cfg(feature = "live")]
pub mod menu;
#[cfg(feature = "live")]
mod server;
#[cfg(feature = "live")]
pub use server::LiveSink;

use haptic_engine::sink::SinkError;
use std::net::SocketAddr;

/// Why the live view could not start or publish.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LiveError {
    /// The `--live` option is malformed.
    #[error("{0}")]
    Option(String),
    /// The server could not start or a publish failed.
    #[error("live view: {0}")]
    Serve(String),
}

impl From<LiveError> for SinkError {
    fn from(e: LiveError) -> Self {
        SinkError::new(e)
    }
}
/// Where the live view listens and how often it publishes.
#[derive(Clone, Debug, PartialEq)]
pub struct LiveConfig {
    /// Address of the WebSocket server (default loopback).
    pub bind: SocketAddr,
    /// Rate of the 3D scene, Hz (≤ the tick rate; the nearest divisor of it is used).
    pub display_hz: u32,
    /// Rate of the per-tick state for plots, Hz (same rule).
    pub plot_hz: u32,
}

impl LiveConfig {
    /// Parses `ws:HOST:PORT`, or `ws:PORT` for loopback (the `--live` option), with the default
    /// rates (50 Hz scene, 200 Hz plots).
    pub fn parse(spec: &str) -> Result<Self, LiveError> {
        let bind =
            haptic_devices::bridge::parse_endpoint(spec, "ws", "--live", "ws:127.0.0.1:8765")
                .map_err(LiveError::Option)?;
        Ok(LiveConfig {
            bind,
            display_hz: 50,
            plot_hz: 200,
        })
    }
}

/// What the live view did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct LiveSummary {
    /// Scene updates published.
    pub scenes: u64,
    /// State snapshots published.
    pub states: u64,
    /// Log lines published.
    pub logs: u64,
    /// Snapshots dropped because the publisher fell behind.
    pub dropped: u64,
    /// Clients connected at the end.
    pub clients_at_end: usize,
    /// Connections refused for a `Host` that is not this machine's (DNS rebinding).
    pub refused_host: u64,
    /// Connections refused for an `Origin` of another site (neither the page's own nor
    /// Foxglove's web app).
    pub refused_origin: u64,
}
