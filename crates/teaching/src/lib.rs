//! # nanohaptics-teaching: lessons of the teaching game
//!
//! A lesson is a TOML file listing steps: the scene each step runs, the switches it sets, the
//! task, how the world says the task is done, and questions before and after; its content
//! questions are asked before the first step and after the last, so a class can measure what
//! it learned (`docs/teaching.md`).
//!
//! * [`file`]: the lesson file, read and checked against the scenes it names (their switches
//!   and the events their worlds emit); errors name the field, what is allowed, and the line
//!   and column ([`error`]).
//! * [`condition`]: the vocabulary of conditions and the events and state each reads.
//! * [`evaluate`]: the evaluator a page feeds with each tick's events and state; pure and
//!   clock-free.
//! * [`progress`]: a student's way through a lesson (never backwards, never into a locked
//!   step), the answers and the ticks on each step.
//! * [`builtin`]: the built-in module, written from the teaching paper.
//! * [`class_report`]: the class report a teacher downloads (CSV for a spreadsheet, a Markdown
//!   page with charts) from the students' progress and what their sessions measured.
//!
//! What it is not: no page, no server, no loop. It reads scenes through the sessions crate
//! (`haptic-loop`) and is its own crate so that a page can drive a lesson without the
//! report's figures (`nanohaptics-lesson`).

pub mod builtin;
mod cells;
pub mod class_report;
pub mod condition;
pub mod error;
pub mod evaluate;
pub mod file;
pub mod progress;

pub use condition::Condition;
pub use error::{LessonError, LessonFileError};
pub use evaluate::Evaluator;
pub use file::{Lesson, Question, QuestionKind, Step, load_lesson, parse_lesson};
pub use progress::{Answer, Place, Progress};
