//! One student's session in the classroom: their world, their page as the hand, their
//! recording, their pages' publisher, and what the teacher page shows of them. The worker
//! ticks it through the loop's one [`TickEngine`], as `play` does through the runner.

use super::Student;
use crate::input::PageDevice;
use crate::protocol::LatencyMs;
use crate::publish::{self, PlaySink, PublishSummary, ToPublisher};
use crate::{apply_page_switches, end_message, offer_end};
use haptic_devices::pacing::Pacer;
use haptic_loop::HapticLoop;
use haptic_loop::header::SessionHeader;
use haptic_loop::runner::{EndReason, TickEngine, TickStart};
use haptic_loop::sinks::SessionSinks;
use haptic_types::{HapticDevice, TickTime};
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::Sender;
use std::thread::JoinHandle;
use std::time::Instant;

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
    lp: HapticLoop,
    header: SessionHeader,
    sinks: SessionSinks,
    play_sink: PlaySink,
    device: PageDevice,
    engine: TickEngine,
    ticks_planned: Option<u64>,
    started: bool,
    ended: bool,
    end: EndReason,
    tx: Sender<ToPublisher>,
    publisher: Option<JoinHandle<PublishSummary>>,
    prox: Option<f64>,
    fields: Vec<String>,
    error: Option<String>,
}

impl Live {
    /// A session of `student` with the world, header and sinks of its set-up, ending after
    /// `ticks_planned` ticks (`None`: when the student or the teacher ends it).
    pub fn new(
        student: Arc<Student>,
        lp: HapticLoop,
        header: SessionHeader,
        sinks: SessionSinks,
        device: PageDevice,
        ticks_planned: Option<u64>,
    ) -> Self {
        let (tx, _) = std::sync::mpsc::channel();
        let play_sink = PlaySink::new(tx.clone(), student.shared.clone());
        let fields = lp.scene().state_fields();
        let prox = haptic_loop::sound::proximity_on_distance_m(lp.scene().kind())
            .filter(|_| fields.iter().any(|f| f == "nearest_m"));
        Live {
            student,
            lp,
            header,
            sinks,
            play_sink,
            device,
            engine: TickEngine::new(Vec::new()),
            ticks_planned,
            started: false,
            ended: false,
            end: EndReason::Completed,
            tx,
            publisher: None,
            prox,
            fields,
            error: None,
        }
    }

    /// Whether it ended (the worker hands it to the finisher).
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// Ends it at its next cycle (the class is stopping).
    pub fn request_end(&self) {
        self.student
            .shared
            .end_requested
            .store(true, Ordering::Relaxed);
    }

    fn start(&mut self) {
        let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
        let sh = self.student.shared.clone();
        let rate = self.lp.config().rate_hz;
        let (fields, prox) = (self.fields.clone(), self.prox);
        self.publisher = std::thread::Builder::new()
            .name("class-publish".into())
            .spawn(move || publish::run_publisher(rx, sh, rate, fields, prox))
            .ok();
        self.play_sink = PlaySink::new(tx.clone(), self.student.shared.clone());
        self.tx = tx;
        let mut list = self.sinks.list();
        list.push(&mut self.play_sink);
        if let Err(e) =
            self.engine
                .start(&mut list, &self.lp, &self.header, self.ticks_planned, true)
        {
            self.error = Some(e.to_string());
            self.ended = true;
        }
        self.started = true;
        self.student.set_phase(Phase::Playing);
    }

    /// This session's part of worker cycle `k`: starts it once its page's hand arrived, runs
    /// one tick, or ends it.
    pub fn cycle(&mut self, k: u64, pacer: &Pacer) {
        if self.ended {
            return;
        }
        let shared = self.student.shared.clone();
        let end_asked = shared.end_requested.load(Ordering::Relaxed);
        if !self.started {
            if end_asked {
                // Ended before it began: an empty recording, complete and verifiable.
                self.start();
                self.end = EndReason::Stopped;
                self.ended = true;
                return;
            }
            if shared.input.latest().1.is_none() {
                return;
            }
            self.start();
        }
        let n = self.engine.ticks();
        if self.ticks_planned.is_some_and(|t| n >= t) {
            self.end = EndReason::Completed;
            self.ended = true;
            return;
        }
        if end_asked {
            self.end = EndReason::Stopped;
            self.ended = true;
            return;
        }
        let rate = self.lp.config().rate_hz;
        let sample = match self.device.sample(TickTime::new(n, rate)) {
            Ok(s) => s,
            Err(e) => {
                self.error = Some(e.to_string());
                self.ended = true;
                return;
            }
        };
        let t0 = Instant::now();
        let late = t0
            .checked_duration_since(pacer.scheduled(k))
            .map_or(0, |d| d.as_nanos() as i64);
        let tx = self.tx.clone();
        let mut hook = |tick: u64, lp: &mut HapticLoop| apply_page_switches(&shared, &tx, tick, lp);
        let device = &mut self.device;
        let mut deadline = |_: u64, _: Instant| pacer.deadline_passed(k);
        let mut send = |lp: &HapticLoop, seq: u64| device.set_force(&lp.command(seq));
        let mut list = self.sinks.list();
        list.push(&mut self.play_sink);
        let r = self.engine.tick(
            &mut list,
            &mut self.lp,
            sample,
            TickStart {
                t0,
                late_ns: late,
                recorded_missed: false,
            },
            Some(&mut hook),
            &mut deadline,
            &mut send,
        );
        if let Err(e) = r {
            self.error = Some(e.to_string());
            self.ended = true;
            return;
        }
        if n % super::STATUS_EVERY_TICKS == 0 {
            self.student.report(n + 1, self.engine.missed(), &self.lp);
        }
    }

    /// Closes the session (on the finisher thread): the statistics, the recording's end, the
    /// publisher's last frame, and the end screen with the recording's download for its pages.
    pub fn finish(mut self: Box<Self>) -> super::StudentSummary {
        let ticks = self.engine.ticks();
        self.student.report(ticks, self.engine.missed(), &self.lp);
        let link = self.device.link_counters();
        let mut list = self.sinks.list();
        list.push(&mut self.play_sink);
        let stats = self.engine.finish(&mut list, &link);
        drop(list);
        let latencies = std::mem::take(&mut self.play_sink.input_latency_ms);
        let (dead_tx, _) = std::sync::mpsc::channel();
        self.play_sink = PlaySink::new(dead_tx.clone(), self.student.shared.clone());
        self.tx = dead_tx;
        let published = self
            .publisher
            .take()
            .and_then(|h| h.join().ok())
            .unwrap_or_default();
        let written = self.sinks.written();
        let input_latency_ms = LatencyMs::of(&latencies);
        let student = self.student.clone();
        let rate = self.lp.config().rate_hz;
        let error = self
            .error
            .take()
            .or(stats.as_ref().err().map(|e| e.to_string()));
        let stats = stats.unwrap_or_default();
        let url = format!("/recording.mcap?s={}", student.token);
        let end_msg = end_message(
            &url,
            &student.out,
            self.end,
            &stats,
            rate,
            &self.sinks.totals,
            input_latency_ms,
            written.as_ref(),
        );
        offer_end(&student.shared, &student.out, &end_msg);
        student.set_phase(Phase::Ended);
        super::StudentSummary {
            name: student.name.clone(),
            end: self.end.name(),
            stats,
            state: self.sinks.totals.state(),
            recording: student.out.clone(),
            written,
            input_latency_ms,
            published,
            error,
        }
    }
}
