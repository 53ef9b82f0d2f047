//! The loop's guarantees, tick by tick (see `haptic_engine::haptic`'s list), on the calibration
//! wall scene.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_engine::haptic::*;
use haptic_loop::scene::load_scene;
use haptic_types::device::FALCON;
use haptic_types::tick::status;
use haptic_types::vec3;
use haptic_types::{Buttons, DeviceSample};

const WALL: &str = r#"
[scene]
name = "w"
kind = "wall"
[loop]
engage_s = 0.0
[wall]
normal = [0.0, 0.0, 1.0]
stiffness_n_per_m = 5000.0
"#;

fn looped(text: &str) -> HapticLoop {
    let s = load_scene(text, None).unwrap();
    HapticLoop::new(s.config, s.scene)
}

fn at(z: f64) -> DeviceSample {
    DeviceSample::new([0.0, 0.0, z], Buttons(0))
}

#[test]
fn stiffness_is_capped_and_force_clamped_along_its_direction() {
    let mut l = looped(WALL);
    // 1 mm deep: the 5000 N/m wall is capped at the Falcon's 3000 N/m -> 3 N.
    let r = l.tick(at(-0.001), false).clone();
    assert!((r.device_force_n[2] - 3.0).abs() < 1e-12);
    assert_eq!(r.status, 0);
    // 2 mm -> 6 N; felt stiffness ΔF/Δx = 3000 N/m exactly (to rounding).
    let f2 = l.tick(at(-0.002), false).device_force_n[2];
    assert!(((f2 - r.device_force_n[2]) / 0.001 - 3000.0).abs() < 1e-6);
    // 5 mm -> 15 N requested, clamped to 8 N, still along +z.
    let r = l.tick(at(-0.005), false).clone();
    assert_eq!(r.status, status::CLAMPED);
    assert!(vec3::norm(r.device_force_n) <= FALCON.limits.max_force_n);
    assert!((r.device_force_n[2] - 8.0).abs() < 1e-12);
    assert_eq!(r.events[0].name, "force.clamped");
    // The clamp event fires once per episode.
    assert!(l.tick(at(-0.006), false).events.is_empty());
}

/// A force limit of 4e-159 N (the libFuzzer bridge target's find: clamping to it stepped
/// the force down one ulp at a time, 12 s for 20 ticks) still clamps, in a bounded number
/// of steps, to a force within the limit.
#[test]
fn a_limit_with_subnormal_squares_still_clamps() {
    let mut specs = FALCON.clone();
    specs.limits.max_force_n = 3.7555737088373936e-159;
    let s = haptic_loop::scene::load_scene_for(WALL, specs).unwrap();
    let mut l = HapticLoop::new(s.config, s.scene);
    for k in 1..=20 {
        let r = l.tick(at(-0.0001 * f64::from(k)), false).clone();
        assert!(vec3::norm(r.device_force_n) <= 3.7555737088373936e-159);
        assert!(r.device_force_n.iter().all(|x| x.is_finite()));
        assert_eq!(r.status & status::CLAMPED, status::CLAMPED);
    }
}

#[test]
fn invalid_input_gives_zero_force_and_holds_the_cursor() {
    let mut l = looped(WALL);
    l.tick(at(-0.001), false);
    let r = l
        .tick(DeviceSample::new([f64::NAN, 0.0, 0.0], Buttons(0)), false)
        .clone();
    assert_eq!(r.device_force_n, [0.0; 3]);
    assert_eq!(r.status, status::INPUT_INVALID);
    assert_eq!(r.cursor_m, [0.0, 0.0, -0.001]);
    assert_eq!(r.events[0].name, "input.invalid");
    let r = l.tick(at(0.05), false).clone();
    assert_eq!(r.device_force_n, [0.0; 3]);
    assert!(r.events.is_empty(), "one event per episode");
    let r = l
        .tick(DeviceSample::new([0.0; 3], Buttons(1 << 7)), false)
        .clone();
    assert_eq!(r.status, status::INPUT_INVALID);
    let r = l.tick(at(-0.001), false).clone();
    assert_eq!(r.events[0].name, "input.valid");
}

#[test]
fn soft_engagement_ramps_with_smoothstep() {
    let mut l = looped(&WALL.replace("engage_s = 0.0", "engage_s = 0.1"));
    let f: Vec<f64> = (0..120)
        .map(|_| l.tick(at(-0.0005), false).device_force_n[2])
        .collect();
    assert_eq!(f[0], 0.0);
    assert!((f[50] - 1.5 * 0.5).abs() < 1e-12, "half way: half force");
    assert!(f.windows(2).all(|w| w[1] >= w[0]));
    assert_eq!(f[100], 1.5);
    assert_eq!(f[119], 1.5);
}

#[test]
fn missed_deadline_sends_zero_force_and_buttons_raise_events() {
    let mut l = looped(WALL);
    let r = l
        .tick(DeviceSample::new([0.0, 0.0, -0.001], Buttons(0b101)), true)
        .clone();
    assert_eq!(r.device_force_n, [0.0; 3]);
    assert!((r.world_force_n[2] - 3.0).abs() < 1e-12);
    assert_eq!(r.status, status::DEADLINE_MISSED);
    let names: Vec<_> = r
        .events
        .iter()
        .map(|e| (e.name.as_str(), e.detail.as_str()))
        .collect();
    assert_eq!(names[0], ("button.down", "centre"));
    assert_eq!(names[1], ("button.down", "minus"));
    assert_eq!(names.last().unwrap().0, "deadline.missed");
}

/// The force-rate limit: a step into the wall that asks 6 N at once is rendered as 3 N
/// (the Falcon's 3000 N/m × 1 m/s × 1 ms), then 6 N, with one event; off, at once.
#[test]
fn the_force_rate_limit_holds_a_step_to_k_max_times_one_metre_per_second() {
    let mut l = looped(WALL);
    l.tick(at(0.001), false);
    let r = l.tick(at(-0.002), false).clone();
    assert_eq!(r.device_force_n, [0.0, 0.0, 3.0]);
    assert_eq!(r.status, status::RATE_LIMITED);
    let ev = r
        .events
        .iter()
        .find(|e| e.name == "safety.rate_limited")
        .unwrap();
    assert_eq!(
        ev.detail,
        "force change of 6.000 N in one tick held to 3.000 N"
    );
    let r = l.tick(at(-0.002), false).clone();
    assert!((r.device_force_n[2] - 6.0).abs() < 1e-12);
    assert_eq!(r.status, 0);
    let mut off =
        looped(&WALL.replace("engage_s = 0.0", "engage_s = 0.0\nforce_rate_limit = false"));
    off.tick(at(0.001), false);
    assert!((off.tick(at(-0.002), false).device_force_n[2] - 6.0).abs() < 1e-12);
}

/// The passivity observer and controller: a stylus that starts deep in the wall and is
/// pushed out by it takes energy the wall never took from it. Past the 20 mJ reserve the
/// controller adds damping against the motion, α = −E / (T v²), at most 2 N·s/m; the
/// observer reads the energy exactly; off, the force is the wall's.
#[test]
fn the_passivity_controller_damps_energy_returned_beyond_the_reserve() {
    let path = |n: usize| -0.005 + 5e-5 * n as f64; // out at 0.05 m/s
    let run = |text: &str| {
        let mut l = looped(text);
        let mut out = Vec::new();
        for n in 0..100 {
            let r = l.tick(at(path(n)), false).clone();
            out.push((r, l.passivity_tank_j()));
        }
        out
    };
    let on = run(WALL);
    let off = run(&WALL.replace("engage_s = 0.0", "engage_s = 0.0\npassivity = false"));
    // The observer, on or off: 0.02 J minus Σ F_(n−1) · (p_n − p_(n−1)).
    let mut e = 0.02;
    for n in 1..100 {
        e -= off[n - 1].0.device_force_n[2] * (path(n) - path(n - 1));
        assert!((off[n].1 - e).abs() < 1e-12, "tick {n}");
    }
    let first = on
        .iter()
        .position(|(r, _)| r.status & status::PASSIVITY != 0)
        .unwrap();
    assert!(on[first - 1].1 >= 0.0 && on[first].1 < 0.0);
    assert!(
        on[first]
            .0
            .events
            .iter()
            .any(|e| e.name == "safety.passivity")
    );
    let mut acted = 0;
    for n in first..100 {
        let (r, tank) = &on[n];
        if r.status & status::PASSIVITY == 0 {
            assert!(*tank >= 0.0, "tick {n}: a deficit left alone");
            continue;
        }
        acted += 1;
        // The reading at tick n holds the work of tick n − 1's force: the deficit the
        // controller damps, against the motion (+z at 0.05 m/s), at most 2 N·s/m.
        let alpha = (-tank / (1e-3 * 0.05 * 0.05)).min(2.0);
        let wall = off[n].0.device_force_n[2];
        let cut = wall - r.device_force_n[2];
        assert!((cut - alpha * 0.05).abs() < 1e-9, "tick {n}: cut {cut} N");
    }
    assert!(acted > 10);
    for (n, (r, _)) in off.iter().enumerate() {
        assert_eq!(r.status & status::PASSIVITY, 0, "tick {n}");
    }
}

/// The observer integrates the work over the path the world saw: every valid sample the loop
/// takes moves the cursor, and the force held over the last tick works along that step. A
/// sample one tick late (age 1) is still a new reading: a link whose every answer comes a
/// tick late, or that alternates on-time and late samples, is observed as the on-time one
/// (found by CI: the late readings were skipped and the whole press was charged at once on the
/// next on-time one, at the deepest force, and the device side's two-port layer then held the
/// wall back).
#[test]
fn the_observer_counts_the_work_of_late_samples_as_of_on_time_ones() {
    let path = |n: u64| 0.001 - 2.9e-5 * n as f64; // into the wall at 29 mm/s
    // Tick n reads sample n − lag(n): `lag` 0 is the on-time link.
    let run = |lag: &dyn Fn(u64) -> u64| {
        let mut l = looped(WALL);
        let mut out = Vec::new();
        for n in 0..120u64 {
            let d = lag(n).min(n);
            let s = DeviceSample {
                seq: n - d,
                age_ticks: d as u32,
                ..at(path(n - d))
            };
            let r = l.tick(s, false).clone();
            out.push((s.position_m[2], r.device_force_n[2], l.passivity_tank_j()));
        }
        out
    };
    let on_time = run(&|_| 0);
    let late = run(&|_| 1);
    let jitter = run(&|n| [0, 1, 1, 0, 2, 0, 1][n as usize % 7]);
    // 2.45 mm into a 3000 N/m wall (the Falcon's cap): −½ k d² = −9.0 mJ of work on the
    // hand, less the explicit sum's ½ k d Δz = 0.1 mJ.
    let e_on = 0.02 - on_time[119].2;
    assert!((-0.0090..-0.0086).contains(&e_on), "{e_on} J");
    // One tick late: the same readings a tick later, the same work.
    for n in 1..120 {
        assert_eq!(late[n].2, on_time[n - 1].2, "tick {n}");
    }
    // Any pattern of lateness: 0.02 J − Σ F_(n−1) (z_n − z_(n−1)) over the readings taken.
    for run in [&on_time, &late, &jitter] {
        let mut e = 0.02;
        for n in 1..120 {
            e -= run[n - 1].1 * (run[n].0 - run[n - 1].0);
            assert!(
                (run[n].2 - e).abs() < 1e-15,
                "tick {n}: {} J, expected {e} J",
                run[n].2
            );
        }
    }
}

use proptest::prelude::*;

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        -0.05f64..0.05,
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-1e300),
        Just(1e300)
    ]
}

proptest! {
    /// Whatever the device reports, the force sent is finite, within the device maximum,
    /// and zero whenever the input is invalid.
    #[test]
    fn sent_force_is_always_finite_and_bounded(
        samples in proptest::collection::vec(((coord(), coord(), coord()), 0u32..64), 1..200),
        k in 1.0f64..1e9,
    ) {
        let text = WALL.replace("5000.0", &format!("{k:?}"));
        let mut l = looped(&text);
        for ((x, y, z), b) in samples {
            let s = DeviceSample::new([x, y, z], Buttons(b));
            let invalid = HapticLoop::check_sample(&FALCON, &s).is_some();
            let r = l.tick(s, false);
            prop_assert!(vec3::is_finite(r.device_force_n));
            prop_assert!(vec3::norm(r.device_force_n) <= FALCON.limits.max_force_n);
            if invalid {
                prop_assert_eq!(r.device_force_n, [0.0; 3]);
                prop_assert!(r.status & status::INPUT_INVALID != 0);
            }
        }
    }
}
