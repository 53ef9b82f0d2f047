//! The lesson's report (`play --lesson`): when the lesson ends, the class report of its one
//! student ([`teaching::class_report`]) is written beside the steps' recordings: two CSV files,
//! a Markdown page and its charts, with each step's time, the largest force felt and the score.

use super::StepRun;
use std::path::{Path, PathBuf};
use teaching::class_report::{self, ReportWriteError, StepFigures, StudentRecord};
use teaching::{Lesson, Progress};

/// Each step's figures from the worlds that ran it: the largest force sent to the hand, N, and
/// the scene's `score` at the world's end (steps not run: none).
pub fn figures(lesson: &Lesson, runs: &[StepRun]) -> Vec<StepFigures> {
    let mut f = vec![StepFigures::default(); lesson.steps.len()];
    for r in runs {
        if let Some(x) = f.get_mut(r.step) {
            x.peak_force_n = Some(r.peak_force_n);
            x.score = r.session.state("score");
        }
    }
    f
}

/// Writes the report of student `name` into `dir`; the files written.
pub fn write(
    dir: &Path,
    name: &str,
    lesson: &Lesson,
    progress: &Progress,
    runs: &[StepRun],
) -> Result<Vec<PathBuf>, ReportWriteError> {
    let figures = figures(lesson, runs);
    let student = StudentRecord {
        name,
        progress,
        figures: &figures,
    };
    class_report::class_report(lesson, &[student]).write(dir)
}
