//! The check's socket: it binds the address as the simulator does, waits for the hello (the
//! first one unanswered, to time the device's repeat), welcomes, answers every fresh sample
//! from its [`CheckWorld`] as the stages say (delayed, dropped, withheld), says bye, and
//! keeps everything it observed for the rules.

use super::super::protocol::{ForceReply, Packet, ProtocolError, Refusal, Sample};
use super::error::CheckError;
use super::observed::{HelloSeen, Observed, Received};
use super::report::Report;
use super::stages::{self, AFTER_BYE_S, HELLO_REPEAT_WAIT_S, LATENCY_S, LOSS, Stage};
use super::world::CheckWorld;
use haptic_types::ButtonRoles;
use haptic_types::device::DeviceSpecs;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;
use std::net::{SocketAddr, UdpSocket};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Where the check listens and how it welcomes.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckConfig {
    /// The address to bind, as the simulator's `--device udp:HOST:PORT`.
    pub bind: SocketAddr,
    /// The tick rate the welcome asks for, Hz (100–10000).
    pub rate_hz: u32,
    /// How long to wait for the device's hello, s.
    pub wait_s: f64,
    /// Seed of the draw of the answers dropped in the loss stage.
    pub seed: u64,
}

impl CheckConfig {
    /// Parses `udp:HOST:PORT` or `udp:PORT` (loopback), with the bridge's own messages; 1 kHz,
    /// a 60 s wait.
    pub fn parse(spec: &str) -> Result<CheckConfig, CheckError> {
        let bind = super::super::parse_endpoint(spec, "udp", "address", "udp:127.0.0.1:9870")
            .map_err(CheckError::Address)?;
        Ok(CheckConfig {
            bind,
            rate_hz: 1000,
            wait_s: 60.0,
            seed: 41,
        })
    }

    fn validate(&self) -> Result<(), CheckError> {
        if !(100..=10_000).contains(&self.rate_hz) {
            return Err(CheckError::Config(format!(
                "`rate_hz` = {} is out of range: allowed 100 ≤ rate_hz ≤ 10000",
                self.rate_hz
            )));
        }
        if !(self.wait_s.is_finite() && self.wait_s > 0.0 && self.wait_s <= 86_400.0) {
            return Err(CheckError::Config(format!(
                "`wait_s` = {} is out of range: allowed 0 < wait_s ≤ 86400 s",
                self.wait_s
            )));
        }
        Ok(())
    }
}

/// Runs the check on `cfg`'s address: waits for a device, drives it through the stages and
/// judges it; `progress` gets one line per stage (the check takes about
/// [`stages::total_s`] seconds after the hello).
pub fn run_check(cfg: &CheckConfig, progress: &mut dyn FnMut(&str)) -> Result<Report, CheckError> {
    cfg.validate()?;
    let socket = UdpSocket::bind(cfg.bind).map_err(|e| CheckError::Bind {
        addr: cfg.bind,
        reason: e.to_string(),
    })?;
    run_check_on(&socket, cfg, progress)
}

/// As [`run_check`], on a socket already bound (its address is the one reported; `cfg.bind`
/// is not used): a test binds port 0 and tells the device the port.
pub fn run_check_on(
    socket: &UdpSocket,
    cfg: &CheckConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<Report, CheckError> {
    cfg.validate()?;
    let cfg = &CheckConfig {
        bind: socket
            .local_addr()
            .map_err(|e| CheckError::Socket(e.to_string()))?,
        ..cfg.clone()
    };
    super::super::rxbuf::enlarge(socket, super::super::rxbuf::RECEIVE_BUFFER_BYTES);
    let sock_err = |e: std::io::Error| CheckError::Socket(e.to_string());
    progress(&format!(
        "waiting up to {} s for a device's hello on udp:{}",
        world_form::fmt_num(cfg.wait_s),
        cfg.bind
    ));
    let first = wait_hello(socket, cfg)?;
    let mut obs = Observed {
        bind: cfg.bind,
        hello: None,
        refused: None,
        hello_repeat_s: None,
        version: 0,
        rate_hz: cfg.rate_hz,
        samples: Vec::new(),
        datagrams: 0,
        malformed: 0,
        first_malformed: None,
        over_cap: 0,
        answers_sent: 0,
        answers_dropped: 0,
        floor_m: None,
        wall_n_per_m: 0.0,
        coupling_n_per_m: 0.0,
        bye_s: 0.0,
        device_bye_s: None,
    };
    let (peer, hello, at) = match first {
        Ok(h) => h,
        Err((from, r)) => {
            let _ = socket.send_to(&Packet::Refusal(r.clone()).encode(), from);
            obs.refused = Some(r);
            return Ok(Report::judge(&obs));
        }
    };
    obs.hello_repeat_s = wait_repeat(socket, peer, at)?;
    obs.version = hello.version.min(super::super::protocol::VERSION_2);
    let welcome = welcome_packet(&hello.specs, obs.version, cfg.rate_hz);
    socket.send_to(&welcome, peer).map_err(sock_err)?;
    let t0 = Instant::now();
    let mut world = CheckWorld::new(
        hello.specs.limits.max_force_n,
        hello.specs.limits.max_stiffness_n_per_m,
        obs.version,
        cfg.rate_hz,
    );
    obs.wall_n_per_m = world.wall_n_per_m;
    obs.coupling_n_per_m = world.coupling_n_per_m;
    progress(&format!(
        "welcomed {} (hello version {}, session version {}, {} Hz)",
        hello.specs.name, hello.version, obs.version, cfg.rate_hz
    ));
    obs.hello = Some(hello);
    let mut link = Link {
        socket,
        peer,
        t0,
        welcome,
        pending: VecDeque::new(),
        rng: ChaCha8Rng::seed_from_u64(cfg.seed),
        hellos: 1,
        first_seq: None,
        last_seq: None,
        last_answered: 0,
        stage: None,
    };
    let end = t0 + Duration::from_secs_f64(stages::total_s());
    link.run_until(end, &mut world, &mut obs, progress)?;
    link.finish(&mut world, &mut obs, progress)?;
    Ok(Report::judge(&obs))
}

impl Link<'_> {
    /// The last packet, then the bye; then listens [`AFTER_BYE_S`] for what the device still
    /// sends.
    fn finish(
        &mut self,
        world: &mut CheckWorld,
        obs: &mut Observed,
        progress: &mut dyn FnMut(&str),
    ) -> Result<(), CheckError> {
        let (socket, peer) = (self.socket, self.peer);
        let sock_err = |e: std::io::Error| CheckError::Socket(e.to_string());
        let last = Packet::Force(ForceReply {
            seq: self.last_answered,
            tick: u64::MAX,
            force_n: [0.0; 3],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: None,
        });
        self.pending.clear();
        socket.send_to(&last.encode(), peer).map_err(sock_err)?;
        socket
            .send_to(&Packet::Bye { reason: 0 }.encode(), peer)
            .map_err(sock_err)?;
        obs.bye_s = self.t0.elapsed().as_secs_f64();
        progress("bye: the check said bye; listening 1 s for the device to stop");
        let after = Instant::now() + Duration::from_secs_f64(AFTER_BYE_S);
        self.run_until(after, world, obs, &mut |_| {})?;
        obs.floor_m = world.floor_m();
        Ok(())
    }
}

/// Waits for the first hello: the device's address, the hello and when it came; or a hello
/// that cannot be accepted (its sender and refusal); or no hello within the wait.
#[allow(clippy::type_complexity)]
fn wait_hello(
    socket: &UdpSocket,
    cfg: &CheckConfig,
) -> Result<Result<(SocketAddr, HelloSeen, Instant), (SocketAddr, Refusal)>, CheckError> {
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.wait_s);
    let mut malformed = 0u64;
    let mut last_err = String::new();
    let mut buf = [0u8; 2048];
    loop {
        let now = Instant::now();
        if now >= deadline {
            let mut m = format!(
                "no device said hello on udp:{} within {} s",
                cfg.bind,
                world_form::fmt_num(cfg.wait_s)
            );
            if malformed > 0 {
                m.push_str(&format!(
                    "; {malformed} datagram{} malformed, the last: {last_err}",
                    if malformed == 1 { "" } else { "s" }
                ));
            }
            return Err(CheckError::NoHello(m));
        }
        let (n, from) = match recv(
            socket,
            &mut buf,
            (deadline - now).min(Duration::from_millis(50)),
        )? {
            Some(x) => x,
            None => continue,
        };
        match Packet::decode(&buf[..n]) {
            Ok(Packet::Hello {
                version,
                rate_hz,
                specs,
            }) => {
                return Ok(Ok((
                    from,
                    HelloSeen {
                        version,
                        rate_hz,
                        specs,
                    },
                    Instant::now(),
                )));
            }
            Err(ProtocolError::Hello(r)) => return Ok(Err((from, r))),
            Err(e) => {
                malformed += 1;
                last_err = e.to_string();
            }
            Ok(_) => {
                malformed += 1;
                last_err = "a packet other than a hello before the welcome".into();
            }
        }
    }
}

/// Waits for the hello from `peer` to be repeated (the first came at `at`): the interval, s.
fn wait_repeat(
    socket: &UdpSocket,
    peer: SocketAddr,
    at: Instant,
) -> Result<Option<f64>, CheckError> {
    let deadline = at + Duration::from_secs_f64(HELLO_REPEAT_WAIT_S);
    let mut buf = [0u8; 2048];
    loop {
        let now = Instant::now();
        if now >= deadline {
            return Ok(None);
        }
        if let Some((n, from)) = recv(socket, &mut buf, deadline - now)? {
            if from == peer && matches!(Packet::decode(&buf[..n]), Ok(Packet::Hello { .. })) {
                return Ok(Some(at.elapsed().as_secs_f64()));
            }
        }
    }
}

/// The welcome: the session's version and rate, the scene `device-check`, the roles in
/// force for the device's buttons (by its preset, or by index).
fn welcome_packet(specs: &DeviceSpecs, version: u8, rate_hz: u32) -> Vec<u8> {
    let start_time_ns = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
    Packet::Welcome {
        version,
        rate_hz,
        start_time_ns,
        scene: "device-check".into(),
        roles: ButtonRoles::resolve(specs, &[]).ok().map(|r| r.wire()),
    }
    .encode()
}

/// One datagram within `wait` (at least 50 µs), or `None`.
fn recv(
    socket: &UdpSocket,
    buf: &mut [u8],
    wait: Duration,
) -> Result<Option<(usize, SocketAddr)>, CheckError> {
    socket
        .set_read_timeout(Some(wait.max(Duration::from_micros(50))))
        .map_err(|e| CheckError::Socket(e.to_string()))?;
    match socket.recv_from(buf) {
        Ok(x) => Ok(Some(x)),
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::WouldBlock
                    | std::io::ErrorKind::TimedOut
                    | std::io::ErrorKind::ConnectionRefused
            ) =>
        {
            Ok(None)
        }
        Err(e) => Err(CheckError::Socket(e.to_string())),
    }
}

/// The session after the welcome.
struct Link<'a> {
    socket: &'a UdpSocket,
    peer: SocketAddr,
    t0: Instant,
    welcome: Vec<u8>,
    /// Answers waiting for their time (the link's latency), in order.
    pending: VecDeque<(Instant, Vec<u8>)>,
    rng: ChaCha8Rng,
    hellos: u32,
    first_seq: Option<u64>,
    last_seq: Option<u64>,
    last_answered: u64,
    stage: Option<Stage>,
}

impl Link<'_> {
    /// Receives, answers and sends until `end`; a progress line as each stage begins.
    fn run_until(
        &mut self,
        end: Instant,
        world: &mut CheckWorld,
        obs: &mut Observed,
        progress: &mut dyn FnMut(&str),
    ) -> Result<(), CheckError> {
        let mut buf = [0u8; 2048];
        loop {
            let now = Instant::now();
            while self.pending.front().is_some_and(|p| p.0 <= now) {
                if let Some((_, b)) = self.pending.pop_front() {
                    if self.socket.send_to(&b, self.peer).is_ok() {
                        obs.answers_sent += 1;
                    }
                }
            }
            let t_s = now.duration_since(self.t0).as_secs_f64();
            let stage = stages::stage_at(t_s);
            if stage != self.stage && stage.is_some() {
                self.stage = stage;
                if let Some(s) = stage {
                    progress(&format!("{}: {}", s.name(), s.prompt()));
                }
            }
            if now >= end || obs.device_bye_s.is_some() {
                return Ok(());
            }
            let next = self.pending.front().map_or(end, |p| p.0.min(end));
            let wait = next
                .saturating_duration_since(now)
                .min(Duration::from_millis(5));
            if let Some((n, from)) = recv(self.socket, &mut buf, wait)? {
                if from == self.peer {
                    self.datagram(&buf[..n], world, obs)?;
                }
            }
        }
    }

    /// A datagram from the device.
    fn datagram(
        &mut self,
        b: &[u8],
        world: &mut CheckWorld,
        obs: &mut Observed,
    ) -> Result<(), CheckError> {
        let at = Instant::now();
        let t_s = at.duration_since(self.t0).as_secs_f64();
        obs.datagrams += 1;
        match Packet::decode(b) {
            Ok(Packet::Sample(s)) => self.sample(s, b[4], at, t_s, world, obs),
            Ok(Packet::Hello { .. }) => {
                // A device that restarted: welcomed again, numbering from 0.
                self.hellos += 1;
                self.first_seq = None;
                self.last_seq = None;
                self.socket
                    .send_to(&self.welcome, self.peer)
                    .map_err(|e| CheckError::Socket(e.to_string()))?;
            }
            Ok(Packet::Bye { .. }) => obs.device_bye_s = Some(t_s),
            Ok(_) => malformed(obs, "a packet only the simulator sends".into()),
            Err(e) => malformed(obs, e.to_string()),
        }
        Ok(())
    }

    /// A sample: kept; a fresh one (numbered after the last) answered by the world, the
    /// answer sent after the link's latency unless the stage drops or withholds it.
    fn sample(
        &mut self,
        s: Sample,
        version: u8,
        at: Instant,
        t_s: f64,
        world: &mut CheckWorld,
        obs: &mut Observed,
    ) {
        if obs.samples.len() >= super::observed::MAX_SAMPLES {
            obs.over_cap += 1;
            return;
        }
        let stage = stages::stage_at(t_s);
        obs.samples.push(Received {
            t_s,
            stage,
            hellos: self.hellos,
            seq: s.seq,
            position_m: s.position_m,
            buttons: s.buttons,
            version,
            two_port_periods: s.two_port_periods,
        });
        if self.last_seq.is_some_and(|l| s.seq <= l) {
            return;
        }
        self.last_seq = Some(s.seq);
        let first = *self.first_seq.get_or_insert(s.seq);
        let Some(stage) = stage else {
            return;
        };
        let reply = world.answer(stage, t_s, s.seq - first, s.seq, s.position_m);
        let drop = match stage {
            Stage::Silence => true,
            Stage::Loss => {
                let lost = self.rng.random::<f64>() < LOSS;
                obs.answers_dropped += u64::from(lost);
                lost
            }
            _ => false,
        };
        if !drop {
            self.last_answered = s.seq;
            self.pending.push_back((
                at + Duration::from_secs_f64(LATENCY_S),
                Packet::Force(reply).encode(),
            ));
        }
    }
}

fn malformed(obs: &mut Observed, why: String) {
    obs.malformed += 1;
    obs.first_malformed.get_or_insert(why);
}
