//! A stand-in device process (`nanohaptics fake-device`): plays a script, rigidly or through
//! the simulated hand, over the bridge, with injectable loss, jitter, latency and an outage;
//! measures the round trip of every answered sample.
//!
//! The device runs its own servo clock at the session's tick rate (from the welcome). Each
//! period it reads its (simulated) stylus, sends a sample, and renders what came back. A
//! receiver thread timestamps each reply on arrival, so the round trip is measured from the
//! send of a sample to the arrival of its answer.
//!
//! A modelled device (`--model`) renders through the device-side library
//! ([`crate::local::DeviceSide`]) as a real device's servo thread would: protocol 2's local
//! model at its own servo rate, or protocol 1's `F0 − K (p − p0)`, behind the two-port
//! passivity layer; the figures it reports (jumps, energy) are of the force its motors
//! rendered, what the hand felt.

pub use super::fault::{BACK_OFF_AFTER_S, Fault};
use super::protocol::{ForceReply, Packet, Sample};
use crate::local::{DeviceSide, Protocol};
use crate::script::Script;
use crate::{OperatorParams, Plant, ScriptedDevice, SimulatedOperator};
use haptic_engine::timing::{Pacer, Percentiles};
use haptic_types::device::{
    DeviceError, DeviceModel, DeviceSpecs, ForceCommand, HapticDevice, TickTime,
};
use haptic_types::vec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What the fake device does.
#[derive(Clone, Debug)]
pub struct FakeConfig {
    /// The simulator's bridge address.
    pub target: SocketAddr,
    /// The device model it pretends to be (its specifications go in the hello).
    pub model: DeviceModel,
    /// The stylus motion.
    pub script: Script,
    /// A simulated hand pushed by the rendered force (`None`: a rigid stylus).
    pub hand: Option<OperatorParams>,
    /// A modelled device held by a hand (`haptic_devices`): moving mass, encoder counts, the
    /// force held over the period. Takes the place of `model`'s specifications and of `hand`.
    pub physical: Option<(crate::Mechanics, crate::Grip)>,
    /// Probability that a sample is lost, 0–1.
    pub loss: f64,
    /// Extra delay of each sample, uniform in 0–`jitter_s`, s (samples may overtake each other).
    pub jitter_s: f64,
    /// Fixed delay of each sample, s.
    pub latency_s: f64,
    /// Seed of the loss and jitter draws.
    pub seed: u64,
    /// How long to play, s (default: the script's duration).
    pub seconds: Option<f64>,
    /// The device goes silent from `.0` s for `.1` s (vanishes and comes back).
    pub outage: Option<(f64, f64)>,
    /// How long to wait for the welcome, s.
    pub wait_s: f64,
    /// Say goodbye at the end (the session then ends too).
    pub bye: bool,
    /// The protocol a modelled device asks for in its hello (the session may answer with 1).
    pub protocol: Protocol,
    /// A deliberate fault, to see `device-check` fail by rule (`None`: a device that follows
    /// the document).
    pub fault: Option<Fault>,
}

/// What the simulator's welcome said.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct WelcomeInfo {
    /// The session's protocol version (1; 2: the local model; 3: with its bond).
    pub version: u8,
    /// The session's tick rate, Hz: the device sends one sample per tick.
    pub rate_hz: u32,
    /// Session start, ns since the Unix epoch.
    pub start_time_ns: u64,
    /// The scene's name.
    pub scene: String,
    /// The button roles in force: the button index of grip, turn_x, turn_y, turn_z (255:
    /// none); `None` from a simulator that does not send them.
    pub roles: Option<[u8; 4]>,
}

/// What the fake device measured.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FakeReport {
    /// The simulator's welcome (the rate the device played at).
    pub welcome: WelcomeInfo,
    /// Servo periods played.
    pub ticks: u64,
    /// Samples sent.
    pub sent: u64,
    /// Samples dropped on purpose (`loss`).
    pub dropped: u64,
    /// Samples not sent during the outage.
    pub silent: u64,
    /// Periods that sent no sample because the device backed off (the fault
    /// `backs-off-in-silence`).
    pub held_back: u64,
    /// Force packets received.
    pub replies: u64,
    /// Round trip from sending a sample to receiving its answer, ns.
    pub round_trip: Percentiles,
    /// Largest force received, N.
    pub max_force_n: f64,
    /// Largest force a modelled device's motors rendered on the hand, N (0 otherwise).
    pub max_felt_n: f64,
    /// The protocol the session speaks (from the welcome).
    pub protocol: u8,
    /// Periods whose force changed by more than 1 N from the period before (a buzz shows
    /// here): the force received, or for a modelled device the force its motors rendered.
    pub jumps_over_1n: u64,
    /// Largest change of force between two periods, N.
    pub max_jump_n: f64,
    /// When the first 100 of those jumps happened, s after the first period.
    pub jump_times_s: Vec<f64>,
    /// Work the device's motors did on the hand, J (modelled device only; 0 otherwise).
    pub energy_to_hand_j: f64,
    /// Servo periods on which the device side's two-port passivity layer held the force back
    /// (modelled device, protocol 2).
    pub two_port_interventions: u64,
    /// Force received after the outage began, as (ms after the last sample sent, N), one entry
    /// per reply until it reached zero.
    pub outage_force: Vec<(f64, f64)>,
    /// Whether every force received was finite and within the device's maximum.
    pub forces_within_limits: bool,
}

struct Reply {
    at: Instant,
    force: ForceReply,
}

/// Runs the fake device to the end; `stop` ends it early.
pub fn run_fake(cfg: &FakeConfig, stop: Option<&AtomicBool>) -> Result<FakeReport, DeviceError> {
    run_fake_as(cfg, None, stop)
}

/// The fake device's specifications: the model's (a modelled preset's own buttons), with
/// `buttons` announced instead of the model's when given.
pub fn fake_specs(cfg: &FakeConfig, buttons: Option<&[String]>) -> DeviceSpecs {
    let specs = match &cfg.physical {
        Some((mech, _)) => crate::modelled::preset_specs(mech),
        None => cfg.model.specs().clone(),
    };
    match buttons {
        Some(names) => with_button_names(specs, names),
        None => specs,
    }
}

/// `specs` announcing the buttons `names` instead of its own (`--button-names`).
pub fn with_button_names(specs: DeviceSpecs, names: &[String]) -> DeviceSpecs {
    DeviceSpecs {
        button_names: names
            .iter()
            .cloned()
            .map(std::borrow::Cow::Owned)
            .collect::<Vec<_>>()
            .into(),
        ..specs
    }
}

/// As [`run_fake`], the hello announcing `buttons` instead of the model's (`None`: the
/// model's own); the script must have been read for a device with those buttons.
pub fn run_fake_as(
    cfg: &FakeConfig,
    buttons: Option<&[String]>,
    stop: Option<&AtomicBool>,
) -> Result<FakeReport, DeviceError> {
    let specs = fake_specs(cfg, buttons);
    super::fault::applies(cfg.fault, cfg.physical.is_some(), cfg.protocol)
        .map_err(DeviceError::Link)?;
    let socket = open_socket(cfg.target)?;
    // 1. Hello until welcome.
    let welcome = handshake(&socket, cfg, &specs, stop)?;
    let rate_hz = super::fault::servo_rate_hz(cfg.fault, welcome.rate_hz);
    // 2. A receiver thread timestamps each reply.
    let receiver = Receiver::spawn(&socket, cfg.target)?;
    // 3. The servo loop.
    let protocol = Protocol::of_version(welcome.version).unwrap_or(Protocol::V1);
    let mut modelled = cfg.physical.map(|(mech, grip)| Modelled {
        plant: Plant::new(mech, grip, cfg.script.position(0.0)),
        side: DeviceSide::new(protocol, mech.limits.max_force_n, 1.0 / f64::from(rate_hz)),
    });
    let mut other: Box<dyn HapticDevice> = match cfg.hand {
        Some(p) => Box::new(SimulatedOperator::new(cfg.script.clone(), specs.clone(), p)),
        None => Box::new(ScriptedDevice::new(cfg.script.clone(), specs.clone())),
    };
    let seconds = cfg.seconds.unwrap_or(cfg.script.duration_s);
    let ticks = (seconds * f64::from(rate_hz)).round().max(0.0) as u64;
    let mut pacer = Pacer::new(1_000_000_000 / u64::from(rate_hz));
    let mut servo = Servo::new(
        cfg,
        &socket,
        specs.limits.max_force_n,
        welcome,
        ticks,
        pacer.start(),
    );
    let dt = 1.0 / f64::from(rate_hz);
    let mut next_seq = u64::from(cfg.fault == Some(Fault::NumbersFrom1));
    for k in 0..ticks {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) || receiver.done.load(Ordering::Relaxed)
        {
            break;
        }
        // Delayed samples leave at their due time, between the servo periods too.
        while let Some(due) = servo.next_due().filter(|&d| d < pacer.scheduled(k)) {
            pacer.wait_until(due);
            servo.send_due();
        }
        pacer.wait_for(k);
        servo.rep.ticks += 1;
        let t = TickTime::new(k, rate_hz);
        // The period's sample number (`None`: a device that backs off sends none this period).
        let seq = servo.sends(k).then(|| {
            next_seq += 1;
            next_seq - 1
        });
        let (position_m, buttons, two_port) = match modelled.as_mut() {
            Some(m) => m.read(k, seq, t.time_s, dt, protocol, &cfg.script, &mut servo),
            None => read_rigid(other.as_mut(), &servo, t)?,
        };
        if let Some(seq) = seq {
            servo.queue(seq, t.time_s, position_m, buttons, two_port);
        }
        servo.send_due();
        // A modelled device renders an answer when it arrives, as a driver's servo thread
        // does: wait for the answer to this period's sample for up to half a period, so the
        // force of sample k is held over [k, k + 1] (plus the round trip), not a period late.
        if let Some(seq) = seq.filter(|s| modelled.is_some() && servo.sent_at.contains_key(s)) {
            receiver.await_answer(seq, Duration::from_nanos(500_000_000 / u64::from(rate_hz)));
        }
        // Replies that arrived since the last period.
        for r in receiver.take() {
            servo.reply(&r, modelled.is_none());
            if let Some(m) = modelled.as_mut() {
                m.receive(&r.force, cfg.fault);
            }
        }
        servo.forget_unanswered(k, rate_hz);
    }
    if cfg.bye {
        let _ = socket.send_to(&Packet::Bye { reason: 0 }.encode(), cfg.target);
    }
    receiver.finish();
    let mut rep = servo.rep;
    rep.round_trip = Percentiles::of(&servo.rtt);
    if let Some(m) = &modelled {
        rep.energy_to_hand_j = m.plant.energy_to_hand_j();
        rep.two_port_interventions = m.side.interventions();
    }
    Ok(rep)
}

/// A rigid stylus or a simulated hand: it renders the force received last, then is read at
/// tick time `t`; its position (m), its buttons and no two-port count.
fn read_rigid(
    other: &mut dyn HapticDevice,
    servo: &Servo,
    t: TickTime,
) -> Result<([f64; 3], u32, Option<u32>), DeviceError> {
    other.set_force(&ForceCommand {
        force_n: servo.force,
        ..Default::default()
    })?;
    let s = other.sample(t)?;
    Ok((s.position_m, s.buttons.0, None))
}

/// A modelled device: the device and hand, and what its servo thread renders.
struct Modelled {
    plant: Plant,
    side: DeviceSide,
}

impl Modelled {
    /// Period `k` at `time_s` (s; periods of `dt` s): the device and hand over the last period,
    /// rendered by the device side (the force its motors rendered goes to `servo`), then its
    /// encoder reading (m, kept as sample `seq`'s when one is sent), the script's buttons and,
    /// in protocol 2, the two-port layer's count.
    #[allow(clippy::too_many_arguments)]
    fn read(
        &mut self,
        k: u64,
        seq: Option<u64>,
        time_s: f64,
        dt: f64,
        protocol: Protocol,
        script: &Script,
        servo: &mut Servo,
    ) -> ([f64; 3], u32, Option<u32>) {
        // The device and hand over the last period, rendered by the device side.
        if k > 0 {
            let t0 = time_s - dt;
            let side = &mut self.side;
            self.plant.advance_with(
                dt,
                |s| (script.position(t0 + s), script.velocity(t0 + s)),
                &mut |p, servo_s| side.render(p, servo_s),
            );
            servo.felt(self.plant.last_force_n());
        }
        let reading = self.plant.reading_m();
        if let Some(seq) = seq {
            self.side.record_reading(seq, reading);
        }
        let count = protocol
            .has_local_model()
            .then(|| u32::try_from(self.side.interventions()).unwrap_or(u32::MAX));
        (reading, script.buttons(time_s).0, count)
    }

    /// An answer, handed to the device side as it arrives (with the fault `ignores-planes`,
    /// its contact planes dropped).
    fn receive(&mut self, f: &ForceReply, fault: Option<Fault>) {
        let mut local = f.local.as_deref().cloned();
        if let (Some(m), Some(Fault::IgnoresPlanes)) = (local.as_mut(), fault) {
            m.planes.clear();
        }
        self.side.receive(&f.command(), local);
    }
}

fn link(what: &str, e: std::io::Error) -> DeviceError {
    DeviceError::Link(format!("{what}: {e}"))
}

/// A socket on any local port of `target`'s family, reading with a 50 ms timeout.
fn open_socket(target: SocketAddr) -> Result<UdpSocket, DeviceError> {
    let bind: SocketAddr = if target.is_ipv4() {
        "0.0.0.0:0"
    } else {
        "[::]:0"
    }
    .parse()
    .map_err(|_| DeviceError::Link("bad local address".into()))?;
    let socket = UdpSocket::bind(bind).map_err(|e| link("cannot bind", e))?;
    socket
        .set_read_timeout(Some(Duration::from_millis(50)))
        .map_err(|e| link("cannot configure the socket", e))?;
    Ok(socket)
}

/// Says hello with `specs` until the simulator's welcome (within `cfg.wait_s`), and returns
/// the welcome (its tick rate checked: 100–10000 Hz).
fn handshake(
    socket: &UdpSocket,
    cfg: &FakeConfig,
    specs: &DeviceSpecs,
    stop: Option<&AtomicBool>,
) -> Result<WelcomeInfo, DeviceError> {
    let version = if cfg.physical.is_some() {
        cfg.protocol.version()
    } else {
        super::protocol::VERSION
    };
    let hello = Packet::Hello {
        version,
        rate_hz: 1000,
        specs: specs.clone(),
    }
    .encode();
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.wait_s.max(0.0));
    let mut buf = [0u8; 2048];
    let welcome = loop {
        if Instant::now() > deadline || stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            return Err(DeviceError::Link(format!(
                "no welcome from {} within {} s",
                cfg.target, cfg.wait_s
            )));
        }
        // ICMP "unreachable" before the simulator binds: retry.
        let _ = socket.send_to(&hello, cfg.target);
        if let Ok((n, from)) = socket.recv_from(&mut buf) {
            if from == cfg.target {
                match Packet::decode(&buf[..n]) {
                    Ok(Packet::Welcome {
                        version,
                        rate_hz,
                        start_time_ns,
                        scene,
                        roles,
                    }) => {
                        break WelcomeInfo {
                            version,
                            rate_hz,
                            start_time_ns,
                            scene,
                            roles,
                        };
                    }
                    // The same hello would be refused again: say why and stop.
                    Ok(Packet::Refusal(r)) => {
                        return Err(DeviceError::Link(format!(
                            "the simulator at {} refused the hello: {}",
                            cfg.target, r.message
                        )));
                    }
                    _ => {}
                }
            }
        }
    };
    let rate_hz = welcome.rate_hz;
    if !(100..=10_000).contains(&rate_hz) {
        return Err(DeviceError::Link(format!(
            "the simulator asked for {rate_hz} Hz (this fake device plays 100–10000 Hz)"
        )));
    }
    Ok(welcome)
}

/// The receiver thread: every force packet from the simulator, timestamped on arrival; a
/// goodbye raises `done`.
struct Receiver {
    replies: Arc<Mutex<Vec<Reply>>>,
    done: Arc<AtomicBool>,
    thread: std::thread::JoinHandle<()>,
}

impl Receiver {
    fn spawn(socket: &UdpSocket, target: SocketAddr) -> Result<Receiver, DeviceError> {
        let replies: Arc<Mutex<Vec<Reply>>> = Arc::new(Mutex::new(Vec::with_capacity(1024)));
        let done = Arc::new(AtomicBool::new(false));
        let rx = socket
            .try_clone()
            .map_err(|e| link("cannot clone the socket", e))?;
        let (r2, d2) = (replies.clone(), done.clone());
        let thread = std::thread::Builder::new()
            .name("fake-rx".into())
            .spawn(move || {
                let mut buf = [0u8; 2048];
                while !d2.load(Ordering::Relaxed) {
                    if let Ok((n, from)) = rx.recv_from(&mut buf) {
                        let at = Instant::now();
                        if from != target {
                            continue;
                        }
                        match Packet::decode(&buf[..n]) {
                            Ok(Packet::Force(f)) => {
                                if let Ok(mut v) = r2.lock() {
                                    v.push(Reply { at, force: f });
                                }
                            }
                            Ok(Packet::Bye { .. }) => {
                                d2.store(true, Ordering::Relaxed);
                            }
                            _ => {}
                        }
                    }
                }
            })
            .map_err(|e| link("cannot start the receiver", e))?;
        Ok(Receiver {
            replies,
            done,
            thread,
        })
    }

    /// Spins until the answer to sample `seq` has arrived, at most `wait`.
    fn await_answer(&self, seq: u64, wait: Duration) {
        let until = Instant::now() + wait;
        while Instant::now() < until
            && !self
                .replies
                .lock()
                .map(|v| v.iter().any(|r| r.force.seq == seq))
                .unwrap_or(true)
        {
            std::hint::spin_loop();
        }
    }

    /// The replies that arrived since the last call.
    fn take(&self) -> Vec<Reply> {
        self.replies
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }

    /// Stops the thread.
    fn finish(self) {
        self.done.store(true, Ordering::Relaxed);
        let _ = self.thread.join();
    }
}

/// The servo loop's sending side and its measurements.
struct Servo<'a> {
    cfg: &'a FakeConfig,
    socket: &'a UdpSocket,
    max_force_n: f64,
    rng: ChaCha8Rng,
    start: Instant,
    /// Samples waiting for their due time, by (due ns, seq).
    pending: BTreeMap<(u64, u64), Vec<u8>>,
    sent_at: BTreeMap<u64, Instant>,
    rtt: Vec<u64>,
    rep: FakeReport,
    last_sent: Option<Instant>,
    /// When the last answer arrived.
    last_reply: Option<Instant>,
    outage_begun: bool,
    /// The force received last, N.
    force: [f64; 3],
    /// The force a modelled device's motors rendered last period, N.
    felt: [f64; 3],
    /// The servo period, s.
    period_s: f64,
}

impl<'a> Servo<'a> {
    /// The sending side of a session the simulator welcomed with `welcome`, for a device of
    /// largest force `max_force_n` (N) playing `ticks` periods from `start`.
    fn new(
        cfg: &'a FakeConfig,
        socket: &'a UdpSocket,
        max_force_n: f64,
        welcome: WelcomeInfo,
        ticks: u64,
        start: Instant,
    ) -> Servo<'a> {
        let rate_hz = welcome.rate_hz;
        Servo {
            cfg,
            socket,
            max_force_n,
            rng: ChaCha8Rng::seed_from_u64(cfg.seed),
            start,
            pending: BTreeMap::new(),
            sent_at: BTreeMap::new(),
            rtt: Vec::with_capacity(ticks as usize),
            rep: FakeReport {
                protocol: welcome.version,
                welcome,
                forces_within_limits: true,
                ..Default::default()
            },
            last_sent: None,
            last_reply: None,
            outage_begun: false,
            force: [0.0; 3],
            felt: [0.0; 3],
            period_s: 1.0 / f64::from(rate_hz),
        }
    }

    /// Forgets sends never answered (lost replies) after a second, at period `k` of a session
    /// at `rate_hz` (Hz).
    fn forget_unanswered(&mut self, k: u64, rate_hz: u32) {
        if self.sent_at.len() > 4 * rate_hz as usize {
            let keep = self
                .sent_at
                .split_off(&k.saturating_sub(u64::from(rate_hz)));
            self.sent_at = keep;
        }
    }

    /// Whether period `k` sends a sample: always, but for a device with the fault
    /// `backs-off-in-silence` that has had no answer for [`BACK_OFF_AFTER_S`] (every tenth
    /// period then); a sample held back is counted.
    fn sends(&mut self, k: u64) -> bool {
        let backing_off = self.cfg.fault == Some(Fault::BacksOffInSilence)
            && self
                .last_reply
                .is_some_and(|t| t.elapsed().as_secs_f64() > BACK_OFF_AFTER_S);
        let send = !backing_off || k % 10 == 0;
        self.rep.held_back += u64::from(!send);
        send
    }

    /// Sample `k`'s at `time_s`: silent in the outage, dropped with the loss's probability,
    /// or else queued after the latency and a jitter draw.
    fn queue(
        &mut self,
        k: u64,
        time_s: f64,
        position_m: [f64; 3],
        buttons: u32,
        two_port_periods: Option<u32>,
    ) {
        let cfg = self.cfg;
        let silent = cfg
            .outage
            .is_some_and(|(a, d)| time_s >= a && time_s < a + d);
        if silent {
            self.rep.silent += 1;
            self.outage_begun = true;
        } else if cfg.loss > 0.0 && self.rng.random::<f64>() < cfg.loss {
            self.rep.dropped += 1;
        } else {
            let delay = cfg.latency_s
                + if cfg.jitter_s > 0.0 {
                    self.rng.random::<f64>() * cfg.jitter_s
                } else {
                    0.0
                };
            let pkt = Packet::Sample(Sample {
                seq: k,
                device_time_ns: self.start.elapsed().as_nanos() as u64,
                position_m,
                buttons,
                two_port_periods,
            })
            .encode();
            // Due the delay after the period's start (when the sample was read).
            let read_ns = (time_s * 1e9).round() as u64;
            let due = read_ns + (delay * 1e9).round() as u64;
            self.pending.insert((due, k), pkt);
        }
    }

    /// When the next delayed sample is due.
    fn next_due(&self) -> Option<Instant> {
        self.pending
            .first_key_value()
            .map(|((due, _), _)| self.start + Duration::from_nanos(*due))
    }

    /// Sends what is due (in due order: jitter may reorder samples).
    fn send_due(&mut self) {
        let now_ns = self.start.elapsed().as_nanos() as u64;
        while let Some(entry) = self.pending.first_entry() {
            if entry.key().0 > now_ns {
                break;
            }
            let ((_, seq), pkt) = entry.remove_entry();
            let at = Instant::now();
            if self.socket.send_to(&pkt, self.cfg.target).is_ok() {
                self.rep.sent += 1;
                self.sent_at.insert(seq, at);
                self.last_sent = Some(at);
            }
        }
    }

    /// A reply: its round trip, its force checked against the device's limit, the force after
    /// an outage began; the force received from now on, and (`count_jumps`: a device that
    /// renders what it receives) its jump.
    fn reply(&mut self, r: &Reply, count_jumps: bool) {
        let rep = &mut self.rep;
        let f = r.force.force_n;
        rep.replies += 1;
        self.last_reply = Some(r.at);
        let mag = vec3::norm(f);
        if !vec3::is_finite(f) || mag > self.max_force_n {
            rep.forces_within_limits = false;
        }
        rep.max_force_n = rep.max_force_n.max(mag);
        if let Some(t0) = self.sent_at.remove(&r.force.seq) {
            self.rtt.push(r.at.duration_since(t0).as_nanos() as u64);
        }
        if self.outage_begun && rep.outage_force.last().is_none_or(|l| l.1 > 0.0) {
            if let Some(ls) = self.last_sent {
                let ms = r.at.saturating_duration_since(ls).as_secs_f64() * 1e3;
                rep.outage_force.push((ms, mag));
            }
        }
        if count_jumps {
            self.jump(f);
        }
        self.force = f;
    }

    /// The force a modelled device's motors rendered over the last period, N.
    fn felt(&mut self, f: [f64; 3]) {
        self.jump(f);
        self.rep.max_felt_n = self.rep.max_felt_n.max(vec3::norm(f));
        self.felt = f;
    }

    fn jump(&mut self, f: [f64; 3]) {
        let before = if self.cfg.physical.is_some() {
            self.felt
        } else {
            self.force
        };
        let jump = vec3::norm(vec3::sub(f, before));
        self.rep.max_jump_n = self.rep.max_jump_n.max(jump);
        if jump > 1.0 {
            self.rep.jumps_over_1n += 1;
            if self.rep.jump_times_s.len() < 100 {
                self.rep
                    .jump_times_s
                    .push(self.period_s * self.rep.ticks as f64);
            }
        }
    }
}
