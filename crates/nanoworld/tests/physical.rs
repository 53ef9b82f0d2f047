//! Physical mode with nanoparticles: pick-up by pulling (the particle's substrate bond is
//! the weakest link), and transfer onto a bonded pair (the tip's hold is the weakest link).

use nalgebra::Vector3;
use nanoworld::{BrokenLink, Event, Interaction, Member, Params, Target, World, polyline};

#[test]
fn particle_is_picked_up_then_transferred_onto_a_bonded_pair() {
    let mut p = Params::physical_default();
    p.loading_zone = None;
    // A alone; B and C touching (bonded), so B is held by an atom–atom bond.
    p.initial_atoms_xy_m = vec![[15e-9, 30e-9], [40e-9, 30e-9], [50e-9, 30e-9]];
    let Interaction::Physical(ph) = p.interaction.clone() else {
        unreachable!()
    };
    let z0 = ph.contact_gap_m;
    let (rt, ra) = (p.tip.radius_m, p.atoms.radius_m);
    let mut w =
        World::new(&p, &p.default_limits(), Vector3::new(15e-9, 30e-9, 50e-9)).expect("valid");
    assert_eq!(w.atoms()[1].bonds(), &[2]);
    let (a, b) = (w.atoms()[0].position_m(), w.atoms()[1].position_m());
    // Resting on the plane at the contact gap z0.
    assert!((a.z - (p.substrate.atom_radius_m + z0 + ra)).abs() < 1e-18);
    let pts = [
        Vector3::new(a.x, a.y, 50e-9),
        Vector3::new(a.x, a.y, a.z + ra + rt + 0.1e-9),
        Vector3::new(a.x, a.y, 50e-9),
        Vector3::new(b.x, b.y, 50e-9),
        Vector3::new(b.x, b.y, b.z + 3.0 * ra + rt + 0.1e-9),
        Vector3::new(b.x, b.y, 50e-9),
    ];
    let mut events = Vec::new();
    for i in polyline(&pts, 2e-12) {
        let r = w.step(&i, 1e-3).expect("valid");
        assert!(r.force_n.iter().all(|v| v.is_finite()));
        events.extend(r.events);
    }
    let dmt = |a_j: f64, r_eff: f64| a_j * r_eff / (6.0 * z0 * z0);
    let h = ph.hamaker_j;
    let expected_kinds: Vec<_> = events
        .iter()
        .map(|e| match e {
            Event::Snap { member, target, .. } => format!("snap {member:?}->{target:?}"),
            Event::PullOff {
                broken, pull_off_n, ..
            } => {
                let want = match broken {
                    BrokenLink::TargetSupport => dmt(h.atom_substrate, ra),
                    BrokenLink::TipCarried => dmt(h.tip_atom, rt * ra / (rt + ra)),
                    _ => f64::NAN,
                };
                assert!(
                    (pull_off_n - want).abs() < 1e-12 * want,
                    "{broken:?} {pull_off_n:e} vs {want:e}"
                );
                format!("pull-off {broken:?}")
            }
            Event::AtomPickedUp { atom } => format!("picked {atom}"),
            Event::AtomTransferred { atom, onto } => format!("transferred {atom} onto {onto:?}"),
            other => format!("{other:?}"),
        })
        .collect();
    assert_eq!(
        expected_kinds,
        [
            "snap Tip->Atom(0)",
            "pull-off TargetSupport",
            "picked 0",
            "snap Atom(0)->Atom(1)",
            "pull-off TipCarried",
            "transferred 0 onto Atom(1)",
        ]
    );
    // The tip jumped to the particle near the sphere–sphere jump-to-contact gap
    // (A·R_eff/(3·k_c))^{1/3} (the distant plane shifts it slightly).
    if let Some(Event::Snap { gap_m, .. }) = events.first() {
        let r_eff = rt * ra / (rt + ra);
        let z_jtc = (h.tip_atom * r_eff / (3.0 * ph.cantilever_stiffness_n_per_m)).cbrt();
        assert!(
            (gap_m - z_jtc).abs() / z_jtc < 0.03,
            "{gap_m:e} vs {z_jtc:e}"
        );
    }
    let placed = &w.atoms()[0];
    assert!(!placed.is_carried());
    assert_eq!(placed.bonds(), &[1]);
    assert!(w.carried().is_empty());
    // It sits on B at the contact gap, above it to within 10 pm (C's lateral pull deflects
    // the cantilever by ~1 pm before the jump).
    let d = placed.position_m() - w.atoms()[1].position_m();
    assert!((d.norm() - (2.0 * ra + z0)).abs() < 1e-18);
    assert!(d.x.abs() < 1e-11 && d.y.abs() < 1e-11, "{d:?}");
    assert!(matches!(
        events[3],
        Event::Snap {
            member: Member::Atom(0),
            target: Target::Atom(1),
            ..
        }
    ));
}
