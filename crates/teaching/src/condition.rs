//! The condition vocabulary: how the world says a step is done, bound to the events and state
//! fields the scenes really emit (`brick.*` from the brick world's adapter, `nano.*` from the
//! nano world's, the score's `complete_s`; `docs/teaching.md` lists them).
//!
//! | `when`           | scene kinds            | met on the tick …                                                                   |
//! |------------------|------------------------|-------------------------------------------------------------------------------------|
//! | `house_complete` | brickworld, nanoworld  | `nano.house_complete` (nano); the state `complete_s` first ≥ 0 (bricks: no event)     |
//! | `brick_lifted`   | brickworld             | a brick held (`holding` = 1) since `brick.grabbed` has risen `height_m` (`proxy_z_m`) |
//! | `brick_thrown`   | brickworld             | `brick.thrown` (a release faster than the world's throw speed)                      |
//! | `brick_placed`   | brickworld             | `brick.slot_filled`                                                                 |
//! | `atom_snapped`   | nanoworld              | `nano.snap` (snap-to-contact)                                                        |
//! | `atom_picked_up` | nanoworld              | `nano.atom_attached` or `nano.atom_picked_up`                                        |
//! | `atom_pulled_off`| nanoworld              | `nano.pull_off`                                                                      |
//! | `atom_put_back`  | nanoworld              | the tip, carrying the atom it took at `nano.atom_attached` / `nano.atom_picked_up`, has gone `away_nm` from that spot and comes back within `within_nm` of it |
//! | `time`           | every scene            | `seconds` after the step began                                                      |

use std::fmt;

/// A step's condition, checked and in SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Condition {
    /// The house is complete.
    HouseComplete,
    /// A held brick has risen `height_m` (m, world) since it was grabbed.
    BrickLifted {
        /// Rise of the hand since the grab, m (world).
        height_m: f64,
    },
    /// A brick was thrown (`brick.thrown`).
    BrickThrown,
    /// A brick came to rest in a blueprint slot (`brick.slot_filled`).
    BrickPlaced,
    /// The tip snapped into contact (`nano.snap`).
    AtomSnapped,
    /// An atom came onto the tip (`nano.atom_attached` or `nano.atom_picked_up`).
    AtomPickedUp,
    /// A contact was pulled off (`nano.pull_off`).
    AtomPulledOff,
    /// The tip brought a carried atom back near where it was taken.
    AtomPutBack {
        /// How near the tip must come back to where it took the atom, m.
        within_m: f64,
        /// How far it must first have gone from there, m.
        away_m: f64,
    },
    /// Time on the step.
    Time {
        /// Seconds after the step began, s.
        seconds: f64,
    },
}

/// One name of the vocabulary: what a lesson file writes in `done.when`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Word {
    /// The name (`brick_thrown`).
    pub name: &'static str,
    /// Scene kinds whose worlds can meet it (empty: every scene).
    pub kinds: &'static [&'static str],
    /// The events (or state fields) it is read from, in words (for errors and docs).
    pub reads: &'static str,
    /// Its parameters, each with the allowed range, for errors.
    pub params: &'static [Param],
}

/// A parameter of a condition: its name in the file, its range and unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    /// Field name (`height_m`).
    pub name: &'static str,
    /// The allowed range in words (`0 < height_m ≤ 1`).
    pub allowed: &'static str,
}

/// The scene kinds of the two worlds of the teaching game.
pub const BRICKS: &str = "brickworld";
/// The nano world's scene kind.
pub const ATOMS: &str = "nanoworld";

/// The vocabulary, in the order errors list it.
pub const WORDS: [Word; 9] = [
    Word {
        name: "house_complete",
        kinds: &[BRICKS, ATOMS],
        reads: "nano.house_complete, or the brick world's state complete_s",
        params: &[],
    },
    Word {
        name: "brick_lifted",
        kinds: &[BRICKS],
        reads: "brick.grabbed and the state holding, proxy_z_m",
        params: &[Param {
            name: "height_m",
            allowed: "0 < height_m ≤ 1 (m, world)",
        }],
    },
    Word {
        name: "brick_thrown",
        kinds: &[BRICKS],
        reads: "brick.thrown",
        params: &[],
    },
    Word {
        name: "brick_placed",
        kinds: &[BRICKS],
        reads: "brick.slot_filled",
        params: &[],
    },
    Word {
        name: "atom_snapped",
        kinds: &[ATOMS],
        reads: "nano.snap",
        params: &[],
    },
    Word {
        name: "atom_picked_up",
        kinds: &[ATOMS],
        reads: "nano.atom_attached, nano.atom_picked_up",
        params: &[],
    },
    Word {
        name: "atom_pulled_off",
        kinds: &[ATOMS],
        reads: "nano.pull_off",
        params: &[],
    },
    Word {
        name: "atom_put_back",
        kinds: &[ATOMS],
        reads: "nano.atom_attached, nano.atom_picked_up, nano.atom_transferred and the state \
                tip_x_m, tip_y_m, tip_z_m, carried_atoms",
        params: &[
            Param {
                name: "within_nm",
                allowed: "0 < within_nm ≤ 10",
            },
            Param {
                name: "away_nm",
                allowed: "within_nm < away_nm ≤ 20",
            },
        ],
    },
    Word {
        name: "time",
        kinds: &[],
        reads: "the ticks on the step",
        params: &[Param {
            name: "seconds",
            allowed: "0 < seconds ≤ 3600",
        }],
    },
];

/// The word called `name`.
pub fn word(name: &str) -> Option<&'static Word> {
    WORDS.iter().find(|w| w.name == name)
}

/// The names of the vocabulary, comma-separated.
pub fn names() -> String {
    WORDS.iter().map(|w| w.name).collect::<Vec<_>>().join(", ")
}

/// The names a scene of `kind` can meet, comma-separated.
pub fn names_for(kind: &str) -> String {
    WORDS
        .iter()
        .filter(|w| w.can_happen_in(kind))
        .map(|w| w.name)
        .collect::<Vec<_>>()
        .join(", ")
}

impl Word {
    /// Whether a scene of `kind` can meet it.
    pub fn can_happen_in(&self, kind: &str) -> bool {
        self.kinds.is_empty() || self.kinds.contains(&kind)
    }
}

impl Condition {
    /// Its name in the vocabulary.
    pub fn name(&self) -> &'static str {
        match self {
            Condition::HouseComplete => "house_complete",
            Condition::BrickLifted { .. } => "brick_lifted",
            Condition::BrickThrown => "brick_thrown",
            Condition::BrickPlaced => "brick_placed",
            Condition::AtomSnapped => "atom_snapped",
            Condition::AtomPickedUp => "atom_picked_up",
            Condition::AtomPulledOff => "atom_pulled_off",
            Condition::AtomPutBack { .. } => "atom_put_back",
            Condition::Time { .. } => "time",
        }
    }
}

impl fmt::Display for Condition {
    /// The condition as a lesson file writes it (`atom_put_back (within 0.3 nm, after 1.5
    /// nm away)`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use world_form::{fmt_num, fmt_sig};
        match self {
            Condition::BrickLifted { height_m } => {
                write!(f, "brick_lifted (by {} m)", fmt_num(*height_m))
            }
            Condition::AtomPutBack { within_m, away_m } => write!(
                f,
                "atom_put_back (within {} nm, after {} nm away)",
                fmt_sig(within_m * 1e9, 9),
                fmt_sig(away_m * 1e9, 9)
            ),
            Condition::Time { seconds } => write!(f, "time ({} s)", fmt_num(*seconds)),
            other => f.write_str(other.name()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_word_names_a_condition_and_kinds_split_the_worlds() {
        assert_eq!(
            names(),
            "house_complete, brick_lifted, brick_thrown, brick_placed, atom_snapped, \
             atom_picked_up, atom_pulled_off, atom_put_back, time"
        );
        assert_eq!(
            names_for("brickworld"),
            "house_complete, brick_lifted, brick_thrown, brick_placed, time"
        );
        assert_eq!(
            names_for("nanoworld"),
            "house_complete, atom_snapped, atom_picked_up, atom_pulled_off, atom_put_back, time"
        );
        assert_eq!(names_for("wall"), "time");
        let all = [
            Condition::HouseComplete,
            Condition::BrickLifted { height_m: 0.1 },
            Condition::BrickThrown,
            Condition::BrickPlaced,
            Condition::AtomSnapped,
            Condition::AtomPickedUp,
            Condition::AtomPulledOff,
            Condition::AtomPutBack {
                within_m: 3e-10,
                away_m: 1.5e-9,
            },
            Condition::Time { seconds: 2.5 },
        ];
        for (c, w) in all.iter().zip(WORDS.iter()) {
            assert_eq!(c.name(), w.name);
        }
        assert_eq!(
            all[7].to_string(),
            "atom_put_back (within 0.3 nm, after 1.5 nm away)"
        );
        assert_eq!(all[8].to_string(), "time (2.5 s)");
    }
}
