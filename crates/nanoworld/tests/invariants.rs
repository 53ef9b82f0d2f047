//! Property tests: the cell list is exact, forces are finite and within the device limit,
//! and the force is continuous except at snap and release events.

use nalgebra::Vector3;
use nanoworld::{Event, GAME_FALCON_LIMITS, PairKind, Params, TipInput, World};
use proptest::prelude::*;

fn bare(mut p: Params, n: usize) -> Params {
    p.substrate.nx = n;
    p.substrate.ny = n;
    p.loading_zone = None;
    p.initial_atoms_xy_m.clear();
    p.house = None;
    p
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The cell list visits exactly the atoms in range, in index order: its sum equals the
    /// brute-force sum bit for bit.
    #[test]
    fn cell_list_equals_brute_force(x in -1e-9f64..13e-9, y in -1e-9f64..13e-9, z in 0.3e-9f64..1.5e-9) {
        let w = World::new(&bare(Params::game_default(), 40), &GAME_FALCON_LIMITS, Vector3::new(0.0, 0.0, 5e-9)).expect("valid");
        let c = w.substrate_force_check(Vector3::new(x, y, z)).expect("game mode");
        for k in 0..3 {
            prop_assert_eq!(c.cell_list_n[k].to_bits(), c.brute_force_n[k].to_bits());
        }
    }

    /// Random cursor walks (small steps and wild jumps, both modes): every force is finite
    /// and within the device limit, and `saturated` says exactly when it was scaled.
    #[test]
    fn forces_finite_and_within_limit(
        physical in any::<bool>(),
        steps in prop::collection::vec((-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, 0u8..10), 1..300),
    ) {
        let p = if physical { Params::physical_default() } else { Params::game_default() };
        let scale = if physical { 20e-9 } else { 1e-9 };
        let max = p.default_limits().max_force_n;
        let start = Vector3::new(2e-9, 2e-9, 2e-9);
        let mut w = World::new(&p, &p.default_limits(), start).expect("valid");
        let mut x = start;
        for (dx, dy, dz, kind) in steps {
            let d = Vector3::new(dx, dy, dz);
            x = if kind == 0 { Vector3::new(6e-9, 6e-9, 0.5e-9) + d * scale } else { x + d * scale * 0.01 };
            let r = w.step(&TipInput { position_m: x }, 1e-3).expect("finite input");
            prop_assert!(r.force_n.iter().all(|v| v.is_finite()));
            prop_assert!(r.unlimited_force_n.iter().all(|v| v.is_finite()));
            prop_assert!(r.force_n.norm() <= max * (1.0 + 1e-12));
            prop_assert_eq!(r.saturated, r.unlimited_force_n.norm() > max);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Along a slow approach–retract path at a random spot and tilt, the force changes by
    /// at most L·|Δx| per tick (L: bound on the summed pair-law gradients) except on ticks
    /// with a snap or pull-off event — and those do jump.
    #[test]
    fn force_jumps_only_at_snap_and_release(
        x in 5e-9f64..7e-9, y in 5e-9f64..7e-9, tilt_x in -0.3f64..0.3, tilt_y in -0.3f64..0.3,
    ) {
        let p = bare(Params::game_default(), 40);
        let w0 = World::new(&p, &p.default_limits(), Vector3::new(x, y, 2e-9)).expect("valid");
        let l = *w0.laws().get(PairKind::TipSubstrate);
        let (rt, rs) = (p.tip.radius_m, p.substrate.atom_radius_m);
        // At most 64 lattice atoms lie within reach (π((R+r+w+a)/a)² < 64).
        let per_pair = 2.0 * l.coef_n_m2 / l.snap_gap_m.powi(3) + l.snap_force_n / (rt + rs);
        let lip = 64.0 * per_pair + l.stiffness_n_per_m;
        let dir = Vector3::new(tilt_x, tilt_y, -1.0).normalize();
        let top = Vector3::new(x, y, 2.5e-9);
        let h = 1e-13;
        let n = 22_000;
        let mut w = w0;
        let mut prev: Option<(Vector3<f64>, Vector3<f64>)> = None;
        let mut snaps = 0;
        let mut releases = 0;
        // Down n ticks, then up 2n ticks (far enough to pull off along any contact normal).
        for k in 0..3 * n {
            let s = if k < n { k as f64 } else { 2.0 * n as f64 - k as f64 } * h;
            let pos = top + dir * s;
            let r = w.step(&TipInput { position_m: pos }, 1e-3).expect("valid");
            let event = r.events.iter().any(|e| matches!(e, Event::Snap { .. } | Event::PullOff { .. }));
            if let Some((px, pf)) = prev {
                let jump = (r.force_n - pf).norm();
                let allowed = lip * (pos - px).norm() * (1.0 + 1e-9);
                if !event {
                    prop_assert!(jump <= allowed, "tick {k}: jump {jump:e} > {allowed:e}");
                }
                if r.events.iter().any(|e| matches!(e, Event::PullOff { .. })) {
                    prop_assert!(jump > allowed);
                }
            }
            snaps += r.events.iter().filter(|e| matches!(e, Event::Snap { .. })).count();
            releases += r.events.iter().filter(|e| matches!(e, Event::PullOff { .. })).count();
            prev = Some((pos, r.force_n));
        }
        prop_assert!(snaps >= 1 && releases >= 1, "path must cross snap and release");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Random low sweeps over the loading zone and the foundation (so atoms spawn, attach,
    /// anchor, transfer): the state stays consistent after every tick.
    #[test]
    fn state_stays_consistent(
        physical in any::<bool>(),
        legs in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0), 2..12),
    ) {
        let p = if physical { Params::physical_default() } else { Params::game_default() };
        let (lo, span, zmax) = if physical { (5e-9, 40e-9, 45e-9) } else { (1e-9, 6e-9, 2.5e-9) };
        let zmin = p.substrate.atom_radius_m + p.tip.radius_m;
        let mut w = World::new(&p, &p.default_limits(), Vector3::new(2e-9, 2e-9, zmax)).expect("valid");
        let mut pts = vec![w.cursor_m()];
        for (a, b, c) in legs {
            pts.push(Vector3::new(lo + a * span, lo + b * span, zmin + c * (zmax - zmin)));
        }
        let step = if physical { 20e-12 } else { 2e-12 };
        for i in nanoworld::polyline(&pts, step) {
            let r = w.step(&i, 1e-3).expect("valid");
            prop_assert!(r.force_n.iter().all(|v| v.is_finite()));
            let atoms = w.atoms();
            let carried: Vec<usize> = (0..atoms.len()).filter(|&i| atoms[i].is_carried()).collect();
            prop_assert_eq!(&carried, w.carried());
            for (i, a) in atoms.iter().enumerate() {
                for &j in a.bonds() {
                    prop_assert!(j != i && atoms[j].bonds().contains(&i), "bond {i}-{j} not mutual");
                }
                if let Some(o) = a.carried_offset_m() {
                    prop_assert!((a.position_m() - (w.tip_position_m() + o)).norm() < 1e-18);
                    prop_assert!(!a.on_substrate());
                }
            }
            if let nanoworld::TipContact::Anchored(an) = w.tip_contact() {
                prop_assert_eq!(an.tip_position_m, w.tip_position_m());
                let (pm, rm) = match an.member {
                    nanoworld::Member::Tip => (w.tip_position_m(), p.tip.radius_m),
                    nanoworld::Member::Atom(c) => (atoms[c].position_m(), p.atoms.radius_m),
                };
                let gap = match an.target {
                    nanoworld::Target::Atom(t) => (pm - atoms[t].position_m()).norm() - rm - p.atoms.radius_m,
                    nanoworld::Target::SubstrateAtom(j) => (pm - w.substrate().positions()[j]).norm() - rm - p.substrate.atom_radius_m,
                    nanoworld::Target::SubstratePlane => pm.z - rm - p.substrate.atom_radius_m,
                };
                let cg = w.laws().get(PairKind::AtomAtom).contact_gap_m;
                prop_assert!((gap - cg).abs() < 1e-17, "anchored gap {gap:e} vs contact {cg:e}");
            }
        }
    }
}

/// BENCHMARKS.md's nanoworld table (its report's 50 probes on the hover circle: radius 1 nm,
/// 0.25 nm gap, over the substrate centre): atoms in range 24 / 24 / 22 / 24 and the activation
/// cutoff's largest difference from the untruncated 1/z² sum 0.643 / 0.656 / 0.659 / 0.660 at
/// 1024 / 10000 / 100489 / 1000000 substrate atoms; the cell list's error 0.
#[test]
fn the_benchmarks_substrate_table_at_four_sizes() {
    for (n, in_range, cutoff) in [
        (32, 24, 0.643),
        (100, 24, 0.656),
        (317, 22, 0.659),
        (1000, 24, 0.660),
    ] {
        let p = bare(Params::game_default(), n);
        let c = n as f64 * p.substrate.spacing_m / 2.0;
        let z = p.substrate.atom_radius_m + p.tip.radius_m + 0.25e-9;
        let w = World::new(&p, &p.default_limits(), Vector3::new(c + 1e-9, c, z)).expect("valid");
        let (mut most, mut worst) = (0, 0.0f64);
        for k in (0..20_000).step_by(400) {
            let t = k as f64 / 997.0 * std::f64::consts::TAU;
            let tip = Vector3::new(c + 1e-9 * t.cos(), c + 1e-9 * t.sin(), z);
            let f = w.substrate_force_check(tip).expect("game mode");
            assert_eq!(f.cell_list_n, f.brute_force_n, "{n}² atoms");
            most = most.max(f.atoms_in_range);
            worst = worst.max((f.cell_list_n - f.untruncated_n).norm() / f.untruncated_n.norm());
        }
        assert_eq!(most, in_range, "{n}² atoms");
        assert!((worst - cutoff).abs() <= 5e-4, "{n}² atoms: {worst}");
    }
}
