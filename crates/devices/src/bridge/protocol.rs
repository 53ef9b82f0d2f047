//! The device bridge's wire format, version 1 (documented byte for byte in
//! `docs/device-bridge.md`).
//!
//! Every packet is one UDP datagram, little-endian, byte-packed, starting with an 8-byte header:
//! the magic `NHDB`, the version (1), the packet type and two reserved zero bytes.
//!
//! | type | name    | direction     | body after the header                                              |
//! |------|---------|---------------|--------------------------------------------------------------------|
//! | 1    | hello   | device → sim  | rate u32, max force f64 (N), max stiffness f64 (N/m), workspace radius f64 (m), name (u8 length + UTF-8), button count u8, button names (u8 length + UTF-8 each) |
//! | 2    | welcome | sim → device  | tick rate u32 (Hz), session start u64 (ns since the Unix epoch), scene name (u8 length + UTF-8) |
//! | 3    | sample  | device → sim  | seq u64, device time u64 (ns), position 3 × f64 (m), buttons u32   |
//! | 4    | force   | sim → device  | seq answered u64, tick u64, force 3 × f64 (N), stiffness 9 × f64 (N/m, row-major), status u8 |
//! | 5    | bye     | either        | reason u8 (0: end of session, 1: error)                             |

use haptic_types::device::DeviceSpecs;
use haptic_types::vec3::Vec3;
use std::borrow::Cow;

/// The magic bytes every packet starts with.
pub const MAGIC: [u8; 4] = *b"NHDB";
/// The protocol version this build speaks.
pub const VERSION: u8 = 1;
/// Largest datagram accepted, bytes (a hello with 32 buttons of 32 characters fits).
pub const MAX_PACKET: usize = 1200;
/// Size of a sample packet, bytes.
pub const SAMPLE_LEN: usize = 52;
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
        /// The device's own servo rate, Hz (information: the session's tick rate rules).
        rate_hz: u32,
        /// The device's specifications.
        specs: DeviceSpecs,
    },
    /// The simulator accepts a device.
    Welcome {
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
}

/// The simulator's answer to a sample.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    #[error("protocol version {0} (this build speaks {VERSION})")]
    Version(u8),
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

fn header(v: &mut Vec<u8>, t: u8) {
    v.clear();
    v.extend_from_slice(&MAGIC);
    v.extend_from_slice(&[VERSION, t, 0, 0]);
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
            Packet::Hello { rate_hz, specs } => {
                header(v, 1);
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
                rate_hz,
                start_time_ns,
                scene,
            } => {
                header(v, 2);
                v.extend_from_slice(&rate_hz.to_le_bytes());
                v.extend_from_slice(&start_time_ns.to_le_bytes());
                put_str(v, scene);
            }
            Packet::Sample(s) => {
                header(v, 3);
                v.extend_from_slice(&s.seq.to_le_bytes());
                v.extend_from_slice(&s.device_time_ns.to_le_bytes());
                for x in s.position_m {
                    v.extend_from_slice(&x.to_le_bytes());
                }
                v.extend_from_slice(&s.buttons.to_le_bytes());
            }
            Packet::Force(f) => {
                header(v, 4);
                v.extend_from_slice(&f.seq.to_le_bytes());
                v.extend_from_slice(&f.tick.to_le_bytes());
                for x in f.force_n.iter().chain(f.stiffness_n_per_m.iter()) {
                    v.extend_from_slice(&x.to_le_bytes());
                }
                v.push(f.status);
            }
            Packet::Bye { reason } => {
                header(v, 5);
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
        if b[4] != VERSION {
            return Err(ProtocolError::Version(b[4]));
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
                Ok(Packet::Hello { rate_hz, specs })
            }
            2 => {
                let rate_hz = r.u32("welcome")?;
                let start_time_ns = r.u64("welcome")?;
                let scene = r.string("welcome scene")?;
                r.end("welcome")?;
                Ok(Packet::Welcome {
                    rate_hz,
                    start_time_ns,
                    scene,
                })
            }
            3 => {
                fixed("sample", SAMPLE_LEN)?;
                Ok(Packet::Sample(Sample {
                    seq: r.u64("sample")?,
                    device_time_ns: r.u64("sample")?,
                    position_m: [r.f64("sample")?, r.f64("sample")?, r.f64("sample")?],
                    buttons: r.u32("sample")?,
                }))
            }
            4 => {
                fixed("force", FORCE_LEN)?;
                let seq = r.u64("force")?;
                let tick = r.u64("force")?;
                let force_n = [r.f64("force")?, r.f64("force")?, r.f64("force")?];
                let mut k = [0.0; 9];
                for x in &mut k {
                    *x = r.f64("force")?;
                }
                Ok(Packet::Force(ForceReply {
                    seq,
                    tick,
                    force_n,
                    stiffness_n_per_m: k,
                    status: r.u8("force")?,
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

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
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
        });
        assert_eq!(f.encode().len(), FORCE_LEN);
        assert_eq!(Packet::decode(&f.encode()), Ok(f));
        for specs in [FALCON, TOUCH] {
            let h = Packet::Hello {
                rate_hz: 1000,
                specs,
            };
            assert_eq!(Packet::decode(&h.encode()), Ok(h));
        }
        let w = Packet::Welcome {
            rate_hz: 1000,
            start_time_ns: 1_700_000_000_000_000_000,
            scene: "wall".into(),
        };
        assert_eq!(Packet::decode(&w.encode()), Ok(w));
        assert_eq!(Packet::Bye { reason: 0 }.encode().len(), BYE_LEN);
    }

    #[test]
    fn malformed_packets_name_what_is_wrong() {
        let good = Packet::Sample(Sample {
            seq: 1,
            device_time_ns: 0,
            position_m: [0.0; 3],
            buttons: 0,
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
        v[4] = 2;
        assert_eq!(e(&v), "protocol version 2 (this build speaks 1)");
        v[4] = 1;
        v[5] = 9;
        assert_eq!(e(&v), "unknown packet type 9");
        assert_eq!(e(b"GET / HT"), "bad magic [47, 45, 54, 20] (expected NHDB)");
        let mut bad = FALCON;
        bad.limits.max_force_n = f64::INFINITY;
        assert_eq!(
            e(&Packet::Hello {
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
                rate_hz: 1000,
                specs: bad
            }
            .encode()),
            "device specs: `max_force_n` = 3.7555737088373936e-159 is out of range: allowed \
             0.001 ≤ max_force_n ≤ 1000"
        );
    }

    proptest! {
        /// Any bytes decode to a packet or an error; never a panic.
        #[test]
        fn arbitrary_bytes_never_panic(b in proptest::collection::vec(any::<u8>(), 0..300)) {
            let _ = Packet::decode(&b);
            let mut h = b"NHDB\x01".to_vec();
            h.extend_from_slice(&b);
            let r = Packet::decode(&h);
            if let Ok(Packet::Sample(_)) = r {
                prop_assert_eq!(h.len(), SAMPLE_LEN);
            }
        }
    }
}
