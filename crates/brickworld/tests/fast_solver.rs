//! The solver setting the shipped brick scene opts into (`scenes/brickworld.toml`: fewer
//! solver iterations, softer contacts; issue 33, "A falling tower within half a tick"),
//! checked for what it costs in accuracy: stacks and a tall wall stay put, flat drops rebound
//! at `e²`, ramps hold up to `atan μ`, and a knocked-over wall is deterministic to the bit.
//! Issue 11's checks (the centred flat drop among them, with this setting's own bounds) run
//! under both settings in `issue11.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::needless_range_loop)]

mod common;
use brickworld::{BrickId, BrickProps, Params};
use common::*;

const PARK: [f64; 3] = [1.5, 1.5, 1.0];

/// The default parameters with the shipped scene's solver setting.
fn fast() -> Params {
    scene_solver()
}

/// The scene's solver fields: absent, today's defaults (4 iterations, 500 Hz: what every
/// recording made before them replays with); out of range, a typed error naming the field and
/// its allowed range.
#[test]
fn the_solver_fields_default_to_today_and_are_range_checked() {
    let p = Params::from_toml("dt_s = 0.001").unwrap();
    assert_eq!((p.solver_iterations, p.contact_frequency_hz), (4, 500.0));
    let p = Params::from_toml("solver_iterations = 1\ncontact_frequency_hz = 175.0").unwrap();
    assert_eq!((p.solver_iterations, p.contact_frequency_hz), (1, 175.0));
    for (text, field, range) in [
        ("solver_iterations = 0", "solver_iterations", "[1, 64]"),
        ("solver_iterations = 65", "solver_iterations", "[1, 64]"),
        (
            "contact_frequency_hz = 0.5",
            "contact_frequency_hz",
            "[1, 1000]",
        ),
        (
            "contact_frequency_hz = nan",
            "contact_frequency_hz",
            "[1, 1000]",
        ),
    ] {
        let e = Params::from_toml(text).unwrap_err();
        let brickworld::ParamsFromTomlError::Param(pe) = &e else {
            panic!("{text}: {e}");
        };
        assert_eq!(pe.field(), field, "{text}");
        assert!(e.to_string().contains(range), "{text}: {e}");
    }
}

/// The largest distance any brick moved between two snapshots, m.
#[test]
fn the_scene_opts_into_a_cheaper_solver() {
    let (p, d) = (fast(), Params::default());
    assert!(p.solver_iterations < d.solver_iterations, "{p:?}");
    p.validate().unwrap();
}

/// A stack of ten bricks, sleeping off (simulated every tick): the top settles within 1.5 mm
/// of the exact stack (measured 1.12 mm at 1 iteration, 175 Hz; 0.14 mm at the default 4,
/// 500 Hz) and no brick moves 0.01 mm between 2 s and 10 s.
#[test]
fn a_stack_of_ten_sinks_under_1_5_mm_and_stays_put() {
    let mut p = fast();
    p.sleeping = false;
    let h = p.brick_half_extents_m;
    p.bricks = (0..10)
        .map(|i| at([0.0, 0.0, h[2] * (2 * i + 1) as f64]))
        .collect();
    let top0 = p.bricks[9].center_m[2];
    let mut w = world(p);
    for _ in 0..2000 {
        idle(&mut w, PARK);
    }
    let settled: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    let sink = top0 - settled[9][2];
    for _ in 0..8000 {
        idle(&mut w, PARK);
    }
    let now: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    let drift = moved(&settled, &now);
    println!(
        "stack sink {:.3} mm, drift 2-10 s {:.2e} m",
        sink * 1e3,
        drift
    );
    assert!(sink.abs() < 1.5e-3, "top sank {sink} m");
    assert!(drift < 1e-5, "drift {drift} m");
    // docs/brickworld.md: "the stack settles 1.12 mm" under the shipped solver (to 0.01 mm);
    // BENCHMARKS.md's solver table, the shipped row: 1.118 mm (to 0.001 mm).
    assert!((sink * 1e3 - 1.118).abs() <= 0.5e-3, "top sank {sink} m");
}

/// The tallest thing the world holds: a 200-brick wall of 20 courses in running bond, 1.2 m
/// high, sleeping off. Standing for 5 s, no brick moves 0.1 mm after the first second
/// (measured 0.013 mm at 1 iteration, 175 Hz; 0.69 mm at 200 Hz and 12.1 mm at 250 Hz, where
/// the stiffer contacts let it creep), and its top settles within 3 mm (1.8 mm).
#[test]
fn a_wall_of_200_bricks_stands() {
    let mut p = fast();
    p.sleeping = false;
    let h = p.brick_half_extents_m;
    running_bond_wall(&mut p);
    let mut w = world(p);
    for _ in 0..1000 {
        idle(&mut w, PARK);
    }
    let settled: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    for _ in 0..4000 {
        idle(&mut w, PARK);
    }
    let now: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    let drift = moved(&settled, &now);
    let top = now.iter().map(|b| b[2]).fold(0.0, f64::max);
    println!("wall drift 1-5 s {drift:.2e} m, top centre {top:.4} m");
    assert!(drift < 1e-4, "drift {drift} m");
    assert!((top - h[2] * 39.0).abs() < 3e-3, "top centre at {top} m");
    // BENCHMARKS.md's solver table, the shipped row: "wall drift 1–5 s 0.0127 mm, wall sink
    // 1.813 mm" (to the printed digit).
    assert!((drift * 1e3 - 0.0127).abs() <= 0.5e-4, "drift {drift} m");
    assert!(
        ((h[2] * 39.0 - top) * 1e3 - 1.813).abs() <= 0.5e-3,
        "top sank {} m",
        h[2] * 39.0 - top
    );
}

/// A flat brick dropped from 0.5 m rebounds to `e² h` within 3 % (the physics target; 2.9 %
/// for e = 0.3 at 1 iteration, 0.8 % at the default 4: the target is met with little room).
#[test]
fn flat_drops_rebound_at_e_squared_within_3_percent() {
    for e in [0.3, 0.5, 0.7, 0.9] {
        let mut p = fast();
        p.restitution = e;
        p.sleeping = false;
        let hz = p.brick_half_extents_m[2];
        p.bricks = vec![at([0.0, 0.0, hz + 0.5])];
        let mut w = world(p);
        let (mut hit, mut apex) = (false, 0.0_f64);
        for _ in 0..4000 {
            idle(&mut w, PARK);
            let b = w.brick(BrickId(0)).unwrap();
            hit |= b.velocity_m_per_s[2] > 0.0;
            if hit {
                apex = apex.max(b.position_m[2] - hz);
                if b.velocity_m_per_s[2] < 0.0 && apex > 0.0 {
                    break;
                }
            }
        }
        let r = apex / 0.5;
        let rel = (r - e * e).abs() / (e * e);
        println!("e = {e}: h1/h0 {r:.4}, rel error {rel:.4}");
        assert!(rel < 0.03, "e = {e}: {r} against {}", e * e);
        // docs/brickworld.md: "within 2.94 % (e = 0.3; 0.10–1.17 % for e = 0.5–0.9)", each
        // end of that range to its printed 0.01 %.
        let pct = 100.0 * rel;
        match e {
            0.3 => assert!((pct - 2.94).abs() < 0.005, "e = 0.3: {pct} %"),
            0.5 => assert!((pct - 0.10).abs() < 0.005, "e = 0.5: {pct} %"),
            0.9 => assert!((pct - 1.17).abs() < 0.005, "e = 0.9: {pct} %"),
            _ => assert!((0.10..=1.17).contains(&pct), "e = {e}: {pct} %"),
        }
    }
}

/// A brick on a ramp 1° below the friction angle (μ = 0.6) holds (under 1 mm in 1 s); 1°
/// above, it slides.
#[test]
fn a_ramp_holds_below_the_friction_angle_and_not_above() {
    let slide = |theta_deg: f64| {
        let mut p = fast();
        p.friction = 0.6;
        p.restitution = 0.0;
        let h = p.brick_half_extents_m;
        p.obstacles = vec![brickworld::Obstacle {
            center_m: [0.0, 0.0, 0.5],
            half_extents_m: [0.6, 0.3, 0.05],
            rotation_deg: [0.0, theta_deg, 0.0],
        }];
        let t = theta_deg.to_radians();
        let up = 0.05 + h[2];
        let c = [up * t.sin(), 0.0, 0.5 + up * t.cos()];
        p.bricks = vec![brickworld::BrickPlacement {
            center_m: c,
            rotation_deg: [0.0, theta_deg, 0.0],
        }];
        let mut w = world(p);
        for _ in 0..1000 {
            idle(&mut w, PARK);
        }
        let b = w.brick(BrickId(0)).unwrap().position_m;
        moved(&[b], &[c])
    };
    let crit = 0.6_f64.atan().to_degrees();
    let (below, above) = (slide(crit - 1.0), slide(crit + 1.0));
    println!("1 s at atan μ − 1°: {below:.2e} m, at + 1°: {above:.3} m");
    assert!(below < 1e-3, "slid {below} m below the friction angle");
    assert!(above > 0.01, "slid only {above} m above the friction angle");
}

/// The knocked-over 200-brick wall, run twice: the same bricks, bit for bit.
#[test]
fn a_knocked_over_wall_is_deterministic() {
    let run = || {
        let p = fast();
        let h = p.brick_half_extents_m;
        let mut w = world(p);
        for c in 0..20 {
            let shift = if c % 2 == 0 { 0.0 } else { h[0] };
            for i in 0..10 {
                let props = BrickProps {
                    velocity_m_per_s: if c >= 10 { [0.0, 1.0, 0.0] } else { [0.0; 3] },
                    ..BrickProps::default()
                };
                w.add_brick_with(
                    at([
                        (i as f64 - 4.5) * (2.0 * h[0] + 0.001) + shift - h[0] / 2.0,
                        0.0,
                        h[2] * (2 * c + 1) as f64,
                    ]),
                    props,
                )
                .unwrap();
            }
        }
        for _ in 0..1500 {
            idle(&mut w, PARK);
        }
        let fell = w
            .bricks()
            .filter(|b| {
                let course = b.id.0 as usize / 10;
                course >= 10 && b.position_m[2] < h[2] * (2 * course + 1) as f64 - 2.0 * h[2]
            })
            .count();
        let bits = w
            .bricks()
            .flat_map(|b| {
                let mut v = b.position_m.to_vec();
                v.extend(b.orientation_xyzw);
                v.extend(b.velocity_m_per_s);
                v
            })
            .map(f64::to_bits)
            .collect::<Vec<u64>>();
        (bits, fell)
    };
    let (a, b) = (run(), run());
    assert_eq!(a, b);
    // The knocked top half did fall: bricks of it are now a course or more below their start.
    println!("{} of the 100 knocked bricks fell a course or more", a.1);
    assert!(a.1 >= 20, "{} bricks fell", a.1);
}
