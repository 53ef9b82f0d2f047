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

/// Velocity from positions that carry encoder counts: first-order adaptive windowing
/// (end-fit FOAW, Janabi-Sharifi, Hayward and Chen, IEEE TCST 8(6), 2000).
///
/// A finite difference over one tick turns one encoder count `q` into a velocity spike of
/// `q / dt` (1.27 m/s for the Falcon's 0.0635 mm count at the brick world's ×20 mapping); a
/// fixed long window lags on fast motion. The adaptive window takes the longest window `n`
/// (up to `max_window` ticks) over which the straight line through the newest and the `n`-th
/// previous sample stays within `band_m` of every sample in between (up to the positions'
/// rounding: a sample exactly `band_m` off is within), and returns its slope.
/// On slow motion the window grows and the count noise falls as `band / (n dt)`; on fast or
/// accelerating motion it shrinks to one tick and the lag vanishes. With `band_m = 0` it is the
/// one-tick difference (exact positions need no smoothing).
#[derive(Debug, Clone)]
pub struct AdaptiveWindow {
    dt: f64,
    band_m: f64,
    /// Oldest first, at most `max_window + 1` samples.
    samples: std::collections::VecDeque<[f64; 3]>,
    max_window: usize,
}

impl AdaptiveWindow {
    /// An empty estimator for samples `dt` s apart, band `band_m` (m) and windows of at most
    /// `max_window` ticks. Rounded to counts of `q`, each sample is within `q / 2` of the truth,
    /// so a sample may sit `q` off the line through two others: `band_m = q` never rejects a
    /// true straight line.
    pub fn new(dt: f64, band_m: f64, max_window: usize) -> Self {
        AdaptiveWindow {
            dt,
            band_m,
            samples: std::collections::VecDeque::with_capacity(max_window + 1),
            max_window: max_window.max(1),
        }
    }

    /// Forgets the history and starts from `p` at rest.
    pub fn reset(&mut self, p: [f64; 3]) {
        self.samples.clear();
        self.samples.push_back(p);
    }

    /// Adds the newest sample, m.
    pub fn push(&mut self, p: [f64; 3]) {
        if self.samples.len() > self.max_window {
            self.samples.pop_front();
        }
        self.samples.push_back(p);
    }

    /// The window of axis `axis` (0, 1, 2), ticks (0 with fewer than two samples): the
    /// longest over which the line through the newest and the oldest sample stays within the
    /// band of every sample between. Each axis has its own window, so the axes stay
    /// independent (a vertical sag does not shorten a horizontal window).
    pub fn window(&self, axis: usize) -> usize {
        let len = self.samples.len();
        if len < 2 {
            return 0;
        }
        let newest = self.samples[len - 1][axis];
        let mut best = 1;
        'grow: for n in 2..len {
            let old = self.samples[len - 1 - n][axis];
            for i in 1..n {
                let mid = self.samples[len - 1 - i][axis];
                let line = newest - (newest - old) * (i as f64 / n as f64);
                // Within the band up to the rounding of the positions it is computed from: a
                // sample exactly one band off must not be rejected by its last bit.
                let rounding = 8.0 * f64::EPSILON * newest.abs().max(old.abs()).max(mid.abs());
                if (mid - line).abs() > self.band_m + rounding {
                    break 'grow;
                }
            }
            best = n;
        }
        best
    }

    /// Velocity of the newest sample, m/s (zero with fewer than two samples).
    pub fn velocity(&self) -> [f64; 3] {
        let len = self.samples.len();
        let mut v = [0.0; 3];
        for (a, va) in v.iter_mut().enumerate() {
            let n = self.window(a);
            if n > 0 {
                let (new, old) = (self.samples[len - 1][a], self.samples[len - 1 - n][a]);
                *va = (new - old) / (n as f64 * self.dt);
            }
        }
        v
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

    #[test]
    fn adaptive_window_is_exact_on_lines_and_quiet_on_counts() {
        let dt = 1e-3;
        // A straight line at 0.3 m/s: exact, any window.
        let mut w = AdaptiveWindow::new(dt, 0.5e-3, 25);
        w.reset([0.0; 3]);
        for k in 1..40 {
            w.push([0.3 * k as f64 * dt, 0.0, 0.0]);
        }
        assert!((w.velocity()[0] - 0.3).abs() < 1e-12);
        assert_eq!(w.window(0), 25);
        // A slow 20 mm/s drift seen through 1.27 mm counts: a one-tick difference gives
        // 1.27 m/s spikes; the adaptive window stays within band / window of the truth.
        let q = 1.27e-3;
        let mut w = AdaptiveWindow::new(dt, q, 200);
        let mut worst: f64 = 0.0;
        for k in 0..2000 {
            let x = 0.02 * k as f64 * dt;
            w.push([(x / q).round() * q, 0.0, 0.0]);
            if k > 200 {
                worst = worst.max((w.velocity()[0] - 0.02).abs());
            }
        }
        assert!(worst < 0.02, "worst {worst} m/s");
        // A step (the hand starts to move): the window shrinks at once, no long lag.
        let mut w = AdaptiveWindow::new(dt, 1e-4, 50);
        w.reset([0.0; 3]);
        for _ in 0..30 {
            w.push([0.0; 3]);
        }
        for k in 1..=3 {
            w.push([0.5 * k as f64 * dt, 0.0, 0.0]);
        }
        assert!((w.velocity()[0] - 0.5).abs() < 1e-9);
    }

    /// A hand at rest whose reading flickers one count for two ticks (a linked Falcon, held
    /// firmly, 1 ms away: the brick house's last placement). The samples are the world's
    /// cursor as recorded, bit for bit: one count (1.27 mm at ×20) is
    /// 0.0012700000000000003 m between them, one rounding above the band. A sample one
    /// count off the line through two others is within the band (the documented rule), so
    /// the window runs past the flicker and the hand is at rest: before, the comparison
    /// rejected it on that rounding, the window stopped at 3 ticks, and the released brick
    /// was thrown sideways at 0.42 m/s and missed its slot.
    #[test]
    fn a_one_count_flicker_at_rest_is_no_throw() {
        let (up, down) = (-0.000_470_000_000_000_005_14, -0.001_740_000_000_000_005_4);
        let mut w = AdaptiveWindow::new(1e-3, 0.001_27, 25);
        w.reset([0.0, up, 0.0]);
        for _ in 0..25 {
            w.push([0.0, up, 0.0]);
        }
        for y in [down, down, up, up, up] {
            w.push([0.0, y, 0.0]);
        }
        assert_eq!(w.window(1), 25);
        assert_eq!(w.velocity(), [0.0; 3]);
        // And a sample a rounding beyond a count is still rejected (the band is not widened).
        let mut w = AdaptiveWindow::new(1e-3, 0.001_27, 25);
        w.reset([0.0; 3]);
        for y in [0.0, 0.0, -0.001_271, 0.0, 0.0] {
            w.push([0.0, y, 0.0]);
        }
        assert_eq!(w.window(1), 2);
    }
}
