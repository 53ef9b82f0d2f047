//! The one way nanohaptics writes a number in a message, the one SI-prefix formatter, and the
//! one percentile.
//!
//! Every error and report that shows a number a person gave or should read uses [`fmt_num`]:
//! plain between 1e-3 and 1e6 (`0.25`, `3000`), exponent form beyond (`1e-6`, `2.5e9`; never
//! the 300 digits of `1e308`). A quantity with its unit for a person to read at a glance (a
//! report's force, a scale bar's length) is [`fmt_si`]'s: `4.91 N`, `3.00 nN`, `5 cm`. Every
//! percentile of the project (tick times, benchmark samples, soak drift) is the nearest-rank one
//! of [`nearest_rank`].

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

/// How [`fmt_si`] writes a quantity: which SI prefixes it may use and how many digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SiStyle {
    /// The prefixes, largest first, as (scale, symbol): `(1e-6, "µ")`; the unscaled unit is
    /// `(1.0, "")`. Empty: the unscaled unit alone.
    pub prefixes: &'static [(f64, &'static str)],
    /// The digits of the number before the prefix.
    pub mantissa: Mantissa,
}

/// The digits [`fmt_si`] writes before the prefix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mantissa {
    /// Three significant digits: `4.91`, `12.5`, `450` (a measured quantity). A value within
    /// half a unit of the third digit below a prefix takes that prefix (`999.6 µ` → `1.00 m`).
    Sig3,
    /// A whole number where it is one to a millionth (`2`, `100`), else three decimals
    /// (`1.500`): a length chosen round, as a scale bar's.
    Whole,
}

impl SiStyle {
    /// A quantity in a report: nano, micro, milli, none and kilo, three significant digits
    /// (`4.91 N`, `3.00 nN`, `-450 mm`).
    pub const QUANTITY: SiStyle = SiStyle {
        prefixes: &[(1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n")],
        mantissa: Mantissa::Sig3,
    };

    /// A round length, as a scale bar reads: none, centi, milli, micro, nano and pico, a whole
    /// number where it is one (`5 cm`, `2 µm`, `1.500 µm`).
    pub const LENGTH: SiStyle = SiStyle {
        prefixes: &[
            (1.0, ""),
            (1e-2, "c"),
            (1e-3, "m"),
            (1e-6, "µ"),
            (1e-9, "n"),
            (1e-12, "p"),
        ],
        mantissa: Mantissa::Whole,
    };
}

/// `v` (in `unit`) with the largest of the style's prefixes not above `|v|`, e.g.
/// `fmt_si(3e-9, "N", SiStyle::QUANTITY)` is `3.00 nN`. Zero is `0 N`; `NaN` and the
/// infinities are written as such; a magnitude below a tenth of the smallest prefix or from a
/// thousand times the largest on is written in exponent form with three significant digits
/// (`1.00e-24 N`).
pub fn fmt_si(v: f64, unit: &str, style: SiStyle) -> String {
    const NONE: &[(f64, &str)] = &[(1.0, "")];
    let prefixes = if style.prefixes.is_empty() {
        NONE
    } else {
        style.prefixes
    };
    let (largest, smallest) = match (prefixes.first(), prefixes.last()) {
        (Some(l), Some(s)) => (*l, *s),
        _ => ((1.0, ""), (1.0, "")),
    };
    if !v.is_finite() {
        return format!("{v} {unit}");
    }
    let a = v.abs();
    if a == 0.0 {
        return format!("0 {unit}");
    }
    if !(smallest.0 / 10.0..1e3 * largest.0).contains(&a) {
        return format!("{v:.2e} {unit}");
    }
    let slack = match style.mantissa {
        Mantissa::Sig3 => 0.9995,
        Mantissa::Whole => 0.999_999,
    };
    let (scale, p) = prefixes
        .iter()
        .find(|(s, _)| a >= *s * slack)
        .copied()
        .unwrap_or(smallest);
    let x = v / scale;
    match style.mantissa {
        Mantissa::Sig3 => {
            let digits = if x.abs() >= 100.0 {
                0
            } else if x.abs() >= 10.0 {
                1
            } else {
                2
            };
            format!("{x:.digits$} {p}{unit}")
        }
        Mantissa::Whole if (x - x.round()).abs() < 1e-6 * x.abs().max(1.0) => {
            format!("{} {p}{unit}", x.round())
        }
        Mantissa::Whole => format!("{x:.3} {p}{unit}"),
    }
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
    fn quantities_take_a_prefix_and_three_significant_digits() {
        let q = |v| fmt_si(v, "N", SiStyle::QUANTITY);
        assert_eq!(q(4.905), "4.91 N");
        assert_eq!(q(3e-9), "3.00 nN");
        assert_eq!(q(2.5e-10), "0.25 nN");
        assert_eq!(q(1e-24), "1.00e-24 N");
        assert_eq!(q(2.5e6), "2.50e6 N");
        assert_eq!(q(0.0), "0 N");
        assert_eq!(q(f64::NAN), "NaN N");
        assert_eq!(q(12.54), "12.5 N");
        assert_eq!(q(4500.0), "4.50 kN");
        // within half a unit of the third digit below a prefix: that prefix
        assert_eq!(q(0.9996e-3), "1.00 mN");
        assert_eq!(q(0.99949e-3), "999 µN");
        assert_eq!(fmt_si(-0.45, "m", SiStyle::QUANTITY), "-450 mm");
        assert_eq!(fmt_si(9.81, "m/s²", SiStyle::QUANTITY), "9.81 m/s²");
    }

    #[test]
    fn round_lengths_read_whole() {
        let l = |v| fmt_si(v, "m", SiStyle::LENGTH);
        assert_eq!(l(2e-6), "2 µm");
        assert_eq!(l(1e-7), "100 nm");
        assert_eq!(l(0.05), "5 cm");
        assert_eq!(l(0.2), "20 cm");
        assert_eq!(l(3.0), "3 m");
        assert_eq!(l(1.5e-6), "1.500 µm");
        assert_eq!(l(5e-12), "5 pm");
        assert_eq!(l(0.0), "0 m");
        assert_eq!(l(2e3), "2.00e3 m");
    }

    #[test]
    fn no_prefixes_is_the_unit_alone() {
        let bare = SiStyle {
            prefixes: &[],
            mantissa: Mantissa::Sig3,
        };
        assert_eq!(fmt_si(0.5, "s", bare), "0.50 s");
        assert_eq!(fmt_si(0.05, "s", bare), "5.00e-2 s");
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
