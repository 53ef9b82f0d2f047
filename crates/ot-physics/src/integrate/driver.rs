//! The step-size driver shared by the embedded Runge–Kutta pairs.

use super::{AdaptiveStats, StepControl};
use crate::error::{PhysicsError, Result};
use crate::state::OdeSystem;

/// `ln(1e-4)`, the floor of the remembered error ratio.
const LN_1E_4: f64 = -9.210340371976184;

/// Outcome of one trial step of an embedded pair.
pub(crate) struct Trial<S> {
    /// The higher-order solution at the end of the step.
    pub y1: S,
    /// Error ratio (≤ 1 accepts).
    pub ratio: f64,
    /// `f(y1)` if the pair computed it (first-same-as-last), else `None`.
    pub k_end: Option<S>,
    /// Right-hand-side evaluations the trial spent.
    pub evals: u64,
}

/// Integrate over `t` (s) from `y0`, first trial step `h0` (s), with a pair
/// whose local error has order `q`; `trial(y, f(y), h)` performs one step.
#[allow(clippy::too_many_arguments)] // internal: the two pairs pass their settings through
pub(crate) fn drive<S: OdeSystem>(
    sys: &S,
    y0: &S::State,
    t: f64,
    h0: f64,
    ctl: &StepControl,
    q: f64,
    method: &'static str,
    mut trial: impl FnMut(&S::State, &S::State, f64) -> Trial<S::State>,
) -> Result<(S::State, AdaptiveStats)> {
    let mut stats = AdaptiveStats::default();
    let mut y = *y0;
    let mut k1 = sys.rhs(&y);
    stats.evals += 1;
    let mut time = 0.0;
    let mut h = h0.min(t);
    let mut err_prev: f64 = 1e-4;
    // PI control (beta > 0): ln(err_prev) kept, one exp per step
    let pi = ctl.beta != 0.0;
    let mut ln_prev = LN_1E_4;
    let factor = |ratio: f64, err_prev: f64, ln_prev: f64| {
        if pi && let Some(l) = super::ln_step(ratio) {
            (ctl.factor_ln(l, ln_prev, q), l)
        } else {
            (ctl.factor(ratio, err_prev, q), 0.0)
        }
    };
    while time < t {
        if stats.accepted + stats.rejected >= ctl.max_steps {
            return Err(PhysicsError::Unsupported {
                method,
                reason: "step limit reached before the end of the interval (stiff problem: use more substeps or an overdamped model)",
            });
        }
        h = h.min(sys.max_step(&y));
        let last = time + h >= t * (1.0 - 1e-14);
        if last {
            h = t - time;
        }
        let tr = trial(&y, &k1, h);
        stats.evals += tr.evals;
        if tr.ratio <= 1.0 {
            time = if last { t } else { time + h };
            y = tr.y1;
            k1 = match tr.k_end {
                Some(k) => k,
                None => {
                    stats.evals += 1;
                    sys.rhs(&y)
                }
            };
            stats.accepted += 1;
            let (fac, ln_err) = factor(tr.ratio, err_prev, ln_prev);
            if pi {
                // ln(max(ratio, 1e-4))
                ln_prev = if tr.ratio >= 1e-4 { ln_err } else { LN_1E_4 };
            }
            err_prev = tr.ratio.max(1e-4);
            h *= fac;
        } else {
            stats.rejected += 1;
            let fac = if tr.ratio.is_finite() {
                factor(tr.ratio, err_prev, ln_prev).0.min(1.0)
            } else {
                0.1
            };
            h *= fac;
        }
    }
    Ok((y, stats))
}
