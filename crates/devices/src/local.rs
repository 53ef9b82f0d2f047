//! The device side of the bridge: what a device's servo thread renders between the
//! simulator's answers, and the two-port passivity layer that bounds it (issue 31).
//!
//! Library code for every device side: `fake-device`, the modelled devices of the closed-loop
//! tests and benchmarks ([`crate::linked`]), and (ported line by line, tested against this one)
//! the Python adapters of `nanohaptics.bridge`.
//!
//! - **Protocol 1** renders the newest answer's `F0 − K (p − p0)`, with `p0` the reading that
//!   answer was computed from (the device keeps its recent readings by sequence number), so
//!   the answer's local stiffness is felt without delay however late the answer arrives.
//! - **Protocol 2** renders the answer's [`LocalModel`]: its residual, its contact planes at
//!   the position read now, and the carried body ([`Body`]), integrated here one step per
//!   sample with the reading sent, as the simulator integrates it: each answer restarts the
//!   body from the state the simulator reports for the answered sample and replays the
//!   readings sent since, so in free carry the device's body and the simulator's are one
//!   trajectory, the device's ahead by the link's delay, and the coupling's dynamics never
//!   wait for the link.
//! - **Protocol 3** renders protocol 2's model with its bond: a spring that breaks where the
//!   world's contact lets go, at the position read now.
//! - **Protocol 4** renders protocol 3's model with its follower: the optical-tweezers world's
//!   held particle, stepped with each reading through the working envelope the answer sent,
//!   from the answered sample on (so it starts as the world's particle met that sample), and
//!   its spring on the excess at the position read now.
//!
//! Protocols 2 to 4 run behind the **two-port passivity layer** (after Ryu, Artigas and Preusche
//! 2010): the device counts the work its motors did on the hand, `W_dev = Σ F·Δp` over its servo
//! periods, and the simulator reports the work its answers did on the readings it received,
//! `W_world`. Whatever the link's delay, loss or jitter, once `W_dev` exceeds `W_world + R` (the
//! reserve) the device adds damping to take the surplus back, and once the surplus passes a second
//! reserve it scales its force down, to zero at `W_world + 4R`: the hand never receives more than
//! the world delivered plus four reserves, 0.08 J (each servo period of intervention is counted).

use haptic_types::device::ForceCommand;
use haptic_types::local::{Body, Follower, LocalModel};
use haptic_types::vec3::{self, Vec3};
use std::collections::VecDeque;

/// Which answers the device side renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Protocol {
    /// `F0 − K (p − p0)` (protocol version 1).
    V1,
    /// The local model (protocol version 2), with the two-port passivity layer.
    V2,
    /// The local model with a bond, a spring that breaks (protocol version 3,
    /// `haptic_types::local::Bond`), with the two-port passivity layer.
    V3,
    /// The local model with a bond and a follower, the held particle of the optical tweezers
    /// (protocol version 4, `haptic_types::local::Follower`), with the two-port passivity
    /// layer.
    V4,
}

impl Protocol {
    /// The version number on the wire.
    pub fn version(self) -> u8 {
        match self {
            Protocol::V1 => 1,
            Protocol::V2 => 2,
            Protocol::V3 => 3,
            Protocol::V4 => 4,
        }
    }

    /// The protocol of version `v` (1 to 4).
    pub fn of_version(v: u8) -> Option<Protocol> {
        match v {
            1 => Some(Protocol::V1),
            2 => Some(Protocol::V2),
            3 => Some(Protocol::V3),
            4 => Some(Protocol::V4),
            _ => None,
        }
    }

    /// Whether the device renders a local model (versions 2 to 4) behind the two-port layer.
    pub fn has_local_model(self) -> bool {
        self != Protocol::V1
    }
}

/// Energy the device may give the hand beyond what the world delivered, J (the single-port
/// layer's default reserve).
pub const DEVICE_RESERVE_J: f64 = 0.02;

/// Largest damping the two-port layer adds, N·s/m: the damping of a loose grip, as the
/// single-port layer's.
pub const DEVICE_MAX_DAMPING_N_S_PER_M: f64 = 2.0;

/// Readings kept for answers that arrive late, periods (1 s at 1 kHz; older answers are
/// rendered against the oldest kept reading).
const KEEP_READINGS: usize = 1000;

/// The answer being rendered.
#[derive(Clone, Debug)]
struct Answer {
    cmd: ForceCommand,
    p0: Vec3,
    local: Option<LocalModel>,
}

/// What the device's servo thread renders, and its two-port passivity layer.
#[derive(Clone, Debug)]
pub struct DeviceSide {
    protocol: Protocol,
    max_force_n: f64,
    /// The loop's period (one sample per period), s.
    period_s: f64,
    /// Recent readings sent, by sequence number (oldest first).
    readings: VecDeque<(u64, Vec3)>,
    answer: Option<Answer>,
    /// The carried body as integrated here, and the sequence number of the reading it is to
    /// be stepped with next (its state is the one that reading meets).
    body: Option<(Body, u64)>,
    /// The follower as stepped here, and the sequence number of the reading it is to be
    /// stepped with next.
    follower: Option<(Follower, u64)>,
    /// Work the motors did on the hand, J.
    work_j: f64,
    /// The world's reported work, J.
    world_j: f64,
    reserve_j: f64,
    last_p: Option<Vec3>,
    last_f: Vec3,
    interventions: u64,
    /// The smallest `tick − seq` of the answers so far: an on-time answer's. A stale tick
    /// answers an older sample (its `tick − seq` is larger by the sample's age): its state
    /// belongs to its tick, not to the sample it answers.
    tick_offset: Option<i128>,
}

impl DeviceSide {
    /// A device side speaking `protocol` whose motors give at most `max_force_n`, sampled
    /// once per loop period of `period_s`.
    pub fn new(protocol: Protocol, max_force_n: f64, period_s: f64) -> DeviceSide {
        DeviceSide {
            protocol,
            max_force_n,
            period_s,
            readings: VecDeque::with_capacity(KEEP_READINGS + 1),
            answer: None,
            body: None,
            follower: None,
            work_j: 0.0,
            world_j: 0.0,
            reserve_j: DEVICE_RESERVE_J,
            last_p: None,
            last_f: [0.0; 3],
            interventions: 0,
            tick_offset: None,
        }
    }

    /// The protocol spoken.
    pub fn protocol(&self) -> Protocol {
        self.protocol
    }

    /// The device sent reading `p` as sample `seq`.
    pub fn record_reading(&mut self, seq: u64, p: Vec3) {
        self.readings.push_back((seq, p));
        if self.readings.len() > KEEP_READINGS {
            self.readings.pop_front();
        }
        self.catch_up(seq);
    }

    /// Steps the follower and the body with every kept reading before `seq` they have not met
    /// yet (a number the
    /// device skipped holds the reading before it).
    fn catch_up(&mut self, seq: u64) {
        if let Some((f, next)) = self.follower.as_mut() {
            while *next < seq {
                let Some(p) = reading_at_or_before(&self.readings, *next) else {
                    break;
                };
                f.step(p);
                *next += 1;
            }
        }
        if let Some((body, next)) = self.body.as_mut() {
            let planes = self
                .answer
                .as_ref()
                .and_then(|a| a.local.as_ref())
                .map_or(&[][..], |m| &m.body_planes[..]);
            while *next < seq {
                let Some(p) = reading_at_or_before(&self.readings, *next) else {
                    break;
                };
                body.step(p, self.period_s, planes);
                *next += 1;
            }
        }
    }

    /// An answer arrived: rendered from now on if it is newer than the one rendered (by tick:
    /// answers overtaken by a newer one are dropped). Protocol 2's body restarts from the
    /// state the answer reports for the sample after its tick and replays the readings sent
    /// since; the world's reported energy becomes the two-port layer's budget.
    pub fn receive(&mut self, cmd: &ForceCommand, local: Option<LocalModel>) {
        if self.answer.as_ref().is_some_and(|a| a.cmd.tick > cmd.tick) {
            return;
        }
        let p0 = reading_at_or_before(&self.readings, cmd.seq)
            .or_else(|| self.readings.front().map(|r| r.1))
            .unwrap_or([0.0; 3]);
        let local = match self.protocol {
            Protocol::V1 => None,
            Protocol::V2 => local.map(|m| LocalModel {
                bond: None,
                follower: None,
                ..m
            }),
            Protocol::V3 => local.map(|m| LocalModel {
                follower: None,
                ..m
            }),
            Protocol::V4 => local,
        };
        let lag = i128::from(cmd.tick) - i128::from(cmd.seq);
        let offset = *self.tick_offset.get_or_insert(lag);
        self.tick_offset = Some(offset.min(lag));
        if let Some(m) = &local {
            self.world_j = m.world_energy_j;
            // The sample whose reading the reported state meets next.
            let next = u64::try_from(i128::from(cmd.tick) - offset.min(lag) + 1).ok();
            self.body = m.body.zip(next);
            // The follower's state is the one the answered sample met: it replays that
            // sample's reading first.
            self.follower = m.follower.clone().zip(next.and_then(|n| n.checked_sub(1)));
        }
        self.answer = Some(Answer {
            cmd: *cmd,
            p0,
            local,
        });
        if let Some(&(newest, _)) = self.readings.back() {
            self.catch_up(newest);
        }
    }

    /// The force to render at the reading `p` for the next servo period of `servo_s`, N (before
    /// the motors' clamp and resolution): the answer's model, held back by the two-port layer.
    pub fn render(&mut self, p: Vec3, servo_s: f64) -> Vec3 {
        // The work the last period's force did on the hand, and the stylus's velocity.
        let mut v = [0.0; 3];
        if let Some(lp) = self.last_p {
            let d = vec3::sub(p, lp);
            let w = vec3::dot(self.last_f, d);
            // A non-finite reading counts no work (it would poison the budget for good).
            if w.is_finite() && vec3::is_finite(d) {
                self.work_j += w;
                v = vec3::scale(d, 1.0 / servo_s);
            }
        }
        if vec3::is_finite(p) {
            self.last_p = Some(p);
        }
        let Some(a) = &self.answer else {
            self.last_f = [0.0; 3];
            return [0.0; 3];
        };
        let mut f = match &a.local {
            None => {
                let d = vec3::sub(p, a.p0);
                let k = &a.cmd.stiffness_n_per_m;
                let mut f = a.cmd.force_n;
                for (i, fi) in f.iter_mut().enumerate() {
                    *fi -= k[3 * i] * d[0] + k[3 * i + 1] * d[1] + k[3 * i + 2] * d[2];
                }
                f
            }
            Some(m) => {
                let mut f = m.static_force(p, a.p0);
                if let Some((body, _)) = &self.body {
                    f = vec3::sub(f, body.pull(p, self.period_s).0);
                }
                if let Some((follower, _)) = &self.follower {
                    f = vec3::add(f, follower.force(p));
                }
                f
            }
        };
        if !vec3::is_finite(f) {
            f = [0.0; 3];
        }
        let n = vec3::norm(f);
        if n > self.max_force_n {
            f = vec3::scale(f, self.max_force_n / n);
        }
        if self.protocol.has_local_model() {
            f = self.bound(f, v, servo_s);
            if !vec3::is_finite(f) {
                f = [0.0; 3];
            }
        }
        self.last_f = f;
        f
    }

    /// The two-port layer: while the hand has received more than the world delivered plus the
    /// reserve, a damper on the stylus's motion (from the last servo period's readings) takes
    /// the surplus back over the next period, at most [`DEVICE_MAX_DAMPING_N_S_PER_M`] (more,
    /// and the damper rendered through a held force chatters itself); and when the surplus
    /// passes a second reserve the force itself is scaled down, to zero when it reaches three
    /// (`W_dev = W_world + 4R`), so the energy the hand can receive beyond the world's is
    /// bounded whatever the link does.
    fn bound(&mut self, f: Vec3, v: Vec3, servo_s: f64) -> Vec3 {
        let surplus = self.work_j - self.world_j - self.reserve_j;
        if surplus <= 0.0 {
            return f;
        }
        self.interventions += 1;
        let v2 = vec3::dot(v, v);
        let mut g = if v2 > 0.0 {
            let alpha = (surplus / (servo_s * v2)).min(DEVICE_MAX_DAMPING_N_S_PER_M);
            vec3::sub(f, vec3::scale(v, alpha))
        } else {
            f
        };
        if surplus > self.reserve_j {
            let scale = (1.0 - (surplus - self.reserve_j) / (2.0 * self.reserve_j)).max(0.0);
            g = vec3::scale(g, scale);
        }
        let n = vec3::norm(g);
        if n > self.max_force_n {
            vec3::scale(g, self.max_force_n / n)
        } else {
            g
        }
    }

    /// Work the motors did on the hand so far, J.
    pub fn work_j(&self) -> f64 {
        self.work_j
    }

    /// Servo periods on which the two-port layer held the force back.
    pub fn interventions(&self) -> u64 {
        self.interventions
    }
}

/// The reading sent as `seq`, or the last one before it (a skipped number holds the reading
/// before it); `None` when `seq` is older than every kept reading.
fn reading_at_or_before(readings: &VecDeque<(u64, Vec3)>, seq: u64) -> Option<Vec3> {
    let i = readings.partition_point(|r| r.0 <= seq);
    i.checked_sub(1).and_then(|i| readings.get(i)).map(|r| r.1)
}
