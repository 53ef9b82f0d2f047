//! Dormand–Prince 8(5,3) (DOP853) embedded Runge–Kutta with error control.
//!
//! Coefficients from Hairer, Nørsett & Wanner, *Solving ODEs I* (the `dop853`
//! code; as tabulated in the ode_solvers crate). Statically sized stages, no
//! allocation per step.

use super::driver::{Trial, drive};
use super::{AdaptiveStats, StepControl};
use crate::error::Result;
use crate::state::{OdeState, OdeSystem, Tolerance};

/// 3rd-order error weights (on stages 1, 9, 12).
const BHH: [f64; 3] = [0.2440944881889764, 0.7338466882816118, 0.022058823529411766];

/// The eleven further stages of one DOP853 step from `y` with `k1 = f(y)`:
/// returns `(y_new, k)` with `k[0..12]` the stage derivatives. Fully unrolled
/// with literal coefficients so the compiler fuses the combinations.
#[inline(always)]
fn stages<S: OdeSystem>(sys: &S, y: &S::State, k1: S::State, h: f64) -> (S::State, [S::State; 12]) {
    let k0 = k1;
    let k1 = sys.rhs(&y.combine(h, &[(0.05260015195876773, &k0)]));
    let k2 = sys.rhs(&y.combine(h, &[(0.0197250569845379, &k0), (0.0591751709536137, &k1)]));
    let k3 = sys.rhs(&y.combine(h, &[(0.02958758547680685, &k0), (0.08876275643042054, &k2)]));
    let k4 = sys.rhs(&y.combine(
        h,
        &[
            (0.2413651341592667, &k0),
            (-0.8845494793282861, &k2),
            (0.924834003261792, &k3),
        ],
    ));
    let k5 = sys.rhs(&y.combine(
        h,
        &[
            (0.037037037037037035, &k0),
            (0.17082860872947386, &k3),
            (0.12546768756682242, &k4),
        ],
    ));
    let k6 = sys.rhs(&y.combine(
        h,
        &[
            (0.037109375, &k0),
            (0.17025221101954405, &k3),
            (0.06021653898045596, &k4),
            (-0.017578125, &k5),
        ],
    ));
    let k7 = sys.rhs(&y.combine(
        h,
        &[
            (0.03709200011850479, &k0),
            (0.17038392571223998, &k3),
            (0.10726203044637328, &k4),
            (-0.015319437748624402, &k5),
            (0.008273789163814023, &k6),
        ],
    ));
    let k8 = sys.rhs(&y.combine(
        h,
        &[
            (0.6241109587160757, &k0),
            (-3.3608926294469414, &k3),
            (-0.868219346841726, &k4),
            (27.59209969944671, &k5),
            (20.154067550477894, &k6),
            (-43.48988418106996, &k7),
        ],
    ));
    let k9 = sys.rhs(&y.combine(
        h,
        &[
            (0.47766253643826434, &k0),
            (-2.4881146199716677, &k3),
            (-0.590290826836843, &k4),
            (21.230051448181193, &k5),
            (15.279233632882423, &k6),
            (-33.28821096898486, &k7),
            (-0.020331201708508627, &k8),
        ],
    ));
    let k10 = sys.rhs(&y.combine(
        h,
        &[
            (-0.9371424300859873, &k0),
            (5.186372428844064, &k3),
            (1.0914373489967295, &k4),
            (-8.149787010746927, &k5),
            (-18.52006565999696, &k6),
            (22.739487099350505, &k7),
            (2.4936055526796523, &k8),
            (-3.0467644718982196, &k9),
        ],
    ));
    let k11 = sys.rhs(&y.combine(
        h,
        &[
            (2.273310147516538, &k0),
            (-10.53449546673725, &k3),
            (-2.0008720582248625, &k4),
            (-17.9589318631188, &k5),
            (27.94888452941996, &k6),
            (-2.8589982771350235, &k7),
            (-8.87285693353063, &k8),
            (12.360567175794303, &k9),
            (0.6433927460157636, &k10),
        ],
    ));
    let y1 = y.combine(
        h,
        &[
            (0.054293734116568765, &k0),
            (4.450312892752409, &k5),
            (1.8915178993145003, &k6),
            (-5.801203960010585, &k7),
            (0.3111643669578199, &k8),
            (-0.1521609496625161, &k9),
            (0.20136540080403034, &k10),
            (0.04471061572777259, &k11),
        ],
    );
    (y1, [k0, k1, k2, k3, k4, k5, k6, k7, k8, k9, k10, k11])
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
        let e5 = y.zero_like().combine(
            h,
            &[
                (0.01312004499419488, &k[0]),
                (-1.2251564463762044, &k[5]),
                (-0.4957589496572502, &k[6]),
                (1.6643771824549864, &k[7]),
                (-0.35032884874997366, &k[8]),
                (0.3341791187130175, &k[9]),
                (0.08192320648511571, &k[10]),
                (-0.022355307863886294, &k[11]),
            ],
        );
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
