//! A network link between a device and the simulator, as a deterministic model: a fixed
//! one-way latency, a uniform jitter on top of it (packets may overtake each other) and a
//! loss probability, each direction with its own seeded draws.
//!
//! `fake-device --latency-ms L --jitter-ms J --loss P` puts the same delays on a real UDP link
//! against the wall clock; this model puts them on the closed-loop tests and benchmarks, where
//! time is simulated in whole nanoseconds and every run is repeatable to the bit.
//!
//! ```
//! use haptic_devices::link::{Link, LinkParams};
//! let p = LinkParams { latency_s: 0.002, jitter_s: 0.0, loss: 0.0, seed: 1 };
//! let mut up: Link<u64> = Link::new(&p, 0);
//! up.send(1_000_000, 7);
//! assert!(up.arrived(2_999_999).is_empty());
//! assert_eq!(up.arrived(3_000_000), vec![(3_000_000, 7)]);
//! ```

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

/// What a link does to each packet.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LinkParams {
    /// Fixed one-way delay, s. Range `[0, 1]`.
    pub latency_s: f64,
    /// Extra delay of each packet, uniform in `[0, jitter_s]`, s. Range `[0, 1]`.
    pub jitter_s: f64,
    /// Probability that a packet is lost, `[0, 1)`.
    pub loss: f64,
    /// Seed of the jitter and loss draws.
    pub seed: u64,
}

impl LinkParams {
    /// An ideal link: no delay, no loss.
    pub const IDEAL: LinkParams = LinkParams {
        latency_s: 0.0,
        jitter_s: 0.0,
        loss: 0.0,
        seed: 0,
    };

    /// `latency_ms` one way, no jitter, no loss.
    pub fn latency_ms(latency_ms: f64) -> LinkParams {
        LinkParams {
            latency_s: latency_ms * 1e-3,
            ..LinkParams::IDEAL
        }
    }

    /// Checks every field against its range; the error names the field and the range.
    pub fn validate(&self) -> Result<(), LinkError> {
        let check = |field: &'static str, v: f64, ok: bool, allowed: &'static str| {
            world_form::value::in_range(format!("`{field}`"), v, ok, allowed).map_err(LinkError)
        };
        check(
            "latency_s",
            self.latency_s,
            (0.0..=1.0).contains(&self.latency_s),
            "0 ≤ latency_s ≤ 1 s",
        )?;
        check(
            "jitter_s",
            self.jitter_s,
            (0.0..=1.0).contains(&self.jitter_s),
            "0 ≤ jitter_s ≤ 1 s",
        )?;
        check(
            "loss",
            self.loss,
            (0.0..1.0).contains(&self.loss),
            "0 ≤ loss < 1",
        )
    }

    /// A short label: `1 ms`, `1 ms + 1 ms jitter, 5 % loss`.
    pub fn label(&self) -> String {
        let mut s = format!("{} ms", world_form::numbers::fmt_num(self.latency_s * 1e3));
        if self.jitter_s > 0.0 {
            s += &format!(
                " + {} ms jitter",
                world_form::numbers::fmt_num(self.jitter_s * 1e3)
            );
        }
        if self.loss > 0.0 {
            s += &format!(
                ", {} % loss",
                world_form::numbers::fmt_num(self.loss * 100.0)
            );
        }
        s
    }
}

/// A link parameter out of range.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("link {0}")]
pub struct LinkError(pub world_form::ValueError);

/// One direction of a link: packets in flight, delivered in order of arrival.
#[derive(Clone, Debug)]
pub struct Link<T> {
    latency_ns: u64,
    jitter_ns: u64,
    loss: f64,
    rng: ChaCha8Rng,
    /// In flight, by (arrival ns, sending order).
    flight: BTreeMap<(u64, u64), T>,
    sent: u64,
    lost: u64,
}

impl<T> Link<T> {
    /// One direction of `p`; `stream` separates the draws of the two directions of one link.
    pub fn new(p: &LinkParams, stream: u64) -> Link<T> {
        let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
        rng.set_stream(stream);
        Link {
            latency_ns: (p.latency_s * 1e9).round() as u64,
            jitter_ns: (p.jitter_s * 1e9).round() as u64,
            loss: p.loss,
            rng,
            flight: BTreeMap::new(),
            sent: 0,
            lost: 0,
        }
    }

    /// Sends `msg` at `now_ns`; returns its arrival time, or `None` when it is lost.
    pub fn send(&mut self, now_ns: u64, msg: T) -> Option<u64> {
        self.sent += 1;
        if self.loss > 0.0 && self.rng.random::<f64>() < self.loss {
            self.lost += 1;
            return None;
        }
        let jitter = if self.jitter_ns > 0 {
            (self.rng.random::<f64>() * self.jitter_ns as f64) as u64
        } else {
            0
        };
        let at = now_ns + self.latency_ns + jitter;
        self.flight.insert((at, self.sent), msg);
        Some(at)
    }

    /// Arrival time of the next packet in flight, ns.
    pub fn next_arrival(&self) -> Option<u64> {
        self.flight.first_key_value().map(|(k, _)| k.0)
    }

    /// Every packet that has arrived by `now_ns`, with its arrival time, in arrival order.
    pub fn arrived(&mut self, now_ns: u64) -> Vec<(u64, T)> {
        let mut out = Vec::new();
        while let Some(e) = self.flight.first_entry() {
            if e.key().0 > now_ns {
                break;
            }
            let ((at, _), msg) = e.remove_entry();
            out.push((at, msg));
        }
        out
    }

    /// Packets sent and lost so far.
    pub fn counts(&self) -> (u64, u64) {
        (self.sent, self.lost)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_reorders_and_loss_drops_at_its_rate() {
        let p = LinkParams {
            latency_s: 0.001,
            jitter_s: 0.002,
            loss: 0.05,
            seed: 3,
        };
        let mut l: Link<u64> = Link::new(&p, 0);
        let mut arrivals = Vec::new();
        for k in 0..10_000u64 {
            if let Some(at) = l.send(k * 1_000_000, k) {
                assert!(at >= k * 1_000_000 + 1_000_000 && at <= k * 1_000_000 + 3_000_000);
                arrivals.push(at);
            }
        }
        let (sent, lost) = l.counts();
        assert_eq!(sent, 10_000);
        assert!((400..600).contains(&lost), "{lost}");
        let got = l.arrived(u64::MAX);
        assert_eq!(got.len() as u64, sent - lost);
        assert!(got.windows(2).all(|w| w[0].0 <= w[1].0));
        let reordered = got.windows(2).filter(|w| w[1].1 < w[0].1).count();
        assert!(reordered > 1000, "{reordered}");
    }

    #[test]
    fn the_two_directions_draw_apart_and_repeat() {
        let p = LinkParams {
            latency_s: 0.0,
            jitter_s: 0.001,
            loss: 0.0,
            seed: 9,
        };
        let draw = |stream| {
            let mut l: Link<()> = Link::new(&p, stream);
            (0..50).map(|_| l.send(0, ()).unwrap()).collect::<Vec<_>>()
        };
        assert_eq!(draw(0), draw(0));
        assert_ne!(draw(0), draw(1));
    }

    #[test]
    fn bad_parameters_name_the_field_and_range() {
        let bad = LinkParams {
            loss: 1.0,
            ..LinkParams::IDEAL
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "link `loss` = 1 is out of range: allowed 0 ≤ loss < 1"
        );
        let bad = LinkParams {
            latency_s: f64::NAN,
            ..LinkParams::IDEAL
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "link `latency_s` = NaN is out of range: allowed 0 ≤ latency_s ≤ 1 s"
        );
        assert_eq!(
            LinkParams {
                latency_s: 0.001,
                jitter_s: 0.001,
                loss: 0.05,
                seed: 0
            }
            .label(),
            "1 ms + 1 ms jitter, 5 % loss"
        );
    }
}
