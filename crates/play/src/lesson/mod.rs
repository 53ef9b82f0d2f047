//! The lesson in the page (`nanohaptics play --lesson`): the driver that takes one student
//! through a lesson of `nanohaptics-teaching` on a play server.
//!
//! The driver holds the lesson and the student's [`Progress`]; the pages' answers (and a
//! demonstration's `?step=ID`) reach it through [`Shared::lesson_asks`] and every move is told
//! to the pages as a `lesson` message ([`view`]). A step's world is one [`PageSession`] of its
//! own (the session object every front end uses): opened with the step's scene and its
//! switches set before the first tick (recorded as that tick's switches), watched after every
//! tick by the step's [`Evaluator`] on the tick thread, completed on the tick the condition is
//! met, and recorded to `DIR/STEP-ID.mcap`.
//!
//! A lone student has no teacher to open a locked step: `play --lesson` opens it when the
//! student reaches it (the `lesson` message says so first).

pub mod report;
pub(crate) mod view;

use crate::protocol::{LessonAsk, LessonView, PageAnswer, ServerMsg};
use crate::server::Shared;
use crate::session::{Hand, PageSession, SessionSpec, SessionSummary};
use haptic_engine::pacing::Pacing;
use haptic_engine::realtime::RtRequest;
use haptic_loop::session::{SessionError, now_unix_ns};
use haptic_loop::setup::session_device;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;
use teaching::progress::ProgressError;
use teaching::{Answer, Evaluator, Lesson, Place, Progress};

/// What the driver refuses a page.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LessonAskError {
    /// The answer does not fit the question now (or none is asked).
    #[error(transparent)]
    Progress(#[from] ProgressError),
    /// `?step=ID` names no step of the lesson.
    #[error("step `{id}` is not in the lesson (its steps: {steps})")]
    UnknownStep {
        /// The id asked for.
        id: String,
        /// The lesson's step ids, comma-separated.
        steps: String,
    },
    /// `?step=ID` after the student began the lesson.
    #[error("a step is opened by its URL only before the lesson begins: the student is at {place}")]
    Begun {
        /// Where the student is, in words.
        place: String,
    },
}

impl LessonAskError {
    /// The page message's field the error is about.
    pub fn field(&self) -> &'static str {
        match self {
            LessonAskError::Progress(_) => "answer",
            _ => "step.id",
        }
    }
}

/// One step's world as it ran.
#[derive(Debug)]
pub struct StepRun {
    /// The step (0 = the lesson's first).
    pub step: usize,
    /// Its id (the recording's name).
    pub id: String,
    /// The tick of the step (0 = its first) on which its condition was met; `None`: it was
    /// stopped first.
    pub met_at: Option<u64>,
    /// The session: its end, ticks, state and recording.
    pub session: SessionSummary,
    /// The largest force sent to the hand in the step's world, N (the recording's
    /// `device_force_n` at its largest).
    pub peak_force_n: f64,
}

/// A step's world, open: its session (step it, or run it) until the evaluator completes it.
pub struct StepWorld {
    /// The step (0 = the lesson's first).
    pub step: usize,
    /// The step's session.
    pub session: PageSession,
    /// The largest force sent to the hand so far, N (an `f64`'s bits; the tick thread's
    /// watcher raises it).
    peak_force: Arc<AtomicU64>,
}

impl StepWorld {
    /// The same world with its session passed through `f` (a classroom adds its reporter).
    pub fn map_session(self, f: impl FnOnce(PageSession) -> PageSession) -> StepWorld {
        StepWorld {
            session: f(self.session),
            ..self
        }
    }
}

/// The lesson of one student on a play server.
pub struct LessonDriver {
    lesson: Lesson,
    progress: Progress,
    shared: Arc<Shared>,
    dir: PathBuf,
    runs: Vec<StepRun>,
    /// The operator the steps' recordings name.
    operator: String,
    /// Where the pages download a step's recording.
    recording_url: String,
}

impl LessonDriver {
    /// The student at the start of `lesson`, the pages of `shared` told so; each step's
    /// recording goes to `dir` (made when the first step opens).
    pub fn new(lesson: Lesson, shared: Arc<Shared>, dir: PathBuf) -> LessonDriver {
        let progress = Progress::new(&lesson);
        if let Ok(mut q) = shared.lesson_asks.lock() {
            *q = Some(Vec::new());
        }
        let d = LessonDriver {
            lesson,
            progress,
            shared,
            dir,
            runs: Vec::new(),
            operator: "person (browser page)".into(),
            recording_url: "/recording.mcap".into(),
        };
        d.tell();
        d
    }

    /// The same driver with the steps' recordings naming `operator` and offered to the pages
    /// at `recording_url` (a classroom student's: their name, their token's address).
    pub fn with_page(mut self, operator: String, recording_url: String) -> LessonDriver {
        self.operator = operator;
        self.recording_url = recording_url;
        self
    }

    /// Opens (`open`) or locks step `s` (the teacher's), the pages told; the place then.
    pub fn set_open(&mut self, s: usize, open: bool) -> Result<Place, ProgressError> {
        let place = if open {
            self.progress.open(s)?
        } else {
            self.progress.lock(s)?
        };
        self.tell();
        Ok(place)
    }

    /// The lesson (a demonstration's: its one step).
    pub fn lesson(&self) -> &Lesson {
        &self.lesson
    }

    /// The student's progress.
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// The steps' worlds as they ran, in order.
    pub fn runs(&self) -> &[StepRun] {
        &self.runs
    }

    /// The recording of step `id`: `DIR/ID.mcap`.
    pub fn recording_of(&self, id: &str) -> PathBuf {
        self.dir.join(format!("{id}.mcap"))
    }

    /// What the pages are told now.
    pub fn view(&self) -> LessonView {
        view::of(&self.lesson, &self.progress)
    }

    /// Tells every page (and later ones) where the student is.
    fn tell(&self) {
        let text = ServerMsg::Lesson(Box::new(self.view())).to_json();
        if let Ok(mut l) = self.shared.lesson.lock() {
            *l = Some(text.clone());
        }
        self.shared.broadcast(&tungstenite::Message::text(text));
    }

    /// Records the answer to the question asked now and moves on (the pages told).
    pub fn answer(&mut self, answer: PageAnswer) -> Result<Place, LessonAskError> {
        let place = self.progress.answer(match answer {
            PageAnswer::Choice(i) => Answer::Choice(i),
            PageAnswer::Text(t) => Answer::Text(t),
        })?;
        self.tell();
        Ok(place)
    }

    /// A demonstration of step `id` (the page's `?step=ID`): the lesson becomes that step
    /// alone (open, its questions, no pre- or post-test). Only before the lesson begins.
    pub fn open_step(&mut self, id: &str) -> Result<(), LessonAskError> {
        let Some(step) = self.lesson.steps.iter().find(|s| s.id == id) else {
            return Err(LessonAskError::UnknownStep {
                id: id.to_string(),
                steps: self
                    .lesson
                    .steps
                    .iter()
                    .map(|s| s.id.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        if self.progress.position() != 0 || !self.runs.is_empty() {
            return Err(LessonAskError::Begun {
                place: teaching::progress::describe(self.progress.place()),
            });
        }
        let mut step = step.clone();
        step.locked = false;
        self.lesson = Lesson {
            title: format!("{}: step {} (demonstration)", self.lesson.title, step.id),
            description: self.lesson.description.clone(),
            test: Vec::new(),
            steps: vec![step],
        };
        self.progress = Progress::new(&self.lesson);
        self.tell();
        Ok(())
    }

    /// Takes what the pages asked since the last call: each answer or step applied, or
    /// refused to its page with the reason.
    pub fn take_asks(&mut self) {
        let asks = match self.shared.lesson_asks.lock() {
            Ok(mut q) => q.as_mut().map(std::mem::take).unwrap_or_default(),
            Err(_) => return,
        };
        for (page, ask) in asks {
            let r = match ask {
                LessonAsk::Answer(a) => self.answer(a).map(|_| ()),
                LessonAsk::Step(id) => self.open_step(&id),
            };
            if let Err(e) = r {
                self.shared.error_to(page, e.field(), &e.to_string());
            }
        }
    }

    /// A locked step the student reached opens (no teacher in `play`); true when one did.
    pub fn open_for_lone_student(&mut self) -> bool {
        match self.progress.place() {
            Place::Waiting(s) => {
                let _ = self.progress.open(s);
                self.tell();
                true
            }
            _ => false,
        }
    }

    /// Opens the world of the step the student is doing: its scene, its switches set before
    /// the first tick, its evaluator watching every tick, its recording `DIR/ID.mcap`. `None`
    /// when the student is not at a step's task.
    pub fn open_world(&mut self) -> Option<Result<StepWorld, SessionError>> {
        let Place::Doing(s) = self.progress.place() else {
            return None;
        };
        let peak_force = Arc::new(AtomicU64::new(0f64.to_bits()));
        Some(
            self.open_world_of(s, peak_force.clone())
                .map(|session| StepWorld {
                    step: s,
                    session,
                    peak_force,
                }),
        )
    }

    fn open_world_of(
        &mut self,
        s: usize,
        peak_force: Arc<AtomicU64>,
    ) -> Result<PageSession, SessionError> {
        let step = &self.lesson.steps[s];
        let file = step.source.parse()?;
        std::fs::create_dir_all(&self.dir).map_err(|e| SessionError::Io {
            path: self.dir.display().to_string(),
            message: e.to_string(),
        })?;
        let start_time_ns = now_unix_ns();
        let hand = Hand::open(session_device(&file, None, start_time_ns), &self.shared)?;
        // The last step's end screen and download are not this step's.
        if let Ok(mut e) = self.shared.end.lock() {
            *e = None;
        }
        let spec = SessionSpec {
            scene: &step.source,
            scene_name: &file.scene.name,
            out: self.recording_of(&step.id),
            recording_url: self.recording_url.clone(),
            start_time_ns,
            operator: self.operator.clone(),
            link: "page".into(),
            seconds: None,
            ticks: None,
        };
        let switches: Vec<(&str, f64)> = step.switch_pairs().collect();
        let mut evaluator = Evaluator::new(step.done, step.kind, &step.state_fields, step.rate_hz)
            .map_err(|e| SessionError::Option(format!("step `{}`: {e}", step.id)))?;
        let mut state = Vec::with_capacity(step.state_fields.len());
        let session = PageSession::open_with_switches(&spec, hand, self.shared.clone(), &switches)?
            .with_sound_block(crate::publish::PLAY_SOUND_BLOCK_TICKS)
            .with_watcher(Box::new(move |lp| {
                let f = lp.last_result().device_force_n;
                let m = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
                if m > f64::from_bits(peak_force.load(Ordering::Relaxed)) {
                    peak_force.store(m.to_bits(), Ordering::Relaxed);
                }
                state.clear();
                lp.scene_state(&mut state);
                evaluator.feed(&lp.last_result().events, &state)
            }));
        Ok(session)
    }

    /// Closes a step's world: its session finished, its ticks counted into the progress (the
    /// last one meeting the condition when the watcher completed it), the pages told.
    pub fn close_world(&mut self, world: StepWorld) -> &StepRun {
        let StepWorld {
            step: s,
            session,
            peak_force,
        } = world;
        let summary = session.finish();
        let met = summary.end == "completed";
        let ticks = summary.stats.ticks;
        for t in 0..ticks {
            let _ = self.progress.tick(met && t + 1 == ticks);
        }
        self.runs.push(StepRun {
            step: s,
            id: self.lesson.steps[s].id.clone(),
            met_at: (met && ticks > 0).then(|| ticks - 1),
            session: summary,
            peak_force_n: f64::from_bits(peak_force.load(Ordering::Relaxed)),
        });
        self.tell();
        let n = self.runs.len() - 1;
        &self.runs[n]
    }

    /// Runs the lesson to its end (or until `stop`): answers taken as they come, a locked
    /// step opened for the lone student, each step's world run under `pacing` (`rt` for its
    /// tick thread) until its condition is met. Ends early when a step's world was stopped
    /// (the player ended it, or `stop`) or failed.
    pub fn run(
        &mut self,
        pacing: Pacing,
        rt: Option<&RtRequest>,
        stop: &AtomicBool,
    ) -> Result<(), SessionError> {
        loop {
            self.take_asks();
            if self.progress.place() == Place::Finished || stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            if self.open_for_lone_student() {
                continue;
            }
            let Some(world) = self.open_world() else {
                std::thread::sleep(Duration::from_millis(10));
                continue;
            };
            let mut world = world?;
            // The page's Start (its first hand) starts the first world; later ones at once.
            if !self.shared.input.wait_first(stop) {
                world.session.request_end();
            }
            world.session.run(pacing.clone(), rt, stop);
            let run = self.close_world(world);
            if let Some(e) = &run.session.error {
                return Err(SessionError::Sink(e.clone()));
            }
            if run.met_at.is_none() {
                return Ok(());
            }
            // A page's End ends this step's world, not the next one's.
            self.shared.end_requested.store(false, Ordering::Relaxed);
        }
    }

    /// The steps' worlds as they ran (the driver done with).
    pub fn into_runs(self) -> Vec<StepRun> {
        self.runs
    }

    /// Where the recordings go.
    pub fn dir(&self) -> &Path {
        &self.dir
    }
}

#[cfg(test)]
mod tests;
