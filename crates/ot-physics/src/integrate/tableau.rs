//! One combination of an explicit Runge–Kutta method given by its Butcher tableau, shared by
//! the embedded pairs (DOP853, Dormand–Prince 5(4)).
//!
//! A tableau row lists `(j, c)` pairs: the coefficient `c` of stage `j`, nonzero coefficients
//! only, in the order they are summed. Each combination is one [`OdeState::combine`] over
//! those terms in that order, so a method written as a table computes bit for bit what the
//! same method written out term by term computes. Rows are fixed-size arrays, so that each
//! combination is unrolled at compile time as the written-out terms were.

use crate::state::OdeState;

/// `y + h · Σ c · k[j]` over the `(j, c)` terms of `row` (a row of a Butcher tableau: stage
/// index and coefficient), in their order.
#[inline(always)]
pub(crate) fn combine<St: OdeState, const M: usize, const N: usize>(
    y: &St,
    h: f64,
    row: &[(usize, f64); M],
    k: &[St; N],
) -> St {
    let terms: [(f64, &St); M] = std::array::from_fn(|i| (row[i].1, &k[row[i].0]));
    y.combine(h, &terms)
}
