//! The device bridge's wire format, versions 1 and 2 (documented byte for byte in
//! `docs/device-bridge.md`).
//!
//! Every packet is one UDP datagram, little-endian, byte-packed, starting with an 8-byte header:
//! the magic `NHDB`, the version (1 or 2), the packet type and two reserved zero bytes.
//!
//! Version 2 (issue 31) adds the local model a device renders between answers
//! (`haptic_types::local`): a device that says hello with version 2 is welcomed with version 2
//! and every force packet it receives carries the local model after the version-1 fields.
//! A version-2 sample also carries the device side's count of servo periods its two-port
//! layer acted on (the simulator reports the largest in its link counters, which the recording
//! keeps). Byes are the same in both versions (sent with version 1, read with either).
//!
//! | type | name    | direction     | body after the header                                              |
//! |------|---------|---------------|--------------------------------------------------------------------|
//! | 1    | hello   | device → sim  | rate u32, max force f64 (N), max stiffness f64 (N/m), workspace radius f64 (m), name (u8 length + UTF-8), button count u8, button names (u8 length + UTF-8 each) |
//! | 2    | welcome | sim → device  | tick rate u32 (Hz), session start u64 (ns since the Unix epoch), scene name (u8 length + UTF-8) |
//! | 3    | sample  | device → sim  | seq u64, device time u64 (ns), position 3 × f64 (m), buttons u32   |
//! | 4    | force   | sim → device  | seq answered u64, tick u64, force 3 × f64 (N), stiffness 9 × f64 (N/m, row-major), status u8 |
//! | 5    | bye     | either        | reason u8 (0: end of session, 1: error)                             |

use haptic_types::device::DeviceSpecs;
use haptic_types::local::{Body, LocalModel, MAX_PLANES, Plane};
use haptic_types::vec3::Vec3;
use std::borrow::Cow;

/// The magic bytes every packet starts with.
pub const MAGIC: [u8; 4] = *b"NHDB";
/// The protocol version of samples and byes (the same in both versions).
pub const VERSION: u8 = 1;
/// The newest protocol version this build speaks: 2, the local model.
pub const VERSION_2: u8 = 2;
/// Size of the local model's fixed part after a version-1 force packet, bytes (residual
/// force and stiffness, world energy).
const LOCAL_FIXED_LEN: usize = 12 * 8 + 8;
/// Size of one plane on the wire: normal, offset, stiffness.
const PLANE_LEN: usize = 5 * 8;
/// Size of the body on the wire: position, velocity, mass, three coupling constants, damper
/// share, external force, substeps (u32), restitution.
const BODY_LEN: usize = 16 * 8 + 4 + 8;
/// Largest datagram accepted, bytes (a hello with 32 buttons of 32 characters fits).
pub const MAX_PACKET: usize = 1200;
/// Size of a sample packet, bytes.
pub const SAMPLE_LEN: usize = 52;
/// Size of a version-2 sample packet, bytes: a version-1 sample and the device side's u32
/// count of servo periods its two-port layer acted on.
pub const SAMPLE_V2_LEN: usize = 56;
/// Size of a force packet, bytes.
pub const FORCE_LEN: usize = 121;
/// Size of a bye packet, bytes.
pub const BYE_LEN: usize = 9;
const HEADER_LEN: usize = 8;

/// A decoded packet.
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    /// A device announces itself and its specifications.
    Hello {
        /// The protocol version the device speaks (1, or 2: it renders the local model).
        version: u8,
        /// The device's own servo rate, Hz (information: the session's tick rate rules).
        rate_hz: u32,
        /// The device's specifications.
        specs: DeviceSpecs,
    },
    /// The simulator accepts a device.
    Welcome {
        /// The protocol version of the session (the device's, at most [`VERSION_2`]).
        version: u8,
        /// The session's tick rate, Hz: send one sample per tick.
        rate_hz: u32,
        /// Session start, ns since the Unix epoch.
        start_time_ns: u64,
        /// Scene name.
        scene: String,
    },
    /// One device reading.
    Sample(Sample),
    /// The simulator's answer to a sample.
    Force(ForceReply),
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
    /// The local model (version 2 only; `None`: a version-1 packet).
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
    #[error("protocol version {0} (this build speaks 1 and 2)")]
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
}

fn header(v: &mut Vec<u8>, version: u8, t: u8) {
    v.clear();
    v.extend_from_slice(&MAGIC);
    v.extend_from_slice(&[version, t, 0, 0]);
}

fn put_f64s(v: &mut Vec<u8>, xs: &[f64]) {
    for x in xs {
        v.extend_from_slice(&x.to_le_bytes());
    }
}

fn put_plane(v: &mut Vec<u8>, p: &Plane) {
    put_f64s(v, &p.normal);
    put_f64s(v, &[p.offset_m, p.stiffness_n_per_m]);
}

fn put_local(v: &mut Vec<u8>, m: &LocalModel) {
    put_f64s(v, &m.residual_force_n);
    put_f64s(v, &m.residual_stiffness_n_per_m);
    put_f64s(v, &[m.world_energy_j]);
    v.push(m.planes.len().min(MAX_PLANES) as u8);
    for p in m.planes.iter().take(MAX_PLANES) {
        put_plane(v, p);
    }
    match &m.body {
        Some(b) => {
            v.push(1);
            put_f64s(v, &b.position_m);
            put_f64s(v, &b.velocity_m_per_s);
            put_f64s(
                v,
                &[
                    b.mass_kg,
                    b.stiffness_n_per_m,
                    b.series_stiffness_n_per_m,
                    b.damping_n_s_per_m,
                ],
            );
            put_f64s(v, &b.damper_m);
            put_f64s(v, &b.external_force_n);
            v.extend_from_slice(&b.substeps.to_le_bytes());
            put_f64s(v, &[b.restitution]);
        }
        None => v.push(0),
    }
    v.push(m.body_planes.len().min(MAX_PLANES) as u8);
    for p in m.body_planes.iter().take(MAX_PLANES) {
        put_plane(v, p);
    }
}

fn put_str(v: &mut Vec<u8>, s: &str) {
    let b = s.as_bytes();
    let n = b.len().min(255);
    v.push(n as u8);
    v.extend_from_slice(&b[..n]);
}

impl Packet {
    /// Encodes to a datagram.
    pub fn encode(&self) -> Vec<u8> {
        let mut v = Vec::with_capacity(128);
        self.encode_into(&mut v);
        v
    }

    /// Encodes into `v` (cleared first), reusing its allocation: the servo tick sends a force
    /// packet every tick without allocating.
    pub fn encode_into(&self, v: &mut Vec<u8>) {
        match self {
            Packet::Hello {
                version,
                rate_hz,
                specs,
            } => {
                header(v, *version, 1);
                v.extend_from_slice(&rate_hz.to_le_bytes());
                for x in [
                    specs.limits.max_force_n,
                    specs.limits.max_stiffness_n_per_m,
                    specs.workspace_radius_m,
                ] {
                    v.extend_from_slice(&x.to_le_bytes());
                }
                put_str(v, &specs.name);
                v.push(specs.button_names.len().min(255) as u8);
                for b in specs.button_names.iter().take(255) {
                    put_str(v, b);
                }
            }
            Packet::Welcome {
                version,
                rate_hz,
                start_time_ns,
                scene,
            } => {
                header(v, *version, 2);
                v.extend_from_slice(&rate_hz.to_le_bytes());
                v.extend_from_slice(&start_time_ns.to_le_bytes());
                put_str(v, scene);
            }
            Packet::Sample(s) => {
                let version = if s.two_port_periods.is_some() {
                    VERSION_2
                } else {
                    VERSION
                };
                header(v, version, 3);
                v.extend_from_slice(&s.seq.to_le_bytes());
                v.extend_from_slice(&s.device_time_ns.to_le_bytes());
                for x in s.position_m {
                    v.extend_from_slice(&x.to_le_bytes());
                }
                v.extend_from_slice(&s.buttons.to_le_bytes());
                if let Some(n) = s.two_port_periods {
                    v.extend_from_slice(&n.to_le_bytes());
                }
            }
            Packet::Force(f) => {
                let version = if f.local.is_some() {
                    VERSION_2
                } else {
                    VERSION
                };
                header(v, version, 4);
                v.extend_from_slice(&f.seq.to_le_bytes());
                v.extend_from_slice(&f.tick.to_le_bytes());
                for x in f.force_n.iter().chain(f.stiffness_n_per_m.iter()) {
                    v.extend_from_slice(&x.to_le_bytes());
                }
                v.push(f.status);
                if let Some(m) = &f.local {
                    put_local(v, m);
                }
            }
            Packet::Bye { reason } => {
                header(v, VERSION, 5);
                v.push(*reason);
            }
        }
    }

    /// Decodes a datagram; every malformed input is an error, never a panic.
    pub fn decode(b: &[u8]) -> Result<Packet, ProtocolError> {
        if b.len() > MAX_PACKET {
            return Err(ProtocolError::Oversized(b.len()));
        }
        if b.len() < HEADER_LEN {
            return Err(ProtocolError::TooShort {
                kind: "header",
                got: b.len(),
                need: HEADER_LEN,
            });
        }
        let magic = [b[0], b[1], b[2], b[3]];
        if magic != MAGIC {
            return Err(ProtocolError::Magic(magic));
        }
        let version = b[4];
        if version != VERSION && version != VERSION_2 {
            return Err(ProtocolError::Version(version));
        }
        let mut r = Reader { b, at: HEADER_LEN };
        let fixed = |kind: &'static str, len: usize| -> Result<(), ProtocolError> {
            if b.len() < len {
                Err(ProtocolError::TooShort {
                    kind,
                    got: b.len(),
                    need: len,
                })
            } else if b.len() > len {
                Err(ProtocolError::TooLong {
                    kind,
                    got: b.len(),
                    expected: len,
                })
            } else {
                Ok(())
            }
        };
        match b[5] {
            1 => {
                let rate_hz = r.u32("hello")?;
                let max_force_n = r.f64("hello")?;
                let max_stiffness_n_per_m = r.f64("hello")?;
                let workspace_radius_m = r.f64("hello")?;
                let name = r.string("hello name")?;
                let n = r.u8("hello")?;
                let mut buttons = Vec::with_capacity(usize::from(n));
                for _ in 0..n {
                    buttons.push(Cow::Owned(r.string("hello button name")?));
                }
                r.end("hello")?;
                let specs = DeviceSpecs {
                    name: Cow::Owned(name),
                    limits: world_form::Limits {
                        max_force_n,
                        max_stiffness_n_per_m,
                    },
                    workspace_radius_m,
                    button_names: Cow::Owned(buttons),
                };
                specs
                    .validate()
                    .map_err(|e| ProtocolError::Spec(e.to_string()))?;
                Ok(Packet::Hello {
                    version,
                    rate_hz,
                    specs,
                })
            }
            2 => {
                let rate_hz = r.u32("welcome")?;
                let start_time_ns = r.u64("welcome")?;
                let scene = r.string("welcome scene")?;
                r.end("welcome")?;
                Ok(Packet::Welcome {
                    version,
                    rate_hz,
                    start_time_ns,
                    scene,
                })
            }
            3 => {
                if version == VERSION {
                    fixed("sample", SAMPLE_LEN)?;
                } else {
                    fixed("sample (version 2)", SAMPLE_V2_LEN)?;
                }
                Ok(Packet::Sample(Sample {
                    seq: r.u64("sample")?,
                    device_time_ns: r.u64("sample")?,
                    position_m: [r.f64("sample")?, r.f64("sample")?, r.f64("sample")?],
                    buttons: r.u32("sample")?,
                    two_port_periods: if version == VERSION_2 {
                        Some(r.u32("sample")?)
                    } else {
                        None
                    },
                }))
            }
            4 => {
                if version == VERSION {
                    fixed("force", FORCE_LEN)?;
                } else if b.len() < FORCE_LEN + LOCAL_FIXED_LEN + 3 {
                    return Err(ProtocolError::TooShort {
                        kind: "force (version 2)",
                        got: b.len(),
                        need: FORCE_LEN + LOCAL_FIXED_LEN + 3,
                    });
                }
                let seq = r.u64("force")?;
                let tick = r.u64("force")?;
                let force_n = [r.f64("force")?, r.f64("force")?, r.f64("force")?];
                let mut k = [0.0; 9];
                for x in &mut k {
                    *x = r.f64("force")?;
                }
                let status = r.u8("force")?;
                let local = if version == VERSION_2 {
                    let m = r.local()?;
                    r.end("force (version 2)")?;
                    Some(Box::new(m))
                } else {
                    None
                };
                Ok(Packet::Force(ForceReply {
                    seq,
                    tick,
                    force_n,
                    stiffness_n_per_m: k,
                    status,
                    local,
                }))
            }
            5 => {
                fixed("bye", BYE_LEN)?;
                Ok(Packet::Bye {
                    reason: r.u8("bye")?,
                })
            }
            t => Err(ProtocolError::Type(t)),
        }
    }
}

/// Size of a version-2 force packet with `planes` contact planes, a body or none and
/// `body_planes` body planes, bytes.
pub fn force_v2_len(planes: usize, body: bool, body_planes: usize) -> usize {
    FORCE_LEN
        + LOCAL_FIXED_LEN
        + 1
        + planes * PLANE_LEN
        + 1
        + if body { BODY_LEN } else { 0 }
        + 1
        + body_planes * PLANE_LEN
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn f64s<const N: usize>(&mut self, kind: &'static str) -> Result<[f64; N], ProtocolError> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f64(kind)?;
        }
        Ok(out)
    }

    fn planes(&mut self, kind: &'static str) -> Result<Vec<Plane>, ProtocolError> {
        let n = usize::from(self.u8(kind)?);
        if n > MAX_PLANES {
            return Err(ProtocolError::Local(format!(
                "{kind}: {n} planes, allowed at most {MAX_PLANES}"
            )));
        }
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let normal = self.f64s::<3>(kind)?;
            let [offset_m, stiffness_n_per_m] = self.f64s::<2>(kind)?;
            out.push(Plane {
                normal,
                offset_m,
                stiffness_n_per_m,
            });
        }
        Ok(out)
    }

    /// The local model after a version-2 force packet's version-1 fields.
    fn local(&mut self) -> Result<LocalModel, ProtocolError> {
        let kind = "force (version 2)";
        let residual_force_n = self.f64s::<3>(kind)?;
        let residual_stiffness_n_per_m = self.f64s::<9>(kind)?;
        let [world_energy_j] = self.f64s::<1>(kind)?;
        let planes = self.planes(kind)?;
        let body = match self.u8(kind)? {
            0 => None,
            1 => {
                let position_m = self.f64s::<3>(kind)?;
                let velocity_m_per_s = self.f64s::<3>(kind)?;
                let [
                    mass_kg,
                    stiffness_n_per_m,
                    series_stiffness_n_per_m,
                    damping_n_s_per_m,
                ] = self.f64s::<4>(kind)?;
                let damper_m = self.f64s::<3>(kind)?;
                let external_force_n = self.f64s::<3>(kind)?;
                let substeps = self.u32(kind)?;
                let [restitution] = self.f64s::<1>(kind)?;
                Some(Body {
                    position_m,
                    velocity_m_per_s,
                    mass_kg,
                    stiffness_n_per_m,
                    series_stiffness_n_per_m,
                    damping_n_s_per_m,
                    damper_m,
                    external_force_n,
                    substeps,
                    restitution,
                })
            }
            other => {
                return Err(ProtocolError::Local(format!(
                    "body flag {other}: allowed 0 (none) or 1"
                )));
            }
        };
        let body_planes = self.planes(kind)?;
        let m = LocalModel {
            residual_force_n,
            residual_stiffness_n_per_m,
            planes,
            body,
            body_planes,
            world_energy_j,
        };
        // Finite, unit normals, masses and stiffnesses non-negative; the stiffnesses' cap is the
        // simulator's (it sends only what the device announced it renders).
        m.check(f64::INFINITY).map_err(ProtocolError::Local)?;
        Ok(m)
    }

    fn take(&mut self, n: usize, kind: &'static str) -> Result<&[u8], ProtocolError> {
        let end = self.at + n;
        if end > self.b.len() {
            return Err(ProtocolError::TooShort {
                kind,
                got: self.b.len(),
                need: end,
            });
        }
        let s = &self.b[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self, kind: &'static str) -> Result<u8, ProtocolError> {
        Ok(self.take(1, kind)?[0])
    }
    fn u32(&mut self, kind: &'static str) -> Result<u32, ProtocolError> {
        let mut a = [0; 4];
        a.copy_from_slice(self.take(4, kind)?);
        Ok(u32::from_le_bytes(a))
    }
    fn u64(&mut self, kind: &'static str) -> Result<u64, ProtocolError> {
        let mut a = [0; 8];
        a.copy_from_slice(self.take(8, kind)?);
        Ok(u64::from_le_bytes(a))
    }
    fn f64(&mut self, kind: &'static str) -> Result<f64, ProtocolError> {
        Ok(f64::from_bits(self.u64(kind)?))
    }
    fn string(&mut self, kind: &'static str) -> Result<String, ProtocolError> {
        let n = usize::from(self.u8(kind)?);
        let b = self.take(n, kind)?;
        String::from_utf8(b.to_vec()).map_err(|_| ProtocolError::Text(kind))
    }
    fn end(&self, kind: &'static str) -> Result<(), ProtocolError> {
        if self.at == self.b.len() {
            Ok(())
        } else {
            Err(ProtocolError::TooLong {
                kind,
                got: self.b.len(),
                expected: self.at,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::device::{FALCON, TOUCH};
    use proptest::prelude::*;

    #[test]
    fn every_packet_round_trips_with_its_documented_size() {
        let s = Packet::Sample(Sample {
            seq: 7,
            device_time_ns: 99,
            position_m: [0.01, -0.02, f64::NAN],
            buttons: 5,
            two_port_periods: None,
        });
        let b = s.encode();
        assert_eq!(b.len(), SAMPLE_LEN);
        assert_eq!(&b[..8], b"NHDB\x01\x03\x00\x00");
        match Packet::decode(&b) {
            Ok(Packet::Sample(x)) => {
                assert_eq!((x.seq, x.device_time_ns, x.buttons), (7, 99, 5));
                assert!(x.position_m[2].is_nan());
            }
            other => panic!("{other:?}"),
        }
        let f = Packet::Force(ForceReply {
            seq: 7,
            tick: 3,
            force_n: [1.0, 2.0, 3.0],
            stiffness_n_per_m: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            status: 32,
            local: None,
        });
        assert_eq!(f.encode().len(), FORCE_LEN);
        assert_eq!(Packet::decode(&f.encode()), Ok(f));
        for (specs, version) in [(FALCON, 1), (TOUCH, 2)] {
            let h = Packet::Hello {
                version,
                rate_hz: 1000,
                specs,
            };
            assert_eq!(h.encode()[4], version);
            assert_eq!(Packet::decode(&h.encode()), Ok(h));
        }
        let w = Packet::Welcome {
            version: 2,
            rate_hz: 1000,
            start_time_ns: 1_700_000_000_000_000_000,
            scene: "wall".into(),
        };
        assert_eq!(Packet::decode(&w.encode()), Ok(w));
        assert_eq!(Packet::Bye { reason: 0 }.encode().len(), BYE_LEN);
        // A version-2 sample: the version-1 fields, then the two-port count.
        let s2 = Packet::Sample(Sample {
            seq: 8,
            device_time_ns: 1,
            position_m: [0.0; 3],
            buttons: 0,
            two_port_periods: Some(41),
        });
        let b = s2.encode();
        assert_eq!(b.len(), SAMPLE_V2_LEN);
        assert_eq!(&b[..8], b"NHDB\x02\x03\x00\x00");
        assert_eq!(&b[52..], &41u32.to_le_bytes());
        assert_eq!(Packet::decode(&b), Ok(s2));
        assert_eq!(
            Packet::decode(&b[..52]).unwrap_err().to_string(),
            "sample (version 2) packet of 52 bytes is too short (needs 56)"
        );
    }

    #[test]
    fn malformed_packets_name_what_is_wrong() {
        let good = Packet::Sample(Sample {
            seq: 1,
            device_time_ns: 0,
            position_m: [0.0; 3],
            buttons: 0,
            two_port_periods: None,
        })
        .encode();
        let e = |b: &[u8]| Packet::decode(b).unwrap_err().to_string();
        assert_eq!(
            e(&good[..51]),
            "sample packet of 51 bytes is too short (needs 52)"
        );
        let mut long = good.clone();
        long.push(0);
        assert_eq!(
            e(&long),
            "sample packet of 53 bytes is too long (expected 52)"
        );
        assert_eq!(
            e(&vec![0; MAX_PACKET + 1]),
            "datagram of 1201 bytes is over the 1200-byte limit"
        );
        let mut v = good.clone();
        v[4] = 3;
        assert_eq!(e(&v), "protocol version 3 (this build speaks 1 and 2)");
        v[4] = 1;
        v[5] = 9;
        assert_eq!(e(&v), "unknown packet type 9");
        assert_eq!(e(b"GET / HT"), "bad magic [47, 45, 54, 20] (expected NHDB)");
        let mut bad = FALCON;
        bad.limits.max_force_n = f64::INFINITY;
        assert_eq!(
            e(&Packet::Hello {
                version: 1,
                rate_hz: 1000,
                specs: bad.clone()
            }
            .encode()),
            "device specs: `max_force_n` = inf is out of range: allowed 0.001 ≤ max_force_n ≤ 1000"
        );
        // A force limit of 4e-159 N (found by the libFuzzer bridge target: its squares are
        // subnormal, and clamping to it took 12 s for 20 ticks) is no haptic device.
        bad.limits.max_force_n = 3.7555737088373936e-159;
        assert_eq!(
            e(&Packet::Hello {
                version: 1,
                rate_hz: 1000,
                specs: bad
            }
            .encode()),
            "device specs: `max_force_n` = 3.7555737088373936e-159 is out of range: allowed \
             0.001 ≤ max_force_n ≤ 1000"
        );
    }

    /// A local model with every part: two planes, a body, one body plane.
    fn full_model() -> LocalModel {
        LocalModel {
            residual_force_n: [0.1, -0.2, 0.3],
            residual_stiffness_n_per_m: [5.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0, 5.0],
            planes: vec![
                Plane {
                    normal: [0.0, 0.0, 1.0],
                    offset_m: -0.01,
                    stiffness_n_per_m: 2500.0,
                },
                Plane {
                    normal: [1.0, 0.0, 0.0],
                    offset_m: 0.02,
                    stiffness_n_per_m: 2500.0,
                },
            ],
            body: Some(Body {
                position_m: [0.001, 0.002, -0.003],
                velocity_m_per_s: [0.01, 0.0, -0.02],
                mass_kg: 1.25,
                stiffness_n_per_m: 900.0,
                series_stiffness_n_per_m: 900.0,
                damping_n_s_per_m: 60.0,
                damper_m: [0.0, 0.0, -1e-4],
                external_force_n: [0.0, 0.0, -0.6],
                substeps: 4,
                restitution: 0.2,
            }),
            body_planes: vec![Plane {
                normal: [0.0, 0.0, 1.0],
                offset_m: -0.02,
                stiffness_n_per_m: 0.0,
            }],
            world_energy_j: -0.125,
        }
    }

    #[test]
    fn a_version_2_force_packet_carries_the_local_model_in_its_documented_size() {
        let f = Packet::Force(ForceReply {
            seq: 9,
            tick: 8,
            force_n: [0.5, 0.0, -1.0],
            stiffness_n_per_m: [0.0; 9],
            status: 1,
            local: Some(Box::new(full_model())),
        });
        let b = f.encode();
        assert_eq!(b.len(), force_v2_len(2, true, 1));
        assert_eq!(b.len(), 121 + 104 + 1 + 80 + 1 + 140 + 1 + 40);
        assert_eq!(&b[..8], b"NHDB\x02\x04\x00\x00");
        // The version-1 fields are where version 1 has them.
        assert_eq!(&b[8..16], &9u64.to_le_bytes());
        assert_eq!(Packet::decode(&b), Ok(f));
        // The largest: four planes, a body, four body planes: within one datagram.
        assert!(force_v2_len(MAX_PLANES, true, MAX_PLANES) <= MAX_PACKET);
        // Without a body.
        let mut m = full_model();
        m.body = None;
        let g = Packet::Force(ForceReply {
            seq: 1,
            tick: 1,
            force_n: [0.0; 3],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(m)),
        });
        assert_eq!(g.encode().len(), force_v2_len(2, false, 1));
        assert_eq!(Packet::decode(&g.encode()), Ok(g));
    }

    #[test]
    fn a_bad_local_model_is_refused_by_name() {
        let mut m = full_model();
        m.planes[1].normal = [2.0, 0.0, 0.0];
        let f = |m: LocalModel| {
            Packet::decode(
                &Packet::Force(ForceReply {
                    seq: 1,
                    tick: 1,
                    force_n: [0.0; 3],
                    stiffness_n_per_m: [0.0; 9],
                    status: 0,
                    local: Some(Box::new(m)),
                })
                .encode(),
            )
            .unwrap_err()
            .to_string()
        };
        assert_eq!(
            f(m),
            "force packet's local model: plane 1: the normal must be a finite unit vector"
        );
        let mut m = full_model();
        if let Some(b) = m.body.as_mut() {
            b.mass_kg = -1.0;
        }
        assert_eq!(
            f(m),
            "force packet's local model: body.mass_kg = -1 is out of range: allowed 0 < m ≤ 10000 kg"
        );
        let mut b = Packet::Force(ForceReply {
            seq: 1,
            tick: 1,
            force_n: [0.0; 3],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(full_model())),
        })
        .encode();
        // Five planes announced.
        b[121 + 104] = 5;
        assert_eq!(
            Packet::decode(&b).unwrap_err().to_string(),
            "force packet's local model: force (version 2): 5 planes, allowed at most 4"
        );
        // Cut short.
        assert_eq!(
            Packet::decode(&b[..200]).unwrap_err().to_string(),
            "force (version 2) packet of 200 bytes is too short (needs 228)"
        );
    }

    proptest! {
        /// Any bytes decode to a packet or an error; never a panic.
        #[test]
        fn arbitrary_bytes_never_panic(b in proptest::collection::vec(any::<u8>(), 0..300)) {
            let _ = Packet::decode(&b);
            for v in [b"NHDB\x01", b"NHDB\x02"] {
                let mut h = v.to_vec();
                h.extend_from_slice(&b);
                let r = Packet::decode(&h);
                if let Ok(Packet::Sample(_)) = r {
                    prop_assert_eq!(h.len(), if v[4] == 1 { SAMPLE_LEN } else { SAMPLE_V2_LEN });
                }
            }
        }
    }
}
