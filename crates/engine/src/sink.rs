//! What a session hands its ticks to: the [`Sink`] trait and the views it receives.
//!
//! A sink (the MCAP recorder, the per-tick arrays, the replay verifier, the frame renderer, the
//! live view) sees each tick once, after the force was sent to the device, and must not block.
//! Adding a sink is one new file implementing [`Sink`] and one line where the session builds its
//! list of sinks (`session::run_session`).

use crate::haptic::{HapticLoop, LoopConfig};

use crate::header::SessionHeader;
use crate::pacing::TickStats;
use haptic_types::DeviceSample;
use haptic_types::TickResult;

/// One tick as the sinks see it.
pub struct TickView<'a> {
    /// The device reading the tick ran on (the tick's recorded input).
    pub sample: DeviceSample,
    /// Whether the tick's real-time deadline was missed (zero force was sent); an input too.
    pub deadline_missed: bool,
    /// What the tick produced.
    pub result: &'a TickResult,
    /// The loop after the tick (scene state and drawing).
    pub lp: &'a HapticLoop,
    /// Start lateness against the schedule, ns (0 in batch mode; wall clock, not reproducible).
    pub start_late_ns: i64,
    /// Work of the tick from reading the device to sending the force, ns (wall clock).
    pub compute_ns: u64,
}

/// What a sink learns before the first tick.
pub struct SessionInfo<'a> {
    /// The session's header (the recorder writes it as the file's description).
    pub header: &'a SessionHeader,
    /// The loop's configuration.
    pub config: &'a LoopConfig,
    /// Number of ticks planned (`None`: until the device ends the session).
    pub ticks: Option<u64>,
}

/// A consumer of ticks.
pub trait Sink {
    /// Short name for reports (`recorder`, `arrays`, `live`, ...).
    fn name(&self) -> &'static str;
    /// Called once before the first tick.
    fn start(&mut self, _info: &SessionInfo<'_>, _lp: &HapticLoop) -> Result<(), SinkError> {
        Ok(())
    }
    /// Called once per tick, after the force was sent; must not block.
    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError>;
    /// Called once after the last tick with the session's statistics and the device's link
    /// counters (empty for headless devices).
    fn finish(
        &mut self,
        _stats: &TickStats,
        _link: &[(&'static str, u64)],
    ) -> Result<(), SinkError> {
        Ok(())
    }
}

/// A sink's failure: the sink's own typed error, kept whole (the session gives it back its type,
/// e.g. a recording's disk error stays an OS error with its code).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct SinkError(pub Box<dyn std::error::Error + Send + Sync + 'static>);

impl SinkError {
    /// Wraps a sink's error.
    pub fn new(e: impl std::error::Error + Send + Sync + 'static) -> Self {
        SinkError(Box::new(e))
    }
}
