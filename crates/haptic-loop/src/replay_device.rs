//! The replay device: plays back the device inputs of a recording, tick by tick.

use haptic_types::Buttons;

use haptic_types::DeviceError;

use haptic_types::DeviceSample;

use haptic_types::DeviceSpecs;

use haptic_types::ForceCommand;

use haptic_types::HapticDevice;

use haptic_types::TickTime;
use haptic_types::vec3::Vec3;
use recording::channels::messages::{Channel, DeviceInputMsg};
use recording::{Recording, RecordingError};

/// Inputs of a recording played back as a device.
#[derive(Clone, Debug)]
pub struct ReplayDevice {
    specs: DeviceSpecs,
    samples: Vec<DeviceSample>,
    missed: Vec<bool>,
    forces_n: Vec<Vec3>,
}

impl ReplayDevice {
    /// Reads the `/device/input` messages of `rec`; they must be ticks 0, 1, 2, … in order, at
    /// log time `start + tick · period_ns` (start: the description's `start_time_ns`).
    pub fn from_recording(
        rec: &Recording,
        specs: DeviceSpecs,
        period_ns: u64,
    ) -> Result<Self, RecordingError> {
        let start = rec.description.start_time_ns;
        let mut samples = Vec::new();
        let mut missed = Vec::new();
        for m in rec
            .messages
            .iter()
            .filter(|m| m.channel == Channel::DeviceInput)
        {
            let bad = |detail: String| RecordingError::BadMessage {
                topic: Channel::DeviceInput.topic().to_string(),
                log_time_ns: m.log_time_ns,
                detail,
            };
            let d = DeviceInputMsg::decode(&m.data).map_err(|e| bad(e.to_string()))?;
            let n = samples.len() as u64;
            let at = start.saturating_add(n.saturating_mul(period_ns));
            if d.tick != n || m.log_time_ns != at {
                return Err(bad(format!(
                    "expected tick {n} at {at} ns, found tick {} at {} ns",
                    d.tick, m.log_time_ns
                )));
            }
            samples.push(DeviceSample {
                position_m: d.position_m,
                buttons: Buttons(d.buttons),
                seq: d.seq,
                age_ticks: d.age_ticks,
            });
            missed.push(d.deadline_missed);
        }
        Ok(ReplayDevice {
            specs,
            samples,
            missed,
            forces_n: Vec::new(),
        })
    }

    /// Number of ticks recorded.
    pub fn ticks(&self) -> u64 {
        self.samples.len() as u64
    }

    /// Whether the deadline of `tick` was missed in the recorded session.
    pub fn deadline_missed(&self, tick: u64) -> bool {
        self.missed.get(tick as usize).copied().unwrap_or(false)
    }

    /// The recorded deadline flags, one per tick.
    pub fn deadline_flags(&self) -> Vec<bool> {
        self.missed.clone()
    }

    /// The recorded device positions, m, device frame, one per tick.
    pub fn positions_m(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.samples.iter().map(|s| s.position_m)
    }

    /// The forces commanded during the replay, N, one per tick.
    pub fn forces_n(&self) -> &[Vec3] {
        &self.forces_n
    }
}

impl HapticDevice for ReplayDevice {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError> {
        self.samples
            .get(time.index as usize)
            .copied()
            .ok_or(DeviceError::EndOfRecording(time.index))
    }

    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError> {
        self.forces_n.push(cmd.force_n);
        Ok(())
    }
}
