//! The step evaluator: fed each tick's events and state (the scene's state fields, in order),
//! it says on which tick of the step its condition was met. Pure and clock-free: the same ticks
//! give the same answer, live or from a recording.

use crate::condition::{ATOMS, Condition};
use haptic_types::Event;

/// A state field the condition needs that the scene does not report.
#[derive(Clone, Debug, thiserror::Error, PartialEq, Eq)]
#[error(
    "condition `{condition}` reads the state field `{field}`, which the scene does not report (its fields: {fields})"
)]
pub struct MissingField {
    /// The condition's name.
    pub condition: &'static str,
    /// The field it needs.
    pub field: &'static str,
    /// The scene's fields, comma-separated.
    pub fields: String,
}

/// What a condition reads and remembers.
#[derive(Clone, Debug, PartialEq)]
enum Watch {
    /// Met on the first tick with one of these events.
    Event(&'static [&'static str]),
    /// Met on the first tick the state field at `index` is ≥ 0 (the score's `complete_s`).
    NonNegative(usize),
    /// A held brick's rise: `grab_z` is the hand's height (m) on the grab's tick.
    Lift {
        height_m: f64,
        holding: usize,
        z: usize,
        grab_z: Option<f64>,
    },
    /// A carried atom brought back: `origin` is where the tip was (m) when it took it.
    PutBack {
        within_m: f64,
        away_m: f64,
        tip: [usize; 3],
        carried: usize,
        origin: Option<[f64; 3]>,
        went_away: bool,
    },
    /// Met when this many ticks have been fed.
    Ticks(u64),
}

/// Evaluates one step's condition, tick by tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluator {
    condition: Condition,
    watch: Watch,
    ticks: u64,
    met_at: Option<u64>,
}

/// The number of ticks in `seconds` at `rate_hz`: the tick on which a `time` condition is met
/// is the last of them (at least one).
pub fn ticks_in(seconds: f64, rate_hz: u32) -> u64 {
    ((seconds * f64::from(rate_hz)).round() as u64).max(1)
}

impl Evaluator {
    /// An evaluator of `condition` for a scene of `kind` whose state lists `state_fields`,
    /// ticking at `rate_hz`.
    pub fn new(
        condition: Condition,
        kind: &str,
        state_fields: &[String],
        rate_hz: u32,
    ) -> Result<Evaluator, MissingField> {
        let field = |name: &'static str| {
            state_fields
                .iter()
                .position(|f| f == name)
                .ok_or_else(|| MissingField {
                    condition: condition.name(),
                    field: name,
                    fields: state_fields.join(", "),
                })
        };
        let watch = match condition {
            Condition::HouseComplete if kind == ATOMS => Watch::Event(&["nano.house_complete"]),
            Condition::HouseComplete => Watch::NonNegative(field("complete_s")?),
            Condition::BrickLifted { height_m } => Watch::Lift {
                height_m,
                holding: field("holding")?,
                z: field("proxy_z_m")?,
                grab_z: None,
            },
            Condition::BrickThrown => Watch::Event(&["brick.thrown"]),
            Condition::BrickPlaced => Watch::Event(&["brick.slot_filled"]),
            Condition::AtomSnapped => Watch::Event(&["nano.snap"]),
            Condition::AtomPickedUp => Watch::Event(&["nano.atom_attached", "nano.atom_picked_up"]),
            Condition::AtomPulledOff => Watch::Event(&["nano.pull_off"]),
            Condition::AtomPutBack { within_m, away_m } => Watch::PutBack {
                within_m,
                away_m,
                tip: [field("tip_x_m")?, field("tip_y_m")?, field("tip_z_m")?],
                carried: field("carried_atoms")?,
                origin: None,
                went_away: false,
            },
            Condition::Time { seconds } => Watch::Ticks(ticks_in(seconds, rate_hz)),
        };
        Ok(Evaluator {
            condition,
            watch,
            ticks: 0,
            met_at: None,
        })
    }

    /// The condition evaluated.
    pub fn condition(&self) -> Condition {
        self.condition
    }

    /// Ticks fed so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// The tick of the step (0 = its first) on which the condition was met, if it was.
    pub fn met_at(&self) -> Option<u64> {
        self.met_at
    }

    /// Feeds one tick: its events (in order) and the scene's state after it. Returns whether
    /// the condition is met (on this tick or before). A state row shorter than the scene's
    /// fields reads as not met.
    pub fn feed(&mut self, events: &[Event], state: &[f64]) -> bool {
        let tick = self.ticks;
        self.ticks += 1;
        if self.met_at.is_some() {
            return true;
        }
        let has = |names: &[&str]| events.iter().any(|e| names.contains(&e.name.as_str()));
        let at = |i: usize| state.get(i).copied();
        let met = match &mut self.watch {
            Watch::Event(names) => has(names),
            Watch::NonNegative(i) => at(*i).is_some_and(|v| v >= 0.0),
            Watch::Lift {
                height_m,
                holding,
                z,
                grab_z,
            } => {
                let held = at(*holding).is_some_and(|h| h >= 1.0);
                if !held {
                    *grab_z = None;
                } else if has(&["brick.grabbed"]) {
                    *grab_z = at(*z);
                }
                match (held, *grab_z, at(*z)) {
                    (true, Some(z0), Some(z_now)) => z_now - z0 >= *height_m,
                    _ => false,
                }
            }
            Watch::PutBack {
                within_m,
                away_m,
                tip,
                carried,
                origin,
                went_away,
            } => {
                let p = [at(tip[0]), at(tip[1]), at(tip[2])];
                let Some(p) = p.iter().copied().collect::<Option<Vec<f64>>>() else {
                    return false;
                };
                let now = [p[0], p[1], p[2]];
                let carrying = at(*carried).is_some_and(|c| c >= 1.0);
                let mut met = false;
                if let Some(o) = *origin {
                    let d = distance(now, o);
                    if d >= *away_m {
                        *went_away = true;
                    }
                    // The tick the atom leaves the tip onto something counts as putting it
                    // down there.
                    let put_down = has(&["nano.atom_transferred"]);
                    met = *went_away && d <= *within_m && (carrying || put_down);
                    if !carrying && !met {
                        *origin = None;
                        *went_away = false;
                    }
                }
                if origin.is_none()
                    && carrying
                    && has(&["nano.atom_attached", "nano.atom_picked_up"])
                {
                    *origin = Some(now);
                }
                met
            }
            Watch::Ticks(n) => self.ticks >= *n,
        };
        if met {
            self.met_at = Some(tick);
        }
        met
    }
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn fields(names: &[&str]) -> Vec<String> {
        names.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn a_time_is_met_on_its_last_tick() {
        let mut e = Evaluator::new(Condition::Time { seconds: 0.003 }, "wall", &[], 1000).unwrap();
        assert!(!e.feed(&[], &[]));
        assert!(!e.feed(&[], &[]));
        assert!(e.feed(&[], &[]));
        assert_eq!(e.met_at(), Some(2));
        assert!(e.feed(&[], &[]));
        assert_eq!((e.met_at(), e.ticks()), (Some(2), 4));
        assert_eq!(ticks_in(0.0001, 1000), 1);
    }

    #[test]
    fn a_lift_counts_from_the_grab_and_a_release_starts_again() {
        let f = fields(&["holding", "proxy_z_m"]);
        let c = Condition::BrickLifted { height_m: 0.1 };
        let mut e = Evaluator::new(c, "brickworld", &f, 1000).unwrap();
        let grab = [Event::new("brick.grabbed", "")];
        assert!(!e.feed(&[], &[0.0, 0.0]));
        assert!(!e.feed(&grab, &[1.0, 0.05]));
        assert!(!e.feed(&[], &[1.0, 0.149]));
        // Let go and grab again higher up: the rise counts from the new grab.
        assert!(!e.feed(&[], &[0.0, 0.2]));
        assert!(!e.feed(&grab, &[1.0, 0.2]));
        assert!(!e.feed(&[], &[1.0, 0.29]));
        assert!(e.feed(&[], &[1.0, 0.31]));
        assert_eq!(e.met_at(), Some(6));
    }

    #[test]
    fn a_condition_without_its_state_field_is_refused() {
        let err = Evaluator::new(
            Condition::HouseComplete,
            "brickworld",
            &fields(&["a"]),
            1000,
        )
        .unwrap_err();
        assert_eq!(
            err.to_string(),
            "condition `house_complete` reads the state field `complete_s`, which the scene \
             does not report (its fields: a)"
        );
    }
}
