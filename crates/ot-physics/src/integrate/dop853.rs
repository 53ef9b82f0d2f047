//! Dormand–Prince 8(5,3) (DOP853) embedded Runge–Kutta with error control.
//!
//! Coefficients from Hairer, Nørsett & Wanner, *Solving ODEs I* (the `dop853`
//! code; as tabulated in the ode_solvers crate). Statically sized stages, no
//! allocation per step.

use super::{AdaptiveStats, StepControl};
use crate::error::{PhysicsError, Result};
use crate::state::{OdeState, OdeSystem, Tolerance};

/// Stage coefficients `a[s][j]` for stages 2..=12 (row `s-2`).
#[rustfmt::skip]
const A: [&[f64]; 11] = [
    &[0.05260015195876773],
    &[0.0197250569845379, 0.0591751709536137],
    &[0.02958758547680685, 0.0, 0.08876275643042054],
    &[0.2413651341592667, 0.0, -0.8845494793282861, 0.924834003261792],
    &[0.037037037037037035, 0.0, 0.0, 0.17082860872947386, 0.12546768756682242],
    &[0.037109375, 0.0, 0.0, 0.17025221101954405, 0.06021653898045596, -0.017578125],
    &[0.03709200011850479, 0.0, 0.0, 0.17038392571223998, 0.10726203044637328, -0.015319437748624402, 0.008273789163814023],
    &[0.6241109587160757, 0.0, 0.0, -3.3608926294469414, -0.868219346841726, 27.59209969944671, 20.154067550477894, -43.48988418106996],
    &[0.47766253643826434, 0.0, 0.0, -2.4881146199716677, -0.590290826836843, 21.230051448181193, 15.279233632882423, -33.28821096898486, -0.020331201708508627],
    &[-0.9371424300859873, 0.0, 0.0, 5.186372428844064, 1.0914373489967295, -8.149787010746927, -18.52006565999696, 22.739487099350505, 2.4936055526796523, -3.0467644718982196],
    &[2.273310147516538, 0.0, 0.0, -10.53449546673725, -2.0008720582248625, -17.9589318631188, 27.94888452941996, -2.8589982771350235, -8.87285693353063, 12.360567175794303, 0.6433927460157636],
];

/// 8th-order weights for stages 1..=12.
#[rustfmt::skip]
const B: [f64; 12] = [0.054293734116568765, 0.0, 0.0, 0.0, 0.0, 4.450312892752409, 1.8915178993145003, -5.801203960010585, 0.3111643669578199, -0.1521609496625161, 0.20136540080403034, 0.04471061572777259];
/// 3rd-order error weights (on stages 1, 9, 12).
const BHH: [f64; 3] = [0.2440944881889764, 0.7338466882816118, 0.022058823529411766];
/// 5th-order error weights for stages 1..=12.
#[rustfmt::skip]
const E: [f64; 12] = [0.01312004499419488, 0.0, 0.0, 0.0, 0.0, -1.2251564463762044, -0.4957589496572502, 1.6643771824549864, -0.35032884874997366, 0.3341791187130175, 0.08192320648511571, -0.022355307863886294];

/// Integrate `y' = f(y)` over `t` (s) with DOP853; 12 evaluations per step.
pub fn dop853<S: OdeSystem>(
    sys: &S,
    y0: &S::State,
    t: f64,
    tol: &Tolerance,
    h0: f64,
    ctl: &StepControl,
) -> Result<(S::State, AdaptiveStats)> {
    let mut stats = AdaptiveStats::default();
    let mut y = *y0;
    let mut k = [y.zero_like(); 12];
    k[0] = sys.rhs(&y);
    stats.evals += 1;
    let mut time = 0.0;
    let mut h = h0.min(t);
    let mut err_prev: f64 = 1e-4;
    while time < t {
        if stats.accepted + stats.rejected >= ctl.max_steps {
            return Err(PhysicsError::Unsupported {
                method: "dop853",
                reason: "step limit reached before the end of the interval (stiff problem: use more substeps or an overdamped model)",
            });
        }
        h = h.min(sys.max_step(&y));
        let last = time + h >= t * (1.0 - 1e-14);
        if last {
            h = t - time;
        }
        for s in 1..12 {
            let mut ys = y;
            for (j, &a) in A[s - 1].iter().enumerate() {
                if a != 0.0 {
                    ys = ys.combine(h, &[(a, &k[j])]);
                }
            }
            k[s] = sys.rhs(&ys);
        }
        stats.evals += 11;
        let mut y1 = y;
        let mut e5 = y.zero_like();
        for s in 0..12 {
            if B[s] != 0.0 {
                y1 = y1.combine(h, &[(B[s], &k[s])]);
            }
            if E[s] != 0.0 {
                e5 = e5.combine(h, &[(E[s], &k[s])]);
            }
        }
        // 3rd-order estimate: (y1 - y) - h (bhh1 k1 + bhh2 k9 + bhh3 k12)
        let e3 = y1
            .combine(-1.0, &[(1.0, &y)])
            .combine(h, &[(-BHH[0], &k[0]), (-BHH[1], &k[8]), (-BHH[2], &k[11])]);
        let r5 = S::State::error_ratio(&e5, &y, &y1, tol);
        let r3 = S::State::error_ratio(&e3, &y, &y1, tol);
        let deno = (r5 * r5 + 0.01 * r3 * r3).sqrt();
        let ratio = if deno > 0.0 { r5 * r5 / deno } else { 0.0 };
        if ratio <= 1.0 {
            time = if last { t } else { time + h };
            y = y1;
            k[0] = sys.rhs(&y);
            stats.evals += 1;
            stats.accepted += 1;
            let fac = ctl.factor(ratio, err_prev, 8.0);
            err_prev = ratio.max(1e-4);
            h *= fac;
        } else {
            stats.rejected += 1;
            let fac = if ratio.is_finite() {
                ctl.factor(ratio, err_prev, 8.0).min(1.0)
            } else {
                0.1
            };
            h *= fac;
        }
    }
    Ok((y, stats))
}
