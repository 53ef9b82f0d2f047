//! A modelled device held by a hand, behind a modelled link: the device side of a bridged
//! session in simulated time (issue 31).
//!
//! The device samples its encoders once per loop period (`k·T`), sends the sample up the link,
//! and renders whatever answer has arrived with the device-side renderer
//! ([`crate::local::DeviceSide`]) at its own servo rate, between and across answers. The
//! simulator's side (which sample each tick uses, and when it runs) is the caller's; see
//! `haptic_loop::closed_loop`. Time is whole nanoseconds; every draw is seeded, so a run
//! repeats to the bit.

use crate::link::{Link, LinkParams};
use crate::local::{DeviceSide, Protocol};
use crate::script::Script;
use crate::{Grip, Mechanics, Plant};
use haptic_types::device::{Buttons, DeviceSample, DeviceSpecs, ForceCommand};
use haptic_types::local::LocalModel;
use haptic_types::vec3::Vec3;

/// A scripted hand holding a modelled device at the far end of a link.
#[derive(Clone, Debug)]
pub struct LinkedDevice {
    script: Script,
    specs: DeviceSpecs,
    plant: Plant,
    side: DeviceSide,
    up: Link<DeviceSample>,
    down: Link<(ForceCommand, Option<LocalModel>)>,
    period_ns: u64,
    now_ns: u64,
    /// The force the motors rendered when each sample was read, N.
    felt: Vec<Vec3>,
    /// Each sample's reading, m.
    readings: Vec<Vec3>,
}

impl LinkedDevice {
    /// The device `mech` held with `grip` following `script` (buttons named as `buttons_of`'s),
    /// behind `link`, at the loop's `rate_hz`, speaking `protocol`.
    pub fn new(
        script: Script,
        mech: Mechanics,
        grip: Grip,
        buttons_of: &DeviceSpecs,
        link: &LinkParams,
        rate_hz: u32,
        protocol: Protocol,
    ) -> LinkedDevice {
        let plant = Plant::new(mech, grip, script.position(0.0));
        LinkedDevice {
            specs: crate::modelled::specs_of(&mech, buttons_of),
            side: DeviceSide::new(
                protocol,
                mech.limits.max_force_n,
                1.0 / f64::from(rate_hz.max(1)),
            ),
            plant,
            script,
            up: Link::new(link, 0),
            down: Link::new(link, 1),
            period_ns: 1_000_000_000 / u64::from(rate_hz.max(1)),
            now_ns: 0,
            felt: Vec::new(),
            readings: Vec::new(),
        }
    }

    /// The device's specifications (what its hello announces).
    pub fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    /// The device and hand.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The device side's renderer (its passivity figures).
    pub fn device_side(&self) -> &DeviceSide {
        &self.side
    }

    /// The force the motors rendered when each sample was read (the last servo period's), N:
    /// what the hand felt, once per loop period.
    pub fn felt(&self) -> &[Vec3] {
        &self.felt
    }

    /// Each sample's encoder reading, m (device frame).
    pub fn readings(&self) -> &[Vec3] {
        &self.readings
    }

    /// Loop period, ns.
    pub fn period_ns(&self) -> u64 {
        self.period_ns
    }

    /// Reads the encoders at `k·T` (the device must have been advanced there) and sends the
    /// sample `k` up the link.
    pub fn send_sample(&mut self, k: u64) {
        let t = k * self.period_ns;
        let reading = self.plant.reading_m();
        self.felt.push(self.plant.last_force_n());
        self.readings.push(reading);
        self.side.record_reading(k, reading);
        let s = DeviceSample {
            position_m: reading,
            buttons: Buttons(self.script.buttons(t as f64 * 1e-9).0),
            seq: k,
            age_ticks: 0,
        };
        let _ = self.up.send(t, s);
    }

    /// The samples that have reached the simulator by `now_ns`, with their arrival times.
    pub fn samples_arrived(&mut self, now_ns: u64) -> Vec<(u64, DeviceSample)> {
        self.up.arrived(now_ns)
    }

    /// Arrival time of the next sample in flight, ns.
    pub fn next_sample_arrival(&self) -> Option<u64> {
        self.up.next_arrival()
    }

    /// The simulator sends its answer (and, protocol 2, its local model) at `now_ns`.
    pub fn send_answer(&mut self, now_ns: u64, cmd: ForceCommand, local: Option<LocalModel>) {
        let _ = self.down.send(now_ns, (cmd, local));
    }

    /// Advances the device and the hand to `t_ns`, taking each answer at its arrival.
    pub fn advance_to(&mut self, t_ns: u64) {
        while self.now_ns < t_ns {
            let next = self
                .down
                .next_arrival()
                .filter(|&a| a < t_ns)
                .unwrap_or(t_ns)
                .max(self.now_ns);
            for (_, (cmd, local)) in self.down.arrived(self.now_ns) {
                self.side.receive(&cmd, local);
            }
            if next > self.now_ns {
                let t0 = self.now_ns as f64 * 1e-9;
                let script = &self.script;
                let side = &mut self.side;
                self.plant.advance_with(
                    (next - self.now_ns) as f64 * 1e-9,
                    |t| (script.position(t0 + t), script.velocity(t0 + t)),
                    &mut |p, dt| side.render(p, dt),
                );
                self.now_ns = next;
            }
        }
        for (_, (cmd, local)) in self.down.arrived(self.now_ns) {
            self.side.receive(&cmd, local);
        }
    }

    /// Packets sent and lost: (samples sent, samples lost, answers sent, answers lost).
    pub fn link_counts(&self) -> [u64; 4] {
        let (a, b) = self.up.counts();
        let (c, d) = self.down.counts();
        [a, b, c, d]
    }
}
