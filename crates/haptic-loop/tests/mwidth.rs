//! The M-width report's headline cells (`examples/mwidth_report.rs`, BENCHMARKS.md "M-width"):
//! a brick of the brick world carried at 0.5–5 Hz through protocol 2 on an ideal link, loose
//! grip. Every run is simulated and deterministic: counts are exact, figures are held to their
//! printed precision both ways, and each felt error against its derived bound
//! ([`haptic_types::local::felt_mass_ratio`]).
#![allow(clippy::unwrap_used)]

use haptic_devices::link::LinkParams;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics};
use haptic_loop::closed_loop::Linked;
use haptic_loop::mwidth::{Carry, Coupling, FREQUENCIES_HZ, MASSES_KG, carry};

fn base() -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    std::fs::read_to_string(root.join("brickworld.toml")).unwrap()
}

const IDEAL_V2: Linked = Linked {
    link: LinkParams::IDEAL,
    protocol: Protocol::V2,
};

fn carry_at(mech: Mechanics, m: f64, hz: f64) -> Carry {
    carry(
        &base(),
        m,
        Coupling::DEFAULT,
        hz,
        mech,
        Grip::LOOSE,
        &IDEAL_V2,
    )
    .unwrap()
}

/// One row of the table: the masses carried stably at every frequency and the unstable runs.
fn row(mech: Mechanics) -> (Vec<f64>, usize) {
    let (mut stable, mut unstable) = (Vec::new(), 0);
    for m in MASSES_KG {
        let ok = FREQUENCIES_HZ
            .iter()
            .filter(|&&hz| !carry_at(mech, m, hz).report.stable())
            .count();
        unstable += ok;
        if ok == 0 {
            stable.push(m);
        }
    }
    (stable, unstable)
}

#[test]
fn the_stable_masses_of_a_loose_falcon_and_delta3_at_0_ms() {
    // BENCHMARKS.md: falcon loose 0 ms "0.2–1 (3 of 8)", 12 of 32 unstable; delta3 loose 0 ms
    // "0.1–5 (6 of 8)", 2 of 32.
    let (falcon, fu) = row(Mechanics::FALCON);
    println!("falcon: stable {falcon:?}, {fu} unstable runs");
    assert_eq!((falcon, fu), (vec![0.2, 0.5, 1.0], 12));
    let (delta3, du) = row(Mechanics::DELTA3);
    println!("delta3: stable {delta3:?}, {du} unstable runs");
    assert_eq!((delta3, du), (vec![0.1, 0.2, 0.5, 1.0, 2.0, 5.0], 2));
}

#[test]
fn the_2_hz_carry_is_felt_heavy_by_the_couplings_figure_within_its_bounds() {
    for (mech, felt_pct, coupling_pct) in [
        (Mechanics::FALCON, 16.0, 15.9),
        (Mechanics::DELTA3, 11.4, 9.8),
    ] {
        let c = carry_at(mech, 0.5, 2.0);
        let (err, h) = (100.0 * c.error(), 100.0 * (c.coupling_ratio - 1.0));
        let locked = 100.0 * (c.limits.0 - 1.0);
        println!(
            "{}: 2 Hz felt {err:+.3} %, coupling {h:+.3} %, dashpot locked {locked:+.3} %, \
             free {:+.3} %",
            mech.name,
            100.0 * (c.limits.1 - 1.0)
        );
        assert!(c.report.stable(), "{}", mech.name);
        // The printed figures, two-sided.
        assert!((err - felt_pct).abs() < 0.05, "{}: {err}", mech.name);
        assert!((h - coupling_pct).abs() < 0.05, "{}: {h}", mech.name);
        // Above the least any damper gives (the locked dashpot), below the free one.
        assert!(c.felt_ratio > c.limits.0 && c.felt_ratio < c.limits.1);
    }
    // The Falcon (1 kHz servo) is felt as its coupling within 0.2 %; the delta.3's 4 kHz
    // servo adds 1.6 points, and at a 1 kHz servo it is its coupling within 0.2 % too.
    let f = carry_at(Mechanics::FALCON, 0.5, 2.0);
    assert!((f.felt_ratio / f.coupling_ratio - 1.0).abs() < 0.002);
    let d = carry_at(Mechanics::DELTA3, 0.5, 2.0);
    assert!(d.felt_ratio / d.coupling_ratio - 1.0 > 0.01);
    let slow = Mechanics {
        servo_rate_hz: 1000.0,
        ..Mechanics::DELTA3
    };
    let s = carry_at(slow, 0.5, 2.0);
    println!(
        "delta3 at a 1 kHz servo: felt {:+.3} % against the coupling's {:+.3} %",
        100.0 * s.error(),
        100.0 * (s.coupling_ratio - 1.0)
    );
    assert!((s.felt_ratio / s.coupling_ratio - 1.0).abs() < 0.002);
    // Issue 41's 5 % target at 2 Hz: out of reach of this coupling on every preset, because
    // its locked-dashpot bound is above it.
    assert!(d.limits.0 - 1.0 > 0.05 && f.limits.0 - 1.0 > 0.05);
}
