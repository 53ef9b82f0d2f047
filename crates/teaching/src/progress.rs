//! A student's way through a lesson: the pre-test, each step (its question before, the task
//! until the world says it is done, its question after), the post-test. What a page and a
//! teacher page drive: the place now, the answers, the ticks on each step.
//!
//! The way is one line of places, walked forwards only: an answer or a met condition moves one
//! place on, nothing moves back. A step that is locked is entered only once the teacher opens
//! it: a student who reaches it waits ([`Place::Waiting`]) and answers and ticks change nothing
//! until then.

use crate::file::{Lesson, QuestionKind};

/// Where a student is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// Answering pre-test question `q`.
    PreTest(usize),
    /// At step `s`, which is locked: waiting for the teacher.
    Waiting(usize),
    /// Answering step `s`'s question before (a prediction).
    Before(usize),
    /// Doing step `s`'s task.
    Doing(usize),
    /// Answering step `s`'s question after (what they noticed).
    After(usize),
    /// Answering post-test question `q`.
    PostTest(usize),
    /// Done.
    Finished,
}

impl Place {
    /// The step this place belongs to, if any.
    pub fn step(&self) -> Option<usize> {
        match *self {
            Place::Waiting(s) | Place::Before(s) | Place::Doing(s) | Place::After(s) => Some(s),
            _ => None,
        }
    }
}

/// An answer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Answer {
    /// The index of a choice.
    Choice(usize),
    /// A short text.
    Text(String),
}

/// What the progress refuses.
#[derive(Clone, Debug, thiserror::Error, PartialEq, Eq)]
pub enum ProgressError {
    /// An answer where no question is asked, or a tick where no task is being done.
    #[error("{what} now: the student is at {place}")]
    NotNow {
        /// What was attempted (`an answer`, `a tick`).
        what: &'static str,
        /// Where the student is, in words.
        place: String,
    },
    /// An answer of the wrong kind or out of range.
    #[error("answer: {0}")]
    Answer(String),
    /// A step index past the lesson's steps.
    #[error("step {index} is out of range: allowed 0 ≤ step < {steps}")]
    NoStep {
        /// The index given.
        index: usize,
        /// The lesson's step count.
        steps: usize,
    },
}

/// Longest text answer, characters.
pub const MAX_ANSWER_CHARS: usize = 2000;

/// What happened on one step.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StepRecord {
    /// Ticks spent doing the task.
    pub ticks: u64,
    /// The tick of the task (0 = its first) on which the condition was met.
    pub met_at: Option<u64>,
    /// The answer to the question before.
    pub before: Option<Answer>,
    /// The answer to the question after.
    pub after: Option<Answer>,
}

/// One student's progress through a lesson.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The places in order.
    places: Vec<Place>,
    /// The place now (index into `places`).
    at: usize,
    /// Each step open (not locked).
    open: Vec<bool>,
    /// The questions' kinds, by place (None for places that are not questions).
    asks: Vec<Option<QuestionKind>>,
    pre: Vec<Option<Answer>>,
    post: Vec<Option<Answer>>,
    steps: Vec<StepRecord>,
    /// The index of each test question's correct choice.
    correct: Vec<Option<usize>>,
}

impl Progress {
    /// A student at the start of `lesson`: steps open or locked as the file says.
    pub fn new(lesson: &Lesson) -> Progress {
        let mut places = Vec::new();
        let mut asks = Vec::new();
        for (q, question) in lesson.test.iter().enumerate() {
            places.push(Place::PreTest(q));
            asks.push(Some(question.kind.clone()));
        }
        for (s, step) in lesson.steps.iter().enumerate() {
            if let Some(b) = &step.before {
                places.push(Place::Before(s));
                asks.push(Some(b.kind.clone()));
            }
            places.push(Place::Doing(s));
            asks.push(None);
            if let Some(a) = &step.after {
                places.push(Place::After(s));
                asks.push(Some(a.kind.clone()));
            }
        }
        for (q, question) in lesson.test.iter().enumerate() {
            places.push(Place::PostTest(q));
            asks.push(Some(question.kind.clone()));
        }
        places.push(Place::Finished);
        asks.push(None);
        let correct = lesson
            .test
            .iter()
            .map(|q| match &q.kind {
                QuestionKind::Choice { correct, .. } => *correct,
                QuestionKind::Text => None,
            })
            .collect();
        Progress {
            places,
            at: 0,
            open: lesson.steps.iter().map(|s| !s.locked).collect(),
            asks,
            pre: vec![None; lesson.test.len()],
            post: vec![None; lesson.test.len()],
            steps: vec![StepRecord::default(); lesson.steps.len()],
            correct,
        }
    }

    /// Where the student is now.
    pub fn place(&self) -> Place {
        let p = self.places[self.at];
        match p.step() {
            Some(s) if self.entering(s) && !self.open[s] => Place::Waiting(s),
            _ => p,
        }
    }

    /// How far along the line of places the student is (0 = the start; never decreases).
    pub fn position(&self) -> usize {
        self.at
    }

    /// The position of the first place of step `s` (where a locked step holds the student).
    pub fn step_start(&self, s: usize) -> Option<usize> {
        self.places.iter().position(|p| p.step() == Some(s))
    }

    /// Whether the place now is the first of step `s`.
    fn entering(&self, s: usize) -> bool {
        self.step_start(s) == Some(self.at)
    }

    /// Whether step `s` is open.
    pub fn is_open(&self, s: usize) -> bool {
        self.open.get(s).copied().unwrap_or(false)
    }

    /// The teacher opens step `s` (a student waiting at it goes on).
    pub fn open(&mut self, s: usize) -> Result<Place, ProgressError> {
        self.set_open(s, true)
    }

    /// The teacher locks step `s`: a student who has not entered it yet will wait there (one
    /// who has goes on; nobody moves back).
    pub fn lock(&mut self, s: usize) -> Result<Place, ProgressError> {
        self.set_open(s, false)
    }

    fn set_open(&mut self, s: usize, open: bool) -> Result<Place, ProgressError> {
        let steps = self.open.len();
        let slot = self
            .open
            .get_mut(s)
            .ok_or(ProgressError::NoStep { index: s, steps })?;
        *slot = open;
        Ok(self.place())
    }

    /// Records the answer to the question asked now and moves on.
    pub fn answer(&mut self, answer: Answer) -> Result<Place, ProgressError> {
        let place = self.place();
        let Some(kind) = (match place {
            Place::PreTest(_) | Place::Before(_) | Place::After(_) | Place::PostTest(_) => {
                self.asks[self.at].as_ref()
            }
            _ => None,
        }) else {
            return Err(self.not_now("an answer"));
        };
        match (kind, &answer) {
            (QuestionKind::Choice { choices, .. }, Answer::Choice(i)) if *i < choices.len() => {}
            (QuestionKind::Choice { choices, .. }, Answer::Choice(i)) => {
                return Err(ProgressError::Answer(format!(
                    "choice {i} is out of range: allowed 0 ≤ choice < {}",
                    choices.len()
                )));
            }
            (QuestionKind::Text, Answer::Text(t)) => {
                let n = t.trim().chars().count();
                if n == 0 || n > MAX_ANSWER_CHARS {
                    return Err(ProgressError::Answer(format!(
                        "a text of {n} characters: allowed 1 to {MAX_ANSWER_CHARS}"
                    )));
                }
            }
            (QuestionKind::Choice { .. }, Answer::Text(_)) => {
                return Err(ProgressError::Answer(
                    "a text where one of the choices is asked".into(),
                ));
            }
            (QuestionKind::Text, Answer::Choice(_)) => {
                return Err(ProgressError::Answer(
                    "a choice where a short text is asked".into(),
                ));
            }
        }
        let answer = match answer {
            Answer::Text(t) => Answer::Text(t.trim().to_string()),
            a => a,
        };
        match place {
            Place::PreTest(q) => self.pre[q] = Some(answer),
            Place::PostTest(q) => self.post[q] = Some(answer),
            Place::Before(s) => self.steps[s].before = Some(answer),
            Place::After(s) => self.steps[s].after = Some(answer),
            _ => {}
        }
        self.at += 1;
        Ok(self.place())
    }

    /// One tick of the task now; `met` is the step's [`crate::evaluate::Evaluator`] saying the
    /// condition was met on it (the student then moves on).
    pub fn tick(&mut self, met: bool) -> Result<Place, ProgressError> {
        let Place::Doing(s) = self.place() else {
            return Err(self.not_now("a tick"));
        };
        let r = &mut self.steps[s];
        r.ticks += 1;
        if met {
            r.met_at = Some(r.ticks - 1);
            self.at += 1;
        }
        Ok(self.place())
    }

    fn not_now(&self, what: &'static str) -> ProgressError {
        ProgressError::NotNow {
            what,
            place: describe(self.place()),
        }
    }

    /// What happened on each step so far.
    pub fn steps(&self) -> &[StepRecord] {
        &self.steps
    }

    /// The pre-test's answers.
    pub fn pre_test(&self) -> &[Option<Answer>] {
        &self.pre
    }

    /// The post-test's answers.
    pub fn post_test(&self) -> &[Option<Answer>] {
        &self.post
    }

    /// Correct answers of a test (`pre` or post): (correct, questions).
    pub fn test_score(&self, pre: bool) -> (usize, usize) {
        let answers = if pre { &self.pre } else { &self.post };
        let right = answers
            .iter()
            .zip(&self.correct)
            .filter(|(a, c)| matches!((a, c), (Some(Answer::Choice(i)), Some(k)) if i == k))
            .count();
        (right, answers.len())
    }
}

/// A place in words (`step 3, doing the task`).
pub fn describe(p: Place) -> String {
    match p {
        Place::PreTest(q) => format!("pre-test question {}", q + 1),
        Place::Waiting(s) => format!("step {}, locked (waiting for the teacher)", s + 1),
        Place::Before(s) => format!("step {}, the question before", s + 1),
        Place::Doing(s) => format!("step {}, doing the task", s + 1),
        Place::After(s) => format!("step {}, the question after", s + 1),
        Place::PostTest(q) => format!("post-test question {}", q + 1),
        Place::Finished => "the end of the lesson".to_string(),
    }
}
