//! A faithful carry through the virtual coupling (issue 31), measured as the wheel's
//! `BrickWorld` measures it: a rigid grip path at 1 kHz in the brick scene's world, on the
//! limits of a Falcon mapped into it (force_scale 0.125, workspace_scale 20: 64 N, 1200 N/m).
//!
//! Through the coupling and the paper's rigid carry (`inertia = "paper"`) alike:
//!
//! - the weight of a brick held still is its weight (relative error ≤ 1e-3);
//! - after a switch while holding (mass doubled; gravity off) the felt force is within 1 % of
//!   its new value within 0.1 s and ends within 0.1 % of it; after a grab the coupled brick's
//!   weight is felt from the first tick (within 0.1 %) and stays within 2 % (the coupling does
//!   not ring);
//! - a thrown brick, read from its body after the release, moves with the hand's velocity
//!   (within 2 %) and lands where a brick thrown at that velocity from the release point lands
//!   (within 2 % of the throw's distance).
//!
//! A 2 Hz carry through the coupling is felt as `M A Ω²` times the coupling's transmissibility
//! `|K / (K − M Ω²)|` (its impedance `K` from the constants the code uses) within 1 %, between
//! the limits of its dashpot locked and free; the rigid carry as `M A Ω²` within 5 %.
#![allow(clippy::unwrap_used)]

use brickworld::{BrickPlacement, Event, Grip, Inertia, Params, World};
use world_form::Limits;

const DT: f64 = 1e-3;
const LIMITS: Limits = Limits {
    max_force_n: 64.0,
    max_stiffness_n_per_m: 1200.0,
};
/// The brick's centre at rest on the ground, m.
const REST: [f64; 3] = [0.0, 0.0, 0.03];
/// The cursor just above the brick's top face (2 mm gap), m.
const ABOVE: [f64; 3] = [0.0, 0.0, 0.067];

fn world(inertia: Inertia) -> World {
    let p = Params {
        inertia,
        sleeping: false,
        release_velocity_band_m: 0.0,
        bricks: vec![BrickPlacement {
            center_m: REST,
            rotation_deg: [0.0; 3],
        }],
        ..Params::default()
    };
    World::new(&p, &LIMITS).unwrap()
}

/// Steps the world at `pos` with the grip; returns the felt force (world N) and the events.
fn step(w: &mut World, pos: [f64; 3], hold: bool) -> ([f64; 3], Vec<Event>) {
    let grip = Grip {
        hold,
        ..Grip::default()
    };
    let r = w.step(&w.input(pos, grip).unwrap());
    (r.force_n, r.events)
}

/// Grabs the brick and lifts it 5 cm over 0.5 s (smoothstep); returns the grip position.
fn grab_and_lift(w: &mut World) -> [f64; 3] {
    for _ in 0..50 {
        step(w, ABOVE, false);
    }
    let mut p = ABOVE;
    for i in 0..500 {
        let s = f64::from(i) / 500.0;
        p[2] = ABOVE[2] + 0.05 * s * s * (3.0 - 2.0 * s);
        step(w, p, true);
    }
    p
}

/// Holds still at `p` for `n` ticks; returns the felt forces.
fn hold(w: &mut World, p: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    (0..n).map(|_| step(w, p, true).0).collect()
}

/// Seconds after which every force stays within 1 % of the last one's step from `before`
/// (or of the weight, when the step is smaller).
fn settle_s(f: &[[f64; 3]], before: f64, weight: f64) -> f64 {
    let last = f[f.len() - 1][2];
    let tol = 0.01 * (last - before).abs().max(weight);
    let i = f.iter().rposition(|x| (x[2] - last).abs() > tol);
    i.map_or(0.0, |i| (i + 1) as f64 * DT)
}

#[test]
fn the_weight_of_a_brick_held_still_is_its_weight() {
    for inertia in [Inertia::Coupling, Inertia::Paper] {
        let mut w = world(inertia);
        let p = grab_and_lift(&mut w);
        let f = hold(&mut w, p, 2000);
        let mg = 0.5 * 9.81;
        let err = (f[1999][2] + mg).abs() / mg;
        println!(
            "{}: weight held still {:.6} N (M g = {mg} N), relative error {err:.2e}",
            inertia.name(),
            -f[1999][2]
        );
        assert!(err <= 1e-3, "{}: {err}", inertia.name());
        // docs/brickworld.md ("A faithful carry") quotes the coupling's 1.7·10⁻⁵: held to
        // that printed precision (the run is deterministic).
        if inertia == Inertia::Coupling {
            assert!((err - 1.7e-5).abs() <= 0.05e-5, "coupling: {err:.3e}");
        }
    }
}

/// The force a switch adds: the run with the switch less the same run without it (the lift
/// before it may still swing the brick a little; that is the same in both).
fn switch_effect(inertia: Inertia, switch: &dyn Fn(&mut World)) -> Vec<[f64; 3]> {
    let run = |with: bool| {
        let mut w = world(inertia);
        let p = grab_and_lift(&mut w);
        hold(&mut w, p, 1000);
        if with {
            switch(&mut w);
        }
        hold(&mut w, p, 1500)
    };
    let (a, b) = (run(true), run(false));
    a.iter()
        .zip(&b)
        .map(|(x, y)| [x[0] - y[0], x[1] - y[1], x[2] - y[2]])
        .collect()
}

#[test]
fn a_switch_while_holding_and_a_grab_do_not_ring() {
    let weight = 0.5 * 9.81;
    for inertia in [Inertia::Coupling, Inertia::Paper] {
        // Brick mass doubled: the hand feels one more weight.
        let f = switch_effect(inertia, &|w| w.set_brick_mass(1.0).unwrap());
        let mass_s = settle_s(&f, 0.0, weight);
        assert!((f[1499][2] + weight).abs() < 1e-3 * weight, "{:?}", f[1499]);
        // Gravity off: the hand loses the weight.
        let f = switch_effect(inertia, &|w| w.set_gravity(0.0).unwrap());
        let gravity_s = settle_s(&f, 0.0, weight);
        assert!((f[1499][2] - weight).abs() < 1e-3 * weight, "{:?}", f[1499]);
        // The grab of a brick resting on the ground: the weight from the grab on.
        let mut w = world(inertia);
        for _ in 0..50 {
            step(&mut w, ABOVE, false);
        }
        let f: Vec<[f64; 3]> = (0..1500).map(|_| step(&mut w, ABOVE, true).0).collect();
        let grab_s = settle_s(&f, 0.0, weight);
        // The weight from the first tick on (before: nothing, then a drop into the coupling
        // and 0.8 s of ringing). The brick still rests on the ground, whose soft contact keeps
        // a slow swing of about 1 % while it is not lifted.
        if inertia == Inertia::Coupling {
            assert!((f[0][2] + weight).abs() < 1e-3 * weight, "{:?}", f[0]);
            let worst = f.iter().map(|x| (x[2] + weight).abs()).fold(0.0, f64::max);
            assert!(worst < 0.02 * weight, "{worst}");
        }
        println!(
            "{}: settled within 1 % {mass_s:.3} s after mass doubled, {gravity_s:.3} s after \
             gravity off, {grab_s:.3} s after a grab",
            inertia.name()
        );
        for s in [mass_s, gravity_s] {
            assert!(s <= 0.1, "{}: {s} s", inertia.name());
        }
        // docs/brickworld.md ("A faithful carry") quotes the coupling's settling: 0 s after the
        // mass is doubled, 0.058 s after gravity is switched off (to the printed ms).
        if inertia == Inertia::Coupling {
            assert_eq!(mass_s, 0.0, "coupling: mass doubled");
            assert!(
                (gravity_s - 0.058).abs() < 0.0005,
                "coupling: {gravity_s} s"
            );
        }
    }
}

/// A thrown brick, read from its own body after the release and followed until it lands.
///
/// The hand accelerates smoothly to `v` over 0.2 s, keeps it 0.1 s and lets go, follows
/// through at `v` for 0.1 s and stops. The release sets the brick's velocity from the
/// grip-velocity estimate, so the `Released` event's velocity says nothing of the brick; this
/// test reads the body (`World::brick`):
///
/// - its velocity after the release tick against the hand's at the release, less the one
///   tick of gravity that tick's physics step adds after the release, `v − g dt ẑ`: within 2 %
///   of `|v|` (the figure);
/// - where it lands: its flight is followed tick by tick while it is free (every tick changes
///   its velocity by exactly `−g dt ẑ`, and it does not turn) until its first contact, and its
///   last free state is carried on to where its bottom face meets the ground (asserted to be
///   under 3 ticks away, so a brick stopped or pushed in the air fails). That point is
///   compared with the ballistic landing of `v` from the brick's centre at the release (before
///   the release tick), under `Params::gravity_m_per_s2`: within 2 % of the throw's horizontal
///   distance. Why 2 % suffices: the only error a correct release leaves is the integration's
///   (rapier's symplectic Euler keeps the brick `g dt t / 2` below the parabola after `t`,
///   0.5–1.7 mm after these 0.10–0.35 s flights, which moves the landing by a fraction of a
///   percent: measured 0.05 % and 0.12 %, the velocity within 1e-12 of `|v|`); a brick that
///   leaves at rest, with the coupling's swing (7 % off before issue 31) or is pushed in the
///   air fails.
#[test]
fn a_thrown_brick_leaves_with_the_hands_velocity_and_lands_where_it_should() {
    for v in [[1.0_f64, 0.0, 1.0], [1.0, 0.0, 0.0]] {
        for inertia in [Inertia::Coupling, Inertia::Paper] {
            let name = inertia.name();
            let mut w = world(inertia);
            let g = w.params().gravity_m_per_s2;
            let hz = w.params().brick_half_extents_m[2];
            let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let brick = |w: &World| w.bricks().next().unwrap();
            let mut p = grab_and_lift(&mut w);
            hold(&mut w, p, 200);
            // Accelerate smoothly to v over 0.2 s, keep it 0.1 s, release; follow through 0.1 s.
            let mut released = None;
            let mut i = 0;
            while released.is_none() {
                assert!(i <= 300, "{name}: no release");
                let t = f64::from(i) * DT;
                let s = (t / 0.2).min(1.0);
                let gs = s * s * (3.0 - 2.0 * s);
                for (a, pa) in p.iter_mut().enumerate() {
                    *pa += v[a] * gs * DT;
                }
                let x0 = brick(&w).position_m;
                let (_, events) = step(&mut w, p, i < 300);
                if events.iter().any(|e| matches!(e, Event::Released { .. })) {
                    released = Some(x0);
                }
                i += 1;
            }
            let x0 = released.unwrap();
            // The body's velocity after the release tick.
            let b = brick(&w);
            let want = [v[0], v[1], v[2] - g * DT];
            let v_err = (0..3)
                .map(|a| (b.velocity_m_per_s[a] - want[a]).powi(2))
                .sum::<f64>()
                .sqrt()
                / speed;
            // Its free flight, tick by tick, until its first contact.
            let q0 = b.orientation_xyzw;
            let mut last = b;
            let mut n = 1;
            loop {
                if n <= 100 {
                    for (a, pa) in p.iter_mut().enumerate() {
                        *pa += v[a] * DT;
                    }
                }
                step(&mut w, p, false);
                let b = brick(&w);
                let free = (0..3).all(|a| {
                    let dv = b.velocity_m_per_s[a] - last.velocity_m_per_s[a];
                    let want = if a == 2 { -g * DT } else { 0.0 };
                    (dv - want).abs() < 1e-9
                });
                if !free {
                    break;
                }
                let turned = (0..4).map(|k| (b.orientation_xyzw[k] - q0[k]).abs());
                assert!(turned.fold(0.0, f64::max) < 1e-12, "{name}: it turned");
                last = b;
                n += 1;
                assert!(n < 2000, "{name}: still flying after 2 s");
            }
            // The last free state carried on to the ground: z + vz τ − g τ² / 2 = h_z.
            let (xl, vl) = (last.position_m, last.velocity_m_per_s);
            let tau = (vl[2] + (vl[2] * vl[2] + 2.0 * g * (xl[2] - hz)).sqrt()) / g;
            let landed = [xl[0] + vl[0] * tau, xl[1] + vl[1] * tau];
            // The ballistic landing of v from the release point.
            let t_fly = (v[2] + (v[2] * v[2] + 2.0 * g * (x0[2] - hz)).sqrt()) / g;
            let ballistic = [x0[0] + v[0] * t_fly, x0[1] + v[1] * t_fly];
            let distance = v[0].hypot(v[1]) * t_fly;
            let land_err = (landed[0] - ballistic[0]).hypot(landed[1] - ballistic[1]) / distance;
            println!(
                "{name}: thrown at {v:?} m/s: the body moves at [{:.4}, {:.4}, {:.4}] m/s after \
                 the release tick ({:.1e} of |v| off v − g dt); lands at x = {:.4} m after {:.3} s \
                 against the ballistic {:.4} m after {t_fly:.3} s ({:.2} % of the {:.4} m throw; \
                 last free tick {:.2} ticks above the ground)",
                b.velocity_m_per_s[0],
                b.velocity_m_per_s[1],
                b.velocity_m_per_s[2],
                v_err,
                landed[0],
                n as f64 * DT + tau,
                ballistic[0],
                100.0 * land_err,
                distance,
                tau / DT,
            );
            assert!(
                (0.0..3.0 * DT).contains(&tau),
                "{name}: stopped {tau} s above the ground"
            );
            assert!(v_err <= 0.02, "{name}: velocity {v_err}");
            assert!(land_err <= 0.02, "{name}: landing {land_err}");
            // docs/brickworld.md ("A faithful carry") quotes these: the body at the hand's
            // velocity within 10⁻¹⁵ of |v|, landing 0.05 % and 0.12 % of the 0.35 m and 0.10 m
            // throws off the ballistic point (to the printed precision; deterministic run).
            let (doc_pct, doc_m) = if v[2] > 0.0 {
                (0.05, 0.35)
            } else {
                (0.12, 0.10)
            };
            assert!(v_err < 1e-15, "{name}: velocity {v_err:e}");
            assert!(
                (100.0 * land_err - doc_pct).abs() < 0.005,
                "{name}: landing {:.3} %",
                100.0 * land_err
            );
            assert!(
                (distance - doc_m).abs() < 0.005,
                "{name}: throw {distance} m"
            );
        }
    }
}

/// A 2 Hz horizontal carry of 2 cm amplitude, gravity off, measured against the coupling's own
/// transfer function, with a lower and an upper bound.
///
/// The model (`hand/carry.rs`, `Hand::coupling_pull`): the brick, mass `M`, is pulled by a
/// spring `k` from the grip point in parallel with a Maxwell element (a damper `b` through a
/// series spring `k_s`), so the coupling's force per lead is `K(s) = k + b k_s s / (b s + k_s)`.
/// With the hand at `x_h` and the brick at `x`, `M s² x = K (x_h − x)`, and the hand feels
/// `F = K (x_h − x) = M s² x_h K / (K + M s²)`: at `s = iΩ` its amplitude is `M A Ω² |H|`,
/// `H = K / (K − M Ω²)`. The constants the code uses, from `Params::default()` and the test's
/// limits: `k = stiffness_fraction · k_max = 0.3 · 1200 = 360 N/m`,
/// `k_s = (max_fraction − stiffness_fraction) · k_max = 360 N/m`,
/// `b = 2 ζ √(k M) = 2 · 0.9 · √(360 · 0.5) = 24.15 N·s/m` (the cap `M / dt²` = 5·10⁵ N/m is
/// far above), `M = 0.5 kg`, `Ω = 4π rad/s`: `|H| = 1.1586`.
///
/// Bounds: the ratio felt / `M A Ω²` within 1 % of `|H|` both ways (the time step changes it by
/// a fraction of `Ω dt` = 1.3 %: the backward-Euler dashpot and the symplectic Euler brick;
/// measured +0.02 %); and whatever the damper, `|H|` lies between its two limits, which are
/// asserted too: the dashpot locked (`K = k + k_s`: `1 / (1 − MΩ²/(k + k_s))` = 1.123) and
/// free (`K = k`: `1 / (1 − MΩ²/k)` = 1.281). A coupling that transmits nothing (0), a rigid
/// one (1) or one without its damper (1.281) fails. The paper's rigid carry is `M A Ω²`
/// within 5 %.
#[test]
fn a_2_hz_carry_is_felt_as_its_inertia_within_the_couplings_bound() {
    let (amp, hz) = (0.02, 2.0);
    let omega = 2.0 * std::f64::consts::PI * hz;
    for inertia in [Inertia::Coupling, Inertia::Paper] {
        let mut w = world(inertia);
        let p0 = grab_and_lift(&mut w);
        w.set_gravity(0.0).unwrap();
        hold(&mut w, p0, 500);
        let mut peak: f64 = 0.0;
        for i in 0..3000 {
            let t = f64::from(i) * DT;
            // A sine that starts at rest: x = A (1 − cos Ω t), a = A Ω² cos Ω t.
            let x = amp * (1.0 - (omega * t).cos());
            let (f, _) = step(&mut w, [p0[0] + x, p0[1], p0[2]], true);
            if i >= 2000 {
                peak = peak.max(f[0].abs());
            }
        }
        let m = w.params().brick_mass_kg;
        let ma = m * amp * omega * omega;
        let ratio = peak / ma;
        if inertia == Inertia::Coupling {
            let c = &w.params().coupling;
            let k_max = LIMITS.max_stiffness_n_per_m;
            let k = c.stiffness_fraction * k_max;
            let ks = (c.max_fraction - c.stiffness_fraction) * k_max;
            let b = 2.0 * c.damping_ratio * (k * m).sqrt();
            assert!(k.max(ks) < m / (DT * DT), "the springs are not capped");
            // |K / (K − M Ω²)| with K(iΩ) = k + iΩ b k_s / (k_s + iΩ b).
            let h = haptic_types::local::felt_mass_ratio(k, ks, b, m, omega);
            let mw2 = m * omega * omega;
            let (locked, free) = (1.0 / (1.0 - mw2 / (k + ks)), 1.0 / (1.0 - mw2 / k));
            println!(
                "coupling: 2 Hz carry felt {peak:.4} N against M A Ω² = {ma:.4} N: ratio \
                 {ratio:.5}, the coupling's |K / (K − M Ω²)| = {h:.5} ({:+.3} %); bounds \
                 [{:.5}, {:.5}], dashpot locked {locked:.4} and free {free:.4}",
                100.0 * (ratio / h - 1.0),
                0.99 * h,
                1.01 * h,
            );
            assert!(locked < h && h < free, "{locked} {h} {free}");
            assert!(
                ratio >= 0.99 * h && ratio <= 1.01 * h,
                "{ratio} against |H| = {h}"
            );
            assert!(
                ratio > locked && ratio < free,
                "{ratio}: [{locked}, {free}]"
            );
            // docs/brickworld.md ("A faithful carry") quotes: 15.88 % above M A Ω², |H| = 1.1586,
            // the felt ratio within 0.02 % of it (each to its printed precision).
            assert!((100.0 * (ratio - 1.0) - 15.88).abs() < 0.005, "{ratio}");
            assert!((h - 1.1586).abs() < 0.00005, "{h}");
            // ... and the damper's two limits this doc comment and the doc quote (28 % undamped).
            assert!((locked - 1.123).abs() < 0.0005 && (free - 1.281).abs() < 0.0005);
            assert!(
                (100.0 * (ratio / h - 1.0) - 0.02).abs() < 0.005,
                "{ratio} / {h}"
            );
        } else {
            println!(
                "paper: 2 Hz carry felt {peak:.4} N against M A Ω² = {ma:.4} N ({:+.3} %)",
                100.0 * (ratio - 1.0)
            );
            assert!((ratio - 1.0).abs() < 0.05, "{ratio}");
        }
    }
}
