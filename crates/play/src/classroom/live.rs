//! One student's session in the classroom: the play session ([`PageSession`]) with their page as
//! the hand, ticked by a shared worker on its own cycle ([`Worker`]), and what the teacher page
//! shows of them.

use super::{Student, StudentSummary};
use crate::lesson::StepWorld;
use crate::session::{PageSession, Step};
use haptic_engine::clock::Worker;
use haptic_engine::timing::Pacer;
use std::sync::Arc;

/// Where a student's session is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Joined; waiting for their page's Start.
    Waiting,
    /// Playing.
    Playing,
    /// Ended: the recording is complete.
    Ended,
}

/// What a worker ticks for a student: their session, or the world of their lesson's step.
enum Held {
    Session(PageSession),
    Step(StepWorld),
}

/// A student's session as a worker holds it.
pub struct Live {
    /// Who plays it.
    pub student: Arc<Student>,
    held: Held,
    playing: bool,
}

/// A session a worker let go, closed on the finisher thread.
pub enum Finished {
    /// A student's session, closed.
    Session(Box<StudentSummary>),
    /// The world of a step of `student`'s lesson, to close through their lesson.
    Step(Arc<Student>, Box<StepWorld>),
}

/// `session` reporting to `student`'s teacher-page status every [`super::STATUS_EVERY_TICKS`]
/// ticks.
fn reporting(student: &Arc<Student>, session: PageSession) -> PageSession {
    let st = student.clone();
    session.with_reporter(
        super::STATUS_EVERY_TICKS,
        Box::new(move |p, lp| st.report(p, lp)),
    )
}

impl Live {
    /// `student`'s session, which reports to their teacher-page status.
    pub fn new(student: Arc<Student>, session: PageSession) -> Self {
        let session = reporting(&student, session);
        Live {
            student,
            held: Held::Session(session),
            playing: false,
        }
    }

    /// The world of a step of `student`'s lesson, which reports to their status (its time is
    /// the time on the step).
    pub fn step(student: Arc<Student>, world: StepWorld) -> Self {
        let world = world.map_session(|s| reporting(&student, s));
        Live {
            student,
            held: Held::Step(world),
            playing: false,
        }
    }

    fn session(&self) -> &PageSession {
        match &self.held {
            Held::Session(s) => s,
            Held::Step(w) => &w.session,
        }
    }

    /// Whether it ended (the worker hands it to the finisher).
    pub fn ended(&self) -> bool {
        self.session().ended()
    }

    /// Whether it can begin (its hand is there or its end was asked for) or has begun.
    pub fn ready(&self) -> bool {
        self.session().ready()
    }

    /// Begins it when it is ready, off the worker (see `lobby`).
    pub fn begin(&mut self) {
        match &mut self.held {
            Held::Session(s) => s.begin(),
            Held::Step(w) => w.session.begin(),
        }
    }

    /// Ends it at its next cycle (the class is stopping).
    pub fn request_end(&self) {
        self.session().request_end();
    }

    /// This session's part of worker cycle `k` of `pacer`: one step of the session.
    pub fn cycle(&mut self, k: u64, pacer: &Pacer) {
        let session = match &mut self.held {
            Held::Session(s) => s,
            Held::Step(w) => &mut w.session,
        };
        let step = session.step(&mut Worker { pacer, k });
        if step == Step::Ticked && !self.playing {
            self.playing = true;
            self.student.set_phase(super::Phase::Playing);
        }
    }

    /// Closes the session (on the finisher thread): the statistics, the recording's end, the
    /// publisher's last frame, and the end screen with the recording's download for its pages.
    /// A lesson step's world is handed back to be closed through the student's lesson.
    pub fn finish(self: Box<Self>) -> Finished {
        match self.held {
            Held::Session(s) => {
                let session = s.finish();
                self.student.set_phase(super::Phase::Ended);
                Finished::Session(Box::new(StudentSummary {
                    name: self.student.name.clone(),
                    step: None,
                    session,
                }))
            }
            Held::Step(w) => Finished::Step(self.student, Box::new(w)),
        }
    }
}
