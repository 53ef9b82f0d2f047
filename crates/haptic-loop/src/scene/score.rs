//! The house task's score, one rule for both worlds of the teaching game.
//!
//! ```text
//! score = 100 × filled / slots − 10 × dropped − 5 × (seconds the force was above the comfort
//!         limit), never below 0
//! ```
//!
//! - **filled / slots**: blueprint slots filled now (a brick resting in place, an atom bonded
//!   at its site).
//! - **dropped**: bricks the hand let go that fell [`DROP_HEIGHT_M`] or more before they hit
//!   something, atoms that left the tip other than onto the structure (thrown off by the hand's
//!   acceleration).
//! - **comfort**: the force the hand feels above half the device's largest force (4 N on a
//!   Falcon), counted in seconds.
//! - **time**: the time the house was completed is recorded too (`complete_s`, −1 until it
//!   is); between equal scores the earlier completion ranks first.
//!
//! The score's parts are state fields of the scene (`score`, `dropped`, `comfort_exceeded_s`,
//! `complete_s`), so they are in the recording, the per-tick arrays and the run summary.

/// Fall (m) from which a released brick counts as dropped.
pub const DROP_HEIGHT_M: f64 = 0.01;
/// Points lost per dropped brick or atom.
pub const DROP_PENALTY: f64 = 10.0;
/// Points lost per second of force above the comfort limit.
pub const COMFORT_PENALTY_PER_S: f64 = 5.0;
/// Comfort limit as a fraction of the device's largest force.
pub const COMFORT_FRACTION: f64 = 0.5;

/// The state field names of the score, in the order [`HouseScore::state`] writes them.
pub const FIELDS: [&str; 4] = ["score", "dropped", "comfort_exceeded_s", "complete_s"];

/// A house world's state fields: its own `world` fields, then the score's ([`FIELDS`]).
pub fn with_score_fields(world: &[&str]) -> Vec<String> {
    world
        .iter()
        .chain(FIELDS.iter())
        .map(|s| s.to_string())
        .collect()
}

/// Running score of a house task.
#[derive(Clone, Debug, PartialEq)]
pub struct HouseScore {
    comfort_n: f64,
    dt_s: f64,
    over_ticks: u64,
    dropped: u32,
    complete_s: Option<f64>,
    filled: usize,
    slots: usize,
}

impl HouseScore {
    /// A score for a task with `slots` slots; `max_force_world_n` is the device's largest force
    /// mapped to the world (N), `dt_s` the tick (s).
    pub fn new(slots: usize, max_force_world_n: f64, dt_s: f64) -> Self {
        HouseScore {
            comfort_n: COMFORT_FRACTION * max_force_world_n,
            dt_s,
            over_ticks: 0,
            dropped: 0,
            complete_s: None,
            filled: 0,
            slots,
        }
    }

    /// Counts a dropped brick or atom.
    pub fn drop_one(&mut self) {
        self.dropped += 1;
    }

    /// Updates after tick `tick` with the world force felt (N) and the slots filled.
    pub fn update(&mut self, tick: u64, force_n: [f64; 3], filled: usize) {
        let f =
            (force_n[0] * force_n[0] + force_n[1] * force_n[1] + force_n[2] * force_n[2]).sqrt();
        if f > self.comfort_n {
            self.over_ticks += 1;
        }
        self.filled = filled;
        if self.slots > 0 && filled == self.slots && self.complete_s.is_none() {
            self.complete_s = Some((tick + 1) as f64 * self.dt_s);
        }
    }

    /// Seconds of force above the comfort limit.
    pub fn comfort_exceeded_s(&self) -> f64 {
        self.over_ticks as f64 * self.dt_s
    }

    /// Bricks or atoms dropped.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// The score by the rule above (0 without slots).
    pub fn value(&self) -> f64 {
        if self.slots == 0 {
            return 0.0;
        }
        let s = 100.0 * self.filled as f64 / self.slots as f64
            - DROP_PENALTY * f64::from(self.dropped)
            - COMFORT_PENALTY_PER_S * self.comfort_exceeded_s();
        s.max(0.0)
    }

    /// Appends the score's state fields ([`FIELDS`]).
    pub fn state(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[
            self.value(),
            f64::from(self.dropped),
            self.comfort_exceeded_s(),
            self.complete_s.unwrap_or(-1.0),
        ]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_adds_up() {
        let mut s = HouseScore::new(4, 8.0, 0.001);
        s.update(0, [0.0, 0.0, 1.0], 1);
        assert_eq!(s.value(), 25.0);
        // 200 ticks at 5 N > 4 N: 0.2 s over comfort, −1 point.
        for t in 1..=200 {
            s.update(t, [3.0, 0.0, 4.0], 2);
        }
        assert!((s.comfort_exceeded_s() - 0.2).abs() < 1e-12);
        assert!((s.value() - 49.0).abs() < 1e-9);
        s.drop_one();
        assert!((s.value() - 39.0).abs() < 1e-9);
        s.update(201, [0.0; 3], 4);
        let mut st = Vec::new();
        s.state(&mut st);
        assert!((st[0] - 89.0).abs() < 1e-9);
        assert_eq!(st[1], 1.0);
        assert!((st[3] - 0.202).abs() < 1e-12);
        // Never below zero.
        for _ in 0..20 {
            s.drop_one();
        }
        assert_eq!(s.value(), 0.0);
    }
}
