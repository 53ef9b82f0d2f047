//! Which sample a tick reads, and how long it waits for it: the bridge's one rule, used on the
//! wall clock by [`UdpDevice`](super::UdpDevice) and in simulated time by the modelled link of
//! the closed-loop checks (`haptic_loop::closed_loop`).
//!
//! Tick `k` reads the device's sample `k`. It waits for it until `(k − a + ½)` periods after
//! the arrival of the last on-time sample (slot `a`, the *anchor*), so ticks without their
//! sample keep the device's clock; it then reads the newest sample with a sequence number up
//! to `k` (earlier ones are superseded, later ones wait for their tick), or, with none, the
//! last one read again. The sample's age is `k` less its sequence number, in ticks; an on-time
//! sample (age 0) moves the anchor. Before the first on-time sample there is no deadline: the
//! caller waits as long as its link allows.

/// A sample as the rule sees it: its sequence number.
pub trait Numbered: Copy {
    /// The device's sequence number of the sample.
    fn seq(&self) -> u64;
}

impl Numbered for haptic_types::DeviceSample {
    fn seq(&self) -> u64 {
        self.seq
    }
}

/// The rule's state between ticks: the anchor and the last sample read.
#[derive(Clone, Debug, Default)]
pub struct SampleRule<S> {
    /// When the last on-time sample arrived (ns on the caller's clock), and its slot.
    anchor: Option<(u64, u64)>,
    last: Option<S>,
}

impl<S: Numbered> SampleRule<S> {
    /// The rule before any sample.
    pub fn new() -> Self {
        SampleRule {
            anchor: None,
            last: None,
        }
    }

    /// Forgets the anchor (a restarted device numbers its samples afresh); the last sample
    /// read stays what a tick reads until a new one arrives.
    pub fn reset(&mut self) {
        self.anchor = None;
    }

    /// The last sample read.
    pub fn last(&self) -> Option<S> {
        self.last
    }

    /// The latest time tick `k` of `period_ns` waits for its sample, ns on the caller's clock
    /// (`None`: no on-time sample yet, no deadline).
    pub fn deadline_ns(&self, k: u64, period_ns: u64) -> Option<u64> {
        self.anchor.map(|(t, a)| {
            t.saturating_add(k.saturating_sub(a).saturating_mul(period_ns))
                .saturating_add(period_ns / 2)
        })
    }

    /// Whether the newest sample that arrived (its sequence number) is tick `k`'s or later:
    /// the tick need not wait.
    pub fn ready(k: u64, newest_seq: Option<u64>) -> bool {
        newest_seq.is_some_and(|s| s >= k)
    }

    /// What tick `k` reads at `now_ns`: `newest`, the newest sample numbered up to `k` that
    /// arrived since the last tick (or `None`), else the last one read, else `none(k)`; with
    /// its age in ticks. An on-time read moves the anchor to (`now_ns`, `k`).
    pub fn read(
        &mut self,
        k: u64,
        newest: Option<S>,
        now_ns: u64,
        none: impl FnOnce(u64) -> S,
    ) -> (S, u32) {
        if newest.is_some() {
            self.last = newest;
        }
        let s = self.last.unwrap_or_else(|| none(k));
        let age = u32::try_from(k.saturating_sub(s.seq())).unwrap_or(u32::MAX);
        if age == 0 {
            self.anchor = Some((now_ns, k));
        }
        (s, age)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::{Buttons, DeviceSample};

    fn at(seq: u64) -> DeviceSample {
        DeviceSample {
            seq,
            ..DeviceSample::new([seq as f64, 0.0, 0.0], Buttons(0))
        }
    }

    #[test]
    fn an_on_time_sample_anchors_the_next_ticks_deadlines_half_a_period_late() {
        let mut r = SampleRule::new();
        assert_eq!(r.deadline_ns(0, 1_000_000), None);
        let (s, age) = r.read(3, Some(at(3)), 10_000_000, at);
        assert_eq!((s.seq, age), (3, 0));
        // Tick 4 waits until 1.5 periods after tick 3's sample arrived, tick 6 3.5.
        assert_eq!(r.deadline_ns(4, 1_000_000), Some(11_500_000));
        assert_eq!(r.deadline_ns(6, 1_000_000), Some(13_500_000));
    }

    #[test]
    fn a_missing_sample_rereads_the_last_and_ages_without_moving_the_anchor() {
        let mut r = SampleRule::new();
        r.read(3, Some(at(3)), 10_000_000, at);
        let (s, age) = r.read(5, None, 12_600_000, at);
        assert_eq!((s.seq, age), (3, 2));
        assert_eq!(r.deadline_ns(6, 1_000_000), Some(13_500_000));
        // Before any sample: the default at the slot itself, on time.
        let mut fresh = SampleRule::new();
        let (s, age) = fresh.read(7, None, 5, at);
        assert_eq!((s.seq, age), (7, 0));
        assert!(SampleRule::<DeviceSample>::ready(7, Some(8)));
        assert!(!SampleRule::<DeviceSample>::ready(7, Some(6)));
        assert!(!SampleRule::<DeviceSample>::ready(7, None));
        fresh.reset();
        assert_eq!(fresh.deadline_ns(8, 1_000_000), None);
        // The stand-in for a missing first sample is read, not kept.
        assert_eq!(fresh.last().map(|s| s.seq), None);
    }
}
