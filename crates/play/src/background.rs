//! The servers' background threads (publishers, page connections) give way to the ticks: each
//! lowers its own priority to nice +5 on start, so under load a session's tick is scheduled
//! before its frames, sound and page traffic. On Linux the nice value is per thread and raising
//! it needs no privilege; elsewhere this does nothing.

/// The nice value of a background thread (0 is the default; higher yields more).
pub const BACKGROUND_NICE: i32 = 5;

/// Lowers the calling thread's priority to [`BACKGROUND_NICE`] (best effort: a refusal leaves
/// it as it was).
#[allow(unsafe_code)] // one libc call on the calling thread, no memory involved
pub fn lower_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: setpriority(PRIO_PROCESS, 0, n) changes only the calling thread's nice value.
    unsafe {
        let _ = libc::setpriority(libc::PRIO_PROCESS, 0, BACKGROUND_NICE);
    }
}

#[cfg(test)]
mod tests {
    #[test]
    #[cfg(target_os = "linux")]
    fn a_background_thread_runs_at_nice_5_and_others_keep_theirs() {
        let nice_of_thread = || {
            let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap();
            // Field 19 of stat is the nice value (counted after the command's parenthesis).
            let after = stat.rsplit(')').next().unwrap();
            after
                .split_whitespace()
                .nth(16)
                .unwrap()
                .parse::<i32>()
                .unwrap()
        };
        let before = nice_of_thread();
        let bg = std::thread::spawn(move || {
            super::lower_priority();
            nice_of_thread()
        })
        .join()
        .unwrap();
        assert_eq!(bg, super::BACKGROUND_NICE.max(before));
        assert_eq!(nice_of_thread(), before, "the calling thread is unchanged");
    }
}
