//! Dormand–Prince 8(5,3) (DOP853) embedded Runge–Kutta with error control.
//!
//! Coefficients from Hairer, Nørsett & Wanner, *Solving ODEs I* (the `dop853`
//! code; as tabulated in the ode_solvers crate). Statically sized stages, no
//! allocation per step.

use super::driver::{Trial, drive};
use super::tableau::combine;
use super::{AdaptiveStats, StepControl};
use crate::error::Result;
use crate::state::{OdeState, OdeSystem, Tolerance};

/// 3rd-order error weights (on stages 1, 9, 12).
const BHH: [f64; 3] = [0.2440944881889764, 0.7338466882816118, 0.022058823529411766];

/// The stage coefficients `a_ij` of DOP853 (Butcher tableau): `Ai` gives stage `i` (`k[i - 1]`)
/// as `(j, a)` pairs over the earlier stages `k[j]`, nonzero ones only, in summation order.
const A2: [(usize, f64); 1] = [(0, 0.05260015195876773)];
const A3: [(usize, f64); 2] = [(0, 0.0197250569845379), (1, 0.0591751709536137)];
const A4: [(usize, f64); 2] = [(0, 0.02958758547680685), (2, 0.08876275643042054)];
const A5: [(usize, f64); 3] = [
    (0, 0.2413651341592667),
    (2, -0.8845494793282861),
    (3, 0.924834003261792),
];
const A6: [(usize, f64); 3] = [
    (0, 0.037037037037037035),
    (3, 0.17082860872947386),
    (4, 0.12546768756682242),
];
const A7: [(usize, f64); 4] = [
    (0, 0.037109375),
    (3, 0.17025221101954405),
    (4, 0.06021653898045596),
    (5, -0.017578125),
];
const A8: [(usize, f64); 5] = [
    (0, 0.03709200011850479),
    (3, 0.17038392571223998),
    (4, 0.10726203044637328),
    (5, -0.015319437748624402),
    (6, 0.008273789163814023),
];
const A9: [(usize, f64); 6] = [
    (0, 0.6241109587160757),
    (3, -3.3608926294469414),
    (4, -0.868219346841726),
    (5, 27.59209969944671),
    (6, 20.154067550477894),
    (7, -43.48988418106996),
];
const A10: [(usize, f64); 7] = [
    (0, 0.47766253643826434),
    (3, -2.4881146199716677),
    (4, -0.590290826836843),
    (5, 21.230051448181193),
    (6, 15.279233632882423),
    (7, -33.28821096898486),
    (8, -0.020331201708508627),
];
const A11: [(usize, f64); 8] = [
    (0, -0.9371424300859873),
    (3, 5.186372428844064),
    (4, 1.0914373489967295),
    (5, -8.149787010746927),
    (6, -18.52006565999696),
    (7, 22.739487099350505),
    (8, 2.4936055526796523),
    (9, -3.0467644718982196),
];
const A12: [(usize, f64); 9] = [
    (0, 2.273310147516538),
    (3, -10.53449546673725),
    (4, -2.0008720582248625),
    (5, -17.9589318631188),
    (6, 27.94888452941996),
    (7, -2.8589982771350235),
    (8, -8.87285693353063),
    (9, 12.360567175794303),
    (10, 0.6433927460157636),
];

/// The 8th-order weights `b_j` as `(j, b)` pairs, nonzero ones only, in summation order.
const B: [(usize, f64); 8] = [
    (0, 0.054293734116568765),
    (5, 4.450312892752409),
    (6, 1.8915178993145003),
    (7, -5.801203960010585),
    (8, 0.3111643669578199),
    (9, -0.1521609496625161),
    (10, 0.20136540080403034),
    (11, 0.04471061572777259),
];

/// 5th-order error weights (`b_j − b̂_j`) as `(j, e)` pairs, nonzero ones only, in
/// summation order.
const E5: [(usize, f64); 8] = [
    (0, 0.01312004499419488),
    (5, -1.2251564463762044),
    (6, -0.4957589496572502),
    (7, 1.6643771824549864),
    (8, -0.35032884874997366),
    (9, 0.3341791187130175),
    (10, 0.08192320648511571),
    (11, -0.022355307863886294),
];

/// The eleven further stages of one DOP853 step from `y` with `k1 = f(y)`:
/// returns `(y_new, k)` with `k[0..12]` the stage derivatives.
#[inline(always)]
fn stages<S: OdeSystem>(sys: &S, y: &S::State, k1: S::State, h: f64) -> (S::State, [S::State; 12]) {
    let mut k = [k1; 12];
    k[1] = sys.rhs(&combine(y, h, &A2, &k));
    k[2] = sys.rhs(&combine(y, h, &A3, &k));
    k[3] = sys.rhs(&combine(y, h, &A4, &k));
    k[4] = sys.rhs(&combine(y, h, &A5, &k));
    k[5] = sys.rhs(&combine(y, h, &A6, &k));
    k[6] = sys.rhs(&combine(y, h, &A7, &k));
    k[7] = sys.rhs(&combine(y, h, &A8, &k));
    k[8] = sys.rhs(&combine(y, h, &A9, &k));
    k[9] = sys.rhs(&combine(y, h, &A10, &k));
    k[10] = sys.rhs(&combine(y, h, &A11, &k));
    k[11] = sys.rhs(&combine(y, h, &A12, &k));
    (combine(y, h, &B, &k), k)
}

/// `n` equal steps of DOP853's 8th-order formula over `t` (s), without error
/// control: 12 evaluations per step. Its variational form is the exact
/// derivative of this discrete map.
pub fn rk8<S: OdeSystem>(sys: &S, y0: &S::State, t: f64, n: u32) -> S::State {
    let h = t / f64::from(n);
    let mut y = *y0;
    for _ in 0..n {
        let k1 = sys.rhs(&y);
        y = stages(sys, &y, k1, h).0;
    }
    y
}

/// Integrate `y' = f(y)` over `t` (s) with DOP853; 12 evaluations per step.
pub fn dop853<S: OdeSystem>(
    sys: &S,
    y0: &S::State,
    t: f64,
    tol: &Tolerance,
    h0: f64,
    ctl: &StepControl,
) -> Result<(S::State, AdaptiveStats)> {
    drive(sys, y0, t, h0, ctl, 8.0, "adaptive", |y, k1, h| {
        let (y1, k) = stages(sys, y, *k1, h);
        let e5 = combine(&y.zero_like(), h, &E5, &k);
        // 3rd-order estimate: (y1 − y) − h (bhh1 k1 + bhh2 k9 + bhh3 k12)
        let e3 = y1
            .combine(-1.0, &[(1.0, y)])
            .combine(h, &[(-BHH[0], &k[0]), (-BHH[1], &k[8]), (-BHH[2], &k[11])]);
        let r5 = S::State::error_ratio(&e5, y, &y1, tol);
        let r3 = S::State::error_ratio(&e3, y, &y1, tol);
        // Hairer's combination of the 5th- and 3rd-order estimates
        let deno = (r5 * r5 + 0.01 * r3 * r3).sqrt();
        Trial {
            y1,
            ratio: if deno > 0.0 { r5 * r5 / deno } else { 0.0 },
            k_end: None,
            evals: 11,
        }
    })
}
