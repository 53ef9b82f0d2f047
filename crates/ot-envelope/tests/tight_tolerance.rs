//! A working envelope asked for a tolerance far finer than its boundary's length is refused
//! before its grid choice compares boundaries sample by sample (CI's libFuzzer `params` target
//! found a table with `envelope_tol_m = 1e-12` that ran for more than 14 minutes: the
//! comparison samples each boundary every tol/8, some 10⁸ points per polygon).

use ot_envelope::world::{Params, World};
use world_form::Limits;

fn falcon() -> Limits {
    Limits {
        max_force_n: 8.0,
        max_stiffness_n_per_m: 3000.0,
    }
}

/// The fuzzer's table (a heavier particle, a longer step), with tolerance `tol` m.
fn params(tol: f64) -> Params {
    Params {
        mass_kg: 2e-14,
        dt_s: 3.2e-6,
        envelope_tol_m: tol,
        envelope_build_evals_per_tick: None,
        tick_map: ot_envelope::world::TickMap::Budget { tol_m: 4.01e-9 },
        ..Params::paper()
    }
}

#[test]
fn a_tolerance_finer_than_the_boundary_can_be_compared_at_is_refused() {
    let e = World::new(&params(1e-12), &falcon())
        .err()
        .expect("a 1 pm tolerance on a micrometre boundary");
    let text = e.to_string();
    assert!(
        text.starts_with("envelope grid choice: boundary samples = "),
        "{text}"
    );
    assert!(
        text.contains(
            "is out of range: allowed ≤ 1e6 (the boundaries are compared every tol/8 = 1.25e-13 m \
             along 5.15e-6 m of boundary: choose a tolerance ≥ 4.12e-11 m for this envelope)"
        ),
        "{text}"
    );
}

#[test]
fn the_fuzzers_own_tolerance_still_builds() {
    // 0.2 nm: about 10⁵ samples, within the budget.
    assert!(World::new(&params(2e-10), &falcon()).is_ok());
}
