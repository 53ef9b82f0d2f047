//! The recording's tick encoder fed from a running loop: the scene's state fields and drawing
//! are read from the loop, then encoded by `recording`'s [`TickEncoder`].

use haptic_engine::haptic::HapticLoop;
use haptic_types::TickResult;
use recording::{OutMsg, TickEncoder};

/// A [`TickEncoder`] for one loop's session, with its scratch buffer for the state fields.
#[derive(Clone, Debug)]
pub struct LoopEncoder {
    enc: TickEncoder,
    state: Vec<f64>,
}

impl LoopEncoder {
    /// An encoder for the loop `l` of a session that started at `start_ns` (ns since the Unix
    /// epoch; log times are `start_ns + tick · period`).
    pub fn new(l: &HapticLoop, start_ns: u64) -> Self {
        let c = l.config();
        LoopEncoder {
            enc: TickEncoder::new(start_ns, c.period_ns(), c.display_every, c.display_scale),
            state: Vec::new(),
        }
    }

    /// Log time of tick `tick`, ns since the Unix epoch.
    pub fn log_time_ns(&self, tick: u64) -> u64 {
        self.enc.log_time_ns(tick)
    }

    /// Appends the verified outputs of tick `r` of `l` to `out`, in their fixed order.
    pub fn outputs(&mut self, r: &TickResult, l: &HapticLoop, out: &mut Vec<OutMsg>) {
        self.state.clear();
        l.scene_state(&mut self.state);
        self.enc
            .outputs(r, &self.state, &mut |p| l.scene().draw(p), out);
    }
}
