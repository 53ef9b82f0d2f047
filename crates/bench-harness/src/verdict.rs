//! The rules that turn a measured figure into a report's verdict on its target.
//!
//! Every report example decides "met" or "not met" through these functions, so the rule
//! (inclusive or strict, what a missing measurement counts as) is the same everywhere and is
//! tested here on both sides of a target, without a clock. A measurement that is not a number
//! (NaN: nothing was measured, or a ratio of two zeros) never meets a target.

/// Whether a measured figure met its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The figure is on the target's side of the bound.
    Met,
    /// It is not, or it is not a number.
    NotMet,
}

impl Verdict {
    /// `Met` when `ok`.
    pub fn from_bool(ok: bool) -> Verdict {
        if ok { Verdict::Met } else { Verdict::NotMet }
    }

    /// A ceiling: `measured ≤ target` (the target itself meets it).
    pub fn at_most(measured: f64, target: f64) -> Verdict {
        Verdict::from_bool(measured <= target)
    }

    /// A strict ceiling: `measured < target`.
    pub fn below(measured: f64, target: f64) -> Verdict {
        Verdict::from_bool(measured < target)
    }

    /// A floor: `measured ≥ target` (the target itself meets it).
    pub fn at_least(measured: f64, target: f64) -> Verdict {
        Verdict::from_bool(measured >= target)
    }

    /// Met when every one of `verdicts` is (and when there are none: nothing failed).
    pub fn all(verdicts: impl IntoIterator<Item = Verdict>) -> Verdict {
        Verdict::from_bool(verdicts.into_iter().all(Verdict::is_met))
    }

    /// Whether it is [`Verdict::Met`].
    pub fn is_met(self) -> bool {
        self == Verdict::Met
    }

    /// "met" or "not met".
    pub fn word(self) -> &'static str {
        if self.is_met() { "met" } else { "not met" }
    }

    /// "**met**" or "**not met**" (Markdown bold).
    pub fn bold(self) -> &'static str {
        if self.is_met() {
            "**met**"
        } else {
            "**not met**"
        }
    }

    /// "yes" or "**no**" (a table's "met" column).
    pub fn yes_no(self) -> &'static str {
        if self.is_met() { "yes" } else { "**no**" }
    }
}

/// A speed-up target that may be met by the one-trajectory-per-call path, by the batch path
/// only, or by neither: "yes", "batch: yes; single call: **no**" or "**no**" for `single` and
/// `batch` (the peer's time over ours, each) against `target` (a floor, inclusive).
pub fn speedup_word(single: f64, batch: f64, target: f64) -> &'static str {
    if Verdict::at_least(single, target).is_met() {
        "yes"
    } else if Verdict::at_least(batch, target).is_met() {
        "batch: yes; single call: **no**"
    } else {
        "**no**"
    }
}

/// A lower bound of how many times slower `baselines` (each its time and error) are than
/// ours (`ours_t`, `ours_err`) at equal accuracy: the largest time ratio among the baselines
/// no more accurate than ours (each would need more time still to reach our error). `None`
/// when no baseline is that inaccurate: then nothing bounds the ratio from below.
pub fn slowdown_lower_bound(ours_t: f64, ours_err: f64, baselines: &[(f64, f64)]) -> Option<f64> {
    baselines
        .iter()
        .filter(|(_, err)| *err >= ours_err)
        .map(|(t, _)| t / ours_t)
        .filter(|r| !r.is_nan())
        .reduce(f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ceiling_is_met_at_the_target_and_not_a_hair_above_it() {
        assert_eq!(Verdict::at_most(250.0, 250.0), Verdict::Met);
        assert_eq!(Verdict::at_most(249.9, 250.0), Verdict::Met);
        assert_eq!(Verdict::at_most(250.0001, 250.0), Verdict::NotMet);
        assert_eq!(Verdict::below(250.0, 250.0), Verdict::NotMet);
        assert_eq!(Verdict::below(249.9999, 250.0), Verdict::Met);
    }

    #[test]
    fn a_floor_is_met_at_the_target_and_not_a_hair_below_it() {
        assert_eq!(Verdict::at_least(59.5, 59.5), Verdict::Met);
        assert_eq!(Verdict::at_least(62.5, 59.5), Verdict::Met);
        assert_eq!(Verdict::at_least(59.49, 59.5), Verdict::NotMet);
    }

    #[test]
    fn nothing_measured_never_meets_a_target() {
        for v in [
            Verdict::at_most(f64::NAN, 1.0),
            Verdict::below(f64::NAN, 1.0),
            Verdict::at_least(f64::NAN, 1.0),
            Verdict::at_most(f64::NAN, f64::INFINITY),
        ] {
            assert_eq!(v, Verdict::NotMet);
        }
        assert_eq!(speedup_word(f64::NAN, f64::NAN, 2.0), "**no**");
    }

    #[test]
    fn all_needs_every_part() {
        assert_eq!(Verdict::all([Verdict::Met, Verdict::Met]), Verdict::Met);
        assert_eq!(
            Verdict::all([Verdict::Met, Verdict::NotMet]),
            Verdict::NotMet
        );
        assert_eq!(Verdict::all([]), Verdict::Met);
    }

    #[test]
    fn the_words() {
        assert_eq!(
            (Verdict::Met.word(), Verdict::NotMet.word()),
            ("met", "not met")
        );
        assert_eq!(
            (Verdict::Met.bold(), Verdict::NotMet.bold()),
            ("**met**", "**not met**")
        );
        assert_eq!(
            (Verdict::Met.yes_no(), Verdict::NotMet.yes_no()),
            ("yes", "**no**")
        );
    }

    #[test]
    fn only_baselines_no_more_accurate_than_ours_bound_the_slowdown() {
        // ours 0.266 nm in 0.273 ms; a baseline at 4.15 nm in 6.98 s bounds it at 25 568×.
        let b = [(6.98, 4.15), (0.02, 36.07)];
        assert_eq!(
            slowdown_lower_bound(2.73e-4, 0.266, &b),
            Some(6.98 / 2.73e-4)
        );
        // A baseline more accurate than ours bounds nothing.
        assert_eq!(slowdown_lower_bound(1e-3, 0.266, &[(5.0, 0.1)]), None);
        assert_eq!(slowdown_lower_bound(1e-3, 0.266, &[]), None);
        // Equal accuracy counts.
        assert_eq!(slowdown_lower_bound(1.0, 0.5, &[(3.0, 0.5)]), Some(3.0));
    }

    #[test]
    fn a_speedup_met_by_one_path_or_both_or_neither() {
        assert_eq!(speedup_word(3.1, 3.3, 2.0), "yes");
        assert_eq!(speedup_word(2.0, 1.0, 2.0), "yes");
        assert_eq!(
            speedup_word(1.67, 2.5, 2.0),
            "batch: yes; single call: **no**"
        );
        assert_eq!(speedup_word(1.67, 1.99, 2.0), "**no**");
        assert_eq!(speedup_word(1.67, f64::NAN, 2.0), "**no**");
    }
}
