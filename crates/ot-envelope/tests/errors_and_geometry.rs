//! Typed errors for bad input, and the planar geometry kernel.

mod common;
use common::*;
use ot_envelope::bounded::SteeringRange;
use ot_envelope::geometry::{contains, outer_boundary, signed_area};
use ot_envelope::{
    EnvelopeOptions, OffsetRegion, solve_trap, working_envelope, working_envelope_with,
};

#[test]
fn bad_arguments_name_the_field_and_range() {
    let p = paper();
    let e = working_envelope(&p, &v(0.0, 0.0), Some(0.0)).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "tol [m] = 0 is out of range: allowed finite and > 0"
    );
    let e = working_envelope(&p, &v(f64::INFINITY, 0.0), None).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "velocity [m/s] = inf is out of range: allowed finite"
    );
    let e = solve_trap(&p, &v(0.0, 0.0), &v(f64::NAN, 0.0)).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "target [m] = NaN is out of range: allowed finite"
    );
    let e = OffsetRegion::new(v(1.0, 0.0), v(0.0, 1.0)).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "region.hi - region.lo [m] = -1 is out of range: allowed > 0 on each axis"
    );
    let opts = EnvelopeOptions {
        cell_waists: Some(1e-6),
        ..Default::default()
    };
    let e = working_envelope_with(&p, &v(0.0, 0.0), &opts).expect_err("must be rejected");
    assert!(
        e.to_string()
            .starts_with("cell_waists [waists] = 1e-6 is out of range")
    );
    let e = SteeringRange::new(v(0.0, 0.0), -1.0).expect_err("must be rejected");
    assert_eq!(
        e.to_string(),
        "steering.radius [m] = -1 is out of range: allowed finite and > 0"
    );
}

#[test]
fn outer_boundary_of_overlapping_squares_is_their_union_outline() {
    let sq = |x: f64, y: f64| vec![v(x, y), v(x + 2.0, y), v(x + 2.0, y + 2.0), v(x, y + 2.0)];
    let poly = outer_boundary(&[(sq(0.0, 0.0), true), (sq(1.0, 1.0), true)], 1e-12);
    assert_eq!(poly.len(), 8);
    assert!((signed_area(&poly) - 7.0).abs() < 1e-12);
    assert!(contains(&poly, &v(2.5, 2.5)) && !contains(&poly, &v(2.5, 0.5)));
}

#[test]
fn outer_boundary_drops_inner_loops_and_dangling_spurs() {
    let outer = vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)];
    let inner = vec![v(1.0, 1.0), v(2.0, 1.0), v(2.0, 2.0)];
    let spur_in = vec![v(0.0, 2.0), v(1.0, 2.0)];
    let spur_out = vec![v(4.0, 2.0), v(5.0, 2.0)];
    let poly = outer_boundary(
        &[
            (outer, true),
            (inner, true),
            (spur_in, false),
            (spur_out, false),
        ],
        1e-12,
    );
    assert!((signed_area(&poly) - 16.0).abs() < 1e-12);
    // the outer spur is walked out and back: removed as a spike
    assert!(poly.iter().all(|p| p.x <= 4.0));
}

#[test]
fn outer_boundary_of_a_self_crossing_curve_is_its_hull_of_lobes() {
    // figure-eight: two lobes crossing at the origin
    let n = 200;
    let fig8: Vec<_> = (0..n)
        .map(|k| {
            let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            v(t.sin(), (2.0 * t).sin() * 0.5)
        })
        .collect();
    let poly = outer_boundary(&[(fig8, true)], 1e-12);
    let a = signed_area(&poly);
    // two lobes of area 4/3 · 0.5 each... both counted, total = 4/3
    assert!((a - 4.0 / 3.0).abs() < 2e-3, "{a}");
}

/// Ctrl-C in the wheel: a raised cancel flag stops an envelope (Δt = 6.4 µs at the paper's
/// constants, four oscillation periods: a quarter second of crossing search) with
/// `Interrupted` at its first flow, and an unraised flag changes nothing. (A tangle that would
/// take minutes is refused before its crossing search: `tests/long_tick.rs`.)
#[test]
fn a_raised_cancel_flag_stops_a_long_envelope() {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    let model = ot_physics::paper::model().expect("paper model");
    let prop = ot_physics::Propagator::new(model, ot_physics::Method::Rk4 { substeps: 52 }, 6.4e-6)
        .expect("tick map");
    let flag = Arc::new(AtomicBool::new(true));
    let r = ot_physics::cancel::watch(Arc::clone(&flag), || {
        ot_envelope::working_envelope(&prop, &nalgebra::Vector2::zeros(), None)
    });
    assert_eq!(
        r.map(|e| e.polygon.len()).map_err(|e| e.to_string()),
        Err("physics: interrupted".to_string())
    );
    let quiet = Arc::new(AtomicBool::new(false));
    let paper = ot_physics::Propagator::new(
        ot_physics::paper::model().expect("paper model"),
        ot_physics::Method::Rk4 { substeps: 8 },
        2e-7,
    )
    .expect("tick map");
    let a = ot_physics::cancel::watch(quiet, || {
        ot_envelope::working_envelope(&paper, &nalgebra::Vector2::zeros(), None)
    })
    .expect("envelope");
    let b =
        ot_envelope::working_envelope(&paper, &nalgebra::Vector2::zeros(), None).expect("envelope");
    assert_eq!(a.polygon, b.polygon);
}
