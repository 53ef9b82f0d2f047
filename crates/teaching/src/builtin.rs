//! The built-in module, written from the teaching paper (Jackson, Pawluk & Taylor, ASEE 2011):
//! `modules/nanoscale.toml`, compiled into the program.

use crate::error::LessonFileError;
use crate::file::{Lesson, parse_lesson};

/// The built-in module's name, as errors name its file (`built-in nanoscale`).
pub const NAME: &str = "nanoscale";

/// The built-in module's text.
pub const TEXT: &str = include_str!("../modules/nanoscale.toml");

/// The built-in module, read and checked (its scenes are the built-in ones).
pub fn module() -> Result<Lesson, LessonFileError> {
    parse_lesson(TEXT, &format!("built-in {NAME}"), None)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::condition::Condition;

    #[test]
    fn the_built_in_module_reads_and_names_its_steps() {
        let m = module().unwrap_or_else(|e| panic!("{e}"));
        let ids: Vec<&str> = m.steps.iter().map(|s| s.id.as_str()).collect();
        assert_eq!(
            ids,
            [
                "brick-house",
                "lift",
                "throw",
                "gravity-off",
                "inertia-off",
                "snap",
                "pull-off",
                "put-back",
                "atom-house",
                "compare-brick",
                "compare-atom"
            ]
        );
        assert_eq!(m.test.len(), 5);
        let locked: Vec<&str> = m
            .steps
            .iter()
            .filter(|s| s.locked)
            .map(|s| s.id.as_str())
            .collect();
        assert_eq!(locked, ["snap"]);
        let g = &m.steps[3];
        assert_eq!(
            g.switch_pairs().collect::<Vec<_>>(),
            [("gravity_m_per_s2", 0.0)]
        );
        assert_eq!(
            m.steps[4].switch_pairs().collect::<Vec<_>>(),
            [("inertia", 0.0)]
        );
        assert_eq!(
            m.steps[7].done,
            Condition::AtomPutBack {
                within_m: 0.5e-9,
                away_m: 2.0e-9
            }
        );
        assert_eq!(m.steps[10].done, Condition::Time { seconds: 15.0 });
        assert_eq!(
            (m.steps[0].kind, m.steps[5].kind),
            ("brickworld", "nanoworld")
        );
    }
}
