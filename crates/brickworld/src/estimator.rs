//! Velocity and acceleration of the grip point from its recent positions.
//!
//! The paper's inertial force uses `a = B4 - 2 B2 + B0` over the last five positions `B0..B4`
//! (`B4` newest); divided by `(2 dt)²` this is the central second difference at `B2`: exact for
//! quadratic motion, two ticks late, and it amplifies position noise by `sqrt(6) / (4 dt²)`.
//! The Savitzky–Golay option fits a quadratic to the last `N` samples by least squares; its
//! second derivative is also exact for quadratic motion, lags `(N - 1) / 2` ticks, and its
//! noise gain is `2 sqrt(180 / (N (N²-1)(N²-4))) / dt²` — 46× lower than the stencil at N = 21.

use crate::params::AccelEstimator;

/// Ring of the last positions (m) sampled every `dt` (s), with the chosen estimator.
#[derive(Debug, Clone)]
pub struct MotionEstimator {
    dt: f64,
    kind: AccelEstimator,
    /// Oldest first; length `len`.
    samples: Vec<[f64; 3]>,
    len: usize,
    /// Least-squares weights on the samples (oldest first) for the velocity at the newest sample.
    w_vel: Vec<f64>,
    /// Least-squares weights for the acceleration (constant over the window).
    w_acc: Vec<f64>,
}

/// Weights of the least-squares quadratic fit over `n` equally spaced samples (oldest first):
/// returns (velocity at newest sample, acceleration), each already divided by `dt` / `dt²`.
fn quadratic_fit_weights(n: usize, dt: f64) -> (Vec<f64>, Vec<f64>) {
    let half = (n as f64 - 1.0) / 2.0;
    let t: Vec<f64> = (0..n).map(|i| i as f64 - half).collect();
    let s2: f64 = t.iter().map(|x| x * x).sum::<f64>() / n as f64;
    let p2: Vec<f64> = t.iter().map(|x| x * x - s2).collect();
    let n1: f64 = t.iter().map(|x| x * x).sum();
    let n2: f64 = p2.iter().map(|x| x * x).sum();
    // y ≈ a + b t + c (t² - s2): b = Σ t y / Σ t², c = Σ p2 y / Σ p2².
    // velocity at t_last = half: b + 2 c half; acceleration 2 c.
    let w_vel = (0..n)
        .map(|i| (t[i] / n1 + 2.0 * half * p2[i] / n2) / dt)
        .collect();
    let w_acc = (0..n).map(|i| 2.0 * p2[i] / n2 / (dt * dt)).collect();
    (w_vel, w_acc)
}

impl MotionEstimator {
    /// A new estimator; call [`Self::reset`] before the first [`Self::push`].
    pub fn new(dt: f64, kind: AccelEstimator) -> Self {
        let (len, w_vel, w_acc) = match kind {
            AccelEstimator::Paper => {
                // velocity: second-order backward difference (3 B4 - 4 B3 + B2) / (2 dt);
                // acceleration: (B4 - 2 B2 + B0) / (2 dt)².
                let w_vel = vec![
                    0.0,
                    0.0,
                    1.0 / (2.0 * dt),
                    -4.0 / (2.0 * dt),
                    3.0 / (2.0 * dt),
                ];
                let a = 1.0 / (4.0 * dt * dt);
                let w_acc = vec![a, 0.0, -2.0 * a, 0.0, a];
                (5, w_vel, w_acc)
            }
            AccelEstimator::SavitzkyGolay { window } => {
                let (wv, wa) = quadratic_fit_weights(window, dt);
                (window, wv, wa)
            }
        };
        MotionEstimator {
            dt,
            kind,
            samples: vec![[0.0; 3]; len],
            len,
            w_vel,
            w_acc,
        }
    }

    /// The estimator kind.
    pub fn kind(&self) -> AccelEstimator {
        self.kind
    }

    /// Time step, s.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Fills the whole history with one position (m): zero velocity and acceleration.
    pub fn reset(&mut self, p: [f64; 3]) {
        self.samples.iter_mut().for_each(|s| *s = p);
    }

    /// Appends the newest position (m), dropping the oldest.
    pub fn push(&mut self, p: [f64; 3]) {
        self.samples.rotate_left(1);
        self.samples[self.len - 1] = p;
    }

    fn apply(&self, w: &[f64]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (s, wi) in self.samples.iter().zip(w) {
            for k in 0..3 {
                out[k] += wi * s[k];
            }
        }
        out
    }

    /// Velocity estimate at the newest sample, m/s.
    pub fn velocity(&self) -> [f64; 3] {
        self.apply(&self.w_vel)
    }

    /// Acceleration estimate, m/s².
    pub fn acceleration(&self) -> [f64; 3] {
        self.apply(&self.w_acc)
    }

    /// Standard deviation of the acceleration estimate per unit (m) of white position noise,
    /// in 1/s²: `sqrt(Σ w_i²)`.
    pub fn accel_noise_gain(&self) -> f64 {
        self.w_acc.iter().map(|w| w * w).sum::<f64>().sqrt()
    }

    /// Delay of the acceleration estimate behind the newest sample, s.
    pub fn accel_lag_s(&self) -> f64 {
        match self.kind {
            AccelEstimator::Paper => 2.0 * self.dt,
            AccelEstimator::SavitzkyGolay { window } => (window as f64 - 1.0) / 2.0 * self.dt,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn feed(m: &mut MotionEstimator, f: impl Fn(f64) -> f64, n: usize) {
        m.reset([f(0.0), 0.0, 0.0]);
        for i in 1..=n {
            m.push([f(i as f64 * m.dt()), 0.0, 0.0]);
        }
    }

    #[test]
    fn both_estimators_are_exact_for_quadratic_motion() {
        let dt = 1e-3;
        let (x0, v0, a) = (0.1, -0.3, 2.5);
        let f = |t: f64| x0 + v0 * t + 0.5 * a * t * t;
        for kind in [
            AccelEstimator::Paper,
            AccelEstimator::SavitzkyGolay { window: 5 },
            AccelEstimator::SavitzkyGolay { window: 21 },
        ] {
            let mut m = MotionEstimator::new(dt, kind);
            let n = 100;
            feed(&mut m, f, n);
            let t = n as f64 * dt;
            assert!((m.acceleration()[0] - a).abs() < 1e-6, "{kind:?}");
            assert!((m.velocity()[0] - (v0 + a * t)).abs() < 1e-9, "{kind:?}");
        }
    }

    #[test]
    fn noise_gains_match_their_closed_forms() {
        let dt = 1e-3;
        let p = MotionEstimator::new(dt, AccelEstimator::Paper);
        let expected = 6f64.sqrt() / (4.0 * dt * dt);
        assert!((p.accel_noise_gain() - expected).abs() < 1e-9 * expected);
        for n in [5usize, 21, 41] {
            let m = MotionEstimator::new(dt, AccelEstimator::SavitzkyGolay { window: n });
            let nf = n as f64;
            let closed =
                2.0 * (180.0 / (nf * (nf * nf - 1.0) * (nf * nf - 4.0))).sqrt() / (dt * dt);
            assert!(
                (m.accel_noise_gain() - closed).abs() < 1e-9 * closed,
                "window {n}"
            );
        }
        let sg21 = MotionEstimator::new(dt, AccelEstimator::SavitzkyGolay { window: 21 });
        let ratio = p.accel_noise_gain() / sg21.accel_noise_gain();
        assert!((ratio - 45.9).abs() < 0.1, "ratio {ratio}");
    }

    #[test]
    fn stencil_lags_two_ticks_on_a_cubic() {
        // For x = t³/6, a(t) = t: the central stencil returns a at t - 2 dt exactly.
        let dt = 1e-3;
        let mut m = MotionEstimator::new(dt, AccelEstimator::Paper);
        feed(&mut m, |t| t * t * t / 6.0, 50);
        let t = 50.0 * dt;
        assert!((m.acceleration()[0] - (t - m.accel_lag_s())).abs() < 1e-9);
    }
}
