//! Quiet steps (`brickworld::rest`) seen from outside: when a world runs quiet, and that a
//! quiet world still answers every change at once.

mod common;

use brickworld::rest::{QUIET_AFTER_S, QUIET_SPEED_M_PER_S};
use brickworld::{BrickId, BrickPlacement, Event, Obstacle, Params};
use common::{at, bare, idle, moved, running_bond_wall, world};

const PARK: [f64; 3] = [1.5, 1.5, 1.5];

/// The number of steps of rest before the first quiet one.
fn rest_steps(p: &Params) -> usize {
    (QUIET_AFTER_S / p.dt_s).round() as usize
}

/// A brick at rest on a 20° ramp (μ = 0.6 holds it), sleeping off, runs quiet; friction set
/// to 0.2 makes it slide at once: the next step is a full one (a recycled contact would keep
/// the old friction, and did: the brick did not move), and 0.3 s later it has slid 2 cm.
#[test]
fn a_quiet_brick_feels_new_friction_at_once() {
    let mut p = bare();
    p.sleeping = false;
    let h = p.brick_half_extents_m;
    let th = 20.0_f64;
    p.obstacles = vec![Obstacle {
        center_m: [0.0, 0.0, 0.5],
        half_extents_m: [0.6, 0.3, 0.05],
        rotation_deg: [0.0, th, 0.0],
    }];
    let up = 0.05 + h[2];
    let t = th.to_radians();
    p.bricks = vec![BrickPlacement {
        center_m: [up * t.sin(), 0.0, 0.5 + up * t.cos()],
        rotation_deg: [0.0, th, 0.0],
    }];
    let mut w = world(p);
    for _ in 0..1000 {
        idle(&mut w, PARK);
    }
    assert!(w.quiet());
    let x0 = w.brick(BrickId(0)).unwrap().position_m[0];
    w.set_friction(0.2).unwrap();
    idle(&mut w, PARK);
    assert!(!w.quiet());
    for _ in 0..299 {
        idle(&mut w, PARK);
    }
    let slid = w.brick(BrickId(0)).unwrap().position_m[0] - x0;
    assert!(slid > 0.02, "slid {slid} m");
}

/// A brick dropped from 5 cm bounces (e = 0.5): no step runs quiet at the apex of a bounce
/// (the brick is slower than the quiet speed there for a few steps), only 50 ms after the
/// last impact, and from then on every step.
#[test]
fn a_bounce_is_not_quiet() {
    let mut p = bare();
    p.sleeping = false;
    p.restitution = 0.5;
    let h = p.brick_half_extents_m;
    p.bricks = vec![at([0.0, 0.0, h[2] + 0.05])];
    let need = rest_steps(&p);
    let mut w = world(p);
    let (mut last_impact, mut quiet) = (None, Vec::new());
    let mut slow_apex = false;
    for n in 0..1000 {
        let r = idle(&mut w, PARK);
        if r.events.iter().any(|e| matches!(e, Event::Impact { .. })) {
            last_impact = Some(n);
        }
        let v = w.brick(BrickId(0)).unwrap().velocity_m_per_s;
        let speed = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if last_impact.is_some() && speed < QUIET_SPEED_M_PER_S && n < 200 && !w.quiet() {
            slow_apex = true;
        }
        quiet.push(w.quiet());
    }
    let last = last_impact.expect("the brick lands");
    let first = quiet
        .iter()
        .position(|&q| q)
        .expect("the brick comes to rest");
    assert!(slow_apex, "some bounce apex is slower than the quiet speed");
    assert!(
        first >= last + need,
        "quiet at {first}, last impact at {last}"
    );
    assert!(quiet[first..].iter().all(|&q| q));
}

/// The hand pressing on a resting brick keeps every step a full one (what it feels is
/// computed from contacts computed afresh); 50 ms after it leaves, the world runs quiet.
#[test]
fn the_hands_touch_keeps_the_world_out_of_quiet() {
    let mut p = bare();
    p.sleeping = false;
    let h = p.brick_half_extents_m;
    p.bricks = vec![at([0.0, 0.0, h[2]])];
    let need = rest_steps(&p);
    let mut w = world(p);
    for _ in 0..200 {
        idle(&mut w, PARK);
    }
    assert!(w.quiet());
    let press = [0.0, 0.0, 2.0 * h[2] - 0.002];
    for _ in 0..300 {
        idle(&mut w, press);
        assert!(!w.touching().is_empty());
        assert!(!w.quiet());
    }
    for n in 0..200 {
        idle(&mut w, PARK);
        assert_eq!(w.quiet(), n + 1 >= need, "step {n} after the hand left");
    }
}

/// The hard case for reused contacts: a 200-brick wall of 20 courses in running bond, 1.2 m
/// high, sleeping off, standing 5 s. Every step from 1 s to 5 s runs quiet, and no brick
/// moves more between 1 s and 5 s than it does when no step runs quiet, to a tenth of a micrometre (BENCHMARKS.md's error table: 0.0003 mm under the default setting,
/// as without quiet steps; the scene's solver setting has its own test in `fast_solver`).
#[test]
fn a_quiet_wall_stands() {
    let mut p = Params {
        sleeping: false,
        loading_zone: None,
        ..Params::default()
    };
    running_bond_wall(&mut p);
    let mut w = world(p);
    for _ in 0..1000 {
        idle(&mut w, PARK);
    }
    let mut quiet = 0;
    let settled: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    for _ in 0..4000 {
        idle(&mut w, PARK);
        quiet += usize::from(w.quiet());
    }
    let now: Vec<[f64; 3]> = w.bricks().map(|b| b.position_m).collect();
    let drift = moved(&settled, &now);
    println!(
        "default solver wall: drift 1-5 s {:.4} mm, {quiet} quiet steps",
        drift * 1e3
    );
    assert_eq!(quiet, 4000);
    assert!((drift * 1e3 - 0.0003).abs() <= 0.5e-4, "drift {drift} m");
}
