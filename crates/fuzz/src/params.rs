//! The `params` target: a world's parameter table as the Python wheel receives it (a dict
//! converted to a TOML value, then read by serde and validated whole). Each of the three
//! worlds reads the same text; a table it accepts builds a world that is stepped along a short
//! path, and every force must be finite and within the device's limit.

use crate::outcome::Outcome;
use nalgebra::Vector3;
use world_form::Limits;

fn falcon() -> Limits {
    Limits {
        max_force_n: 8.0,
        max_stiffness_n_per_m: 3000.0,
    }
}

fn finding(world: &str, k: usize, f: &[f64], max: f64) -> Option<Outcome> {
    let n = f.iter().map(|x| x * x).sum::<f64>().sqrt();
    if f.iter().all(|x| x.is_finite()) && n <= max * (1.0 + 1e-9) {
        return None;
    }
    Some(Outcome::Finding(
        "non-finite",
        format!("{world} tick {k}: force of norm {n} N (limit {max} N)"),
    ))
}

/// Runs one parameter table through the three worlds.
pub fn run_params(input: &[u8]) -> Outcome {
    let Ok(text) = std::str::from_utf8(input) else {
        return Outcome::Refused;
    };
    let Ok(table) = toml::from_str::<toml::Table>(text) else {
        return Outcome::Refused;
    };
    let value = toml::Value::Table(table);
    let mut accepted = false;
    if let Ok(p) = value.clone().try_into::<nanoworld::Params>() {
        let limits = p.default_limits();
        if let Ok(mut w) = nanoworld::World::new(&p, &limits, Vector3::new(0.0, 0.0, 2e-9)) {
            accepted = true;
            for k in 0..20 {
                let z = 2e-9 - 1e-10 * k as f64;
                let input = nanoworld::TipInput {
                    position_m: Vector3::new(1e-10 * k as f64, 0.0, z),
                };
                if let Ok(r) = w.step(&input, 1e-3) {
                    let f = [r.force_n.x, r.force_n.y, r.force_n.z];
                    if let Some(o) = finding("nano", k, &f, limits.max_force_n) {
                        return o;
                    }
                }
            }
        }
    }
    if let Ok(p) = value.clone().try_into::<brickworld::Params>() {
        let limits = falcon();
        if let Ok(mut w) = brickworld::World::new(&p, &limits) {
            accepted = true;
            for k in 0..20 {
                let grip = brickworld::input::Grip {
                    hold: k >= 10,
                    ..Default::default()
                };
                let pos = [0.001 * k as f64, 0.0, 0.05 - 0.002 * k as f64];
                if let Ok(i) = w.input(pos, grip) {
                    let r = w.step(&i);
                    if let Some(o) = finding("brick", k, &r.force_n, limits.max_force_n) {
                        return o;
                    }
                }
            }
        }
    }
    if let Ok(p) = value.try_into::<ot_envelope::world::Params>() {
        let limits = falcon();
        if let Ok(mut w) = ot_envelope::world::World::new(&p, &limits) {
            accepted = true;
            for k in 0..8 {
                let input = ot_envelope::world::Input {
                    cursor_m: [1e-8 * k as f64, 0.0],
                    grab: k >= 2,
                };
                let r = w.step(&input);
                if let Some(o) = finding("optical", k, &r.force_n, limits.max_force_n) {
                    return o;
                }
            }
        }
    }
    if accepted {
        Outcome::Accepted
    } else {
        Outcome::Refused
    }
}

/// Seeds: each world's default table, as TOML.
pub fn seeds() -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut push = |v: Result<String, toml::ser::Error>| {
        if let Ok(s) = v {
            out.push(s.into_bytes());
        }
    };
    push(toml::to_string(&nanoworld::Params::game_default()));
    push(toml::to_string(&nanoworld::Params::physical_default()));
    push(toml::to_string(&brickworld::Params::default()));
    push(toml::to_string(&ot_envelope::world::Params::paper()));
    out
}
