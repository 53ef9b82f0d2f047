//! One student's session in the classroom: the play session ([`PageSession`]) with their page as
//! the hand, ticked by a shared worker on its own cycle ([`Worker`]), and what the teacher page
//! shows of them.

use super::{Student, StudentSummary};
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

/// A student's session as a worker holds it.
pub struct Live {
    /// Who plays it.
    pub student: Arc<Student>,
    session: PageSession,
    playing: bool,
}

impl Live {
    /// `student`'s session, which reports to their teacher-page status every
    /// [`super::STATUS_EVERY_TICKS`] ticks.
    pub fn new(student: Arc<Student>, session: PageSession) -> Self {
        let st = student.clone();
        let session = session.with_reporter(
            super::STATUS_EVERY_TICKS,
            Box::new(move |ticks, missed, lp| st.report(ticks, missed, lp)),
        );
        Live {
            student,
            session,
            playing: false,
        }
    }

    /// Whether it ended (the worker hands it to the finisher).
    pub fn ended(&self) -> bool {
        self.session.ended()
    }

    /// Ends it at its next cycle (the class is stopping).
    pub fn request_end(&self) {
        self.session.request_end();
    }

    /// This session's part of worker cycle `k` of `pacer`: one step of the session.
    pub fn cycle(&mut self, k: u64, pacer: &Pacer) {
        let step = self.session.step(&mut Worker { pacer, k });
        if step == Step::Ticked && !self.playing {
            self.playing = true;
            self.student.set_phase(super::Phase::Playing);
        }
    }

    /// Closes the session (on the finisher thread): the statistics, the recording's end, the
    /// publisher's last frame, and the end screen with the recording's download for its pages.
    pub fn finish(self: Box<Self>) -> StudentSummary {
        let session = self.session.finish();
        self.student.set_phase(super::Phase::Ended);
        StudentSummary {
            name: self.student.name.clone(),
            session,
        }
    }
}
