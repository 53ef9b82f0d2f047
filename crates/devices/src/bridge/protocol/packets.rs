//! The packets of the bridge protocol as Rust types, and the reasons a datagram is refused.

use super::MAX_PACKET;
use haptic_types::device::DeviceSpecs;
use haptic_types::local::LocalModel;
use haptic_types::vec3::Vec3;

/// A decoded packet.
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    /// A device announces itself and its specifications.
    Hello {
        /// The protocol version the device speaks (1; 2: it renders the local model; 3: and
        /// its bond).
        version: u8,
        /// The device's own servo rate, Hz (information: the session's tick rate rules).
        rate_hz: u32,
        /// The device's specifications.
        specs: DeviceSpecs,
    },
    /// The simulator accepts a device.
    Welcome {
        /// The protocol version of the session (the device's, at most [`VERSION_4`](super::VERSION_4)).
        version: u8,
        /// The session's tick rate, Hz: send one sample per tick.
        rate_hz: u32,
        /// Session start, ns since the Unix epoch.
        start_time_ns: u64,
        /// Scene name.
        scene: String,
        /// The button roles in force: the button index of grip, turn_x, turn_y and turn_z,
        /// 255 where no button plays the role (`None`: a welcome without them, from a
        /// simulator before issue 41).
        roles: Option<[u8; 4]>,
    },
    /// One device reading.
    Sample(Sample),
    /// The simulator's answer to a sample.
    Force(ForceReply),
    /// The simulator cannot accept a hello: which field, what it allows, and the whole
    /// message (sent at most [`REFUSAL_INTERVAL_S`](super::REFUSAL_INTERVAL_S) apart).
    Refusal(Refusal),
    /// End of the session.
    Bye {
        /// 0: end of session, 1: error.
        reason: u8,
    },
}

/// A device reading on the wire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// The device's sequence number (increasing by one per sample).
    pub seq: u64,
    /// The device's clock when it read the sample, ns (information only).
    pub device_time_ns: u64,
    /// Stylus position, m, device frame.
    pub position_m: Vec3,
    /// Button bits.
    pub buttons: u32,
    /// Version 2 only: the servo periods the device side's two-port passivity layer has
    /// acted on since the hello (`None`: a version-1 sample).
    pub two_port_periods: Option<u32>,
}

/// The simulator's answer to a sample.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceReply {
    /// Sequence number of the sample this answers.
    pub seq: u64,
    /// The tick that computed it.
    pub tick: u64,
    /// Force to render, N, device frame.
    pub force_n: Vec3,
    /// Local stiffness, N/m, device frame, row-major 3×3.
    pub stiffness_n_per_m: [f64; 9],
    /// Status bits of the tick (1 clamped, 2 input invalid, 4 deadline missed, 8 stiffness over
    /// cap, 16 force invalid, 32 watchdog, 64 passivity controller, 128 force-rate limit).
    pub status: u8,
    /// The local model (versions 2 and 3; `None`: a version-1 packet). A model with a bond is
    /// sent as a version-3 packet.
    pub local: Option<Box<LocalModel>>,
}

impl ForceReply {
    /// The answer as the device interface's command (its local model apart).
    pub fn command(&self) -> haptic_types::device::ForceCommand {
        haptic_types::device::ForceCommand {
            tick: self.tick,
            seq: self.seq,
            force_n: self.force_n,
            stiffness_n_per_m: self.stiffness_n_per_m,
            status: self.status,
        }
    }
}

/// Why a hello was refused: the field, the values allowed and the whole message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The hello's field: `version`, `size`, `name`, `max_force_n`, `max_stiffness_n_per_m`,
    /// `workspace_radius_m`, `button_names`, `buttons.<role>` (a role the scene maps to a
    /// button the device lacks) or `specs` (a hello that changes the session's specifications).
    pub field: String,
    /// The values allowed, in words.
    pub allowed: String,
    /// The simulator's message (names the field, the value and the allowed values).
    pub message: String,
}

impl Refusal {
    /// A refusal of `field` with `allowed` values; `message` the simulator's words.
    pub fn new(field: &str, allowed: &str, message: String) -> Refusal {
        Refusal {
            field: field.to_string(),
            allowed: allowed.to_string(),
            message,
        }
    }

    /// The refusal of a hello whose specifications `e` names as out of range.
    pub fn of_spec(e: &haptic_types::device::DeviceError) -> Refusal {
        use haptic_types::device::DeviceError as E;
        let message = format!("hello refused: {e}");
        match e {
            E::Spec(world_form::ValueError::OutOfRange { field, allowed, .. }) => {
                Refusal::new(field.trim_matches('`'), allowed, message)
            }
            E::BadSpec { field, allowed, .. } => Refusal::new(field, allowed, message),
            E::Buttons { field, allowed, .. } => Refusal::new(field, allowed, message),
            _ => Refusal::new("specs", "specifications in range", message),
        }
    }
}

/// Why a datagram was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProtocolError {
    /// Shorter than a header or than its type needs.
    #[error("{kind} packet of {got} bytes is too short (needs {need})")]
    TooShort {
        /// Packet type name.
        kind: &'static str,
        /// Bytes received.
        got: usize,
        /// Bytes needed.
        need: usize,
    },
    /// Longer than its type allows.
    #[error("{kind} packet of {got} bytes is too long (expected {expected})")]
    TooLong {
        /// Packet type name.
        kind: &'static str,
        /// Bytes received.
        got: usize,
        /// Bytes expected.
        expected: usize,
    },
    /// Larger than [`MAX_PACKET`].
    #[error("datagram of {0} bytes is over the {MAX_PACKET}-byte limit")]
    Oversized(usize),
    /// Does not start with `NHDB`.
    #[error("bad magic {0:02x?} (expected NHDB)")]
    Magic([u8; 4]),
    /// Another protocol version.
    #[error("protocol version {0} (this build speaks 1 to 4)")]
    Version(u8),
    /// A local model out of range.
    #[error("force packet's local model: {0}")]
    Local(String),
    /// Unknown packet type.
    #[error("unknown packet type {0}")]
    Type(u8),
    /// A string that is not UTF-8 or runs past the end.
    #[error("{0}: bad string")]
    Text(&'static str),
    /// Announced specifications out of range.
    #[error("{0}")]
    Spec(String),
    /// A hello the simulator cannot accept (answered with a [`Packet::Refusal`]).
    #[error("{}", .0.message)]
    Hello(Refusal),
}
