//! The session's running totals: what a run's summary reports (peak force, clamped and
//! watchdog ticks, events, the house score from the last state), kept in constant memory so a
//! session of any length can summarise itself without per-tick arrays.

use crate::sink::{Sink, SinkError, TickView};
use haptic_types::tick::status;

/// Running totals of a session, updated every tick.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Totals {
    /// Ticks seen.
    pub ticks: u64,
    /// Largest norm of the force sent to the device, N.
    pub peak_device_force_n: f64,
    /// Ticks whose force was scaled down to the device maximum (status bit
    /// [`status::CLAMPED`]).
    pub clamped_ticks: u64,
    /// Ticks whose force the watchdog reduced (status bit [`status::WATCHDOG`]).
    pub watchdog_ticks: u64,
    /// Events of all ticks.
    pub events: u64,
    /// The scene's state fields, in the order of [`Totals::last_state`].
    pub state_fields: Vec<String>,
    /// The scene's state after the last tick (its fields' values).
    pub last_state: Vec<f64>,
}

impl Totals {
    /// The value of state field `name` after the last tick, if the scene has it.
    pub fn last(&self, name: &str) -> Option<f64> {
        let k = self.state_fields.iter().position(|f| f == name)?;
        self.last_state.get(k).copied()
    }

    /// The scene's state after the last tick, (field name, value) in the scene's order.
    pub fn state(&self) -> Vec<(String, f64)> {
        self.state_fields
            .iter()
            .cloned()
            .zip(self.last_state.iter().copied())
            .collect()
    }
}

impl Sink for Totals {
    fn name(&self) -> &'static str {
        "totals"
    }

    fn start(
        &mut self,
        info: &crate::sink::SessionInfo<'_>,
        _lp: &crate::haptic::HapticLoop,
    ) -> Result<(), SinkError> {
        *self = Totals {
            state_fields: info.header.state_fields.clone(),
            ..Totals::default()
        };
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let r = t.result;
        let f = r.device_force_n;
        self.ticks += 1;
        self.peak_device_force_n = self
            .peak_device_force_n
            .max((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt());
        self.clamped_ticks += u64::from(r.status & status::CLAMPED != 0);
        self.watchdog_ticks += u64::from(r.status & status::WATCHDOG != 0);
        self.events += r.events.len() as u64;
        self.last_state.clear();
        t.lp.scene_state(&mut self.last_state);
        Ok(())
    }
}
