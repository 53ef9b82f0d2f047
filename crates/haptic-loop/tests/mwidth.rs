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
        let want_locked = if mech.name == "falcon" { 12.3 } else { 7.0 };
        assert!(
            (locked - want_locked).abs() < 0.05,
            "{}: {locked}",
            mech.name
        );
        // Above the least any damper gives (the locked dashpot), below the free one.
        assert!(c.felt_ratio > c.limits.0 && c.felt_ratio < c.limits.1);
    }
    // docs/devices.md: the Touch +16 % and the Inverse3 +17 % (their coupling is the
    // Falcon's: the fitted mapping scales the brick's mass with the stiffness).
    for (mech, want) in [(Mechanics::TOUCH, 15.9), (Mechanics::INVERSE3, 16.7)] {
        let c = carry_at(mech, 0.5, 2.0);
        println!("{}: 2 Hz felt {:+.3} %", mech.name, 100.0 * c.error());
        assert!(c.report.stable(), "{}", mech.name);
        assert!(
            (100.0 * c.error() - want).abs() < 0.05,
            "{}: {}",
            mech.name,
            c.error()
        );
        assert!((100.0 * (c.coupling_ratio - 1.0) - 15.9).abs() < 0.05);
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
    assert!((100.0 * s.error() - 10.0).abs() < 0.05, "{}", s.error());
    // Issue 41's 5 % target at 2 Hz: out of reach of this coupling on every preset, because
    // its locked-dashpot bound is above it.
    assert!(d.limits.0 - 1.0 > 0.05 && f.limits.0 - 1.0 > 0.05);
    // Only the delta.3 admits 5 % at all: a spring at its whole rated stiffness, +4.1 %
    // (m ω² / (k_max − m ω²)); the Falcon's +7.0 %.
    let at_k_max = |c: &Carry, mech: Mechanics| {
        let mw2 = c.device_mass_kg * (4.0 * std::f64::consts::PI).powi(2);
        100.0 * mw2 / (mech.limits.max_stiffness_n_per_m - mw2)
    };
    assert!((at_k_max(&d, Mechanics::DELTA3) - 4.1).abs() < 0.05);
    assert!((at_k_max(&f, Mechanics::FALCON) - 7.0).abs() < 0.05);
}

/// BENCHMARKS.md: the stiffer coupling (0.6 / 1.0) brings the Falcon's 2 Hz carry to +8.1 %
/// (loose) and +8.6 % (firm) at 0 ms, +5.9 % behind 10 ms with either hand, but 32 of its 64
/// runs at 2 Hz (every mass, grip and latency) are unstable.
#[test]
fn a_stiffer_coupling_on_the_falcon_is_lighter_but_unstable_in_half_its_runs() {
    let run = |m: f64, grip: Grip, ms: f64| {
        let l = Linked {
            link: LinkParams::latency_ms(ms),
            protocol: Protocol::V2,
        };
        carry(
            &base(),
            m,
            Coupling::STIFF,
            2.0,
            Mechanics::FALCON,
            grip,
            &l,
        )
        .unwrap()
    };
    for (grip, ms, want) in [
        (Grip::LOOSE, 0.0, 8.1),
        (Grip::LOOSE, 10.0, 5.9),
        (Grip::FIRM, 0.0, 8.6),
        (Grip::FIRM, 10.0, 5.9),
    ] {
        let c = run(0.5, grip, ms);
        println!(
            "stiff coupling, {} {ms} ms: {:+.3} %",
            grip.label(),
            100.0 * c.error()
        );
        assert!(c.report.stable());
        assert!((100.0 * c.error() - want).abs() < 0.05, "{}", c.error());
    }
    let mut unstable = 0;
    for grip in [Grip::LOOSE, Grip::FIRM] {
        for ms in [0.0, 1.0, 5.0, 10.0] {
            for m in MASSES_KG {
                unstable += usize::from(!run(m, grip, ms).report.stable());
            }
        }
    }
    assert_eq!(unstable, 32);
}

/// BENCHMARKS.md, other cells the prose reads (loose grip, 0.5 kg): on a Falcon the 0.5 Hz
/// carry +1.3 % at 0 ms and +11.1 % behind 1 ms; at 5 Hz, past its coupling's resonance,
/// +216.9 % (the delta.3, below it, +78.6 %); the stiffer coupling on the delta.3 +8.3 %,
/// +13.0 %, +8.0 %, +13.2 % (loose 0 and 10 ms, firm 0 and 10 ms).
#[test]
fn the_latency_the_resonance_and_the_delta3s_stiffer_coupling() {
    let at = |mech: Mechanics, c: Coupling, hz: f64, grip: Grip, ms: f64| {
        let l = Linked {
            link: LinkParams::latency_ms(ms),
            protocol: Protocol::V2,
        };
        100.0 * carry(&base(), 0.5, c, hz, mech, grip, &l).unwrap().error()
    };
    let d = Coupling::DEFAULT;
    let cells = [
        (at(Mechanics::FALCON, d, 0.5, Grip::LOOSE, 0.0), 1.3),
        (at(Mechanics::FALCON, d, 0.5, Grip::LOOSE, 1.0), 11.1),
        (at(Mechanics::FALCON, d, 5.0, Grip::LOOSE, 0.0), 216.9),
        (at(Mechanics::DELTA3, d, 5.0, Grip::LOOSE, 0.0), 78.6),
        (
            at(Mechanics::DELTA3, Coupling::STIFF, 2.0, Grip::LOOSE, 0.0),
            8.3,
        ),
        (
            at(Mechanics::DELTA3, Coupling::STIFF, 2.0, Grip::LOOSE, 10.0),
            13.0,
        ),
        (
            at(Mechanics::DELTA3, Coupling::STIFF, 2.0, Grip::FIRM, 0.0),
            8.0,
        ),
        (
            at(Mechanics::DELTA3, Coupling::STIFF, 2.0, Grip::FIRM, 10.0),
            13.2,
        ),
    ];
    for (i, (got, want)) in cells.iter().enumerate() {
        println!("cell {i}: {got:+.3} % (printed {want:+.1} %)");
        assert!((got - want).abs() < 0.05, "cell {i}: {got} against {want}");
    }
}
