//! Statistics of thermal time series: variance, autocorrelation, averaged
//! periodogram and the corner-frequency fit of a trapped bead.
//!
//! Instantaneous position samples of an Ornstein–Uhlenbeck process alias:
//! their spectrum is not the continuous Lorentzian `D/(π²(fc² + f²))` but
//! the AR(1) spectrum `σ²Δt / (1 + c² − 2c cos 2πfΔt)` with
//! `c = exp(−2π fc Δt)` (Berg-Sørensen & Flyvbjerg 2004). Fitting the
//! continuous Lorentzian to aliased data biases `fc`; [`fit_corner_aliased`]
//! fits the exact aliased form instead, which is unbiased at any sample rate.

use rustfft::{FftPlanner, num_complex::Complex};

/// Sample mean and (unbiased) variance.
pub fn mean_variance(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// Normalised autocorrelation `C(k)/C(0)` for lags `0..max_lag`.
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let (mean, _) = mean_variance(x);
    let n = x.len();
    let c = |k: usize| -> f64 {
        (0..n - k)
            .map(|i| (x[i] - mean) * (x[i + k] - mean))
            .sum::<f64>()
            / (n - k) as f64
    };
    let c0 = c(0);
    (0..max_lag.min(n)).map(|k| c(k) / c0).collect()
}

/// One-sided power spectral density (units² / Hz) averaged over
/// non-overlapping blocks of `block` samples (rectangular window, mean
/// removed per block). Returns `(frequencies Hz, psd)` for bins 1..block/2.
pub fn block_periodogram(x: &[f64], fs: f64, block: usize) -> (Vec<f64>, Vec<f64>) {
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(block);
    let nb = x.len() / block;
    let half = block / 2;
    let mut psd = vec![0.0; half];
    let mut buf = vec![Complex::new(0.0, 0.0); block];
    for b in 0..nb {
        let seg = &x[b * block..(b + 1) * block];
        let m = seg.iter().sum::<f64>() / block as f64;
        for (c, v) in buf.iter_mut().zip(seg) {
            *c = Complex::new(v - m, 0.0);
        }
        fft.process(&mut buf);
        for k in 1..half {
            psd[k] += 2.0 * buf[k].norm_sqr() / (fs * block as f64);
        }
    }
    let freqs: Vec<f64> = (1..half).map(|k| k as f64 * fs / block as f64).collect();
    let psd: Vec<f64> = psd[1..].iter().map(|p| p / nb.max(1) as f64).collect();
    (freqs, psd)
}

/// Weighted least-squares line `y = α + β u` through `(u, y, w)` points.
fn weighted_line(points: impl Iterator<Item = (f64, f64, f64)>) -> Option<(f64, f64)> {
    let (mut sw, mut su, mut sy, mut suu, mut suy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for (u, y, w) in points {
        sw += w;
        su += w * u;
        sy += w * y;
        suu += w * u * u;
        suy += w * u * y;
    }
    let det = sw * suu - su * su;
    if det == 0.0 {
        return None;
    }
    let beta = (sw * suy - su * sy) / det;
    Some(((sy - beta * su) / sw, beta))
}

/// Points `(u(f), 1/S, S²)` of a periodogram: `1/S` is the quantity fitted,
/// `S²` weights its residuals as relative errors of `S`.
fn inverse_psd_points<'a>(
    freqs: &'a [f64],
    psd: &'a [f64],
    u: impl Fn(f64) -> f64 + 'a,
) -> impl Iterator<Item = (f64, f64, f64)> + 'a {
    freqs
        .iter()
        .zip(psd)
        .filter(|(_, s)| **s > 0.0)
        .map(move |(f, s)| (u(*f), 1.0 / s, s * s))
}

/// Corner frequency (Hz) from the exact aliased (AR(1)) spectrum of
/// instantaneous samples. `1/S(f)` is linear in `cos 2πfΔt`; a weighted
/// least-squares fit of that line (weights `S²`, i.e. relative errors) gives
/// `c`, hence `fc = −ln c / (2πΔt)`. Returns `None` if the fit is degenerate.
pub fn fit_corner_aliased(freqs: &[f64], psd: &[f64], fs: f64) -> Option<f64> {
    let dt = 1.0 / fs;
    let (alpha, beta) = weighted_line(inverse_psd_points(freqs, psd, |f| {
        (2.0 * std::f64::consts::PI * f * dt).cos()
    }))?;
    let rho = -beta / alpha; // = 2c/(1+c²)
    if !(rho > 0.0 && rho < 1.0) {
        return None;
    }
    let c = (1.0 - (1.0 - rho * rho).sqrt()) / rho;
    Some(-c.ln() / (2.0 * std::f64::consts::PI * dt))
}

/// Corner frequency (Hz) from the continuous Lorentzian `A/(fc² + f²)`
/// fitted the same way (`1/S` is linear in `f²`), ignoring aliasing — kept
/// to show its bias.
pub fn fit_corner_lorentzian(freqs: &[f64], psd: &[f64]) -> Option<f64> {
    let (alpha, beta) = weighted_line(inverse_psd_points(freqs, psd, |f| f * f))?;
    let fc2 = alpha / beta;
    (fc2 > 0.0).then(|| fc2.sqrt())
}
