//! What the pages show of a student's place in a lesson: the `lesson` message.

use crate::protocol::{LessonView, QuestionView, Scores};
use teaching::progress::MAX_ANSWER_CHARS;
use teaching::{Lesson, Place, Progress, Question, QuestionKind};

/// The `lesson` message for `progress` through `lesson`.
pub fn of(lesson: &Lesson, progress: &Progress) -> LessonView {
    let place = progress.place();
    let step = place.step().and_then(|s| lesson.steps.get(s));
    let question = match place {
        Place::PreTest(q) | Place::PostTest(q) => lesson.test.get(q),
        Place::Before(s) => lesson.steps.get(s).and_then(|st| st.before.as_ref()),
        Place::After(s) => lesson.steps.get(s).and_then(|st| st.after.as_ref()),
        _ => None,
    };
    let score = (place == Place::Finished).then(|| Scores {
        pre: progress.test_score(true),
        post: progress.test_score(false),
    });
    LessonView {
        title: lesson.title.clone(),
        place: name(place).to_string(),
        step: place.step(),
        steps: lesson.steps.len(),
        step_id: step.map(|s| s.id.clone()).unwrap_or_default(),
        step_title: step.map(|s| s.title.clone()).unwrap_or_default(),
        task: step.map(|s| s.task.clone()).unwrap_or_default(),
        question: question.map(question_view),
        score,
        words: words(lesson, place, question, score),
    }
}

/// The place's kind as the `lesson` message names it.
pub fn name(place: Place) -> &'static str {
    match place {
        Place::PreTest(_) => "pre_test",
        Place::Waiting(_) => "waiting",
        Place::Before(_) => "before",
        Place::Doing(_) => "doing",
        Place::After(_) => "after",
        Place::PostTest(_) => "post_test",
        Place::Finished => "finished",
    }
}

fn question_view(q: &Question) -> QuestionView {
    QuestionView {
        prompt: q.prompt.clone(),
        choices: match &q.kind {
            QuestionKind::Choice { choices, .. } => choices.clone(),
            QuestionKind::Text => Vec::new(),
        },
        max_chars: MAX_ANSWER_CHARS,
    }
}

/// The place in one sentence, for the page's live region.
fn words(
    lesson: &Lesson,
    place: Place,
    question: Option<&Question>,
    score: Option<Scores>,
) -> String {
    let n = lesson.test.len();
    let prompt = question.map(|q| q.prompt.as_str()).unwrap_or_default();
    let step = |s: usize| {
        let title = lesson.steps.get(s).map_or("", |st| st.title.as_str());
        format!("Step {} of {}, {title}.", s + 1, lesson.steps.len())
    };
    let task = |s: usize| lesson.steps.get(s).map_or("", |st| st.task.as_str());
    match place {
        Place::PreTest(q) => format!("Before the lesson, question {} of {n}: {prompt}", q + 1),
        Place::Waiting(s) => format!("{} It is locked until it is opened.", step(s)),
        Place::Before(s) => format!("{} {} Before you start: {prompt}", step(s), task(s)),
        Place::Doing(s) => format!("{} {}", step(s), task(s)),
        Place::After(s) => format!("{} Done. {prompt}", step(s)),
        Place::PostTest(q) => format!("After the lesson, question {} of {n}: {prompt}", q + 1),
        Place::Finished => match score {
            Some(Scores { pre, post }) if n > 0 => format!(
                "The lesson is finished. Before: {} of {} right. After: {} of {} right.",
                pre.0, pre.1, post.0, post.1
            ),
            _ => "The lesson is finished.".to_string(),
        },
    }
}
