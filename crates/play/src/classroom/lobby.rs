//! Sessions waiting for their page's Start, begun off the tick workers. A session's start opens
//! its recording (a file, a writer thread, the scene's description) and its pages' publisher (a
//! thread), which takes milliseconds, tens of them on a loaded machine with the memory locked
//! (every new thread's stack is faulted in at once). Begun on a shared worker, it held every
//! other session of that worker past its deadline: in the 30-student bench each start stalled
//! its worker by 7–95 ms, most of the ticks the class missed. So a session waits here until its
//! hand is there, is begun here, and only then goes to the least busy worker.

use super::Class;
use super::live::Live;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::Duration;

/// How often the lobby looks at its waiting sessions: a page's Start is begun within this.
const POLL: Duration = Duration::from_millis(2);

/// The lobby's loop: takes sessions from `inbox`, begins each once its hand is there (or its end
/// was asked for) and hands it to the least busy worker; on `stop` it hands every waiting one
/// over with its end asked for (each then ends at once, with an empty recording) and returns.
pub(super) fn lobby(class: &Arc<Class>, inbox: Receiver<Box<Live>>, stop: &AtomicBool) {
    let mut waiting: Vec<Box<Live>> = Vec::new();
    loop {
        match inbox.recv_timeout(POLL) {
            Ok(l) => waiting.push(l),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                if waiting.is_empty() {
                    return;
                }
            }
        }
        while let Ok(l) = inbox.try_recv() {
            waiting.push(l);
        }
        let stopping = stop.load(Ordering::Relaxed);
        let mut i = 0;
        while i < waiting.len() {
            if stopping {
                waiting[i].request_end();
            }
            if waiting[i].ready() {
                let mut l = waiting.swap_remove(i);
                l.begin();
                // A worker that refuses (the class is shutting down) ends with its sessions.
                let _ = class.to_worker(l);
            } else {
                i += 1;
            }
        }
        if stopping && waiting.is_empty() {
            return;
        }
    }
}
