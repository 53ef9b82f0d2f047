//! The project's one percentile (`world_form::numbers`, nearest rank on sorted samples) and a
//! summary of samples.
//!
//! The q-quantile of n samples sorted ascending is the sample of 1-based rank ⌈q·n⌉, clamped
//! to 1…n (see the crate documentation). Samples are sorted with `f64::total_cmp`, so a NaN
//! sorts last and shows up as the maximum instead of vanishing.

/// The q-quantile (0 ≤ q ≤ 1) of `sorted` (ascending) by nearest rank: the sample of 1-based
/// rank ⌈q·n⌉, clamped to 1…n. `None` when `sorted` is empty or q is outside 0…1 or NaN.
/// The samples keep their unit (µs in, µs out).
pub fn percentile(sorted: &[f64], q: f64) -> Option<f64> {
    world_form::numbers::percentile(sorted, q)
}

/// Samples sorted once, with their nearest-rank percentiles; every figure keeps the unit of
/// the samples.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    sorted: Vec<f64>,
}

impl Summary {
    /// Sorts `samples` (any unit). `None` when there are none.
    pub fn of(samples: impl IntoIterator<Item = f64>) -> Option<Self> {
        let mut sorted: Vec<f64> = samples.into_iter().collect();
        if sorted.is_empty() {
            return None;
        }
        sorted.sort_by(f64::total_cmp);
        Some(Self { sorted })
    }

    /// The q-quantile by nearest rank (see [`percentile`]); `None` if q is outside 0…1.
    pub fn percentile(&self, q: f64) -> Option<f64> {
        percentile(&self.sorted, q)
    }

    /// The median: the sample of rank ⌈n/2⌉ (the lower middle for even n).
    pub fn median(&self) -> f64 {
        self.sorted[self.sorted.len().div_ceil(2) - 1]
    }

    /// The 99th percentile: the sample of rank ⌈0.99·n⌉.
    pub fn p99(&self) -> f64 {
        self.rank_of(0.99)
    }

    /// The 99.9th percentile: the sample of rank ⌈0.999·n⌉.
    pub fn p999(&self) -> f64 {
        self.rank_of(0.999)
    }

    /// The smallest sample.
    pub fn min(&self) -> f64 {
        self.sorted[0]
    }

    /// The largest sample.
    pub fn max(&self) -> f64 {
        self.sorted[self.sorted.len() - 1]
    }

    /// The arithmetic mean.
    pub fn mean(&self) -> f64 {
        self.sorted.iter().sum::<f64>() / self.sorted.len() as f64
    }

    /// How many samples.
    pub fn len(&self) -> usize {
        self.sorted.len()
    }

    /// Always false: a summary has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.sorted.is_empty()
    }

    /// How many samples are strictly above `x` (same unit as the samples).
    pub fn count_above(&self, x: f64) -> usize {
        self.sorted.len() - self.sorted.partition_point(|v| *v <= x)
    }

    /// The samples, ascending.
    pub fn sorted(&self) -> &[f64] {
        &self.sorted
    }

    /// Every sample scaled by `factor` (a change of unit, e.g. 1e6 for s → µs).
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            sorted: self.sorted.iter().map(|v| v * factor).collect(),
        }
    }

    fn rank_of(&self, q: f64) -> f64 {
        let n = self.sorted.len();
        self.sorted[((q * n as f64).ceil() as usize).clamp(1, n) - 1]
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_on_small_exact_cases() {
        let s = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(percentile(&s, 0.5), Some(2.0));
        assert_eq!(percentile(&s, 0.25), Some(1.0));
        assert_eq!(percentile(&s, 0.26), Some(2.0));
        assert_eq!(percentile(&s, 0.75), Some(3.0));
        assert_eq!(percentile(&s, 0.99), Some(4.0));
        assert_eq!(percentile(&s, 1.0), Some(4.0));
        assert_eq!(percentile(&s, 0.0), Some(1.0));
        assert_eq!(percentile(&[7.5], 0.99), Some(7.5));
    }

    #[test]
    fn p99_of_100_and_1000_samples() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.99), Some(99.0));
        assert_eq!(percentile(&v, 0.5), Some(50.0));
        let w: Vec<f64> = (1..=1000).map(f64::from).collect();
        let s = Summary::of(w.iter().rev().copied()).unwrap();
        assert_eq!(s.p99(), 990.0);
        assert_eq!(s.p999(), 999.0);
        assert_eq!(s.median(), 500.0);
        assert_eq!(s.max(), 1000.0);
        assert_eq!(s.min(), 1.0);
        assert_eq!(s.mean(), 500.5);
        assert_eq!(s.len(), 1000);
    }

    #[test]
    fn summary_sorts_and_counts() {
        let s = Summary::of([5.0, 1.0, 4.0, 2.0, 3.0]).unwrap();
        assert_eq!(s.sorted(), &[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(s.median(), 3.0);
        assert_eq!(s.p99(), 5.0);
        assert_eq!(s.count_above(3.0), 2);
        assert_eq!(s.count_above(0.5), 5);
        assert_eq!(s.count_above(5.0), 0);
        assert_eq!(s.scaled(1e3).median(), 3000.0);
        assert_eq!(s.percentile(0.4), Some(2.0));
        // the lower middle for an even count
        assert_eq!(Summary::of([4.0, 1.0, 3.0, 2.0]).unwrap().median(), 2.0);
    }

    #[test]
    fn empty_input_and_bad_q_give_none() {
        assert_eq!(percentile(&[], 0.5), None);
        assert_eq!(percentile(&[1.0], 1.5), None);
        assert_eq!(percentile(&[1.0], -0.1), None);
        assert_eq!(percentile(&[1.0], f64::NAN), None);
        assert!(Summary::of(std::iter::empty()).is_none());
    }

    #[test]
    fn nan_sorts_last() {
        let s = Summary::of([2.0, f64::NAN, 1.0]).unwrap();
        assert_eq!(s.min(), 1.0);
        assert_eq!(s.median(), 2.0);
        assert!(s.max().is_nan());
    }
}
