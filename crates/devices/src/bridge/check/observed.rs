//! What the check observed of the device: its hello, every sample with its arrival and
//! stage, the datagrams, the answers sent, and the times of the byes (data only; the rules
//! judge it).

use super::super::protocol::Refusal;
use super::stages::Stage;
use haptic_types::device::DeviceSpecs;
use haptic_types::vec3::Vec3;
use std::net::SocketAddr;

/// Most samples the check keeps: 20 kHz (twice the fastest welcome) over the 6 s sequence and
/// the 1 s after its bye, rounded up. A device sending more is flooding the check, which keeps
/// its memory bounded and fails `packets`.
pub const MAX_SAMPLES: usize = 150_000;

/// The hello the device said.
#[derive(Clone, Debug, PartialEq)]
pub struct HelloSeen {
    /// Its version byte.
    pub version: u8,
    /// Its servo rate, Hz (information).
    pub rate_hz: u32,
    /// Its specifications.
    pub specs: DeviceSpecs,
}

/// One sample as the check received it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Received {
    /// Arrival, s from the welcome.
    pub t_s: f64,
    /// The stage it arrived in (`None`: after the sequence, around the bye).
    pub stage: Option<Stage>,
    /// Hellos welcomed before it (1 for the session's first; a device that restarts says
    /// hello again and numbers from 0).
    pub hellos: u32,
    /// Its sequence number.
    pub seq: u64,
    /// Stylus position, m.
    pub position_m: Vec3,
    /// Button bits.
    pub buttons: u32,
    /// Its version byte (1: 52 bytes, 2: 56 bytes with the two-port count).
    pub version: u8,
    /// The two-port count of a version-2 sample.
    pub two_port_periods: Option<u32>,
}

/// Everything the check observed, for the rules.
#[derive(Clone, Debug)]
pub struct Observed {
    /// The address the check listened on.
    pub bind: SocketAddr,
    /// The first hello.
    pub hello: Option<HelloSeen>,
    /// The refusal of a hello that cannot be accepted (the simulator's message).
    pub refused: Option<Refusal>,
    /// Time from the first hello to its repeat, s (`None`: no repeat within
    /// [`super::stages::HELLO_REPEAT_WAIT_S`]).
    pub hello_repeat_s: Option<f64>,
    /// The session's version (the smaller of the hello's and 2).
    pub version: u8,
    /// The welcome's rate, Hz.
    pub rate_hz: u32,
    /// Every sample from the device, in arrival order.
    pub samples: Vec<Received>,
    /// Datagrams from the device after the welcome.
    pub datagrams: u64,
    /// Of those, not a valid packet (size, version byte, type, magic), or a packet only the
    /// simulator sends.
    pub malformed: u64,
    /// The first malformed datagram's reason.
    pub first_malformed: Option<String>,
    /// Samples that arrived after [`MAX_SAMPLES`] were kept (counted, not kept).
    pub over_cap: u64,
    /// Answers sent, and dropped on purpose in the loss stage.
    pub answers_sent: u64,
    /// Answers dropped in the loss stage.
    pub answers_dropped: u64,
    /// The wall's and floor's offset along +z, m.
    pub floor_m: Option<f64>,
    /// The wall's stiffness, N/m.
    pub wall_n_per_m: f64,
    /// The brick coupling's spring, N/m.
    pub coupling_n_per_m: f64,
    /// When the check said bye, s from the welcome.
    pub bye_s: f64,
    /// When the device said bye, s from the welcome.
    pub device_bye_s: Option<f64>,
}
