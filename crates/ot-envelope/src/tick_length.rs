//! The longest tick of the trap's inverse problem: one bound, computed here and nowhere else.
//!
//! A particle with inertia oscillates in the well at up to `ω = sqrt(κ_max / m)` rad/s
//! ([`ot_physics::TrapModel::fastest_rate`] without drag). The tick map folds about once per
//! half period, and the work of every grid sampling (the working envelope, the inverse solve,
//! steering) grows with the folds. So a tick is bounded in periods `2π/ω` of that oscillation:
//! [`MAX_OSCILLATIONS_PER_TICK`] for a sampling of the map ([`check_tick_length`], called by
//! every [`crate::SampledMap`] build, so by [`crate::solve_trap`] and
//! [`crate::working_envelope`]), and [`HAPTIC_OSCILLATIONS_PER_TICK`] for a haptic loop's
//! tick ([`crate::world::Params::validate`], the scene files and the program through it).
//! A particle without inertia does not oscillate: any tick passes.

use crate::error::{EnvelopeError, Result};
use ot_physics::{Propagator, TrapModel};
use world_form::{ValueError, fmt_sig};

/// Longest tick of a sampling of the map, in periods of the well's fastest small oscillation.
/// The crossings of the folds' images grow faster than their number: at the paper's constants
/// 4 periods (6.4 µs) take about 1 s with an accurate tick map, 6 periods (10 µs) 7 to 14 s,
/// 12 periods (20 µs) up to a minute.
pub const MAX_OSCILLATIONS_PER_TICK: u32 = 4;

/// Longest tick of the optical-tweezers world in a haptic loop, in the same periods: a whole
/// envelope build must fit between device samples when the served one is no longer trusted
/// (at the paper's constants, 1 µs ticks cost about 2 ms at p99, 5 µs ticks up to 0.5 s).
pub const HAPTIC_OSCILLATIONS_PER_TICK: u32 = 1;

/// The angular frequency of the well's fastest small oscillation, `sqrt(κ_max / m)` rad/s;
/// `None` without inertia (nothing oscillates).
pub fn oscillation_rate<const D: usize>(model: &TrapModel<D>) -> Option<f64> {
    let m = model.mass?;
    Some((model.well.stiffness().max() / m).sqrt())
}

/// The longest tick (s) spanning `periods` periods of the well's fastest small oscillation;
/// `None` without inertia (any tick).
pub fn max_tick_s<const D: usize>(model: &TrapModel<D>, periods: u32) -> Option<f64> {
    oscillation_rate(model).map(|omega| f64::from(periods) * std::f64::consts::TAU / omega)
}

/// [`EnvelopeError::TickTooLong`] when a tick of `dt_s` (s) spans more than `periods` periods
/// of `model`'s fastest small oscillation (the one check of the bound).
pub fn check_tick<const D: usize>(model: &TrapModel<D>, dt_s: f64, periods: u32) -> Result<()> {
    let (Some(omega), Some(max_dt)) = (oscillation_rate(model), max_tick_s(model, periods)) else {
        return Ok(());
    };
    if dt_s > max_dt || !max_dt.is_finite() {
        let noun = if periods == 1 { "period" } else { "periods" };
        return Err(EnvelopeError::TickTooLong {
            error: ValueError::out_of_range(
                "dt [s]",
                dt_s,
                format!(
                    "≤ {} s, {periods} {noun} of the well's fastest oscillation (ω = {} rad/s); \
                     a longer tick folds the map so often that the envelope's boundary search \
                     grows without bound",
                    fmt_sig(max_dt, 5),
                    fmt_sig(omega, 5),
                ),
            ),
            max_dt,
            periods,
            omega,
        });
    }
    Ok(())
}

/// [`check_tick`] at [`MAX_OSCILLATIONS_PER_TICK`] for `prop`'s model and tick: the bound of
/// every sampling of the map.
pub fn check_tick_length<const D: usize>(prop: &Propagator<D>) -> Result<()> {
    check_tick(prop.model(), prop.dt(), MAX_OSCILLATIONS_PER_TICK)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_trap_bounds() {
        let model = ot_physics::paper::model().expect("paper model");
        let omega = oscillation_rate(&model).expect("inertia");
        assert!((omega - 3.9247e6).abs() < 1e2, "{omega}");
        let max4 = max_tick_s(&model, MAX_OSCILLATIONS_PER_TICK).expect("inertia");
        assert!((max4 * omega - 8.0 * std::f64::consts::PI).abs() < 1e-12);
        assert!(check_tick(&model, max4, 4).is_ok());
        assert!(check_tick(&model, max4 * (1.0 + 1e-9), 4).is_err());
        assert_eq!(
            check_tick(&model, 2e-6, HAPTIC_OSCILLATIONS_PER_TICK)
                .expect_err("over one period")
                .to_string(),
            "dt [s] = 2e-6 is out of range: allowed ≤ 1.6009e-6 s, 1 period of the well's \
             fastest oscillation (ω = 3.9247e6 rad/s); a longer tick folds the map so often \
             that the envelope's boundary search grows without bound"
        );
    }
}
