//! Encoding packets to datagrams.

use super::{MAGIC, Packet, VERSION, VERSION_2, VERSION_3, VERSION_4};
use haptic_types::local::{Bond, Follower, LocalModel, MAX_PLANES, MAX_REACH_VERTICES, Plane};

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

fn put_bond(v: &mut Vec<u8>, b: &Bond) {
    put_f64s(v, &b.anchor_m);
    put_f64s(v, &b.normal);
    put_f64s(v, &[b.stiffness_n_per_m, b.break_m]);
}

fn put_follower(v: &mut Vec<u8>, f: &Follower) {
    put_f64s(v, &f.position_m);
    put_f64s(v, &f.drift_m);
    put_f64s(v, &[f.retain, f.stiffness_n_per_m]);
    v.push(f.reach_m.len().min(MAX_REACH_VERTICES) as u8);
    for p in f.reach_m.iter().take(MAX_REACH_VERTICES) {
        put_f64s(v, p);
    }
}

/// A string as a u8 length and its bytes, cut to 255 bytes at a character boundary.
fn put_str(v: &mut Vec<u8>, s: &str) {
    let mut n = s.len().min(255);
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    let b = s.as_bytes();
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
                roles,
            } => {
                header(v, *version, 2);
                v.extend_from_slice(&rate_hz.to_le_bytes());
                v.extend_from_slice(&start_time_ns.to_le_bytes());
                put_str(v, scene);
                if let Some(r) = roles {
                    v.extend_from_slice(r);
                }
            }
            Packet::Refusal(r) => {
                header(v, VERSION, super::REFUSAL_TYPE);
                put_str(v, &r.field);
                put_str(v, &r.allowed);
                put_str(v, &r.message);
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
                let version = match &f.local {
                    Some(m) if m.follower.is_some() => VERSION_4,
                    Some(m) if m.bond.is_some() => VERSION_3,
                    Some(_) => VERSION_2,
                    None => VERSION,
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
                    match (&m.follower, &m.bond) {
                        (Some(fo), bond) => {
                            v.push(u8::from(bond.is_some()));
                            if let Some(b) = bond {
                                put_bond(v, b);
                            }
                            put_follower(v, fo);
                        }
                        (None, Some(b)) => put_bond(v, b),
                        (None, None) => {}
                    }
                }
            }
            Packet::Bye { reason } => {
                header(v, VERSION, 5);
                v.push(*reason);
            }
        }
    }
}
