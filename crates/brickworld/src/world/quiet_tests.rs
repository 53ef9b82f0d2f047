//! Quiet steps (`crate::rest`) against a world where no step runs quiet.

use crate::Grip;
use crate::event::Event;
use crate::params::{BrickPlacement, BrickProps, Params};
use crate::world::World;
use world_form::Limits;

fn at(c: [f64; 3]) -> BrickPlacement {
    BrickPlacement {
        center_m: c,
        rotation_deg: [0.0; 3],
    }
}

/// What a run gave: every impact (tick, speed m/s, impulse N·s), which steps ran quiet,
/// and the world.
struct Run {
    impacts: Vec<(u64, f64, f64)>,
    quiet: Vec<bool>,
    world: World,
}

/// `ticks` steps of `p`, the hand parked far away, `drop` added at its tick.
fn run(p: &Params, never_quiet: bool, ticks: u64, drop: Option<(u64, BrickPlacement)>) -> Run {
    let mut w = World::new(p, &Limits::FALCON).unwrap();
    w.never_quiet = never_quiet;
    let input = w.input([1.5, 1.5, 1.5], Grip::default()).unwrap();
    let (mut impacts, mut quiet) = (Vec::new(), Vec::new());
    for t in 0..ticks {
        if let Some((when, placement)) = drop
            && when == t
        {
            w.add_brick_with(placement, BrickProps::default()).unwrap();
        }
        let r = w.step(&input);
        quiet.push(w.quiet());
        for e in r.events {
            if let Event::Impact {
                impulse_n_s,
                speed_m_per_s,
                ..
            } = e
            {
                impacts.push((r.tick, speed_m_per_s, impulse_n_s));
            }
        }
    }
    Run {
        impacts,
        quiet,
        world: w,
    }
}

/// Largest distance, m, between the same brick in two worlds.
fn apart(a: &World, b: &World) -> f64 {
    a.bricks()
        .zip(b.bricks())
        .map(|(a, b)| {
            (0..3)
                .map(|k| (a.position_m[k] - b.position_m[k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .fold(0.0, f64::max)
}

/// A floor of 5 × 4 bricks laid 5 mm apart, sleeping off: every step from the 50th (50 ms
/// of rest) runs quiet, no brick collider has hooks then, only the 80 ground contacts reach
/// the solver, only the 20 ground pairs are left, and after 2 s every brick is within a
/// micrometre of where it is when no step runs quiet.
#[test]
fn a_resting_floor_runs_quiet() {
    let p = super::tests::floor();
    let q = run(&p, false, 2000, None);
    let n = run(&p, true, 2000, None);
    assert_eq!(q.quiet.iter().position(|&x| x), Some(49));
    assert!(q.quiet[49..].iter().all(|&x| x));
    assert!(n.quiet.iter().all(|&x| !x));
    let phys = &q.world.bricks.phys;
    for (_, co) in phys.colliders.iter() {
        assert!(co.active_hooks().is_empty());
    }
    let mut solver = 0;
    for pair in phys.narrow_phase.contact_pairs() {
        for m in pair.solver_manifolds() {
            solver += m.data.solver_contacts.len();
        }
    }
    assert_eq!(solver, 80);
    // Nothing can sleep, so turning quiet fitted the broad-phase boxes to the short
    // prediction: only the 20 ground pairs are left (the world that is never quiet keeps
    // every pair of neighbours within its 2 cm prediction, 55 more).
    assert_eq!(phys.narrow_phase.contact_pairs().count(), 20);
    assert_eq!(n.world.bricks.phys.narrow_phase.contact_pairs().count(), 75);
    let d = apart(&q.world, &n.world);
    assert!(d < 1e-6, "{d} m");
}

/// A brick dropped flat from 1 m onto a resting stack of ten (asleep, or awake with
/// sleeping off): the stack rests quiet for 3 s first, and the drop sounds the same as when
/// no step runs quiet: the same impacts on the same ticks, the landing's speed and impulse
/// to 1e-6. The bricks end within a millimetre of where they end then, under half as far
/// as placing one brick of the stack a micrometre off moves them (the rattle after the
/// landing is that sensitive to the stack's state).
#[test]
fn a_drop_onto_a_quiet_stack_sounds_the_same() {
    for sleeping in [false, true] {
        let mut p = Params {
            sleeping,
            ..Params::default()
        };
        let h = p.brick_half_extents_m;
        p.bricks = (0..10)
            .map(|i| at([0.0, 0.0, h[2] * (2 * i + 1) as f64]))
            .collect();
        let drop = Some((3000, at([0.0, 0.0, h[2] * 21.0 + 1.0])));
        let q = run(&p, false, 6000, drop);
        let n = run(&p, true, 6000, drop);
        let mut off = p.clone();
        off.bricks[5].center_m[0] += 1e-6;
        let m = run(&off, true, 6000, drop);
        assert!(q.quiet[100..3000].iter().all(|&x| x), "sleeping {sleeping}");
        let ticks = |r: &Run| r.impacts.iter().map(|i| i.0).collect::<Vec<_>>();
        assert_eq!(ticks(&q), ticks(&n), "sleeping {sleeping}");
        let (a, b) = (q.impacts[0], n.impacts[0]);
        assert!(((a.1 - b.1) / b.1).abs() < 1e-6 && ((a.2 - b.2) / b.2).abs() < 1e-6);
        assert!(a.1 > 4.4 && a.1 < 4.45, "landing at {} m/s", a.1);
        let (qn, mn) = (apart(&q.world, &n.world), apart(&m.world, &n.world));
        assert!(
            qn < 1e-3 && qn < mn / 2.0,
            "sleeping {sleeping}: {qn} m, {mn} m"
        );
    }
}
