//! The stage loop of an explicit Runge–Kutta method given by its Butcher tableau, shared by
//! the embedded pairs (DOP853, Dormand–Prince 5(4)).
//!
//! A tableau row lists `(j, c)` pairs: the coefficient `c` of stage `j`, nonzero coefficients
//! only, in the order they are summed. Each combination is one [`OdeState::combine`] over
//! those terms in that order, so a method written as a table computes bit for bit what the
//! same method written out term by term computes.

use crate::state::{OdeState, OdeSystem};

/// One row of a Butcher tableau: `(stage index, coefficient)` pairs in summation order.
pub(crate) type Row = [(usize, f64)];

/// `y + h · Σ c · k[j]` over the `(j, c)` terms of `row`, in their order.
#[inline(always)]
pub(crate) fn combine<St: OdeState, const N: usize>(y: &St, h: f64, row: &Row, k: &[St; N]) -> St {
    let mut terms: [(f64, &St); N] = [(0.0, &k[0]); N];
    for (t, &(j, c)) in terms.iter_mut().zip(row) {
        *t = (c, &k[j]);
    }
    y.combine(h, &terms[..row.len()])
}

/// The stage derivatives of one step of length `h` (s) from `y` with `k1 = f(y)`: row `i` of
/// `a` gives stage `i + 1` (`k[i + 1] = f(y + h · Σ a_ij k[j])`). The stages past
/// `a.len()` are left as copies of `k1` for the caller to fill.
#[inline(always)]
pub(crate) fn stages<S: OdeSystem, const N: usize>(
    sys: &S,
    y: &S::State,
    k1: S::State,
    h: f64,
    a: &[&Row],
) -> [S::State; N] {
    let mut k = [k1; N];
    for (i, row) in a.iter().enumerate() {
        k[i + 1] = sys.rhs(&combine(y, h, row, &k));
    }
    k
}
