//! The real-time flags every command with a tick thread shares (`run`, `play`, `classroom`):
//! `--no-rt` and `--rt-priority`.

use haptic_engine::realtime::{DEFAULT_PRIORITY, RtRequest};

/// `--no-rt` and `--rt-priority N`.
#[derive(clap::Args, Debug, Clone)]
pub(crate) struct RtArgs {
    /// Do not ask for real-time scheduling: the tick thread runs at normal priority (by default
    /// a real-time session asks for SCHED_FIFO, locked memory and a core of its own, and says
    /// once, with the fix, when the system refuses; `nanohaptics doctor` tells what it allows).
    #[arg(long)]
    no_rt: bool,
    /// SCHED_FIFO priority of the tick thread, 1–99.
    #[arg(long, default_value_t = i64::from(DEFAULT_PRIORITY))]
    rt_priority: i64,
}

impl RtArgs {
    /// The request (`None` with `--no-rt`), or the priority's error.
    pub(crate) fn request(&self) -> Result<Option<RtRequest>, String> {
        let req = RtRequest::with_priority(self.rt_priority).map_err(|e| format!("--{e}"))?;
        Ok((!self.no_rt).then_some(req))
    }
}
