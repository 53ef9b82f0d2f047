//! Stopping long work on request: a caller (the Python wheel, on Ctrl-C) runs work under
//! [`watch`] with a flag; every flow of a [`crate::flow::Propagator`] on that thread checks
//! the flag first and returns [`PhysicsError::Interrupted`] once it is raised, so an
//! envelope, inverse or steering call made of hundreds of flows ends within one flow.
//!
//! Not for the haptic loop: a tick is never interrupted (the session stops between ticks).
//! The check is one thread-local load when nothing is watched.

use crate::error::{PhysicsError, Result};
use std::cell::{Cell, RefCell};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

thread_local! {
    static WATCHING: Cell<bool> = const { Cell::new(false) };
    static FLAG: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// Runs `work` on this thread with `flag` watched: flows return
/// [`PhysicsError::Interrupted`] once `flag` is true. The previous watch (if any) is restored
/// afterwards, also when `work` panics.
pub fn watch<T>(flag: Arc<AtomicBool>, work: impl FnOnce() -> T) -> T {
    struct Restore(Option<Arc<AtomicBool>>, bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            let prev = self.0.take();
            FLAG.with(|f| *f.borrow_mut() = prev);
            WATCHING.with(|w| w.set(self.1));
        }
    }
    let prev = FLAG.with(|f| f.borrow_mut().replace(flag));
    let _restore = Restore(prev, WATCHING.with(|w| w.replace(true)));
    work()
}

/// `Err(Interrupted)` when the watched flag of this thread is raised.
pub fn check() -> Result<()> {
    if !WATCHING.with(Cell::get) {
        return Ok(());
    }
    let raised = FLAG.with(|f| {
        f.borrow()
            .as_ref()
            .is_some_and(|a| a.load(Ordering::Relaxed))
    });
    if raised {
        Err(PhysicsError::Interrupted)
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Method, Propagator, TrapModel};
    use nalgebra::Vector2;

    #[test]
    fn a_raised_flag_stops_flows_on_this_thread_only_while_watched() {
        let model = TrapModel::<2>::builder(1e-18, [600e-9, 300e-9])
            .mass(1e-15)
            .build()
            .expect("model");
        let prop = Propagator::new(model, Method::Rk4 { substeps: 8 }, 1e-6).expect("prop");
        let (o, v) = (Vector2::new(1e-7, 0.0), Vector2::zeros());
        let flag = Arc::new(AtomicBool::new(false));
        let ok = watch(flag.clone(), || prop.flow(&o, &v));
        assert!(ok.is_ok());
        flag.store(true, Ordering::Relaxed);
        let stopped = watch(flag.clone(), || prop.flow(&o, &v));
        assert_eq!(stopped.unwrap_err(), PhysicsError::Interrupted);
        // Another thread, and this one after the watch, are not affected.
        let other = std::thread::scope(|s| s.spawn(|| prop.flow(&o, &v).is_ok()).join());
        assert!(matches!(other, Ok(true)));
        assert!(prop.flow(&o, &v).is_ok());
    }
}
