//! Parameters, input validation, determinism, events and the house task.
#![allow(clippy::unwrap_used, clippy::field_reassign_with_default)]

mod common;
use brickworld::script::WallScript;
use brickworld::{
    AccelEstimator, BrickId, BrickPlacement, Event, Grip, InputError, ParamError, Params, World,
};
use common::*;
use proptest::prelude::*;
use world_form::Limits;

#[test]
fn old_unit_spellings_still_load_and_device_limits_are_checked_by_name() {
    let new = Params::from_toml(
        "gravity_m_per_s2 = 3.7\nproxy_stiffness_n_per_m = 800.0\nthrow_min_speed_m_per_s = 0.4",
    )
    .unwrap();
    let old = Params::from_toml(
        "gravity_m_s2 = 3.7\nproxy_stiffness_n_m = 800.0\nthrow_min_speed_m_s = 0.4",
    )
    .unwrap();
    assert_eq!(old, new);
    assert_eq!(old.gravity_m_per_s2, 3.7);
    assert_eq!(old.proxy_stiffness_n_per_m, 800.0);
    assert_eq!(old.throw_min_speed_m_per_s, 0.4);
    let props: brickworld::BrickProps = toml::from_str("velocity_m_s = [1.0, 0.0, 0.0]").unwrap();
    assert_eq!(props.velocity_m_per_s, [1.0, 0.0, 0.0]);
    // The Falcon is 8 N everywhere (CHAI3D's figure).
    assert_eq!(Limits::FALCON.max_force_n, 8.0);
    let bad = Limits {
        max_force_n: f64::NAN,
        ..Limits::FALCON
    };
    assert_eq!(
        World::new(&Params::default(), &bad)
            .err()
            .unwrap()
            .to_string(),
        "parameter `device.max_force_n` = NaN is out of range: allowed 0 < max_force_n ≤ 100000 N"
    );
}

#[test]
fn bad_parameters_name_the_field_and_range() {
    let mut p = Params::default();
    p.restitution = 1.5;
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "parameter `restitution` = 1.5 is out of range: allowed [0, 1]"
    );
    let mut p = Params::default();
    p.brick_half_extents_m[1] = f64::NAN;
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "parameter `brick_half_extents_m[1]` = NaN is out of range: allowed [0.001, 1]"
    );
    let mut p = Params::default();
    p.proxy_stiffness_n_per_m = 5000.0;
    let e = World::new(&p, &Limits::FALCON).err().unwrap();
    assert_eq!(
        e.to_string(),
        "parameter `proxy_stiffness_n_per_m` = 5000 is out of range: allowed (0, 3000]"
    );
    let mut p = Params::default();
    p.accel_estimator = AccelEstimator::SavitzkyGolay { window: 3 };
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "parameter `accel_estimator.savitzky_golay.window` = 3 is out of range: allowed [5, 201]"
    );
    let mut z = brickworld::LoadingZone::default();
    z.max_m[0] = z.min_m[0];
    let p = Params {
        loading_zone: Some(z),
        ..Params::default()
    };
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "parameter `loading_zone.max_m[0]` is invalid: must exceed loading_zone.min_m[0] = -0.6"
    );
}

#[test]
fn toml_parameters_parse_and_reject_unknown_fields() {
    let p = Params::from_toml(
        r#"
        gravity_m_per_s2 = 1.62
        restitution = 0.4
        accel_estimator = { savitzky_golay = { window = 21 } }
        [[bricks]]
        center_m = [0.0, 0.0, 0.03]
        [blueprint]
        slots = [{ center_m = [0.3, 0.0, 0.03], rotation_deg = [0.0, 0.0, 90.0] }]
        "#,
    )
    .unwrap();
    assert_eq!(p.gravity_m_per_s2, 1.62);
    assert_eq!(
        p.accel_estimator,
        AccelEstimator::SavitzkyGolay { window: 21 }
    );
    assert_eq!(p.blueprint.slots.len(), 1);
    let e = Params::from_toml("gravity = 9.81").unwrap_err().to_string();
    assert!(e.contains("unknown field `gravity`"), "{e}");
    let e = Params::from_toml("friction = -1.0")
        .unwrap_err()
        .to_string();
    assert_eq!(
        e,
        "parameter `friction` = -1 is out of range: allowed [0, 10]"
    );
}

#[test]
fn parameters_round_trip_through_toml() {
    let mut p = wall_params();
    p.accel_estimator = AccelEstimator::SavitzkyGolay { window: 31 };
    p.bricks = vec![at([0.1, 0.2, 0.03])];
    p.obstacles = vec![brickworld::Obstacle {
        center_m: [0.0, 1.0, 0.1],
        half_extents_m: [0.5, 0.2, 0.1],
        rotation_deg: [0.0, 10.0, 0.0],
    }];
    let text = toml::to_string(&p).unwrap();
    assert_eq!(Params::from_toml(&text).unwrap(), p, "{text}");
    let none = toml::to_string(&Params::default()).unwrap();
    assert_eq!(Params::from_toml(&none).unwrap().loading_zone, None);
}

#[test]
fn bad_cursor_input_and_switches_are_typed_errors() {
    let mut w = world(bare());
    assert_eq!(
        w.input([0.0, f64::INFINITY, 0.0], Grip::default()),
        Err(InputError::NotFinite {
            axis: 1,
            value: f64::INFINITY
        })
    );
    assert_eq!(
        w.input([0.0, 0.0, 3.0], Grip::default())
            .unwrap_err()
            .to_string(),
        "cursor input `position_m[2]` = 3 m is outside the workspace: allowed [-2, 2] m"
    );
    assert_eq!(
        w.set_gravity(-1.0).unwrap_err(),
        ParamError::out_of_range("gravity_m_per_s2", -1.0, "[0, 100]")
    );
    assert!(w.set_brick_mass(0.0).is_err());
    assert!(w.set_friction(f64::NAN).is_err());
    assert_eq!(
        w.params().friction,
        Params::default().friction,
        "rejected switch leaves state"
    );
}

/// Runs a scripted session with grab, carry, rotate, throw and pushes; returns all state bits.
fn session(p: Params) -> (Vec<u64>, Vec<Vec<Event>>) {
    let mut w = world(p);
    let mut bits = Vec::new();
    let mut events = Vec::new();
    let mut script = WallScript::new(&w, [0.3, -0.4, 0.35]).unwrap();
    for _ in 0..6000 {
        let i = script.next_input(&w).unwrap();
        let r = w.step(&i);
        bits.extend(r.force_n.iter().map(|f| f.to_bits()));
        if !r.events.is_empty() {
            events.push(r.events);
        }
    }
    for b in w.bricks() {
        bits.extend(
            b.position_m
                .iter()
                .chain(&b.orientation_xyzw)
                .map(|x| x.to_bits()),
        );
    }
    (bits, events)
}

fn wall_params() -> Params {
    let h = Params::default().brick_half_extents_m;
    let mut p = Params {
        loading_zone: Some(brickworld::LoadingZone::default()),
        ..Params::default()
    };
    let (z0, z1) = (h[2], 3.0 * h[2]);
    let step = 2.0 * h[0] + 0.004;
    p.blueprint.slots = vec![
        BrickPlacement {
            center_m: [0.0, 0.0, z0],
            rotation_deg: [0.0; 3],
        },
        BrickPlacement {
            center_m: [step, 0.0, z0],
            rotation_deg: [0.0; 3],
        },
        BrickPlacement {
            center_m: [step / 2.0, 0.0, z1],
            rotation_deg: [0.0; 3],
        },
        BrickPlacement {
            center_m: [2.0 * step + h[1] + 0.05, h[0] - h[1], z0],
            rotation_deg: [0.0, 0.0, 90.0],
        },
    ];
    p
}

#[test]
fn two_worlds_with_identical_inputs_are_bit_identical() {
    let (a, ea) = session(wall_params());
    let (b, eb) = session(wall_params());
    assert!(
        ea.iter()
            .flatten()
            .any(|e| matches!(e, Event::Grabbed { .. }))
    );
    assert_eq!(a.len(), b.len());
    assert!(a == b, "state bits differ");
    assert_eq!(ea, eb);
}

#[test]
fn scripted_session_builds_the_wall() {
    let mut w = world(wall_params());
    let mut script = WallScript::new(&w, [0.3, -0.4, 0.35]).unwrap();
    let mut log = Vec::new();
    let mut ticks = 0;
    while !script.done() && ticks < 40_000 {
        let i = script.next_input(&w).unwrap();
        log.extend(w.step(&i).events);
        ticks += 1;
    }
    for _ in 0..1000 {
        log.extend(idle(&mut w, [0.3, -0.4, 0.35]).events);
    }
    let s = w.score();
    println!(
        "wall built in {:.1} s: {}/{} slots",
        ticks as f64 * 1e-3,
        s.filled,
        s.total
    );
    assert!(script.done());
    assert_eq!((s.filled, s.total), (4, 4), "events: {log:?}");
    // BENCHMARKS.md: "`script::WallScript` builds a 4-slot wall ... in 21.7 s of simulated
    // time; score **4/4**" (its report runs this script on these parameters; 21 676 ticks)
    assert!((21_650..21_750).contains(&ticks), "{ticks} ticks");
    assert!(log.contains(&Event::Spawned { brick: BrickId(0) }));
    assert!(log.iter().any(|e| matches!(e, Event::Rotated { .. })));
    assert!(
        log.iter()
            .any(|e| matches!(e, Event::SlotFilled { slot: 3, .. }))
    );
    assert_eq!(w.brick_count(), 4);
}

#[test]
fn rotate_buttons_turn_the_carried_brick_by_quarter_turns() {
    let mut p = bare();
    let h = p.brick_half_extents_m;
    p.bricks = vec![at([0.0, 0.0, h[2]])];
    let mut w = world(p);
    let r = w.params().proxy_radius_m;
    for _ in 0..300 {
        idle(&mut w, [0.0, 0.0, 0.2]);
    }
    for i in 0..200 {
        idle(&mut w, [0.0, 0.0, 0.2 - i as f64 * 0.001]);
    }
    hold(&mut w, [0.0, 0.0, 2.0 * h[2] + r - 0.002], true);
    for i in 0..300 {
        hold(&mut w, [0.0, 0.0, 0.06 + i as f64 * 0.001], true);
    }
    let c = w.cursor_position_m();
    let q0 = w.brick(BrickId(0)).unwrap().orientation_xyzw;
    let b = Grip {
        hold: true,
        turn_z: true,
        ..Grip::default()
    };
    let rep = w.step(&w.input(c, b).unwrap());
    assert!(rep.events.contains(&Event::Rotated {
        brick: BrickId(0),
        axis: brickworld::Axis::Z
    }));
    // Holding the button does not turn again (edge-triggered).
    let rep = w.step(&w.input(c, b).unwrap());
    assert!(
        !rep.events
            .iter()
            .any(|e| matches!(e, Event::Rotated { .. }))
    );
    // q = Rz(90°) q0, with Rz(90°) = (0, 0, s, s), s = 1/√2 (quaternion product by hand).
    let q = w.brick(BrickId(0)).unwrap().orientation_xyzw;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let [x, y, z, ww] = q0;
    let expected = [s * (x - y), s * (x + y), s * (ww + z), s * (ww - z)];
    for k in 0..4 {
        assert!((q[k] - expected[k]).abs() < 1e-12, "{q:?} vs {expected:?}");
    }
    assert!(
        q0[0].abs() < 1e-3 && q0[1].abs() < 1e-3,
        "brick was lying flat: {q0:?}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, failure_persistence: None, ..ProptestConfig::default() })]
    /// Whatever the cursor does, the force is finite and within the device limit, and the cursor
    /// sphere never sinks into the ground by more than 1 mm.
    #[test]
    fn force_is_finite_and_proxy_stays_out_of_the_ground(
        path in prop::collection::vec((-0.5f64..0.5, -0.5f64..0.5, -0.3f64..0.4, any::<bool>()), 50..120)
    ) {
        let mut p = bare();
        let h = p.brick_half_extents_m;
        p.bricks = vec![at([0.0, 0.0, h[2]]), at([0.0, 0.0, 3.0 * h[2]])];
        let mut w = world(p);
        let r = w.params().proxy_radius_m;
        let max_f = w.limits().max_force_n;
        for (x, y, z, c) in path {
            for _ in 0..10 {
                let rep = hold(&mut w, [x, y, z], c);
                let f = rep.force_n;
                prop_assert!(f.iter().all(|v| v.is_finite()));
                prop_assert!((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() <= max_f * (1.0 + 1e-12));
                prop_assert!(w.proxy_position_m()[2] - r >= -1e-3);
            }
        }
    }
}

#[test]
fn loading_zone_spawns_one_brick_per_entry_when_the_spot_is_clear() {
    let p = Params {
        loading_zone: Some(brickworld::LoadingZone::default()),
        ..Params::default()
    };
    let z = p.loading_zone.clone().unwrap();
    let mut w = world(p);
    let inside = [z.spawn_m[0] + 0.05, z.spawn_m[1] + 0.1, 0.2];
    let outside = [z.max_m[0] + 0.2, 0.0, 0.2];
    let mut spawned = 0;
    for _ in 0..3 {
        for _ in 0..50 {
            spawned += idle(&mut w, outside)
                .events
                .iter()
                .filter(|e| matches!(e, Event::Spawned { .. }))
                .count();
        }
        for _ in 0..50 {
            spawned += idle(&mut w, inside)
                .events
                .iter()
                .filter(|e| matches!(e, Event::Spawned { .. }))
                .count();
        }
    }
    // Three entries, but the first brick still occupies the spawn spot.
    assert_eq!(spawned, 1);
    assert_eq!(w.brick_count(), 1);
    let g = w.ground();
    assert_eq!(
        g.position_m[2] + g.half_extents_m[2],
        0.0,
        "ground top face is z = 0"
    );
    let b = w.brick(BrickId(0)).unwrap();
    let h = w.params().brick_half_extents_m;
    assert!((b.position_m[0] - z.spawn_m[0]).abs() < 1e-6);
    assert!(
        (b.position_m[2] - h[2]).abs() < 1e-3,
        "rests on the ground: {:?}",
        b.position_m
    );
}

#[test]
fn run_time_switches_wake_resting_bricks() {
    // A brick resting on a 20° ramp with mu = 0.6 (holds: tan 20° = 0.36).
    let mut p = bare();
    let h = p.brick_half_extents_m;
    let th = 20.0_f64;
    p.obstacles = vec![brickworld::Obstacle {
        center_m: [0.0, 0.0, 0.5],
        half_extents_m: [0.6, 0.3, 0.05],
        rotation_deg: [0.0, th, 0.0],
    }];
    let up = 0.05 + h[2];
    let t = th.to_radians();
    let c = [up * t.sin(), 0.0, 0.5 + up * t.cos()];
    p.bricks = vec![BrickPlacement {
        center_m: c,
        rotation_deg: [0.0, th, 0.0],
    }];
    let mut w = world(p);
    for _ in 0..2000 {
        idle(&mut w, [1.5, 1.5, 1.5]);
    }
    let b = w.brick(BrickId(0)).unwrap();
    assert!(b.sleeping, "brick at rest on the ramp falls asleep");
    let x_rest = b.position_m[0];
    assert!((x_rest - c[0]).abs() < 1e-3);
    // Friction down to 0.2 < tan 20°: it must slide now, although it was asleep.
    w.set_friction(0.2).unwrap();
    for _ in 0..300 {
        idle(&mut w, [1.5, 1.5, 1.5]);
    }
    let slid = w.brick(BrickId(0)).unwrap().position_m[0] - x_rest;
    assert!(slid > 0.02, "slid only {slid} m");
    // Gravity off: a brick released in mid-air stays there.
    w.set_gravity(0.0).unwrap();
    let id = w.add_brick(at([-1.0, -1.0, 0.5])).unwrap();
    for _ in 0..500 {
        idle(&mut w, [1.5, 1.5, 1.5]);
    }
    let z = w.brick(id).unwrap().position_m[2];
    assert!((z - 0.5).abs() < 1e-12, "floating brick moved to {z}");
    // Gravity back on: it falls (it had gone to sleep in mid-air).
    w.set_gravity(9.81).unwrap();
    for _ in 0..500 {
        idle(&mut w, [1.5, 1.5, 1.5]);
    }
    let z = w.brick(id).unwrap().position_m[2];
    assert!(z < 0.1, "brick should have fallen, z = {z}");
}

#[test]
fn world_can_move_to_the_haptic_thread() {
    fn send<T: Send + 'static>(_: &T) {}
    let w = world(bare());
    send(&w);
    let h = std::thread::spawn(move || {
        let mut w = w;
        idle(&mut w, [0.0, 0.0, 0.2]).tick
    });
    assert_eq!(h.join().unwrap(), 0);
}
