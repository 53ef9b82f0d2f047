//! Dormand–Prince 5(4): embedded Runge–Kutta with error control
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.5), FSAL, PI step control.

use super::driver::{Trial, drive};
use super::tableau::combine;
use super::{AdaptiveStats, StepControl};
use crate::error::Result;
use crate::state::{OdeState, OdeSystem, Tolerance};

/// The stage coefficients `a_ij` (Butcher tableau): `Ai` gives stage `i` (`k[i - 1]`) as `(j, a)`
/// pairs over the earlier stages `k[j]`, in summation order.
const A2: [(usize, f64); 1] = [(0, 1.0 / 5.0)];
const A3: [(usize, f64); 2] = [(0, 3.0 / 40.0), (1, 9.0 / 40.0)];
const A4: [(usize, f64); 3] = [(0, 44.0 / 45.0), (1, -56.0 / 15.0), (2, 32.0 / 9.0)];
const A5: [(usize, f64); 4] = [
    (0, 19372.0 / 6561.0),
    (1, -25360.0 / 2187.0),
    (2, 64448.0 / 6561.0),
    (3, -212.0 / 729.0),
];
const A6: [(usize, f64); 5] = [
    (0, 9017.0 / 3168.0),
    (1, -355.0 / 33.0),
    (2, 46732.0 / 5247.0),
    (3, 49.0 / 176.0),
    (4, -5103.0 / 18656.0),
];

/// The 5th-order weights `b_j` as `(j, b)` pairs, nonzero ones only, in summation order.
const B: [(usize, f64); 5] = [
    (0, 35.0 / 384.0),
    (2, 500.0 / 1113.0),
    (3, 125.0 / 192.0),
    (4, -2187.0 / 6784.0),
    (5, 11.0 / 84.0),
];

/// The error weights `e = b(5th) − b(4th)` as `(j, e)` pairs (stage 6 is `f(y1)`), nonzero
/// ones only, in summation order.
const E: [(usize, f64); 6] = [
    (0, 71.0 / 57600.0),
    (2, -71.0 / 16695.0),
    (3, 71.0 / 1920.0),
    (4, -17253.0 / 339200.0),
    (5, 22.0 / 525.0),
    (6, -1.0 / 40.0),
];

/// Integrate `y' = f(y)` over `t` (s) with Dormand–Prince 5(4).
///
/// `h0` is the first trial step (s). Fails only if `max_steps` steps do not
/// reach `t` (a stiff or singular problem).
pub fn dopri5<S: OdeSystem>(
    sys: &S,
    y0: &S::State,
    t: f64,
    tol: &Tolerance,
    h0: f64,
    ctl: &StepControl,
) -> Result<(S::State, AdaptiveStats)> {
    drive(sys, y0, t, h0, ctl, 5.0, "dopri5", |y, k1, h| {
        let mut k = [*k1; 7];
        k[1] = sys.rhs(&combine(y, h, &A2, &k));
        k[2] = sys.rhs(&combine(y, h, &A3, &k));
        k[3] = sys.rhs(&combine(y, h, &A4, &k));
        k[4] = sys.rhs(&combine(y, h, &A5, &k));
        k[5] = sys.rhs(&combine(y, h, &A6, &k));
        let y1 = combine(y, h, &B, &k);
        // first same as last: f(y1) is the next step's k1
        k[6] = sys.rhs(&y1);
        let err = combine(&y.zero_like(), h, &E, &k);
        Trial {
            y1,
            ratio: S::State::error_ratio(&err, y, &y1, tol),
            k_end: Some(k[6]),
            evals: 6,
        }
    })
}
