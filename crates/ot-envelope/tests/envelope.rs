//! The 2D working envelope against a dense brute-force forward sampling.

mod common;
use common::*;
use ot_envelope::geometry::{hausdorff, signed_area};
use ot_envelope::reference::Reference;
use ot_envelope::{EnvelopeOptions, OffsetRegion, working_envelope, working_envelope_with};

/// Check an envelope against `n × n` forward samples of the same map over
/// the envelope's region: returns (outside, overreach) in nm.
fn errors(p: &ot_physics::Propagator<2>, we: &ot_envelope::Envelope, n: usize) -> (f64, f64) {
    let r = Reference::sample(p, &we.v0, &we.region, n).expect("sampling");
    let e = r.errors(p, &we.polygon, 10.0 * NM).expect("errors");
    (e.outside / NM, e.overreach / NM)
}

#[test]
fn paper_envelope_matches_brute_force_at_rest_and_moving() {
    let p = paper();
    for v0 in [v(0.0, 0.0), v(0.1, 0.1)] {
        let we = working_envelope(&p, &v0, None).expect("envelope");
        // polygon conventions: counter-clockwise, first vertex not repeated
        assert!(signed_area(&we.polygon) > 0.0);
        assert_ne!(we.polygon.first(), we.polygon.last());
        assert_eq!(we.fold_curves, 1);
        assert!(!we.touches_region_edge);
        let (outside, over) = errors(&p, &we, 500);
        assert!(
            outside < 0.5 && over < 0.5,
            "v0 {v0:?}: outside {outside} nm, overreach {over} nm"
        );
        // the sanity displacement of ot-physics is reachable
        assert!(we.contains(&v(-136.0 * NM, -86.6 * NM)) || v0.x != 0.0);
        // extent: the paper-constant envelope spans about ±564 nm × ±753 nm at rest
        let xmax = we.polygon.iter().map(|q| q.x).fold(f64::MIN, f64::max);
        let ymax = we.polygon.iter().map(|q| q.y).fold(f64::MIN, f64::max);
        if v0.x == 0.0 {
            assert!(
                (xmax / NM - 564.3).abs() < 1.0 && (ymax / NM - 753.1).abs() < 1.0,
                "{xmax} {ymax}"
            );
        }
    }
}

#[test]
fn envelope_at_rest_has_the_wells_mirror_symmetry() {
    let p = paper();
    let we = working_envelope(&p, &v(0.0, 0.0), None).expect("envelope");
    let mx: Vec<_> = we.polygon.iter().map(|q| v(-q.x, q.y)).collect();
    let my: Vec<_> = we.polygon.iter().map(|q| v(q.x, -q.y)).collect();
    assert!(hausdorff(&we.polygon, &mx, 5.0 * NM) < 2.0 * we.tol);
    assert!(hausdorff(&we.polygon, &my, 5.0 * NM) < 2.0 * we.tol);
}

#[test]
fn envelope_is_bit_identical_when_recomputed() {
    let p = paper();
    let a = working_envelope(&p, &v(0.1, -0.05), None).expect("envelope");
    let b = working_envelope(&p, &v(0.1, -0.05), None).expect("envelope");
    assert_eq!(a, b);
}

#[test]
fn fast_particle_envelope_excludes_zero_displacement() {
    // 3 m/s: kinetic energy 4.5e-15 J > depth 1e-15 J, the trap cannot stop it.
    let p = paper();
    let v0 = v(3.0, 1.0);
    let we = working_envelope(&p, &v0, None).expect("envelope");
    assert!(!we.contains(&v(0.0, 0.0)));
    assert!(we.contains(&we.free_displacement));
    let (outside, over) = errors(&p, &we, 500);
    assert!(
        outside < 0.5 && over < 0.5,
        "outside {outside} nm, overreach {over} nm"
    );
}

#[test]
fn several_periods_tick_folds_the_map_and_the_envelope_still_holds() {
    // Δt = 5 µs ≈ 3 y-periods; RK4 × 48 keeps ωh ≈ 0.4.
    let p = prop([600e-9, 300e-9], 48, 5e-6);
    let we = working_envelope(&p, &v(0.0, 0.0), None).expect("envelope");
    assert!(we.fold_curves >= 5, "{} fold curves", we.fold_curves);
    let (outside, over) = errors(&p, &we, 700);
    assert!(
        outside < 0.5 && over < 0.5,
        "outside {outside} nm, overreach {over} nm"
    );
}

#[test]
fn line_trap_envelope_is_a_sliver_bounded_by_the_peak_force() {
    // b/a = 1/100: a = 30 µm, b = 300 nm.
    let p = prop([30e-6, 300e-9], 8, 1e-6);
    let we = working_envelope(&p, &v(0.0, 0.0), None).expect("envelope");
    let (outside, over) = errors(&p, &we, 500);
    assert!(
        outside < 0.5 && over < 0.5,
        "outside {outside} nm, overreach {over} nm"
    );
    // from rest |Δx| ≤ F_max,x Δt² / 2m with F_max,x = 2 ln2 P0 /a · e^{-1/2}/sqrt(2 ln2)
    let ln2 = std::f64::consts::LN_2;
    let fmax = 2.0 * ln2 * 1e-15 / 30e-6 * (-0.5f64).exp() / (2.0 * ln2).sqrt();
    let bound = fmax * 1e-12 / 2e-15;
    let xmax = we.polygon.iter().map(|q| q.x.abs()).fold(0.0, f64::max);
    assert!(
        xmax <= bound && xmax > 0.95 * bound,
        "xmax {xmax:e} bound {bound:e}"
    );
    let ymax = we.polygon.iter().map(|q| q.y.abs()).fold(0.0, f64::max);
    assert!(ymax > 20.0 * xmax);
}

#[test]
fn paper_one_step_model_envelope_differs_from_converged_one() {
    // The paper's difference equation (one RK4 step) gives its own envelope;
    // at Δt = 1 µs it is far from the converged dynamics.
    let one = prop([600e-9, 300e-9], 1, 1e-6);
    let a = working_envelope(&one, &v(0.0, 0.0), Some(2.0 * NM)).expect("envelope");
    let (outside, over) = errors(&one, &a, 400);
    assert!(
        outside < 2.0 && over < 2.0,
        "outside {outside} nm, overreach {over} nm"
    );
    let b = working_envelope(&paper(), &v(0.0, 0.0), None).expect("envelope");
    assert!(hausdorff(&a.polygon, &b.polygon, 10.0 * NM) > 50.0 * NM);
}

#[test]
fn small_steering_region_bounds_the_envelope_by_its_edge() {
    let p = paper();
    let region =
        OffsetRegion::new(v(-150.0 * NM, -80.0 * NM), v(150.0 * NM, 80.0 * NM)).expect("region");
    let opts = EnvelopeOptions {
        region: Some(region),
        cell_waists: Some(0.05),
        ..Default::default()
    };
    let we = working_envelope_with(&p, &v(0.0, 0.0), &opts).expect("envelope");
    assert!(we.touches_region_edge);
    let (outside, over) = errors(&p, &we, 400);
    assert!(
        outside < 0.5 && over < 0.5,
        "outside {outside} nm, overreach {over} nm"
    );
}

#[test]
fn coarse_grid_interior_changes_nothing_beyond_the_tolerance() {
    use ot_envelope::sample::coarse_companion;
    let p = paper();
    for v0 in [v(0.0, 0.0), v(0.1, 0.1), v(-0.08, 0.05)] {
        let full = working_envelope_with(
            &p,
            &v0,
            &EnvelopeOptions {
                coarse_grid: false,
                ..Default::default()
            },
        )
        .expect("envelope");
        let fast = working_envelope_with(&p, &v0, &EnvelopeOptions::default()).expect("envelope");
        assert!(
            (fast.evals as f64) < 0.75 * full.evals as f64,
            "{} vs {}",
            fast.evals,
            full.evals
        );
        assert!(hausdorff(&full.polygon, &fast.polygon, 2.0 * NM) < fast.tol);
    }
    // long ticks and fast particles always sample at full accuracy
    assert!(coarse_companion(&p, &v(0.0, 0.0)).is_some());
    assert!(coarse_companion(&p, &v(3.0, 1.0)).is_none());
    assert!(coarse_companion(&prop([600e-9, 300e-9], 48, 5e-6), &v(0.0, 0.0)).is_none());
    assert!(coarse_companion(&prop([600e-9, 300e-9], 1, 1e-6), &v(0.0, 0.0)).is_none());
}

#[test]
fn damped_particle_with_external_force_matches_brute_force() {
    // 1 µm bead in water (γ/m ≈ 9.4e6 /s, overdamped within a tick) pushed
    // by 2 pN: the search region follows the drift, the envelope holds.
    let model = ot_physics::TrapModel::builder(1e-15, [600e-9, 300e-9])
        .mass(1e-15)
        .stokes_drag(0.5e-6, 1e-3)
        .external_force([2e-12, 0.0])
        .build()
        .expect("model");
    let p = ot_physics::Propagator::new(model, ot_physics::Method::Rk4 { substeps: 16 }, 1e-6)
        .expect("prop");
    let v0 = v(0.05, 0.0);
    let we = working_envelope(&p, &v0, None).expect("envelope");
    assert!(we.contains(&we.free_displacement));
    let (outside, over) = errors(&p, &we, 500);
    assert!(
        outside < 0.5 && over < 0.5,
        "outside {outside} nm, overreach {over} nm"
    );
}

/// BENCHMARKS.md (docs/bench/ot-envelope.md), the paper's 961-envelope cache: "All 961
/// envelopes (RK4 × 4 at Δt = 0.2 µs: ωh ≈ 0.2): ... 81284 polygon vertices in total (1.3 MB
/// as f64 pairs) ... Error of the v0 = (80, −80) nm/µs envelope vs converged: 0.078 nm" (the
/// report's computation; its time is the benchmark's).
#[test]
fn the_paper_cache_of_961_envelopes_has_the_benchmarks_vertices_and_error() {
    let m = paper_model([600e-9, 300e-9]);
    let p02 = ot_physics::Propagator::new(m, ot_physics::Method::Rk4 { substeps: 4 }, 0.2e-6)
        .expect("tick map");
    let (mut verts, mut corner) = (0usize, None);
    for i in 0..31 {
        for j in 0..31 {
            let v0 = v(
                -0.08 + 0.16 * i as f64 / 30.0,
                -0.08 + 0.16 * j as f64 / 30.0,
            );
            let we = working_envelope(&p02, &v0, None).expect("envelope");
            verts += we.polygon.len();
            if (i, j) == (30, 0) {
                corner = Some(we);
            }
        }
    }
    assert_eq!(verts, 81_284);
    assert!((1.25..1.35).contains(&(verts as f64 * 16.0 / 1e6)));
    let we = corner.expect("the (80, −80) nm/µs envelope");
    let conv = ot_physics::Propagator::new(m, ot_physics::Method::Adaptive { rtol: 1e-10 }, 0.2e-6)
        .expect("converged");
    let r = Reference::sample(&conv, &we.v0, &we.region, 700).expect("sampling");
    let e = r
        .errors(&conv, &we.polygon, 1.0 * NM)
        .expect("errors")
        .hausdorff();
    eprintln!(
        "961 envelopes, {verts} vertices; (80, −80) nm/µs: {:.4} nm",
        e / NM
    );
    assert!((0.0775..0.0785).contains(&(e / NM)), "{} nm", e / NM);
}

/// BENCHMARKS.md (docs/bench/ot-envelope.md), paper constants at Δt = 1 µs against DOP853 at
/// rtol 1e-10: "Tick-map accuracy (max displacement error over 41×41 offsets within ±3
/// waists)": paper-rk4 337.361, rk4 × 4 5.538, rk4 × 8 0.205, rk4 × 16 0.012 nm; "Working
/// envelope": (0, 0) 336 vertices, 11440 force evaluations, outside 0.266, overreach 0.000 nm;
/// (100, 100) 335, 12864, 0.314, 0.002 nm (a 900×900 sampling, as the report).
#[test]
fn the_benchmarks_tick_map_and_envelope_table() {
    use ot_physics::{Method, Propagator};
    let m = paper_model([600e-9, 300e-9]);
    let conv = Propagator::new(m, Method::Adaptive { rtol: 1e-10 }, 1e-6).unwrap();
    for (meth, doc) in [
        (Method::PaperRk4, 337.361),
        (Method::Rk4 { substeps: 4 }, 5.538),
        (Method::Rk4 { substeps: 8 }, 0.205),
        (Method::Rk4 { substeps: 16 }, 0.012),
    ] {
        let p = Propagator::new(m, meth, 1e-6).unwrap();
        let mut err: f64 = 0.0;
        for i in -20..=20 {
            for j in -20..=20 {
                let o = v(i as f64 * 90e-9, j as f64 * 45e-9);
                let (a, b) = (
                    p.flow(&o, &v(0.0, 0.0)).unwrap(),
                    conv.flow(&o, &v(0.0, 0.0)).unwrap(),
                );
                err = err.max((a.0 - b.0).norm());
            }
        }
        assert!((err / NM - doc).abs() <= 5e-4, "{meth:?}: {} nm", err / NM);
    }
    let fast = paper();
    for (v0, doc) in [
        (v(0.0, 0.0), (336, 11440, 0.266, 0.000)),
        (v(0.1, 0.1), (335, 12864, 0.314, 0.002)),
    ] {
        let we = working_envelope(&fast, &v0, None).unwrap();
        assert_eq!((we.polygon.len(), we.evals), (doc.0, doc.1), "{v0:?}");
        let r = Reference::sample(&conv, &v0, &we.region, 900).unwrap();
        let e = r.errors(&conv, &we.polygon, 2.0 * NM).unwrap();
        eprintln!(
            "{v0:?}: outside {:.4} nm, overreach {:.4} nm",
            e.outside / NM,
            e.overreach / NM
        );
        assert!((e.outside / NM - doc.2).abs() <= 5e-4, "{v0:?}: {e:?}");
        assert!((e.overreach / NM - doc.3).abs() <= 5e-4, "{v0:?}: {e:?}");
    }
}
