//! A lesson in the classroom (`classroom --lesson`): every student takes the lesson on their
//! own page, and the teacher follows each one, opens a locked step for everyone or holds the
//! class before a step.
//!
//! - **Each student** has the same [`LessonDriver`] as `play --lesson`, on their session's link:
//!   their answers reach it, and every move is told to their pages.
//! - **The coach**, one thread for the class, goes round the students every
//!   [`COACH_EVERY`]: it takes their answers, and when a student reaches a step's task it opens
//!   that step's world and hands it to the least busy tick worker. That is the same worker,
//!   on the same schedule, as every session.
//! - **A met condition** ends the world on its tick. The worker lets it go, and the finisher
//!   closes it through the student's lesson ([`close_step`]). Its recording is
//!   `DIR/NAME-START/STEP-ID.mcap`. The coach then opens the next step.
//! - **The teacher's locks** ([`ClassLesson`]) reach every student at once, and a student who
//!   joins later starts with them.
//! - **A student's lesson ends** when they finish it, end it (their End, the teacher's, or the
//!   class stopping), or a step's world fails.

use super::{Class, Phase, Student, StudentSummary};
use crate::lesson::{LessonDriver, StepWorld, report};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};
use teaching::class_report::{self, ClassReport, StepFigures, StudentRecord};
use teaching::progress::describe;
use teaching::{Lesson, Place, Progress};

/// How often the coach goes round the students.
pub const COACH_EVERY: Duration = Duration::from_millis(10);

/// The class's lesson and each step's lock for the class now.
pub(crate) struct ClassLesson {
    pub(crate) lesson: Lesson,
    locks: Mutex<Vec<bool>>,
}

/// One student's way through the lesson.
pub(crate) struct StudentLesson {
    pub(crate) driver: LessonDriver,
    /// A step's world is with a worker.
    world_out: bool,
    /// The step the student is on, and since when.
    on_step: Option<(usize, Instant)>,
    /// The lesson ended for them (finished, ended, or failed).
    pub(crate) ended: bool,
    /// Why a step's world failed, in words.
    error: Option<String>,
}

/// The lock of a student's lesson (a panic elsewhere leaves what it had).
pub(crate) fn locked(m: &Mutex<StudentLesson>) -> MutexGuard<'_, StudentLesson> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl ClassLesson {
    /// `lesson` for a class, its steps locked as the file says.
    pub(crate) fn new(lesson: Lesson) -> ClassLesson {
        let locks = lesson.steps.iter().map(|s| s.locked).collect();
        ClassLesson {
            lesson,
            locks: Mutex::new(locks),
        }
    }

    /// Each step locked for the class now.
    pub(crate) fn locks(&self) -> Vec<bool> {
        self.locks
            .lock()
            .map(|l| l.clone())
            .unwrap_or_else(|e| e.into_inner().clone())
    }

    /// A new student's lesson on the pages of `shared`, their steps' recordings in `dir`,
    /// with the class's locks.
    pub(crate) fn student(
        &self,
        shared: Arc<crate::server::Shared>,
        dir: PathBuf,
        name: &str,
        token: &str,
    ) -> StudentLesson {
        let mut driver = LessonDriver::new(self.lesson.clone(), shared, dir).with_page(
            format!("person (browser page, classroom student `{name}`)"),
            format!("/recording.mcap?s={token}"),
        );
        for (s, (&lock, step)) in self.locks().iter().zip(&self.lesson.steps).enumerate() {
            if lock != step.locked {
                let _ = driver.set_open(s, !lock);
            }
        }
        StudentLesson {
            driver,
            world_out: false,
            on_step: None,
            ended: false,
            error: None,
        }
    }

    /// The index of step `id`, or the error naming the lesson's steps.
    pub(crate) fn step_index(&self, id: &str) -> Result<usize, String> {
        self.lesson
            .steps
            .iter()
            .position(|s| s.id == id)
            .ok_or_else(|| {
                let ids: Vec<&str> = self.lesson.steps.iter().map(|s| s.id.as_str()).collect();
                format!(
                    "step `{id}` is not in the lesson (its steps: {})",
                    ids.join(", ")
                )
            })
    }

    /// The first step locked for the class, if any.
    pub(crate) fn next_locked(&self) -> Option<usize> {
        self.locks().iter().position(|&l| l)
    }

    /// Opens (`open`) or locks step `s` for the class: every student's lesson told (a student
    /// waiting at it goes on; one past it is not moved back), and students joining later. The
    /// number of students it reached.
    pub(crate) fn set_open(&self, class: &Class, s: usize, open: bool) -> usize {
        if let Ok(mut l) = self.locks.lock()
            && let Some(x) = l.get_mut(s)
        {
            *x = !open;
        }
        let mut reached = 0;
        for st in class.students() {
            if let Some(m) = &st.lesson {
                let mut l = locked(m);
                if !l.ended && l.driver.set_open(s, open).is_ok() {
                    reached += 1;
                }
            }
        }
        reached
    }
}

impl StudentLesson {
    /// Notes the step the student is on now (its time starts when they reach it).
    fn note_step(&mut self) {
        let step = self.driver.progress().place().step();
        if step != self.on_step.map(|(s, _)| s) {
            self.on_step = step.map(|s| (s, Instant::now()));
        }
    }

    /// What the teacher page shows of the student's lesson.
    pub(crate) fn view(&self) -> serde_json::Value {
        let lesson = self.driver.lesson();
        let p = self.driver.progress();
        let place = p.place();
        let done: Vec<&str> = p
            .steps()
            .iter()
            .zip(&lesson.steps)
            .filter(|(r, _)| r.met_at.is_some())
            .map(|(_, s)| s.id.as_str())
            .collect();
        let finished = place == Place::Finished;
        serde_json::json!({
            "place": crate::lesson::view::name(place),
            "where": describe(place),
            "step": place.step(),
            "step_id": place.step().and_then(|s| lesson.steps.get(s)).map(|s| s.id.clone()),
            "step_title": place.step().and_then(|s| lesson.steps.get(s)).map(|s| s.title.clone()),
            "on_step_s": self.on_step.map(|(_, t)| t.elapsed().as_secs_f64()),
            "done": done,
            "answers": answers(lesson, p),
            "pre": (!lesson.test.is_empty() && p.pre_test().iter().all(Option::is_some))
                .then(|| p.test_score(true)),
            "post": (finished && !lesson.test.is_empty()).then(|| p.test_score(false)),
            "ended": self.ended,
            "error": self.error,
        })
    }
}

/// Every answer a student gave, in the lesson's order: where, the question, the answer.
fn answers(lesson: &Lesson, p: &Progress) -> Vec<serde_json::Value> {
    let mut out = Vec::new();
    let mut push = |at: String, q: &teaching::Question, a: &teaching::Answer| {
        out.push(serde_json::json!({
            "at": at,
            "prompt": q.prompt,
            "answer": class_report::answer_text(q, a),
        }));
    };
    for (i, (q, a)) in lesson.test.iter().zip(p.pre_test()).enumerate() {
        if let Some(a) = a {
            push(format!("pre-test {}", i + 1), q, a);
        }
    }
    for (step, r) in lesson.steps.iter().zip(p.steps()) {
        if let (Some(q), Some(a)) = (&step.before, &r.before) {
            push(format!("{}, before", step.id), q, a);
        }
        if let (Some(q), Some(a)) = (&step.after, &r.after) {
            push(format!("{}, after", step.id), q, a);
        }
    }
    for (i, (q, a)) in lesson.test.iter().zip(p.post_test()).enumerate() {
        if let Some(a) = a {
            push(format!("post-test {}", i + 1), q, a);
        }
    }
    out
}

/// The coach: every [`COACH_EVERY`] until `stop`, each student's answers taken and the world
/// of the step they reached handed to a worker.
pub(crate) fn coach(class: &Class, stop: &AtomicBool) {
    while !stop.load(Ordering::Relaxed) {
        for s in class.students() {
            coach_one(class, &s);
        }
        std::thread::sleep(COACH_EVERY);
    }
}

/// One student's turn with the coach.
fn coach_one(class: &Class, student: &Arc<Student>) {
    let Some(m) = &student.lesson else {
        return;
    };
    // A step's world being closed holds the lock: the student is seen next round.
    let Ok(mut l) = m.try_lock() else {
        return;
    };
    if l.ended {
        return;
    }
    l.driver.take_asks();
    l.note_step();
    if l.world_out {
        return;
    }
    let place = l.driver.progress().place();
    if place == Place::Finished || student.shared.end_requested.load(Ordering::Relaxed) {
        end(class, &mut l, student);
        return;
    }
    if !matches!(place, Place::Doing(_)) {
        return;
    }
    match l.driver.open_world() {
        Some(Ok(world)) => {
            match class.dispatch(Box::new(super::live::Live::step(student.clone(), world))) {
                Ok(()) => l.world_out = true,
                Err(e) => {
                    l.error = Some(e.to_string());
                    end(class, &mut l, student);
                }
            }
        }
        Some(Err(e)) => {
            l.error = Some(e.to_string());
            end(class, &mut l, student);
        }
        None => {}
    }
}

/// The student's lesson ended (counted once among the class's ended sessions).
pub(crate) fn end(class: &Class, l: &mut StudentLesson, student: &Student) {
    if !l.ended {
        class.ended.fetch_add(1, Ordering::Relaxed);
    }
    l.ended = true;
    student.set_phase(Phase::Ended);
}

/// Closes a step's world through `student`'s lesson (on the finisher thread): its recording
/// complete, its ticks counted, their pages told. A world stopped before its condition was met
/// (their End, the teacher's, the class stopping) or failed ends their lesson.
pub(crate) fn close_step(
    class: &Class,
    student: &Arc<Student>,
    world: StepWorld,
) -> StudentSummary {
    let Some(m) = &student.lesson else {
        // Not a lesson's student: the world closes alone.
        let session = world.session.finish();
        return StudentSummary {
            name: student.name.clone(),
            step: None,
            session,
        };
    };
    let mut l = locked(m);
    let run = l.driver.close_world(world);
    let summary = StudentSummary {
        name: student.name.clone(),
        step: Some(run.id.clone()),
        session: run.session.clone(),
    };
    let met = run.met_at.is_some() && run.session.error.is_none();
    let error = run.session.error.clone();
    l.world_out = false;
    if met {
        // Their End ended this step's world, not the next one's.
        student.shared.end_requested.store(false, Ordering::Relaxed);
    } else {
        l.error = error;
        end(class, &mut l, student);
    }
    summary
}

/// The class report now ([`teaching::class_report`]): every student of the lesson, where
/// they are, each step's time, largest force and score, the answers and the tests.
pub(crate) fn class_report(class: &Class) -> Option<ClassReport> {
    let cl = class.lesson.as_ref()?;
    let students = class.students();
    let mut held: Vec<(String, Progress, Vec<StepFigures>)> = Vec::new();
    for s in &students {
        if let Some(m) = &s.lesson {
            let l = locked(m);
            let figures = report::figures(l.driver.lesson(), l.driver.runs());
            held.push((s.name.clone(), l.driver.progress().clone(), figures));
        }
    }
    let records: Vec<StudentRecord> = held
        .iter()
        .map(|(name, progress, figures)| StudentRecord {
            name,
            progress,
            figures,
        })
        .collect();
    Some(class_report::class_report(&cl.lesson, &records))
}

/// The recording of step `id` of `student`'s lesson, once its world has closed.
pub(crate) fn step_recording(student: &Student, id: &str) -> Result<PathBuf, String> {
    let m = student
        .lesson
        .as_ref()
        .ok_or_else(|| format!("{} is not taking a lesson", student.name))?;
    let l = locked(m);
    if l.driver.runs().iter().any(|r| r.id == id) {
        Ok(l.driver.recording_of(id))
    } else {
        Err(format!(
            "{} has no finished step `{id}` yet: a step can be replayed once its world has closed",
            student.name
        ))
    }
}

/// The ids of `student`'s steps whose worlds have closed, in order.
pub(crate) fn steps_run(student: &Student) -> Vec<String> {
    student
        .lesson
        .as_ref()
        .map(|m| {
            locked(m)
                .driver
                .runs()
                .iter()
                .map(|r| r.id.clone())
                .collect()
        })
        .unwrap_or_default()
}
