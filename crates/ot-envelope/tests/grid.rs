//! The envelope's region and grid sized from the error budget: the chosen
//! grid meets the budget against converged dynamics, and is not finer than
//! needed (the next coarser spacing misses it).
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::Vector2;
use ot_envelope::geometry::hausdorff;
use ot_envelope::grid::{CELL_LADDER, choose_grid, cut_bound, region_margin};
use ot_envelope::{EnvelopeOptions, OffsetRegion, working_envelope_with};
use ot_physics::budget::{choose_tick_map, converged};

type V2 = Vector2<f64>;

/// The scene's tick: Δt = 0.2 µs, the map chosen for 0.01 nm.
fn scene_tick() -> ot_physics::Propagator<2> {
    choose_tick_map(paper_model([600e-9, 300e-9]), 0.2e-6, 1e-11, 0.1)
        .unwrap()
        .0
}

#[test]
fn the_region_margin_is_the_smallest_whose_cut_fits_its_share() {
    let model = paper_model([600e-9, 300e-9]);
    for (dt, tol) in [(0.2e-6, 0.5e-9), (0.2e-6, 0.1e-9), (1e-6, 0.5e-9)] {
        let (m, bound) = region_margin(&model, dt, tol).unwrap();
        assert!(bound <= tol / 4.0, "{bound:e}");
        assert!(2.0 * cut_bound(&model, dt, m - 0.25) > tol / 4.0, "{m}");
    }
    // a longer tick or a tighter tolerance needs a wider region
    let m = |dt, tol| region_margin(&model, dt, tol).unwrap().0;
    assert!(m(1e-6, 0.5e-9) > m(0.2e-6, 0.5e-9));
    assert!(m(0.2e-6, 0.1e-9) > m(0.2e-6, 0.5e-9));
    // the bound is a bound: a trap on the region's edge, particle at rest
    let prop = scene_tick();
    let (m, bound) = region_margin(&model, 0.2e-6, 0.5e-9).unwrap();
    for o in [
        V2::new(0.0, m * 300e-9),
        V2::new(m * 600e-9, 0.0),
        V2::new(m * 600e-9, m * 300e-9),
    ] {
        let (d, _, _) = prop.flow(&o, &V2::zeros()).unwrap();
        assert!(
            2.0 * d.norm() <= bound * 1.01,
            "{:e} vs {bound:e}",
            d.norm()
        );
    }
}

#[test]
fn the_chosen_grid_meets_the_budget_against_converged_dynamics_and_no_coarser_one_does() {
    let prop = scene_tick();
    let tol = 0.5e-9;
    let g = choose_grid(&prop, tol, 0.1).unwrap();
    eprintln!("{g}");
    assert!(g.grid_error_m <= tol / 2.0, "{g}");
    // docs/ot-envelope.md quotes the scene's choice: region 3.75 waists (cut ≤ 4.05e-11 m),
    // cell 0.6 waists (5.98e-11 m), 196 vertices at rest.
    assert_eq!(
        (g.margin_waists, g.cell_waists, g.vertices),
        (3.75, 0.6, 196),
        "{g}"
    );
    assert!((g.region_bound_m - 4.05e-11).abs() < 0.005e-11, "{g}");
    assert!((g.grid_error_m - 5.98e-11).abs() < 0.005e-11, "{g}");
    let truth = converged(*prop.model(), prop.dt()).unwrap();
    let k = CELL_LADDER
        .iter()
        .position(|c| *c == g.cell_waists)
        .unwrap();
    let mut worst = [0.0f64; 2];
    for v0 in [V2::zeros(), V2::new(0.0, 0.1), V2::new(0.1, 0.0)] {
        // the reachable set of converged dynamics: a wide region, a fine grid
        let reference = working_envelope_with(
            &truth,
            &v0,
            &EnvelopeOptions {
                tol: 0.02e-9,
                cell_waists: Some(0.05),
                region: Some(OffsetRegion::around_drift(&truth, &v0, 6.0).unwrap()),
                coarse_grid: false,
            },
        )
        .unwrap();
        let region = OffsetRegion::around_drift(&prop, &v0, g.margin_waists).unwrap();
        let cells = [
            Some(g.cell_waists),
            k.checked_sub(1).map(|j| CELL_LADDER[j]),
        ];
        for (w, cell) in worst.iter_mut().zip(cells) {
            let Some(cell) = cell else { continue };
            let poly = working_envelope_with(
                &prop,
                &v0,
                &EnvelopeOptions {
                    tol,
                    cell_waists: Some(cell),
                    region: Some(region),
                    coarse_grid: true,
                },
            )
            .unwrap()
            .polygon;
            *w = w.max(hausdorff(&poly, &reference.polygon, 0.02e-9));
        }
    }
    eprintln!(
        "chosen cell {}: {:.3e} m; next coarser: {:.3e} m",
        g.cell_waists, worst[0], worst[1]
    );
    // docs/ot-envelope.md: the chosen grid within 0.061 nm of converged dynamics, the next
    // coarser spacing (0.8 waist) 0.50 nm off (each to the printed digits).
    assert!((worst[0] - 0.061e-9).abs() < 0.0005e-9, "{worst:?}");
    assert!((worst[1] - 0.50e-9).abs() < 0.005e-9 && CELL_LADDER[k - 1] == 0.8);
    // the budget: the grid's share, the region's cut, the tick map (1e-11 m)
    // and the reference's own tolerance
    assert!(
        worst[0] <= tol / 2.0 + g.region_bound_m + 1e-11 + 0.02e-9,
        "{worst:?}"
    );
    if k > 0 {
        assert!(
            worst[1] > tol / 2.0,
            "a coarser grid meets the budget too: {worst:?}"
        );
    }
}
