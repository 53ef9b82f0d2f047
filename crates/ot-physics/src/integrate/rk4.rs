//! Classical fourth-order Runge–Kutta, fixed step.

use crate::state::{OdeState, OdeSystem};

/// One classical RK4 step of length `h` (s). Four right-hand-side evaluations.
#[inline(always)]
pub fn rk4_step<S: OdeSystem>(sys: &S, y: &S::State, h: f64) -> S::State {
    let k1 = sys.rhs(y);
    let k2 = sys.rhs(&y.combine(h, &[(0.5, &k1)]));
    let k3 = sys.rhs(&y.combine(h, &[(0.5, &k2)]));
    let k4 = sys.rhs(&y.combine(h, &[(1.0, &k3)]));
    y.combine(
        h,
        &[
            (1.0 / 6.0, &k1),
            (1.0 / 3.0, &k2),
            (1.0 / 3.0, &k3),
            (1.0 / 6.0, &k4),
        ],
    )
}

/// `n` equal RK4 substeps over `t` (s). Returns the end state; `4n` evaluations.
pub fn rk4<S: OdeSystem>(sys: &S, y0: &S::State, t: f64, n: u32) -> S::State {
    let h = t / f64::from(n);
    let mut y = *y0;
    for _ in 0..n {
        y = rk4_step(sys, &y, h);
    }
    y
}
