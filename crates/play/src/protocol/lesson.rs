//! The lesson's part of the protocol: what the page shows of a lesson ([`LessonView`], the
//! server's `lesson` message) and what a student answers (the page's `answer` message, read by
//! [`super::parse`]).

use serde::{Deserialize, Serialize};

/// Where the student is in the lesson and what the page shows there: sent to every page when
/// the lesson starts and on every move, and first (after the `hello`) to a page that connects
/// later.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LessonView {
    /// The lesson's title.
    pub title: String,
    /// The place's kind: `pre_test`, `waiting` (a locked step), `before` (the step's
    /// prediction), `doing` (the task, the world runs), `after` (what the student noticed),
    /// `post_test` or `finished`.
    pub place: String,
    /// The step (0 = the first) at a step's place, `None` in the tests and at the end.
    pub step: Option<usize>,
    /// The lesson's step count.
    pub steps: usize,
    /// The step's id, title and task (empty outside a step).
    pub step_id: String,
    /// The step's title.
    pub step_title: String,
    /// What the student is asked to do.
    pub task: String,
    /// The question asked now, if any.
    pub question: Option<QuestionView>,
    /// The pre- and post-test scores (correct, questions), once finished.
    pub score: Option<Scores>,
    /// All of it in one sentence, for the page's live region (what a screen reader says).
    pub words: String,
}

/// A question as the page shows it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QuestionView {
    /// What is asked.
    pub prompt: String,
    /// The choices, in order (the answer is the index of one); empty: a short text is asked.
    pub choices: Vec<String>,
    /// Longest text answer, characters.
    pub max_chars: usize,
}

/// The scores of the content questions: (correct, questions) before and after the steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Scores {
    /// The pre-test's (correct, questions).
    pub pre: (usize, usize),
    /// The post-test's (correct, questions).
    pub post: (usize, usize),
}

/// A student's answer as the page sends it (the fields of an `answer` message): exactly one
/// of `choice` and `text`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PageAnswer {
    /// The index of a choice (0 = the first).
    Choice(usize),
    /// A short text.
    Text(String),
}

/// What a page asked of the lesson (its `answer` and `step` messages), queued for the lesson's
/// driver.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LessonAsk {
    /// The answer to the question now.
    Answer(PageAnswer),
    /// Open step `id` alone, for a demonstration.
    Step(String),
}
