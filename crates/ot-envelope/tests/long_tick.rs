//! The working envelope refuses a tick that spans more than four periods of the well's fastest
//! oscillation (issue 25): past it the folds multiply and the boundary search grows without
//! bound (at Δt = 95 µs it ran for minutes).

use nalgebra::Vector2;
use ot_envelope::envelope::{MAX_OSCILLATIONS_PER_TICK, check_tick_length};
use ot_envelope::{EnvelopeError, working_envelope};
use ot_physics::{Method, Propagator, TrapModel};

fn paper_tick(dt: f64) -> Propagator<2> {
    let model = ot_physics::paper::model().expect("paper model");
    Propagator::new(model, Method::Rk4 { substeps: 8 }, dt).expect("tick map")
}

#[test]
fn a_tick_of_many_oscillations_is_refused_naming_the_limit() {
    let e = working_envelope(&paper_tick(9.5e-5), &Vector2::zeros(), None)
        .expect_err("a 95 µs tick holds about 59 oscillations");
    assert_eq!(
        e.to_string(),
        "dt [s] = 9.5e-5 is out of range: allowed ≤ 6.4037e-6 s, 4 periods of the well's fastest \
         oscillation (ω = 3.9247e6 rad/s); a longer tick folds the map so often that the \
         envelope's boundary search grows without bound"
    );
    let EnvelopeError::TickTooLong {
        max_dt,
        omega,
        periods,
        ..
    } = e
    else {
        panic!("expected TickTooLong");
    };
    assert_eq!(periods, MAX_OSCILLATIONS_PER_TICK);
    // The bound is exactly 4 periods of ω.
    assert!((max_dt * omega - 8.0 * std::f64::consts::PI).abs() < 1e-12);
    // The paper's tick and the bound itself pass; just past it does not.
    assert!(check_tick_length(&paper_tick(1e-6)).is_ok());
    assert!(check_tick_length(&paper_tick(max_dt)).is_ok());
    assert!(check_tick_length(&paper_tick(max_dt * (1.0 + 1e-9))).is_err());
}

#[test]
fn an_overdamped_trap_has_no_oscillation_to_bound() {
    let model = TrapModel::builder(1e-15, [600e-9, 300e-9])
        .stokes_drag(0.5e-6, 1e-3)
        .build()
        .expect("overdamped model");
    let prop = Propagator::new(model, Method::Rk4 { substeps: 8 }, 1e-4).expect("tick map");
    assert!(check_tick_length(&prop).is_ok());
}

#[test]
fn a_tangle_of_fold_images_is_refused_before_its_crossing_search() {
    // Δt = 5 µs (3.1 periods, within the tick bound) with 8 RK4 substeps: ω·h = 2.5 rad, the
    // polynomial map folds where the flow does not, and its fold images cross ~5·10⁷ times
    // (about a minute of search). 41 substeps (ω·h = 0.48) give the true, untangled envelope.
    let e = working_envelope(&paper_tick(5e-6), &Vector2::zeros(), None)
        .expect_err("a tangle of fold images");
    assert_eq!(
        e.to_string(),
        "physics: envelope boundary: segment pairs to test = 5.3854177e7 is out of range: \
         allowed ≤ 2e6 (the images of the map's folds are tangled: take a shorter tick, a \
         slower particle or a tick map with more substeps)"
    );
    let model = ot_physics::paper::model().expect("paper model");
    let fine = Propagator::new(model, Method::Rk4 { substeps: 41 }, 5e-6).expect("tick map");
    let we = working_envelope(&fine, &Vector2::zeros(), None).expect("envelope");
    assert_eq!(we.polygon.len(), 792);
    // The free drift (zero here) is reachable; from rest, energy conservation keeps the
    // particle within twice its offset from the trap centre: every displacement is within
    // twice the farthest offset of the region, per axis.
    assert!(we.contains(&Vector2::zeros()));
    for p in &we.polygon {
        for i in 0..2 {
            let o = we.region.lo[i].abs().max(we.region.hi[i].abs());
            assert!(p[i].abs() <= 2.0 * o, "{p:?}");
        }
    }
}

/// The inverse solve refuses the tick the working envelope refuses, by the same bound and
/// before any work: `nh.solve_trap(nh.paper_trap(), [-0.288, -0.070], 9.97e-5,
/// [-3.6e-144, -2.3e-274])` ran for more than 20 s (the wheel's default tick map at that Δt:
/// ⌈ω·Δt / 0.5⌉ = 783 RK4 substeps).
#[test]
fn the_inverse_solve_refuses_a_tick_of_many_oscillations_quickly() {
    let model = ot_physics::paper::model().expect("paper model");
    let prop = Propagator::new(model, Method::Rk4 { substeps: 783 }, 9.97e-5).expect("tick map");
    let started = std::time::Instant::now();
    let e = ot_envelope::solve_trap(
        &prop,
        &Vector2::new(-0.288, -0.070),
        &Vector2::new(-3.6e-144, -2.3e-274),
    )
    .expect_err("a 99.7 µs tick holds about 62 oscillations");
    let took = started.elapsed();
    assert!(
        matches!(e, EnvelopeError::TickTooLong { .. }),
        "expected TickTooLong, got {e}"
    );
    assert!(
        e.to_string()
            .starts_with("dt [s] = 9.97e-5 is out of range: allowed ≤ 6.4037e-6 s, 4 periods"),
        "{e}"
    );
    // Refused before sampling the map (a bound on work, not a timing target: seconds apart).
    assert!(took.as_secs_f64() < 2.0, "took {took:?}");
}
