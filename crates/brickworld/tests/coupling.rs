//! The carried brick through the virtual coupling (`inertia = "coupling"`, the default): the
//! weight of a brick held still, the inertia of a 2 Hz carry against −M a, a brick set down
//! at 0.5 m/s felt no stiffer than the coupling, a throw with the brick's own velocity, and
//! the same force both ways.
#![allow(clippy::unwrap_used, clippy::needless_range_loop)]

mod common;
use brickworld::{BrickId, Event, Inertia};
use common::*;
use world_form::Limits;

const PARK: [f64; 3] = [1.5, 1.5, 1.0];

/// Velocity profile that rises smoothly from 0 to 1 over `ramp` s (½ − ½ cos), then stays 1.
fn ramp(t: f64, ramp: f64) -> f64 {
    if t >= ramp {
        1.0
    } else {
        0.5 - 0.5 * (std::f64::consts::PI * t / ramp).cos()
    }
}

/// A world with one brick on the ground, the cursor holding it 0.2 m up, settled for 1 s.
fn holding(mass_kg: f64) -> (brickworld::World, [f64; 3]) {
    holding_with(bare(), mass_kg)
}

fn holding_with(mut p: brickworld::Params, mass_kg: f64) -> (brickworld::World, [f64; 3]) {
    p.brick_mass_kg = mass_kg;
    let h = p.brick_half_extents_m;
    p.bricks = vec![at([0.0, 0.0, h[2]])];
    assert_eq!(p.inertia, Inertia::Coupling, "the default");
    let mut w = world(p);
    for _ in 0..600 {
        idle(&mut w, PARK);
    }
    let top = h[2] * 2.0;
    let r = w.params().proxy_radius_m;
    for i in 0..100 {
        idle(&mut w, [0.0, 0.0, top + r + 0.02 - 0.0003 * i as f64]);
    }
    let rep = hold(&mut w, [0.0, 0.0, top + r - 0.005], true);
    assert!(rep.events.contains(&Event::Grabbed { brick: BrickId(0) }));
    let mut c = w.proxy_position_m();
    let dt = w.params().dt_s;
    for n in 0..600 {
        c[2] += 0.4 * ramp(n as f64 * dt, 0.2) * dt;
        hold(&mut w, c, true);
    }
    for _ in 0..1000 {
        hold(&mut w, c, true);
    }
    (w, c)
}

#[test]
fn a_brick_held_still_weighs_m_g_within_1_percent() {
    for m in [0.1, 0.3, 0.5] {
        let (mut w, c) = holding(m);
        let rep = hold(&mut w, c, true);
        let g = w.params().gravity_m_per_s2;
        let rel = (-rep.force_n[2] - m * g) / (m * g);
        println!(
            "held still, M = {m} kg: felt {:.6} N vs M g {:.6} N ({rel:+.2e})",
            -rep.force_n[2],
            m * g
        );
        assert!(rel.abs() < 0.01, "M = {m}: {rel}");
        // docs/brickworld.md (the coupling's table) quotes each after 1 s of holding, to two
        // digits: +2.8·10⁻⁵, +2.8·10⁻⁴, +9.2·10⁻³ (the 0.5 kg brick still swings a little).
        if default_solver() {
            let (doc, half_ulp) = if m == 0.1 {
                (2.8e-5, 0.05e-5)
            } else if m == 0.3 {
                (2.8e-4, 0.05e-4)
            } else {
                (9.2e-3, 0.05e-3)
            };
            assert!((rel - doc).abs() <= half_ulp, "M = {m}: {rel:e}");
        }
        assert!(rep.force_n[0].abs() < 1e-6 && rep.force_n[1].abs() < 1e-6);
        assert_eq!(
            rep.weight_force_n, [0.0; 3],
            "the weight arrives through the coupling"
        );
        assert_eq!(rep.coupling_force_n, rep.force_n);
        // The felt stiffness is the coupling's, 0.3 of the device's largest.
        assert_eq!(
            rep.stiffness_n_per_m,
            0.3 * Limits::FALCON.max_stiffness_n_per_m
        );
    }
}

/// A 2 Hz sideways carry of ±5 cm: the felt sideways force is −M a of the brick within 5 %
/// (exactly the brick's own momentum change), and −M a of the hand times the coupling's
/// transmissibility |k + iωb| / |k − M ω² + iωb| within 2 %.
#[test]
fn a_2_hz_carry_is_felt_as_minus_m_a() {
    let (felt, predicted) = carry_2_hz();
    assert!(((felt - predicted) / predicted).abs() < 0.02);
}

/// Peak felt sideways force and its prediction for a 2 Hz ±5 cm carry of a 0.5 kg brick.
fn carry_2_hz() -> (f64, f64) {
    let m = 0.5;
    let (mut w, c0) = holding_with(bare(), m);
    let dt = w.params().dt_s;
    let (amp, f_hz) = (0.05, 2.0);
    let om = 2.0 * std::f64::consts::PI * f_hz;
    let mut felt = Vec::new();
    let mut xb = Vec::new();
    for n in 1..=3000 {
        let t = n as f64 * dt;
        let mut c = c0;
        c[0] += amp * (om * t).sin();
        let rep = hold(&mut w, c, true);
        felt.push(rep.force_n[0]);
        xb.push(w.brick(BrickId(0)).unwrap().position_m[0]);
    }
    // The last 2 s (4 periods), after the start-up transient.
    let (mut peak_felt, mut peak_ma, mut worst) = (0.0f64, 0.0f64, 0.0f64);
    for n in 1000..xb.len() - 1 {
        // The brick's acceleration over the step that the force of tick n + 1 drove.
        let a = (xb[n + 1] - 2.0 * xb[n] + xb[n - 1]) / (dt * dt);
        peak_felt = peak_felt.max(felt[n + 1].abs());
        peak_ma = peak_ma.max((m * a).abs());
        worst = worst.max((felt[n + 1] + m * a).abs());
    }
    // The coupling's impedance Z(iω) = k + iω b k_s / (iω b + k_s) (spring, and the damper
    // through its series spring); felt force over hand motion: M ω² Z / (Z − M ω²).
    let k_max = Limits::FALCON.max_stiffness_n_per_m;
    let k = 0.3 * k_max;
    let ks = (0.6 - 0.3) * k_max;
    let b = 2.0 * w.params().coupling.damping_ratio * (k * m).sqrt();
    let tr = haptic_types::local::felt_mass_ratio(k, ks, b, m, om);
    let predicted = m * amp * om * om * tr;
    println!(
        "2 Hz carry: peak felt {peak_felt:.4} N, peak M a(brick) {peak_ma:.4} N, worst tick \
         difference {worst:.2e} N; M a(hand) {:.4} N × transmissibility {tr:.4} = {predicted:.4} N",
        m * amp * om * om,
    );
    assert!(worst < 0.05 * peak_ma, "felt vs −M a of the brick: {worst}");
    // docs/brickworld.md quotes the felt force as the brick's own −M a to 1.4·10⁻¹¹ N and the
    // transmissibility's prediction 1.9 % under it (each to its printed precision).
    if default_solver() {
        assert!((worst - 1.4e-11).abs() < 0.05e-11, "{worst:e} N");
        let off = 100.0 * (peak_felt - predicted) / predicted;
        assert!((off - 1.9).abs() < 0.05, "{off} %");
    }
    (peak_felt, predicted)
}

/// Set down on the ground at 0.5 m/s: the force at the hand rises no faster than the
/// coupling's stiffness times the speed, k v dt per tick, and the brick does not sink.
#[test]
fn a_brick_set_down_at_half_a_metre_per_second_is_felt_no_stiffer_than_the_device() {
    let mut p = bare();
    p.restitution = 0.0;
    let (mut w, mut c) = holding_with(p, 0.2);
    let dt = w.params().dt_s;
    let k_max = Limits::FALCON.max_stiffness_n_per_m;
    let hz = w.params().brick_half_extents_m[2];
    let v = 0.5;
    let mut last = hold(&mut w, c, true).force_n[2];
    let (mut worst_rate, mut sink, mut first_contact) = (0.0f64, 0.0f64, None);
    for n in 0..800 {
        c[2] = (c[2] - v * ramp(n as f64 * dt, 0.25) * dt).max(0.02);
        let rep = hold(&mut w, c, true);
        let b = w.brick(BrickId(0)).unwrap();
        if first_contact.is_none() && b.position_m[2] < hz + 1e-3 {
            first_contact = Some(n);
        }
        sink = sink.max(hz - b.position_m[2]);
        if first_contact.is_some() {
            worst_rate = worst_rate.max((rep.force_n[2] - last).abs() / dt);
        }
        last = rep.force_n[2];
    }
    println!(
        "set down at {v} m/s: steepest force change after contact {worst_rate:.1} N/s vs the \
         device's k_max v = {:.1} N/s, sink {sink:.2e} m",
        k_max * v
    );
    assert!(first_contact.is_some());
    // No faster than the coupling's high-frequency stiffness allows (0.6 k_max), let alone
    // the device's.
    assert!(worst_rate <= 0.6 * k_max * v, "{worst_rate}");
    // docs/brickworld.md quotes the steepest rise: 871 N/s (to the N/s).
    if default_solver() {
        assert!((worst_rate - 871.0).abs() < 0.5, "{worst_rate} N/s");
    }
    assert!(sink < 1e-3);
}

/// Let go while swinging: the brick leaves with the hand's velocity (issue 31: not with the
/// coupling's own swing on top of it), then flies as a projectile.
#[test]
fn a_coupled_throw_leaves_with_the_hands_velocity() {
    let (mut w, mut c) = holding(0.2);
    let dt = w.params().dt_s;
    let v = [1.0, 0.3, 0.6];
    for n in 0..400 {
        let r = ramp(n as f64 * dt, 0.2);
        for k in 0..3 {
            c[k] += v[k] * r * dt;
        }
        hold(&mut w, c, true);
    }
    let before = w.brick(BrickId(0)).unwrap().velocity_m_per_s;
    let rel = hold(&mut w, c, false);
    let after = w.brick(BrickId(0)).unwrap().velocity_m_per_s;
    let v0 = rel
        .events
        .iter()
        .find_map(|e| match e {
            Event::Thrown {
                velocity_m_per_s, ..
            } => Some(*velocity_m_per_s),
            _ => None,
        })
        .expect("a throw");
    // Each component within 0.012 m/s, 1 % of the 1.2 m/s throw (measured: 1e-14).
    let g = w.params().gravity_m_per_s2;
    for k in 0..3 {
        assert!((v0[k] - v[k]).abs() < 0.01 * 1.2, "{v0:?} vs hand {v:?}");
        // The brick's own velocity just before the release was the hand's but for the
        // coupling's swing: the release changes it by less than 0.05 m/s (measured 2.5 mm/s).
        assert!(
            (v0[k] - before[k]).abs() < 0.05,
            "{v0:?} vs brick {before:?}"
        );
        // And the body leaves with it: after the release tick it moves at the released
        // velocity less that tick's gravity (measured: within 1e-14 m/s).
        let fall = if k == 2 { g * dt } else { 0.0 };
        assert!(
            (after[k] - (v0[k] - fall)).abs() < 1e-9,
            "body {after:?} vs released {v0:?}"
        );
    }
    // Nothing held, nothing touched: no force. The cursor still sits on the brick's top face
    // (taken from above, issue 31), but the hand passes through a brick it let go of until it
    // has left it, so the release tick renders exactly nothing.
    assert_eq!(
        rel.force_n, [0.0; 3],
        "nothing held, nothing touched: no force"
    );
    // Flight: gravity only (no contact within 0.1 s).
    let b0 = w.brick(BrickId(0)).unwrap();
    for _ in 0..100 {
        idle(&mut w, PARK);
    }
    let b1 = w.brick(BrickId(0)).unwrap();
    let g = w.params().gravity_m_per_s2;
    assert!((b1.velocity_m_per_s[2] - (b0.velocity_m_per_s[2] - g * 0.1)).abs() < 1e-9);
    assert!((b1.velocity_m_per_s[0] - b0.velocity_m_per_s[0]).abs() < 1e-12);
}

/// Switching `inertia` while holding: the brick changes between coupled and rigidly carried
/// where it is, and the felt force stays the weight (no jump beyond the coupling's sag).
#[test]
fn switching_inertia_while_holding_keeps_the_weight() {
    let (mut w, c) = holding(0.5);
    let g = w.params().gravity_m_per_s2;
    w.set_inertia(Inertia::Off);
    let rep = hold(&mut w, c, true);
    assert!((rep.force_n[2] + 0.5 * g).abs() < 1e-9);
    assert_eq!(rep.coupling_force_n, [0.0; 3]);
    w.set_inertia(Inertia::Coupling);
    let mut rep = hold(&mut w, c, true);
    for _ in 0..2000 {
        rep = hold(&mut w, c, true);
    }
    assert!((rep.force_n[2] + 0.5 * g).abs() < 0.01 * 0.5 * g);
}
