//! Scenes shared by the report (`brickworld-report`) and the awake-cost probe
//! (`brickworld-awake`): everything awake at once, the case a knocked-over tower creates.
#![allow(dead_code)]

use bench_harness::{Summary, Timings};
use brickworld::{BrickPlacement, BrickProps, Grip, Params, World};
use world_form::Limits;

/// The default parameters with the solver setting of `BRICKWORLD_SOLVER`: `[brickworld.params]`
/// lines (e.g. `solver_iterations = 1` and `contact_frequency_hz = 175.0`), or `scene` for
/// the shipped brick scene's (`scenes/brickworld.toml`); unset: the defaults.
pub fn solver_from_env() -> Params {
    let Ok(text) = std::env::var("BRICKWORLD_SOLVER") else {
        return Params::default();
    };
    if text != "scene" {
        return Params::from_toml(&text).expect("BRICKWORLD_SOLVER: valid parameters");
    }
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/brickworld.toml");
    let scene: toml::Value =
        toml::from_str(&std::fs::read_to_string(path).expect("scenes/brickworld.toml"))
            .expect("the scene is TOML");
    let params = &scene["brickworld"]["params"];
    let d = Params::default();
    Params {
        solver_iterations: params
            .get("solver_iterations")
            .and_then(toml::Value::as_integer)
            .map_or(d.solver_iterations, |i| {
                usize::try_from(i).expect("a count")
            }),
        contact_frequency_hz: params
            .get("contact_frequency_hz")
            .and_then(toml::Value::as_float)
            .unwrap_or(d.contact_frequency_hz),
        ..d
    }
}

/// Where the cursor waits, m: above every scene, touching nothing.
pub const PARK: [f64; 3] = [0.0, 0.0, 1.9];

/// An axis-aligned brick centred at `c`, m.
pub fn at(c: [f64; 3]) -> BrickPlacement {
    BrickPlacement {
        center_m: c,
        rotation_deg: [0.0; 3],
    }
}

/// One tick with the cursor parked at `pos`, no buttons.
pub fn step_idle(w: &mut World, pos: [f64; 3]) -> brickworld::StepReport {
    let i = w.input(pos, Grip::default()).unwrap();
    w.step(&i)
}

/// `layers` layers of a 10 × 10 grid of bricks, each layer resting on the one below
/// (100 bricks a layer; the world's maximum, 200, is two layers). Neighbours in a layer are
/// `gap_m` apart (5 mm: a floor laid by hand), close enough for rapier's speculative contacts.
pub fn layers(p: &Params, layers: usize, gap_m: f64) -> World {
    let mut p = p.clone();
    p.loading_zone = None;
    let h = p.brick_half_extents_m;
    for l in 0..layers {
        for i in 0..10 {
            for j in 0..10 {
                p.bricks.push(at([
                    (i as f64 - 4.5) * (2.0 * h[0] + gap_m),
                    (j as f64 - 4.5) * (2.0 * h[1] + gap_m),
                    h[2] * (2 * l + 1) as f64,
                ]));
            }
        }
    }
    World::new(&p, &Limits::FALCON).expect("valid scene")
}

/// Adds to `p` a 200-brick wall of 20 courses in running bond (1 mm joints), 1.2 m high,
/// standing on the ground (the report's wall, and the tests' through `tests/common`).
pub fn running_bond_wall(p: &mut Params) {
    let h = p.brick_half_extents_m;
    for c in 0..20 {
        let shift = if c % 2 == 0 { 0.0 } else { h[0] };
        for i in 0..10 {
            p.bricks.push(at([
                (i as f64 - 4.5) * (2.0 * h[0] + 0.001) + shift - h[0] / 2.0,
                0.0,
                h[2] * (2 * c + 1) as f64,
            ]));
        }
    }
}

/// A wall of `courses` courses of 10 bricks in running bond (each course shifted by half a
/// brick), 2 m wide, standing on the ground, 1 mm between neighbours, with every brick of its top `knocked` courses
/// moving at `speed` m/s along +y: the moment a student knocks a tower over. Sleeping as in
/// `p`; all bricks start awake.
pub fn tower(p: &Params, courses: usize, knocked: usize, speed: f64) -> World {
    let mut p = p.clone();
    p.loading_zone = None;
    let h = p.brick_half_extents_m;
    let mut w = World::new(&p, &Limits::FALCON).expect("valid scene");
    for c in 0..courses {
        let shift = if c % 2 == 0 { 0.0 } else { h[0] };
        for i in 0..10 {
            let props = BrickProps {
                velocity_m_per_s: if c + knocked >= courses {
                    [0.0, speed, 0.0]
                } else {
                    [0.0; 3]
                },
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
            .expect("room for the tower");
        }
    }
    w
}

/// One tick's cost, µs: thread CPU (what the tick costs) and wall (preemption included),
/// with the most bricks awake during the run.
pub struct Timing {
    pub cpu: Summary,
    pub wall: Summary,
    pub awake: usize,
}

/// Times `n` ticks with the cursor parked.
pub fn time_parked(w: &mut World, n: usize) -> Timing {
    time_moving(w, n, |_| PARK)
}

/// Times `n` ticks with the cursor at `at(k)` on tick `k`, no buttons.
pub fn time_moving(w: &mut World, n: usize, at: impl Fn(usize) -> [f64; 3]) -> Timing {
    let mut t = Timings::with_capacity(n);
    let mut awake = 0;
    for k in 0..n {
        let i = w.input(at(k), Grip::default()).unwrap();
        t.time(|| std::hint::black_box(w.step(&i)));
        awake = awake.max(w.awake_brick_count());
    }
    Timing {
        cpu: t.cpu_us().expect("n > 0 ticks"),
        wall: t.wall_us().expect("n > 0 ticks"),
        awake,
    }
}

/// Times `n` ticks of the hand sweeping through the scene at `speed_m_per_s` along y, back and
/// forth between y = ±0.5 m, at height `z_m` over x = 0 (the cursor pushes what it meets).
pub fn time_sweep(w: &mut World, n: usize, z_m: f64, speed_m_per_s: f64) -> Timing {
    let dt = w.params().dt_s;
    time_moving(w, n, |k| {
        // A triangle wave of amplitude 0.5 m starting at y = -0.5.
        let s = (k as f64 * dt * speed_m_per_s).rem_euclid(2.0);
        [0.0, if s < 1.0 { s - 0.5 } else { 1.5 - s }, z_m]
    })
}
