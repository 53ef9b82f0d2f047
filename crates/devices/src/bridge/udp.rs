//! The simulator's side of the bridge: a [`HapticDevice`] whose readings arrive over UDP.
//!
//! A receiver thread blocks on the socket, checks every datagram (magic, version, type, length,
//! sender, sequence number) and queues fresh samples; the tick waits on a condition variable
//! for its sample, so a tick starts as soon as its sample arrives. The device's sequence
//! numbers are the clock: tick n stands for the device's sample `first + n`. When that sample
//! has not come 0.5 period after its due time, the tick runs on the newest sample it has, with
//! its age (how many device periods old it is), and the loop's watchdog ramps the force down
//! from that age; a late sample is still used by the next tick. So the world advances exactly
//! one tick per device period, whatever the network does. Every fault is counted, never fatal: duplicates, reordered and malformed packets,
//! oversized datagrams, packets from a stranger, gaps in the sequence.

use super::protocol::{ForceReply, Packet, ProtocolError, Refusal, Sample};
use super::rule::{Numbered, SampleRule};
use haptic_types::device::{
    Buttons, DeviceError, DeviceSample, DeviceSpecs, FALCON, ForceCommand, HapticDevice, TickTime,
};
use haptic_types::{ButtonRoles, Role};
use std::collections::VecDeque;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Where and how the simulator listens for a device.
#[derive(Clone, Debug, PartialEq)]
pub struct BridgeConfig {
    /// Address to bind (default loopback: `127.0.0.1:PORT`).
    pub bind: SocketAddr,
    /// How long to wait for the device's hello (and its first sample), s.
    pub wait_s: f64,
    /// The session's tick rate, Hz (sent in the welcome).
    pub rate_hz: u32,
    /// Scene name (sent in the welcome).
    pub scene: String,
    /// Session start, ns since the Unix epoch (sent in the welcome).
    pub start_time_ns: u64,
    /// The scene's overrides of the button roles (role, button name): a device lacking a
    /// named button is refused; the welcome states the roles in force.
    pub buttons: Vec<(Role, String)>,
}

impl BridgeConfig {
    /// Parses `udp:HOST:PORT`, or `udp:PORT` for loopback (the `--device` option).
    pub fn parse(spec: &str) -> Result<Self, DeviceError> {
        let bind = super::parse_endpoint(spec, "udp", "device", "udp:127.0.0.1:9870")
            .map_err(DeviceError::Link)?;
        Ok(BridgeConfig {
            bind,
            wait_s: 120.0,
            rate_hz: 1000,
            scene: String::new(),
            start_time_ns: 0,
            buttons: Vec::new(),
        })
    }

    /// This configuration with the scene's overrides of the button roles.
    pub fn with_buttons(mut self, buttons: Vec<(Role, String)>) -> Self {
        self.buttons = buttons;
        self
    }

    /// This configuration for a session of `scene` at `rate_hz` that starts at
    /// `start_time_ns` (ns since the Unix epoch): what the welcome tells the device. Every
    /// way of running a bridged session (`run`, `play`, the wheel) fills it from the scene.
    pub fn for_session(mut self, rate_hz: u32, scene: &str, start_time_ns: u64) -> Self {
        self.rate_hz = rate_hz;
        self.scene = scene.to_string();
        self.start_time_ns = start_time_ns;
        self
    }
}

/// Counters of the link, in the order they are reported.
#[derive(Clone, Copy, Debug, Default)]
struct Counters {
    received: u64,
    duplicate: u64,
    reordered: u64,
    gap_lost: u64,
    malformed: u64,
    oversized: u64,
    stranger: u64,
    superseded: u64,
    hellos: u64,
    send_errors: u64,
    stale_ticks: u64,
    resync: u64,
    /// Hellos refused (each answered with a refusal, at most one per
    /// [`REFUSAL_INTERVAL_S`](super::protocol::REFUSAL_INTERVAL_S)).
    refused: u64,
    /// The largest count of two-port servo periods a version-2 device reported.
    device_two_port: u64,
}

#[derive(Default)]
struct State {
    peer: Option<SocketAddr>,
    specs: Option<DeviceSpecs>,
    last_seq: Option<u64>,
    generation: u64,
    queue: VecDeque<Sample>,
    ended: bool,
    error: Option<String>,
    c: Counters,
    /// The protocol version of the session: the device's hello's, at most version 3.
    version: u8,
    /// The last refusal, for the simulator's own message when no device is welcomed.
    last_refusal: Option<String>,
    /// When the last refusal was sent.
    refusal_sent: Option<Instant>,
}

struct Shared {
    state: Mutex<State>,
    arrived: Condvar,
    stop: AtomicBool,
}

/// A device in another process, over UDP.
pub struct UdpDevice {
    config: BridgeConfig,
    specs: DeviceSpecs,
    socket: Option<UdpSocket>,
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    /// The device sequence number the next tick stands for.
    slot: Option<u64>,
    /// Which sample a tick reads (the anchor's time is ns since `epoch`).
    rule: SampleRule<Sample>,
    epoch: Instant,
    generation: u64,
    peer: Option<SocketAddr>,
    tx: Vec<u8>,
    /// The session's protocol version as of the last sample.
    version: u8,
    /// The local model for the next force packet (protocol 2).
    local: Option<haptic_types::local::LocalModel>,
    /// The socket's kernel receive buffer as granted, bytes (0 before `open` or where the
    /// system cannot say).
    receive_buffer_bytes: usize,
}

/// Most samples waiting for a tick; older ones are dropped (counted as superseded) so latency
/// cannot build up.
const QUEUE: usize = 4;

/// A device sequence number this many samples ahead of the tick's slot resynchronises the
/// slot instead of running that many stale ticks.
const RESYNC: u64 = 1000;

impl UdpDevice {
    /// A bridged device; nothing is bound before [`HapticDevice::open`].
    pub fn new(config: BridgeConfig) -> Self {
        UdpDevice {
            config,
            specs: FALCON,
            socket: None,
            shared: Arc::new(Shared {
                state: Mutex::new(State::default()),
                arrived: Condvar::new(),
                stop: AtomicBool::new(false),
            }),
            thread: None,
            slot: None,
            rule: SampleRule::new(),
            epoch: Instant::now(),
            generation: 0,
            peer: None,
            tx: Vec::with_capacity(super::protocol::MAX_PACKET),
            version: super::protocol::VERSION,
            local: None,
            receive_buffer_bytes: 0,
        }
    }

    /// The address the socket is bound to (after `open`).
    pub fn local_addr(&self) -> Option<SocketAddr> {
        self.socket.as_ref().and_then(|s| s.local_addr().ok())
    }

    fn lock(&self) -> Result<std::sync::MutexGuard<'_, State>, DeviceError> {
        self.shared
            .state
            .lock()
            .map_err(|_| DeviceError::Link("bridge state lock poisoned".into()))
    }
}

/// Answers a hello: the welcome with the session's version and the device's button roles, or
/// a refusal (rate-limited) when the device lacks a button the scene maps.
fn answer_hello(
    socket: &UdpSocket,
    from: SocketAddr,
    st: &mut State,
    config: &BridgeConfig,
    specs: DeviceSpecs,
    version: u8,
) {
    let roles = match ButtonRoles::resolve(&specs, &config.buttons) {
        Ok(r) => r,
        Err(e) => {
            refuse(socket, from, st, Refusal::of_spec(&e));
            return;
        }
    };
    st.c.hellos += 1;
    st.specs = Some(specs);
    if st.peer != Some(from) || st.last_seq.is_some() {
        // A device that restarted: its old samples and numbering are gone.
        st.generation += 1;
        st.queue.clear();
    }
    st.peer = Some(from);
    st.last_seq = None;
    // Negotiate down: a hello above version 4 is welcomed with 4.
    st.version = version.min(super::protocol::VERSION_4);
    let welcome = Packet::Welcome {
        version: st.version,
        rate_hz: config.rate_hz,
        start_time_ns: config.start_time_ns,
        scene: config.scene.clone(),
        roles: Some(roles.wire()),
    };
    if socket.send_to(&welcome.encode(), from).is_err() {
        st.c.send_errors += 1;
    }
}

/// Counts a refused hello, keeps its message, and answers it unless a refusal went out less
/// than [`REFUSAL_INTERVAL_S`](super::protocol::REFUSAL_INTERVAL_S) ago.
fn refuse(socket: &UdpSocket, from: SocketAddr, st: &mut State, r: Refusal) {
    st.c.refused += 1;
    let now = Instant::now();
    let due = st.refusal_sent.is_none_or(|t| {
        now.duration_since(t) >= Duration::from_secs_f64(super::protocol::REFUSAL_INTERVAL_S)
    });
    st.last_refusal = Some(r.message.clone());
    if due {
        st.refusal_sent = Some(now);
        if socket.send_to(&Packet::Refusal(r).encode(), from).is_err() {
            st.c.send_errors += 1;
        }
    }
}

fn receive(socket: UdpSocket, shared: Arc<Shared>, config: BridgeConfig) {
    let mut buf = vec![0u8; 2048];
    while !shared.stop.load(Ordering::Relaxed) {
        let (n, from) = match socket.recv_from(&mut buf) {
            Ok(x) => x,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue;
            }
            Err(e) => {
                // ICMP "port unreachable" from a vanished device surfaces here on some systems.
                if e.kind() == std::io::ErrorKind::ConnectionRefused {
                    continue;
                }
                if let Ok(mut st) = shared.state.lock() {
                    st.error = Some(e.to_string());
                }
                shared.arrived.notify_all();
                return;
            }
        };
        let packet = Packet::decode(&buf[..n]);
        let Ok(mut st) = shared.state.lock() else {
            return;
        };
        match packet {
            Err(ProtocolError::Oversized(_)) => st.c.oversized += 1,
            Err(ProtocolError::Hello(r)) => refuse(&socket, from, &mut st, r),
            Err(_) => st.c.malformed += 1,
            Ok(Packet::Hello { specs, version, .. }) => {
                // A first hello, a repeated one, or a device that restarted: welcome it and
                // accept its new numbering. Its limits cannot change during a session.
                if st.specs.as_ref().is_some_and(|s| *s != specs) {
                    st.c.stranger += 1;
                    refuse(
                        &socket,
                        from,
                        &mut st,
                        Refusal::new(
                            "specs",
                            "the specifications of the session's first hello",
                            "hello refused: `specs` differ from the session's first hello \
                             (name, limits and buttons cannot change during a session)"
                                .into(),
                        ),
                    );
                } else {
                    answer_hello(&socket, from, &mut st, &config, specs, version);
                    drop(st);
                    shared.arrived.notify_all();
                    continue;
                }
            }
            Ok(Packet::Sample(s)) if st.peer == Some(from) => {
                if let Some(n) = s.two_port_periods {
                    st.c.device_two_port = st.c.device_two_port.max(u64::from(n));
                }
                match st.last_seq {
                    Some(l) if s.seq == l => st.c.duplicate += 1,
                    Some(l) if s.seq < l => st.c.reordered += 1,
                    last => {
                        if let Some(l) = last {
                            st.c.gap_lost += s.seq - l - 1;
                        }
                        st.last_seq = Some(s.seq);
                        st.c.received += 1;
                        if st.queue.len() >= QUEUE {
                            st.queue.pop_front();
                            st.c.superseded += 1;
                        }
                        st.queue.push_back(s);
                        drop(st);
                        shared.arrived.notify_all();
                        continue;
                    }
                }
            }
            Ok(Packet::Bye { .. }) if st.peer == Some(from) => {
                st.ended = true;
                drop(st);
                shared.arrived.notify_all();
                continue;
            }
            Ok(Packet::Sample(_) | Packet::Bye { .. }) => st.c.stranger += 1,
            // Packets only the simulator sends.
            Ok(Packet::Welcome { .. } | Packet::Force(_) | Packet::Refusal(_)) => {
                st.c.malformed += 1
            }
        }
    }
}

/// The simulator's message when no device was welcomed: what it received instead.
fn no_hello(config: &BridgeConfig, st: &State) -> String {
    let mut m = format!(
        "no device said hello on udp:{} within {} s",
        config.bind, config.wait_s
    );
    let c = &st.c;
    if c.refused > 0 {
        m.push_str(&format!(
            "; {} hello{} refused, the last: {}",
            c.refused,
            if c.refused == 1 { "" } else { "s" },
            st.last_refusal.as_deref().unwrap_or("")
        ));
    }
    let other = [
        ("malformed", c.malformed),
        ("oversized", c.oversized),
        ("from a stranger", c.stranger),
    ];
    for (what, n) in other {
        if n > 0 {
            m.push_str(&format!(
                "; {n} datagram{} {what}",
                if n == 1 { "" } else { "s" }
            ));
        }
    }
    m
}

impl HapticDevice for UdpDevice {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn open(&mut self) -> Result<(), DeviceError> {
        let link = |what: &str, e: std::io::Error| {
            DeviceError::Link(format!("{what} {}: {e}", self.config.bind))
        };
        let socket = UdpSocket::bind(self.config.bind).map_err(|e| link("cannot bind", e))?;
        // The receiver wakes at least every 100 ms to notice the end of the session.
        socket
            .set_read_timeout(Some(Duration::from_millis(100)))
            .map_err(|e| link("cannot configure", e))?;
        // Room for ~200 ms of a 10 kHz device while the receiver is off the CPU (the default
        // held ~20 ms: a loaded machine lost 70 of 5000 samples on loopback).
        self.receive_buffer_bytes =
            super::rxbuf::enlarge(&socket, super::rxbuf::RECEIVE_BUFFER_BYTES).unwrap_or(0);
        let rx = socket.try_clone().map_err(|e| link("cannot clone", e))?;
        let shared = self.shared.clone();
        let config = self.config.clone();
        self.thread = Some(
            std::thread::Builder::new()
                .name("bridge-rx".into())
                .spawn(move || receive(rx, shared, config))
                .map_err(|e| link("cannot start the receiver for", e))?,
        );
        self.socket = Some(socket);
        let deadline = Instant::now() + Duration::from_secs_f64(self.config.wait_s.max(0.0));
        let mut st = self.lock()?;
        while st.specs.is_none() {
            let now = Instant::now();
            if now >= deadline {
                return Err(DeviceError::Link(no_hello(&self.config, &st)));
            }
            st = self
                .shared
                .arrived
                .wait_timeout(st, deadline - now)
                .map_err(|_| DeviceError::Link("bridge state lock poisoned".into()))?
                .0;
        }
        let specs = st.specs.clone();
        drop(st);
        if let Some(s) = specs {
            self.specs = s;
        }
        Ok(())
    }

    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError> {
        let period = Duration::from_secs_f64(time.dt_s);
        let shared = self.shared.clone();
        let mut st = shared
            .state
            .lock()
            .map_err(|_| DeviceError::Link("bridge state lock poisoned".into()))?;
        if st.generation != self.generation {
            // A (re)started device numbers its samples afresh.
            self.generation = st.generation;
            self.slot = None;
            self.rule.reset();
        }
        // The tick of slot k waits for the device's sample k until the rule's deadline (the
        // bridge's one rule, `rule`); before an on-time sample, as long as the link allows.
        let deadline = match self
            .slot
            .and_then(|k| self.rule.deadline_ns(k, period.as_nanos() as u64))
        {
            Some(ns) => self.epoch + Duration::from_nanos(ns),
            None => Instant::now() + Duration::from_secs_f64(self.config.wait_s.max(0.0)),
        };
        loop {
            if let Some(e) = st.error.take() {
                return Err(DeviceError::Link(format!("receiving: {e}")));
            }
            let ready = match self.slot {
                None => !st.queue.is_empty(),
                Some(k) => SampleRule::<Sample>::ready(k, st.queue.back().map(|s| s.seq)),
            };
            if ready {
                break;
            }
            if st.ended {
                return Err(DeviceError::Ended);
            }
            let now = Instant::now();
            if now >= deadline {
                break;
            }
            st = shared
                .arrived
                .wait_timeout(st, deadline - now)
                .map_err(|_| DeviceError::Link("bridge state lock poisoned".into()))?
                .0;
        }
        self.peer = st.peer;
        self.version = st.version.max(super::protocol::VERSION);
        let Some(k) = self.slot.or_else(|| st.queue.front().map(|s| s.seq)) else {
            return Err(DeviceError::Link(format!(
                "no sample from the device within {} s of its hello",
                self.config.wait_s
            )));
        };
        // A device clock far ahead of ours (a jump in its numbering): follow it.
        let k = match st.queue.front().map(|f| f.seq) {
            Some(f) if f > k.saturating_add(RESYNC) => {
                st.c.resync += 1;
                f
            }
            _ => k,
        };
        // The newest sample for this slot or an earlier one (late samples are superseded by
        // newer ones; samples for later slots wait for their tick).
        let mut used = None;
        while st.queue.front().is_some_and(|s| s.seq <= k) {
            if used.is_some() {
                st.c.superseded += 1;
            }
            used = st.queue.pop_front();
        }
        let now_ns = self.epoch.elapsed().as_nanos() as u64;
        let (s, age) = self.rule.read(k, used, now_ns, |k| Sample {
            seq: k,
            device_time_ns: 0,
            position_m: [0.0; 3],
            buttons: 0,
            two_port_periods: None,
        });
        if age > 0 {
            st.c.stale_ticks += 1;
        }
        drop(st);
        self.slot = Some(k + 1);
        Ok(DeviceSample {
            position_m: s.position_m,
            buttons: Buttons(s.buttons),
            seq: s.seq,
            age_ticks: age,
        })
    }

    fn wants_local_model(&self) -> bool {
        self.version >= super::protocol::VERSION_2
    }

    fn local_model_version(&self) -> u8 {
        self.version
    }

    fn set_local_model(&mut self, model: haptic_types::local::LocalModel) {
        self.local = Some(model);
    }

    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError> {
        if let (Some(sock), Some(peer)) = (&self.socket, self.peer) {
            let local = self
                .local
                .take()
                .filter(|_| self.version >= super::protocol::VERSION_2)
                .map(Box::new);
            let p = Packet::Force(ForceReply {
                seq: cmd.seq,
                tick: cmd.tick,
                force_n: cmd.force_n,
                stiffness_n_per_m: cmd.stiffness_n_per_m,
                status: cmd.status,
                local,
            });
            p.encode_into(&mut self.tx);
            if sock.send_to(&self.tx, peer).is_err() {
                if let Ok(mut st) = self.shared.state.lock() {
                    st.c.send_errors += 1;
                }
            }
        }
        Ok(())
    }

    fn close(&mut self) -> Result<(), DeviceError> {
        if let (Some(sock), Some(peer)) = (&self.socket, self.peer) {
            let zero = Packet::Force(ForceReply {
                seq: self.rule.last().map_or(0, |s| s.seq),
                tick: u64::MAX,
                force_n: [0.0; 3],
                stiffness_n_per_m: [0.0; 9],
                status: 0,
                // A version-1 packet in either session: a device's two-port budget stays.
                local: None,
            });
            let _ = sock.send_to(&zero.encode(), peer);
            let _ = sock.send_to(&Packet::Bye { reason: 0 }.encode(), peer);
        }
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        Ok(())
    }

    fn link_counters(&self) -> Vec<(&'static str, u64)> {
        let c = self.shared.state.lock().map(|s| s.c).unwrap_or_default();
        vec![
            ("received", c.received),
            ("duplicate", c.duplicate),
            ("reordered", c.reordered),
            ("lost_in_transit", c.gap_lost),
            ("malformed", c.malformed),
            ("oversized", c.oversized),
            ("stranger", c.stranger),
            ("superseded", c.superseded),
            ("hellos", c.hellos),
            ("send_errors", c.send_errors),
            ("stale_ticks", c.stale_ticks),
            ("resync", c.resync),
            ("refused", c.refused),
            ("device_two_port_periods", c.device_two_port),
            ("receive_buffer_bytes", self.receive_buffer_bytes as u64),
        ]
    }
}

impl Drop for UdpDevice {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Numbered for Sample {
    fn seq(&self) -> u64 {
        self.seq
    }
}
