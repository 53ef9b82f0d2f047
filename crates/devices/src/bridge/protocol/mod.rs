//! The device bridge's wire format, versions 1 to 4 (documented byte for byte in
//! `docs/device-bridge.md`).
//!
//! Every packet is one UDP datagram, little-endian, byte-packed, starting with an 8-byte header:
//! the magic `NHDB`, the version (1 to 4), the packet type and two reserved zero bytes.
//!
//! Version 2 (issue 31) adds the local model a device renders between answers
//! (`haptic_types::local`): a device that says hello with version 2 is welcomed with version 2
//! and every force packet it receives carries the local model after the version-1 fields.
//! A version-2 sample also carries the device side's count of servo periods its two-port
//! layer acted on (the simulator reports the largest in its link counters, which the recording
//! keeps). Byes are the same in every version (sent with version 1, read with any).
//!
//! Version 3 adds the local model's bond (`haptic_types::local::Bond`, a spring that breaks):
//! a force packet whose model has one is a version-2 force packet followed by the bond, with
//! version byte 3; the session's samples are version-2 samples.
//!
//! Version 4 adds the local model's follower (`haptic_types::local::Follower`, the optical
//! tweezers' held particle and its working envelope): a force packet whose model has one is a
//! version-2 force packet followed by a bond flag (u8, 0 or 1) and the bond when it is 1, then
//! the follower, with version byte 4. A version-4 force packet is at most [`MAX_PACKET`] bytes
//! whatever the model holds.
//!
//! | type | name    | direction     | body after the header                                              |
//! |------|---------|---------------|--------------------------------------------------------------------|
//! | 1    | hello   | device → sim  | rate u32, max force f64 (N), max stiffness f64 (N/m), workspace radius f64 (m), name (u8 length + UTF-8), button count u8, button names (u8 length + UTF-8 each) |
//! | 2    | welcome | sim → device  | tick rate u32 (Hz), session start u64 (ns since the Unix epoch), scene name (u8 length + UTF-8), button roles 4 × u8 |
//! | 3    | sample  | device → sim  | seq u64, device time u64 (ns), position 3 × f64 (m), buttons u32   |
//! | 4    | force   | sim → device  | seq answered u64, tick u64, force 3 × f64 (N), stiffness 9 × f64 (N/m, row-major), status u8 |
//! | 5    | bye     | either        | reason u8 (0: end of session, 1: error)                             |
//! | 6    | refusal | sim → device  | field, allowed values, message (u8 length + UTF-8 each)             |
//!
//! The module holds the packets as types (`packets`: [`Packet`], [`Sample`], [`ForceReply`],
//! [`ProtocolError`]) apart from their codec: `encode` ([`Packet::encode`]) and `decode`
//! ([`Packet::decode`], one decoder per packet type, over the bounds-checked byte reader of
//! `reader`).

mod decode;
mod encode;
mod packets;
mod reader;

pub use packets::{ForceReply, Packet, ProtocolError, Refusal, Sample};

/// The magic bytes every packet starts with.
pub const MAGIC: [u8; 4] = *b"NHDB";
/// The protocol version of samples and byes (the same in both versions).
pub const VERSION: u8 = 1;
/// Protocol version 2: the local model.
pub const VERSION_2: u8 = 2;
/// Protocol version 3: the local model with a bond (a spring that breaks).
pub const VERSION_3: u8 = 3;
/// The newest protocol version this build speaks: 4, the local model with a follower (the
/// optical tweezers' held particle and its working envelope).
pub const VERSION_4: u8 = 4;
/// Size of the local model's fixed part after a version-1 force packet, bytes (residual
/// force and stiffness, world energy).
const LOCAL_FIXED_LEN: usize = 12 * 8 + 8;
/// Size of one plane on the wire: normal, offset, stiffness.
const PLANE_LEN: usize = 5 * 8;
/// Size of the body on the wire: position, velocity, mass, three coupling constants, damper
/// share, external force, substeps (u32), restitution.
const BODY_LEN: usize = 16 * 8 + 4 + 8;
/// Size of the bond on the wire: anchor, normal, stiffness, breaking stretch.
const BOND_LEN: usize = 8 * 8;
/// Size of the follower's fixed part on the wire: position, drift, retain, stiffness, vertex
/// count (u8); each vertex adds [`VERTEX_LEN`].
const FOLLOWER_FIXED_LEN: usize = 6 * 8 + 1;
/// Size of one envelope vertex on the wire: x, y.
const VERTEX_LEN: usize = 2 * 8;
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
/// Size of the header, bytes.
const HEADER_LEN: usize = 8;
/// Shortest time between two refusals the simulator sends, s (a device repeats its hello every
/// 50 ms; it hears why at most every 100 ms).
pub const REFUSAL_INTERVAL_S: f64 = 0.1;
/// The packet type of a refusal.
pub const REFUSAL_TYPE: u8 = 6;

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

/// Size of a version-3 force packet (a version-2 one and its bond), bytes.
pub fn force_v3_len(planes: usize, body: bool, body_planes: usize) -> usize {
    force_v2_len(planes, body, body_planes) + BOND_LEN
}

/// Size of a version-4 force packet (a version-2 one, the bond flag and the bond if `bond`,
/// the follower with `vertices` envelope vertices), bytes.
pub fn force_v4_len(
    planes: usize,
    body: bool,
    body_planes: usize,
    bond: bool,
    vertices: usize,
) -> usize {
    force_v2_len(planes, body, body_planes)
        + 1
        + if bond { BOND_LEN } else { 0 }
        + FOLLOWER_FIXED_LEN
        + vertices * VERTEX_LEN
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::device::{FALCON, TOUCH};
    use haptic_types::local::{Body, LocalModel, MAX_PLANES, MAX_REACH_VERTICES, Plane};
    use proptest::prelude::*;

    /// A force reply at tick 1 with no force and no stiffness, carrying the local model `m`.
    fn at_rest(m: LocalModel) -> Packet {
        Packet::Force(ForceReply {
            seq: 1,
            tick: 1,
            force_n: [0.0; 3],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(m)),
        })
    }

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
            roles: Some([0, 1, 2, 3]),
        };
        // 8 + 4 + 8 + 1 + 4 ("wall") + 4 role bytes.
        assert_eq!(w.encode().len(), 29);
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
        v[4] = 5;
        assert_eq!(e(&v), "protocol version 5 (this build speaks 1 to 4)");
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
            "hello refused: device specs: `max_force_n` = inf is out of range: allowed 0.001 ≤ \
             max_force_n ≤ 1000"
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
            "hello refused: device specs: `max_force_n` = 3.7555737088373936e-159 is out of \
             range: allowed 0.001 ≤ max_force_n ≤ 1000"
        );
    }

    /// A hello above version 4 is read (the simulator welcomes it with 4); version 0, bad
    /// limits, bad names and a bad size are refusals naming the field and the allowed values;
    /// the reserved bytes are not read.
    #[test]
    fn hellos_negotiate_down_or_are_refused_by_field() {
        let hello = |version: u8, specs: haptic_types::DeviceSpecs| {
            Packet::Hello {
                version,
                rate_hz: 1000,
                specs,
            }
            .encode()
        };
        let mut h3 = hello(5, FALCON);
        assert!(matches!(
            Packet::decode(&h3),
            Ok(Packet::Hello { version: 5, .. })
        ));
        // Reserved bytes 6–7: sent as 0, never read.
        h3[6] = 1;
        h3[7] = 0xff;
        assert!(matches!(Packet::decode(&h3), Ok(Packet::Hello { .. })));
        let refusal = |b: &[u8]| match Packet::decode(b) {
            Err(ProtocolError::Hello(r)) => (r.field, r.allowed),
            other => panic!("{other:?}"),
        };
        assert_eq!(
            refusal(&hello(0, FALCON)),
            (
                "version".into(),
                "1 or more (a hello above 4 is welcomed with version 4)".into()
            )
        );
        let mut bad = FALCON;
        bad.workspace_radius_m = 20.0;
        assert_eq!(
            refusal(&hello(2, bad)),
            (
                "workspace_radius_m".into(),
                "1e-4 ≤ workspace_radius_m ≤ 10".into()
            )
        );
        let mut many = FALCON;
        many.button_names = vec![std::borrow::Cow::Borrowed("b"); 33].into();
        assert_eq!(
            refusal(&hello(2, many)),
            ("button_names".into(), "at most 32 buttons".into())
        );
        // Roles bind to buttons by name: a hello naming two buttons alike is refused.
        let mut twice = FALCON;
        twice.button_names = ["a", "b", "a"]
            .map(std::borrow::Cow::Borrowed)
            .to_vec()
            .into();
        let e = |b: &[u8]| Packet::decode(b).unwrap_err().to_string();
        assert_eq!(
            e(&hello(2, twice.clone())),
            "hello refused: device specs: `button_names` = \"a\" (buttons 0 and 2) is out of \
             range: allowed distinct names (a role is bound to a button by its name)"
        );
        assert_eq!(
            refusal(&hello(2, twice)),
            (
                "button_names".into(),
                "distinct names (a role is bound to a button by its name)".into()
            )
        );
        let good = hello(2, FALCON);
        assert_eq!(refusal(&good[..30]).0, "size");
        let mut long = good.clone();
        long.push(0);
        assert_eq!(refusal(&long).0, "size");
        // Other packets keep the strict version check.
        let mut bye = Packet::Bye { reason: 0 }.encode();
        bye[4] = 5;
        assert_eq!(Packet::decode(&bye), Err(ProtocolError::Version(5)));
    }

    /// A refusal is the header (version byte 1, type 6) and three strings; it round-trips,
    /// and a message longer than 255 bytes is cut at a character boundary.
    #[test]
    fn a_refusal_round_trips_with_its_documented_layout() {
        let r = Packet::Refusal(Refusal::new(
            "version",
            "1 or more",
            "hello refused: `version` = 0".into(),
        ));
        let b = r.encode();
        assert_eq!(&b[..8], b"NHDB\x01\x06\x00\x00");
        assert_eq!(b.len(), 8 + 1 + 7 + 1 + 9 + 1 + 28);
        assert_eq!(Packet::decode(&b), Ok(r));
        let long = Packet::Refusal(Refusal::new("f", "a", "≤".repeat(100)));
        match Packet::decode(&long.encode()) {
            Ok(Packet::Refusal(r)) => assert_eq!(r.message, "≤".repeat(85)),
            other => panic!("{other:?}"),
        }
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
            bond: None,
            follower: None,
        }
    }

    /// The packet `b` one byte short and one byte long is refused by size, named `kind`.
    fn refused_a_byte_off(b: &[u8], kind: &str) {
        let e = |b: &[u8]| Packet::decode(b).unwrap_err().to_string();
        let n = b.len();
        assert_eq!(
            e(&b[..n - 1]),
            format!("{kind} packet of {} bytes is too short (needs {n})", n - 1)
        );
        let mut long = b.to_vec();
        long.push(0);
        assert_eq!(
            e(&long),
            format!(
                "{kind} packet of {} bytes is too long (expected {n})",
                n + 1
            )
        );
    }

    /// A model with a bond travels as a version-3 force packet: the version-2 packet and 64
    /// bytes of bond, read back bit for bit; a version-3 packet one byte short or long, or
    /// with a bond out of range, is refused by name.
    #[test]
    fn a_version_3_force_packet_carries_the_bond_after_the_model() {
        let bond = haptic_types::local::Bond {
            anchor_m: [0.001, -0.002, 0.003],
            normal: [0.0, 0.6, 0.8],
            stiffness_n_per_m: 350.0,
            break_m: 0.0025,
        };
        let m = LocalModel {
            bond: Some(bond),
            ..full_model()
        };
        let b = at_rest(m.clone()).encode();
        assert_eq!(b[4], 3);
        let (n, body, nb) = (m.planes.len(), m.body.is_some(), m.body_planes.len());
        assert_eq!(b.len(), force_v3_len(n, body, nb));
        assert_eq!(b.len(), force_v2_len(n, body, nb) + 64);
        match Packet::decode(&b) {
            Ok(Packet::Force(f)) => assert_eq!(f.local.as_deref(), Some(&m)),
            other => panic!("{other:?}"),
        }
        // Without a bond the same model is a version-2 packet.
        let v2 = at_rest(full_model()).encode();
        assert_eq!((v2[4], v2.len()), (2, b.len() - 64));
        let e = |b: &[u8]| Packet::decode(b).unwrap_err().to_string();
        refused_a_byte_off(&b, "force (version 3)");
        let broken = LocalModel {
            bond: Some(haptic_types::local::Bond {
                break_m: -1.0,
                ..bond
            }),
            ..full_model()
        };
        assert_eq!(
            e(&at_rest(broken).encode()),
            "force packet's local model: bond.break_m = -1 is out of range: allowed 0 < s ≤ 1 m"
        );
    }

    fn follower(vertices: usize) -> haptic_types::local::Follower {
        haptic_types::local::Follower {
            position_m: [0.004, -0.003],
            drift_m: [1e-5, 2e-5],
            reach_m: (0..vertices)
                .map(|k| {
                    let th = std::f64::consts::TAU * k as f64 / vertices as f64;
                    [6e-5 * th.cos(), 3e-5 * th.sin()]
                })
                .collect(),
            retain: 0.1,
            stiffness_n_per_m: 800.0,
        }
    }

    /// A model with a follower travels as a version-4 force packet: the version-2 packet, the
    /// bond flag (and bond), the follower's 49 bytes and 16 a vertex, read back bit for bit;
    /// the largest (every plane, a body, a bond, 24 vertices) fits one datagram; a packet one
    /// byte short or long, a bad bond flag or a bad follower is refused by name.
    #[test]
    fn a_version_4_force_packet_carries_the_follower_after_the_bond_flag() {
        let e = |b: &[u8]| Packet::decode(b).unwrap_err().to_string();
        for (bond, vertices) in [(false, 3), (false, 24), (true, 24)] {
            let m = LocalModel {
                bond: bond.then_some(haptic_types::local::Bond {
                    anchor_m: [0.001, -0.002, 0.003],
                    normal: [0.0, 0.6, 0.8],
                    stiffness_n_per_m: 350.0,
                    break_m: 0.0025,
                }),
                follower: Some(follower(vertices)),
                ..full_model()
            };
            let b = at_rest(m.clone()).encode();
            assert_eq!(b[4], 4);
            let (n, body, nb) = (m.planes.len(), m.body.is_some(), m.body_planes.len());
            assert_eq!(b.len(), force_v4_len(n, body, nb, bond, vertices));
            assert_eq!(
                b.len(),
                force_v2_len(n, body, nb) + 1 + if bond { 64 } else { 0 } + 49 + 16 * vertices
            );
            match Packet::decode(&b) {
                Ok(Packet::Force(f)) => assert_eq!(f.local.as_deref(), Some(&m)),
                other => panic!("{other:?}"),
            }
            refused_a_byte_off(&b, "force (version 4)");
        }
        let largest = force_v4_len(MAX_PLANES, true, MAX_PLANES, true, MAX_REACH_VERTICES);
        assert!(largest <= MAX_PACKET, "{largest}");
        // The bond flag sits right after the version-2 model.
        let m = LocalModel {
            follower: Some(follower(8)),
            ..full_model()
        };
        let mut b = at_rest(m).encode();
        let flag = force_v2_len(2, true, 1);
        assert_eq!(b[flag], 0);
        b[flag] = 2;
        assert_eq!(
            e(&b),
            "force packet's local model: bond flag 2: allowed 0 (none) or 1"
        );
        let bad = LocalModel {
            follower: Some(haptic_types::local::Follower {
                retain: 2.0,
                ..follower(8)
            }),
            ..full_model()
        };
        assert_eq!(
            e(&at_rest(bad).encode()),
            "force packet's local model: follower.retain = 2 is out of range: allowed 0 ≤ r ≤ 1"
        );
        let few = LocalModel {
            follower: Some(follower(2)),
            ..full_model()
        };
        assert_eq!(
            e(&at_rest(few).encode()),
            "force packet's local model: follower.reach_m (vertices) = 2 is out of range: \
             allowed 3 ≤ n ≤ 24"
        );
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
        let g = at_rest(m);
        assert_eq!(g.encode().len(), force_v2_len(2, false, 1));
        assert_eq!(Packet::decode(&g.encode()), Ok(g));
    }

    #[test]
    fn a_bad_local_model_is_refused_by_name() {
        let mut m = full_model();
        m.planes[1].normal = [2.0, 0.0, 0.0];
        let f = |m: LocalModel| {
            Packet::decode(&at_rest(m).encode())
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
        let mut b = at_rest(full_model()).encode();
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
