//! The one way nanohaptics writes a number in a message, and the one percentile.
//!
//! Every error and report that shows a number a person gave or should read uses [`fmt_num`]:
//! plain between 1e-3 and 1e6 (`0.25`, `3000`), exponent form beyond (`1e-6`, `2.5e9`; never
//! the 300 digits of `1e308`). Every percentile of the project (tick times, benchmark samples,
//! soak drift) is the nearest-rank one of [`nearest_rank`].

/// A number as people read it: Rust's shortest round-trip form, plain for magnitudes in
/// `[1e-3, 1e6)` and zero, exponent form otherwise; `NaN`, `inf` and `-inf` as such.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// [`fmt_num`] of `x` rounded to `digits` (≥ 1) significant digits: a computed bound reads
/// `6.4037e-6` or `20`, not `6.403735507964395e-6` or `19.999999999999996`.
pub fn fmt_sig(x: f64, digits: usize) -> String {
    let rounded: f64 = format!("{x:.*e}", digits.max(1) - 1).parse().unwrap_or(x);
    fmt_num(rounded)
}

/// The 1-based rank of the q-quantile of `n` samples by nearest rank: ⌈q·n⌉ clamped to 1…n
/// (`None` when `n` is 0 or q is outside 0…1 or NaN). The sample of that rank in ascending
/// order is the percentile.
pub fn nearest_rank(n: u64, q: f64) -> Option<u64> {
    if n == 0 || !(0.0..=1.0).contains(&q) {
        return None;
    }
    Some(((q * n as f64).ceil() as u64).clamp(1, n))
}

/// The q-quantile (0 ≤ q ≤ 1) of `sorted` (ascending) by [`nearest_rank`]; `None` when empty
/// or q is out of range. The samples keep their unit.
pub fn percentile<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    let rank = nearest_rank(sorted.len() as u64, q)?;
    sorted.get(rank as usize - 1).copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_plain_in_the_middle_and_in_exponent_form_outside() {
        let cases = [
            (0.0, "0"),
            (0.25, "0.25"),
            (3000.0, "3000"),
            (-0.001, "-0.001"),
            (1e-6, "1e-6"),
            (2.5e9, "2.5e9"),
            (1e308, "1e308"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (x, want) in cases {
            assert_eq!(fmt_num(x), want);
        }
    }

    #[test]
    fn significant_digits_then_the_one_form() {
        assert_eq!(fmt_sig(6.403735507964395e-6, 5), "6.4037e-6");
        assert_eq!(fmt_sig(19.999999999999996, 6), "20");
        assert_eq!(fmt_sig(3924700.0750515824, 5), "3.9247e6");
        assert_eq!(fmt_sig(f64::NAN, 3), "NaN");
        assert_eq!(fmt_sig(0.0, 0), "0");
    }

    #[test]
    fn nearest_rank_percentiles() {
        let v: Vec<u32> = (1..=100).collect();
        assert_eq!(percentile(&v, 0.5), Some(50));
        assert_eq!(percentile(&v, 0.99), Some(99));
        assert_eq!(percentile(&v, 0.999), Some(100));
        assert_eq!(percentile(&v, 0.0), Some(1));
        assert_eq!(percentile(&v[..1], 0.5), Some(1));
        assert_eq!(percentile::<u32>(&[], 0.5), None);
        assert_eq!(nearest_rank(10, f64::NAN), None);
        assert_eq!(nearest_rank(10, 1.5), None);
    }
}
