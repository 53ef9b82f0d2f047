//! Pacing without a thread per student: a few workers (one per core, at most four), each
//! ticking every session it holds once per period, in turn, against one wall-clock schedule.
//! A session's tick `n` runs in its worker's cycle `k0 + n`; its deadline is the start of the
//! next cycle, as [`haptic_engine::timing::Pacer`] counts it for `play` (a missed deadline
//! sends zero force and is recorded, so the session still replays bit for bit). A session that
//! ended leaves its worker for the finisher thread, which closes its recording and tells its
//! pages, so ending never delays the others' ticks.

use super::live::Live;
use haptic_engine::realtime::{self, RtRequest, RtStatus};
use haptic_engine::timing::Pacer;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::time::Duration;

/// How long a worker spins before each cycle (the rest it sleeps): its sessions' deadlines are
/// a whole period away, so the cores go to the other workers and the pages instead.
const SPIN: Duration = Duration::from_micros(20);

/// One worker's loop: asks for real time (`rt`), takes new sessions from `inbox`, ticks every
/// session each cycle, hands ended ones to `finished`; on `stop` it ends every session and
/// returns what real time it got.
pub(crate) fn worker(
    inbox: Receiver<Box<Live>>,
    finished: Sender<Box<Live>>,
    period_ns: u64,
    load: Arc<AtomicUsize>,
    stop: Arc<AtomicBool>,
    rt: Option<RtRequest>,
) -> RtStatus {
    let guard = realtime::enter_if(rt.as_ref());
    realtime::advise_once(&guard.status());
    run_worker(inbox, finished, period_ns, load, stop);
    guard.status()
}

fn run_worker(
    inbox: Receiver<Box<Live>>,
    finished: Sender<Box<Live>>,
    period_ns: u64,
    load: Arc<AtomicUsize>,
    stop: Arc<AtomicBool>,
) {
    let mut pacer = Pacer::with_spin(period_ns, SPIN);
    let mut k: u64 = 0;
    let mut lives: Vec<Box<Live>> = Vec::new();
    loop {
        if lives.is_empty() {
            // Idle: wait for a session without spinning, then start a fresh schedule.
            match inbox.recv_timeout(Duration::from_millis(50)) {
                Ok(l) => lives.push(l),
                Err(RecvTimeoutError::Timeout) if !stop.load(Ordering::Relaxed) => continue,
                Err(_) => return,
            }
            pacer = Pacer::with_spin(period_ns, SPIN);
            k = 0;
        }
        while let Ok(l) = inbox.try_recv() {
            lives.push(l);
        }
        let stopping = stop.load(Ordering::Relaxed);
        pacer.wait_for(k);
        for l in lives.iter_mut() {
            if stopping {
                l.request_end();
            }
            l.cycle(k, &pacer);
        }
        let mut i = 0;
        while i < lives.len() {
            if lives[i].ended() {
                let l = lives.swap_remove(i);
                load.fetch_sub(1, Ordering::Relaxed);
                if finished.send(l).is_err() {
                    return;
                }
            } else {
                i += 1;
            }
        }
        k += 1;
    }
}
