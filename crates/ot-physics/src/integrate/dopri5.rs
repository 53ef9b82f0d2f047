//! Dormand–Prince 5(4): embedded Runge–Kutta with error control
//! (Hairer, Nørsett & Wanner, *Solving ODEs I*, §II.5), FSAL, PI step control.

use super::driver::{Trial, drive};
use super::{AdaptiveStats, StepControl};
use crate::error::Result;
use crate::state::{OdeState, OdeSystem, Tolerance};

const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const B1: f64 = 35.0 / 384.0;
const B3: f64 = 500.0 / 1113.0;
const B4: f64 = 125.0 / 192.0;
const B5: f64 = -2187.0 / 6784.0;
const B6: f64 = 11.0 / 84.0;
// e = b(5th) − b(4th)
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;

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
        let k1 = *k1;
        let k2 = sys.rhs(&y.combine(h, &[(A21, &k1)]));
        let k3 = sys.rhs(&y.combine(h, &[(A31, &k1), (A32, &k2)]));
        let k4 = sys.rhs(&y.combine(h, &[(A41, &k1), (A42, &k2), (A43, &k3)]));
        let k5 = sys.rhs(&y.combine(h, &[(A51, &k1), (A52, &k2), (A53, &k3), (A54, &k4)]));
        let k6 = sys.rhs(&y.combine(
            h,
            &[(A61, &k1), (A62, &k2), (A63, &k3), (A64, &k4), (A65, &k5)],
        ));
        let y1 = y.combine(h, &[(B1, &k1), (B3, &k3), (B4, &k4), (B5, &k5), (B6, &k6)]);
        let k7 = sys.rhs(&y1);
        let err = y.zero_like().combine(
            h,
            &[
                (E1, &k1),
                (E3, &k3),
                (E4, &k4),
                (E5, &k5),
                (E6, &k6),
                (E7, &k7),
            ],
        );
        Trial {
            y1,
            ratio: S::State::error_ratio(&err, y, &y1, tol),
            k_end: Some(k7),
            evals: 6,
        }
    })
}
