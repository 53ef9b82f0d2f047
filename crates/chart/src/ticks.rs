//! Axes: data-to-pixel mapping, automatic ranges, tick positions and tick labels.

use crate::{ChartError, Scale};

/// "Nice" tick positions (1-2-5 steps) covering `[lo, hi]`, about `n` of them.
pub fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo || n == 0 {
        return Vec::new();
    }
    let raw = (hi - lo) / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| (hi - lo) / s <= n as f64 + 0.5)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < step * 1e-9 { 0.0 } else { v }
        })
        .collect()
}

/// Decades `10^k` within `[lo, hi]` (both > 0), at most about nine of them (every second or
/// third decade on a wide axis).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
    let every = (((b - a) as f64 / 8.0).ceil() as i32).max(1);
    (a..=b)
        .filter(|k| (k - a) % every == 0)
        .map(|k| 10f64.powi(k))
        .collect()
}

/// A tick label in scientific notation with at most two significant digits (`1e-3`,
/// `2.5e6`, `-4e0`; `0` for zero).
pub fn sci_label(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    format!("{v:.1e}").replace(".0e", "e")
}

/// A tick label: compact decimal, or [`sci_label`] for magnitudes below 1e-3 or from 1e5 up.
pub fn tick_label(v: f64) -> String {
    let a = v.abs();
    if v != 0.0 && !(1e-3..1e5).contains(&a) {
        return sci_label(v);
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A bar's value: three significant digits (`57.3`, `4.91`, `3e-9`, `9.81e-25`).
pub fn value_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let t = format!("{v:.2e}");
        let (m, e) = t.split_once('e').unwrap_or((&t, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let digits = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Maps data to pixels along one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    /// Data range (for a log axis, the range of the values themselves).
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Scale.
    pub scale: Scale,
    /// Pixel of `lo`.
    pub px_lo: f64,
    /// Pixel of `hi`.
    pub px_hi: f64,
}

impl Axis {
    fn t(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => v,
            Scale::Log10 => v.log10(),
        }
    }

    /// Pixel of data value `v` (`None` when it cannot be shown: non-finite, or ≤ 0 on a log
    /// axis).
    pub fn px(&self, v: f64) -> Option<f64> {
        if !v.is_finite() || (self.scale == Scale::Log10 && v <= 0.0) {
            return None;
        }
        let (a, b) = (self.t(self.lo), self.t(self.hi));
        Some(self.px_lo + (self.t(v) - a) / (b - a) * (self.px_hi - self.px_lo))
    }

    /// The tick positions: 1-2-5 steps on a linear axis, decades on a log axis.
    pub fn ticks(&self) -> Vec<f64> {
        match self.scale {
            Scale::Linear => nice_ticks(self.lo, self.hi, 6),
            Scale::Log10 => log_ticks(self.lo, self.hi),
        }
    }
}

/// The range of `values` on a `scale` axis (with a margin), or an error naming `axis`.
pub(super) fn auto_range(
    values: impl Iterator<Item = f64>,
    scale: Scale,
    include_zero: bool,
    axis: &'static str,
) -> Result<[f64; 2], ChartError> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut any = false;
    for v in values.filter(|v| v.is_finite()) {
        any = true;
        if scale == Scale::Log10 && v <= 0.0 {
            continue;
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !any {
        return Err(ChartError::NoData { field: "series" });
    }
    if lo > hi {
        return Err(ChartError::LogAxis { axis });
    }
    Ok(match scale {
        Scale::Log10 => {
            let (a, b) = (lo.log10().floor(), hi.log10().ceil());
            let b = if b <= a { a + 1.0 } else { b };
            [10f64.powf(a), 10f64.powf(b)]
        }
        Scale::Linear => {
            if include_zero && lo <= 0.0 && hi >= 0.0 {
                // keep 0 inside
            } else if include_zero && lo > 0.0 && lo < 0.25 * hi {
                lo = 0.0;
            } else if include_zero && hi < 0.0 && hi > 0.25 * lo {
                hi = 0.0;
            }
            if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
                let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
                [lo - d, hi + d]
            } else {
                let m = 0.04 * (hi - lo);
                [lo - m, hi + m]
            }
        }
    })
}

/// `Ok` when `r` is two finite increasing numbers (positive on a log axis).
pub(super) fn check_range(
    r: [f64; 2],
    scale: Scale,
    field: &'static str,
) -> Result<(), ChartError> {
    let ok = r[0].is_finite() && r[1].is_finite() && r[0] < r[1];
    if !ok || (scale == Scale::Log10 && r[0] <= 0.0) {
        return Err(ChartError::Range {
            field,
            lo: r[0],
            hi: r[1],
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_ticks_are_1_2_5_steps() {
        assert_eq!(nice_ticks(0.0, 7.3, 6), vec![0.0, 2.0, 4.0, 6.0]);
        assert_eq!(nice_ticks(-1.0, 1.0, 4), vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        assert_eq!(log_ticks(1e-12, 1e-8).len(), 5);
        assert_eq!(tick_label(0.25), "0.25");
        assert_eq!(tick_label(1.5e-9), "1.5e-9");
        assert_eq!(tick_label(1e-9), "1e-9");
        assert_eq!(tick_label(-4.0), "-4");
        assert_eq!(value_label(57.2964), "57.3");
        assert_eq!(value_label(4.905), "4.91");
        assert_eq!(value_label(3e-9), "3e-9");
        assert_eq!(value_label(9.81e-25), "9.81e-25");
        assert_eq!(value_label(1603.7), "1604");
    }

    #[test]
    fn scientific_labels_keep_two_digits() {
        assert_eq!(sci_label(0.001), "1e-3");
        assert_eq!(sci_label(10.0), "1e1");
        assert_eq!(sci_label(1.0), "1e0");
        assert_eq!(sci_label(2.5e6), "2.5e6");
        assert_eq!(sci_label(-4.0), "-4e0");
        assert_eq!(sci_label(0.0), "0");
        // the same labels tick_label gives far from 1
        assert_eq!(tick_label(2.5e6), sci_label(2.5e6));
        assert_eq!(tick_label(1e5), "1e5");
        assert_eq!(tick_label(99999.0), "99999");
    }

    #[test]
    fn log_ticks_thin_out_over_many_decades() {
        // 1e-6 … 1e10: 17 decades, every second one drawn
        let t = log_ticks(1e-6, 1e10);
        assert_eq!(t.len(), 9);
        assert_eq!(t[0], 1e-6);
        assert!((t[1] / 1e-4 - 1.0).abs() < 1e-12);
        assert_eq!(t[8], 1e10);
        // 1e-3 … 1e5: nine decades, all drawn
        assert_eq!(log_ticks(1e-3, 1e5).len(), 9);
        let a = Axis {
            lo: 1e-6,
            hi: 1e10,
            scale: Scale::Log10,
            px_lo: 0.0,
            px_hi: 160.0,
        };
        // ten px per decade
        assert!((a.px(1e-3).unwrap() - 30.0).abs() < 1e-9);
        assert!((a.px(1.0).unwrap() - 60.0).abs() < 1e-9);
        assert_eq!(a.px(0.0), None);
        assert_eq!(a.px(-1.0), None);
    }

    #[test]
    fn auto_ranges_pad_and_take_in_zero() {
        let r = auto_range([1.0, 9.0].into_iter(), Scale::Linear, true, "y").unwrap();
        assert_eq!(r, [-0.36, 9.36]);
        let r = auto_range([5.0, 9.0].into_iter(), Scale::Linear, true, "y").unwrap();
        assert_eq!(r, [4.84, 9.16]);
        let r = auto_range([0.03, 700.0, -1.0].into_iter(), Scale::Log10, true, "y").unwrap();
        assert_eq!(r, [0.01, 1000.0]);
    }
}
