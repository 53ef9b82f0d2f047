//! Long calls that Ctrl-C can stop: the work runs on a worker thread with the GIL released
//! while the calling thread waits for it and checks for Python signals every 50 ms.

use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::time::Duration;

/// How often the waiting thread checks for signals.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work(stop)` on a worker thread without the GIL. When a signal handler raises (Ctrl-C
/// raises `KeyboardInterrupt`), `stop` is set; `work` must end soon after it sees `stop` (a
/// session ends after its current tick, with its recording finished), and the exception is
/// raised once it has. Without a signal, returns what `work` returned.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let done = (Mutex::new(false), Condvar::new());
    std::thread::scope(|s| {
        let (stop_ref, done_ref) = (&stop, &done);
        let worker = s.spawn(move || {
            // Signal completion even if `work` panics (the panic is re-raised at the join).
            struct Done<'a>(&'a (Mutex<bool>, Condvar));
            impl Drop for Done<'_> {
                fn drop(&mut self) {
                    *self.0.0.lock().unwrap_or_else(PoisonError::into_inner) = true;
                    self.0.1.notify_all();
                }
            }
            let _done = Done(done_ref);
            work(stop_ref)
        });
        let mut raised: Option<PyErr> = None;
        loop {
            let finished = py.detach(|| {
                let g = done.0.lock().unwrap_or_else(PoisonError::into_inner);
                let (g, _) = done
                    .1
                    .wait_timeout_while(g, POLL, |d| !*d)
                    .unwrap_or_else(PoisonError::into_inner);
                *g
            });
            if finished {
                break;
            }
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                stop.store(true, Ordering::Relaxed);
                raised = Some(e);
            }
        }
        let out = match worker.join() {
            Ok(v) => v,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        match raised {
            Some(e) => Err(e),
            None => Ok(out),
        }
    })
}

/// [`interruptible`] for optical-tweezers work made of many flows (envelopes, the inverse
/// solver, steering): every flow checks the flag, so Ctrl-C ends the call within one flow.
pub(crate) fn interruptible_flows<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send,
) -> PyResult<T> {
    interruptible(py, |stop| ot_physics::cancel::watch(Arc::clone(stop), work))
}
