//! The `scene`, `script` and `bridge` targets: an accepted input drives the haptic loop (or a
//! script is sampled), and every force must be finite and within the device's limit.

use super::{Outcome, falcon};
use haptic_devices::Script;
use haptic_devices::bridge::protocol::{ForceReply, Packet, Sample};
use haptic_devices::local::{DeviceSide, Protocol};
use haptic_engine::HapticLoop;
use haptic_loop::scene::load_scene_for;
use haptic_types::Buttons;
use haptic_types::DeviceSample;
use haptic_types::DeviceSpecs;

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Ticks a loop along a short path (with the first button pressed half-way), checking that every
/// force is finite and the device force within the device's limit.
fn drive(lp: &mut HapticLoop, specs: &DeviceSpecs, start: [f64; 3], ticks: u64) -> Outcome {
    let r = 0.5 * specs.workspace_radius_m.clamp(0.0, 0.2);
    for k in 0..ticks {
        let a = k as f64 * 0.2;
        let p = [
            start[0] + 0.1 * r * a.cos(),
            start[1] + 0.1 * r * a.sin(),
            start[2] - 0.2 * r * (k as f64 / ticks as f64),
        ];
        let s = DeviceSample {
            position_m: p,
            buttons: Buttons(u32::from(k > ticks / 2)),
            seq: k,
            age_ticks: 0,
        };
        let t = lp.tick(s, false);
        if !finite3(t.world_force_n) || !finite3(t.device_force_n) {
            return Outcome::Finding(
                "non-finite",
                format!(
                    "tick {k}: world force ({}, {}, {}) N, device force ({}, {}, {}) N",
                    t.world_force_n[0],
                    t.world_force_n[1],
                    t.world_force_n[2],
                    t.device_force_n[0],
                    t.device_force_n[1],
                    t.device_force_n[2]
                ),
            );
        }
        let f = norm(t.device_force_n);
        if f > specs.limits.max_force_n * (1.0 + 1e-9) {
            return Outcome::Finding(
                "over-limit",
                format!(
                    "tick {k}: device force {f} N over the limit {} N",
                    specs.limits.max_force_n
                ),
            );
        }
    }
    Outcome::Accepted
}

/// A scene file for a Falcon; an accepted scene is ticked 40 times along a path.
pub fn run_scene(input: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(input);
    match load_scene_for(&text, falcon().clone()) {
        Err(_) => Outcome::Refused,
        Ok(l) => {
            let mut lp = HapticLoop::new(l.config, l.scene);
            drive(&mut lp, falcon(), [0.0, 0.0, 0.0], 40)
        }
    }
}

/// A script file; an accepted script is sampled at 51 times (finite positions and velocities).
pub fn run_script(input: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(input);
    match Script::from_toml(&text, falcon()) {
        Err(_) => Outcome::Refused,
        Ok(s) => {
            if !s.duration_s.is_finite() {
                return Outcome::Finding("non-finite", format!("duration {} s", s.duration_s));
            }
            for k in 0..=50 {
                let t = s.duration_s * f64::from(k) / 50.0;
                let p = s.position(t);
                if !finite3(p) || !finite3(s.velocity(t)) {
                    return Outcome::Finding(
                        "non-finite",
                        format!("position ({}, {}, {}) m at t = {t} s", p[0], p[1], p[2]),
                    );
                }
            }
            Outcome::Accepted
        }
    }
}

/// A bridge datagram: decode, re-encode, decode; samples and announced specifications drive the
/// wall scene (finite forces within the limit).
pub fn run_bridge(input: &[u8]) -> Outcome {
    let Ok(p) = Packet::decode(input) else {
        return Outcome::Refused;
    };
    if let Some(finding) = round_trip(&p) {
        return finding;
    }
    let wall = haptic_loop::builtin::SCENES
        .iter()
        .find(|b| b.name == "wall")
        .map(|b| b.scene)
        .unwrap_or_default();
    match p {
        Packet::Sample(s) => bridge_sample(wall, &s),
        Packet::Force(f) => bridge_force(&f),
        Packet::Hello { specs, .. } => {
            // Announced specifications drive a session: its forces respect them.
            match load_scene_for(wall, specs.clone()) {
                Err(_) => Outcome::Refused,
                Ok(l) => {
                    let mut lp = HapticLoop::new(l.config, l.scene);
                    drive(&mut lp, &specs, [0.0, 0.0, 0.0], 20)
                }
            }
        }
        _ => Outcome::Accepted,
    }
}

/// Encoding what was decoded and decoding it again gives the same packet; a finding if not.
fn round_trip(p: &Packet) -> Option<Outcome> {
    let once = p.encode();
    match Packet::decode(&once).map(|q| q.encode()) {
        Ok(twice) if twice == once => None,
        Ok(_) => Some(Outcome::Finding(
            "round-trip",
            "re-encoding changes the packet".into(),
        )),
        Err(e) => Some(Outcome::Finding(
            "round-trip",
            format!("an accepted packet, re-encoded, is refused: {e}"),
        )),
    }
}

/// A device sample straight into the loop of the `wall` scene: the force stays finite and
/// bounded.
fn bridge_sample(wall: &str, s: &Sample) -> Outcome {
    let Ok(l) = load_scene_for(wall, falcon().clone()) else {
        return Outcome::Finding("seed", "the wall scene does not load".into());
    };
    let mut lp = HapticLoop::new(l.config, l.scene);
    for k in 0..3 {
        let t = lp.tick(
            DeviceSample {
                position_m: s.position_m,
                buttons: Buttons(s.buttons),
                seq: s.seq,
                age_ticks: k,
            },
            false,
        );
        if !finite3(t.device_force_n) || norm(t.device_force_n) > falcon().limits.max_force_n {
            return Outcome::Finding(
                "non-finite",
                format!(
                    "sample at ({}, {}, {}) m gives device force ({}, {}, {}) N",
                    s.position_m[0],
                    s.position_m[1],
                    s.position_m[2],
                    t.device_force_n[0],
                    t.device_force_n[1],
                    t.device_force_n[2]
                ),
            );
        }
    }
    Outcome::Accepted
}

/// A force packet rendered by the device side (a Falcon's servo thread, every protocol): the
/// force its motors are asked for stays finite and within the limit.
fn bridge_force(f: &ForceReply) -> Outcome {
    let max = falcon().limits.max_force_n;
    for protocol in [Protocol::V1, Protocol::V2, Protocol::V3, Protocol::V4] {
        let mut side = DeviceSide::new(protocol, max, 1e-3);
        side.record_reading(f.seq, [0.0; 3]);
        side.record_reading(f.seq.saturating_add(1), [0.001, 0.0, -0.002]);
        side.receive(&f.command(), f.local.as_deref().cloned());
        for p in [[0.0; 3], [0.001, 0.0, -0.002], [0.03, -0.03, 0.03]] {
            let g = side.render(p, 2.5e-4);
            // Within the limit to rounding (the motors clamp exactly).
            if !finite3(g) || norm(g) > max * (1.0 + 1e-12) {
                return Outcome::Finding(
                    "non-finite",
                    format!(
                        "protocol {} device side renders ({}, {}, {}) N at ({}, {}, {}) m",
                        protocol.version(),
                        g[0],
                        g[1],
                        g[2],
                        p[0],
                        p[1],
                        p[2]
                    ),
                );
            }
        }
    }
    Outcome::Accepted
}
