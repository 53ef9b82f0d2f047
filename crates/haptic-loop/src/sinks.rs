//! The one list of a session's sinks, in the order they see each tick: the running totals
//! (always first), the per-tick arrays, the MCAP recorder and the live view. `run_session`,
//! the [`Stepper`](crate::stepper::Stepper) and the wheel's sessions all hold a
//! [`SessionSinks`]; a new sink of every session is one field and one line of
//! [`SessionSinks::list`].

use crate::arrays::SessionArrays;
use crate::error::SessionError;
use crate::live::{LiveConfig, LiveSummary};
use crate::record_sink::RecorderSink;
use haptic_engine::sink::Sink;
use haptic_engine::totals::Totals;
use recording::WriteSummary;
use std::path::PathBuf;

/// The live view's sink (this build serves the live view: the `live` feature).
#[cfg(feature = "live")]
pub type Live = crate::live::LiveSink;
/// Without the `live` feature there is no live view to serve.
#[cfg(not(feature = "live"))]
pub type Live = std::convert::Infallible;

/// Without the `live` feature there is no menu to read (no live view serves one).
#[cfg(not(feature = "live"))]
pub enum Menu {}

#[cfg(not(feature = "live"))]
impl Menu {
    /// Never called: no menu exists without the live view.
    pub fn take(&mut self) -> Vec<(String, f64)> {
        match *self {}
    }

    /// Never called: no menu exists without the live view.
    pub fn set_value(&mut self, _name: &str, _value: f64) {
        match *self {}
    }
}

/// The sinks of one session.
pub struct SessionSinks {
    /// Running totals (the summary); always delivered.
    pub totals: Totals,
    /// Per-tick arrays; delivered when `keep_arrays`.
    pub arrays: SessionArrays,
    /// Whether the arrays are filled.
    pub keep_arrays: bool,
    /// The MCAP recorder, when recording.
    pub recorder: Option<RecorderSink>,
    /// The live view, when serving one.
    pub live: Option<Live>,
}

impl SessionSinks {
    /// Totals, `arrays` (filled when `keep_arrays`) and a recorder writing to `out` (if any);
    /// no live view.
    pub fn new(arrays: SessionArrays, keep_arrays: bool, out: Option<PathBuf>) -> Self {
        SessionSinks {
            totals: Totals::default(),
            arrays,
            keep_arrays,
            recorder: out.map(RecorderSink::new),
            live: None,
        }
    }

    /// The sinks, in delivery order, with room for one more (a front end's own, such as
    /// `play`'s pages): one allocation a tick, never a reallocation.
    pub fn list(&mut self) -> Vec<&mut dyn Sink> {
        let mut v: Vec<&mut dyn Sink> = Vec::with_capacity(5);
        v.push(&mut self.totals);
        if self.keep_arrays {
            v.push(&mut self.arrays);
        }
        if let Some(r) = self.recorder.as_mut() {
            v.push(r);
        }
        #[cfg(feature = "live")]
        if let Some(l) = self.live.as_mut() {
            v.push(l);
        }
        v
    }

    /// The live view's menu, when serving one.
    #[cfg(feature = "live")]
    pub fn menu(&self) -> Option<std::sync::Arc<std::sync::Mutex<crate::live::menu::Menu>>> {
        self.live.as_ref().map(|l| l.menu())
    }

    /// The live view's menu (none without the `live` feature).
    #[cfg(not(feature = "live"))]
    pub fn menu(&self) -> Option<std::sync::Arc<std::sync::Mutex<Menu>>> {
        None
    }

    /// What the recorder wrote (after the session's end).
    pub fn written(&self) -> Option<WriteSummary> {
        self.recorder.as_ref().and_then(|r| r.summary().cloned())
    }
}

/// Starts the live view `config` asks for (before the device is opened, so a viewer may connect
/// before a bridged device's hello).
pub fn start_live(config: Option<&LiveConfig>) -> Result<Option<Live>, SessionError> {
    match config {
        #[cfg(feature = "live")]
        Some(c) => Ok(Some(crate::live::LiveSink::new(c.clone())?)),
        #[cfg(not(feature = "live"))]
        Some(c) => Err(SessionError::Live(format!(
            "cannot serve ws:{}: this build has no live view (build haptic-loop with its \
             `live` feature, as the `nanohaptics` program is)",
            c.bind
        ))),
        None => Ok(None),
    }
}

/// What the live view published.
#[cfg(feature = "live")]
pub fn live_summary(live: Option<Live>) -> Option<LiveSummary> {
    live.map(|l| l.summary())
}

/// What the live view published (none without the `live` feature).
#[cfg(not(feature = "live"))]
pub fn live_summary(live: Option<Live>) -> Option<LiveSummary> {
    live.map(|never| match never {})
}
