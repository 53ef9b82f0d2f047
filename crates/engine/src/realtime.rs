//! Real-time scheduling for a tick thread: `SCHED_FIFO` at a chosen priority, memory locked
//! (`mlockall`), the thread pinned to one core, and an honest account of what the system
//! granted ([`RtStatus`]) with the fix when it refused ([`RtStatus::advice`]).
//!
//! The set-up is the one every tick thread uses: the runner's (`run`, `play`, the wheel's
//! real-time sessions), the classroom's workers and `nanohaptics doctor`. It asks; it never
//! insists. When the system refuses (no `CAP_SYS_NICE` and `RLIMIT_RTPRIO` 0, a container, a
//! cgroup with no real-time runtime) the thread runs at normal priority exactly as before, and
//! the status says which part was refused and why.
//!
//! What it deliberately leaves alone: the kernel's real-time throttling
//! (`/proc/sys/kernel/sched_rt_runtime_us`, 95 % by default) stays on, so a runaway tick thread
//! can never take a whole core; and the threads the tick thread starts run at normal priority
//! (`SCHED_RESET_ON_FORK`): the recorder, the publisher, the live view and the receivers
//! never inherit real-time priority.
//!
//! Not for: the sleeping itself ([`Pacer`](crate::timing::Pacer), which sleeps to absolute
//! deadlines with `clock_nanosleep`), or choosing the rate.
//!
//! ```
//! use haptic_engine::realtime::{RtRequest, enter};
//! // Ask for SCHED_FIFO 50, locked memory and a core of its own; whatever the answer, the
//! // thread goes on (restored to what it was when the guard drops).
//! let guard = enter(&RtRequest::default());
//! let st = guard.status();
//! assert!(st.requested);
//! if st.priority.is_none() {
//!     // Refused: `advice` says why and what to change.
//!     assert!(st.advice().is_some());
//! }
//! drop(guard);
//! ```

use std::marker::PhantomData;
use std::sync::atomic::{AtomicBool, Ordering};
use world_form::ValueError;

/// The default `SCHED_FIFO` priority of a tick thread: ros2_control's choice, below the
/// kernel's own watchdogs (99) and equal to a PREEMPT_RT kernel's threaded interrupts (50),
/// so a network card's interrupt still delivers a bridged device's packets.
pub const DEFAULT_PRIORITY: u8 = 50;

/// What a tick thread asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RtRequest {
    /// `SCHED_FIFO` priority, 1–99.
    pub priority: u8,
    /// Lock the process's memory (`mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT)`): no page
    /// is paged out once touched, and locking populates nothing (a page faults in once, at its
    /// first touch), so its cost does not grow with what the allocator keeps: a tick faults no
    /// page it touched before. Only tried where it cannot make a later allocation fail (a process with
    /// `CAP_IPC_LOCK` or an unlimited `RLIMIT_MEMLOCK`).
    pub lock_memory: bool,
    /// Pin the thread to one core (the last it may run on) when it may run on more than one.
    pub pin: bool,
}

impl Default for RtRequest {
    fn default() -> Self {
        RtRequest {
            priority: DEFAULT_PRIORITY,
            lock_memory: true,
            pin: true,
        }
    }
}

impl RtRequest {
    /// A request at `priority` (1–99), memory locked and the thread pinned.
    pub fn with_priority(priority: i64) -> Result<Self, ValueError> {
        if !(1..=99).contains(&priority) {
            return Err(ValueError::out_of_range(
                "rt-priority",
                priority as f64,
                "1 to 99",
            ));
        }
        Ok(RtRequest {
            priority: priority as u8,
            ..RtRequest::default()
        })
    }
}

/// Why a part of the request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Refusal {
    /// No `CAP_SYS_NICE` and `RLIMIT_RTPRIO` below the priority asked for.
    NoPermission,
    /// Permitted, yet refused: the process's cgroup gives real-time tasks no runtime (a
    /// container), or a security module said no.
    NoRuntime,
    /// Memory not locked: no `CAP_IPC_LOCK` and a finite `RLIMIT_MEMLOCK`, where locking all
    /// future allocations could make one fail.
    MemlockLimit,
    /// This operating system has no such call (only Linux is supported).
    Unsupported,
    /// Another error from the system, by its errno.
    Errno(i32),
}

impl Refusal {
    /// The reason in words.
    pub fn reason(self) -> String {
        match self {
            Refusal::NoPermission => {
                "no CAP_SYS_NICE, and RLIMIT_RTPRIO is below the priority asked for".into()
            }
            Refusal::NoRuntime => {
                "permitted, but the system gives real-time tasks no run time here, as in a \
                 container or a cgroup with cpu.rt_runtime_us 0"
                    .into()
            }
            Refusal::MemlockLimit => {
                "no CAP_IPC_LOCK, and RLIMIT_MEMLOCK is finite, so locking every future \
                 allocation could make one fail"
                    .into()
            }
            Refusal::Unsupported => "real-time scheduling is only supported on Linux".into(),
            Refusal::Errno(e) => format!("the system answered errno {e}"),
        }
    }
}

/// What the tick thread got: written to the run's summary and to the recording's `session`
/// metadata (`rt_*` keys).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RtStatus {
    /// Real time was asked for (false with `--no-rt`, and in batch runs).
    pub requested: bool,
    /// The `SCHED_FIFO` priority granted; `None`: the normal scheduler.
    pub priority: Option<u8>,
    /// Memory locked with `mlockall`.
    pub memory_locked: bool,
    /// The core the thread is pinned to.
    pub cpu: Option<u16>,
    /// Why `SCHED_FIFO` was refused.
    pub sched_refused: Option<Refusal>,
    /// Why the memory was not locked.
    pub lock_refused: Option<Refusal>,
}

impl RtStatus {
    /// The scheduler in one word: `fifo`, `normal` (refused) or `off` (not asked for).
    pub fn policy(&self) -> &'static str {
        match (self.requested, self.priority) {
            (_, Some(_)) => "fifo",
            (true, None) => "normal",
            (false, None) => "off",
        }
    }

    /// One line for a summary: `SCHED_FIFO 50, memory locked, pinned to CPU 1`, or what was
    /// refused.
    pub fn describe(&self) -> String {
        if !self.requested {
            return "off (normal scheduling)".into();
        }
        let mut parts = Vec::new();
        match (self.priority, self.sched_refused) {
            (Some(p), _) => parts.push(format!("SCHED_FIFO {p}")),
            (None, Some(r)) => parts.push(format!(
                "normal priority, SCHED_FIFO refused: {}",
                r.reason()
            )),
            (None, None) => parts.push("normal priority".into()),
        }
        match (self.memory_locked, self.lock_refused) {
            (true, _) => parts.push("memory locked".into()),
            (false, Some(r)) => parts.push(format!("memory not locked: {}", r.reason())),
            (false, None) => {}
        }
        if let Some(c) = self.cpu {
            parts.push(format!("pinned to CPU {c}"));
        }
        parts.join(", ")
    }

    /// When something asked for was refused: what happened and how to allow it. `None` when
    /// everything asked for was granted (or nothing was asked).
    pub fn advice(&self) -> Option<String> {
        if !self.requested || (self.sched_refused.is_none() && self.lock_refused.is_none()) {
            return None;
        }
        let mut s = String::from("real time: ");
        s.push_str(&self.describe());
        s.push_str(
            ". The session runs as without real time, its deadlines at the mercy of whatever \
             else runs. To allow it: ",
        );
        let fix = match (self.sched_refused, self.lock_refused) {
            (Some(Refusal::NoRuntime), _) => {
                "give the container real-time run time (docker run --cap-add SYS_NICE \
                 --ulimit rtprio=95 --cpu-rt-runtime=950000, with the daemon's \
                 --cpu-rt-runtime set), or run on the host"
            }
            (Some(Refusal::Unsupported), _) => "run on Linux",
            _ => {
                "add `@audio - rtprio 95` and `@audio - memlock unlimited` to \
                 /etc/security/limits.conf and put your user in the audio group (log in \
                 again), or `sudo setcap cap_sys_nice,cap_ipc_lock+ep $(command -v nanohaptics)`, \
                 or run it under rtkit"
            }
        };
        s.push_str(fix);
        s.push_str(". --no-rt turns the request off.");
        Some(s)
    }

    /// The status as the recording's `session` metadata keys.
    pub fn metadata(&self) -> Vec<(&'static str, String)> {
        let opt = |v: Option<String>| v.unwrap_or_else(|| "none".into());
        vec![
            ("rt_policy", self.policy().into()),
            ("rt_priority", opt(self.priority.map(|p| p.to_string()))),
            ("rt_memory_locked", self.memory_locked.to_string()),
            ("rt_cpu", opt(self.cpu.map(|c| c.to_string()))),
            (
                "rt_refused",
                opt(self.sched_refused.or(self.lock_refused).map(|r| r.reason())),
            ),
        ]
    }
}

static ADVISED: AtomicBool = AtomicBool::new(false);

/// Prints `status.advice()` to standard error the first time a refusal happens in this
/// process (a classroom's workers or a sweep of sessions say it once); true when it printed.
pub fn advise_once(status: &RtStatus) -> bool {
    match status.advice() {
        Some(a) if !ADVISED.swap(true, Ordering::Relaxed) => {
            eprintln!("nanohaptics: {a}");
            true
        }
        _ => false,
    }
}

/// The calling thread in real time for as long as it lives; dropping it puts the thread back
/// as it was (scheduler, priority, cores) and unlocks memory it locked. Not `Send`: it must be
/// dropped on the thread it set up.
#[derive(Debug)]
pub struct RtGuard {
    status: RtStatus,
    #[cfg(target_os = "linux")]
    saved: Option<sys::Saved>,
    _thread: PhantomData<*const ()>,
}

impl RtGuard {
    /// What was granted.
    pub fn status(&self) -> RtStatus {
        self.status
    }

    /// A guard that asked for nothing (`--no-rt`, batch runs).
    pub fn off() -> Self {
        RtGuard {
            status: RtStatus::default(),
            #[cfg(target_os = "linux")]
            saved: None,
            _thread: PhantomData,
        }
    }
}

/// Puts the calling thread in real time as far as the system allows (see the module doc).
pub fn enter(req: &RtRequest) -> RtGuard {
    #[cfg(target_os = "linux")]
    {
        let (status, saved) = sys::enter(req);
        RtGuard {
            status,
            saved: Some(saved),
            _thread: PhantomData,
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = req;
        RtGuard {
            status: RtStatus {
                requested: true,
                sched_refused: Some(Refusal::Unsupported),
                lock_refused: req.lock_memory.then_some(Refusal::Unsupported),
                ..RtStatus::default()
            },
            _thread: PhantomData,
        }
    }
}

/// `enter(req)` when `req` is given, else [`RtGuard::off`].
pub fn enter_if(req: Option<&RtRequest>) -> RtGuard {
    req.map_or_else(RtGuard::off, enter)
}

impl Drop for RtGuard {
    fn drop(&mut self) {
        #[cfg(target_os = "linux")]
        if let Some(saved) = self.saved.take() {
            sys::restore(&self.status, saved);
        }
    }
}

/// What the system allows this process, as `nanohaptics doctor` reports it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Permissions {
    /// `CAP_SYS_NICE` is effective (any real-time priority allowed).
    pub cap_sys_nice: bool,
    /// `CAP_IPC_LOCK` is effective (memory may be locked without limit).
    pub cap_ipc_lock: bool,
    /// `RLIMIT_RTPRIO`'s soft limit (the highest priority allowed without the capability).
    pub rlimit_rtprio: Option<u64>,
    /// `RLIMIT_MEMLOCK`'s soft limit, bytes; `None`: unlimited.
    pub rlimit_memlock_bytes: Option<u64>,
    /// `/proc/sys/kernel/sched_rt_runtime_us` (−1: real-time throttling off), µs per
    /// `sched_rt_period_us`.
    pub rt_runtime_us: Option<i64>,
    /// The kernel's preemption model, from `uname -v` (`PREEMPT_RT`, `PREEMPT_DYNAMIC`,
    /// `PREEMPT` or `none`).
    pub preemption: String,
    /// Cores this process may run on.
    pub cores: usize,
}

/// What the system allows this process.
pub fn permissions() -> Permissions {
    #[cfg(target_os = "linux")]
    {
        sys::permissions()
    }
    #[cfg(not(target_os = "linux"))]
    {
        Permissions {
            cap_sys_nice: false,
            cap_ipc_lock: false,
            rlimit_rtprio: None,
            rlimit_memlock_bytes: None,
            rt_runtime_us: None,
            preemption: "unknown".into(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// The calling thread's scheduler: its `SCHED_FIFO` priority, `None` for any other policy.
pub fn current_fifo_priority() -> Option<u8> {
    #[cfg(target_os = "linux")]
    {
        sys::current_fifo_priority()
    }
    #[cfg(not(target_os = "linux"))]
    {
        None
    }
}

#[cfg(target_os = "linux")]
mod sys {
    //! The Linux calls. Every `unsafe` block is a plain libc call on this thread with
    //! arguments that live on the stack for the call's duration.
    use super::{Permissions, Refusal, RtRequest, RtStatus};

    /// The thread's scheduling before `enter`.
    #[derive(Debug)]
    pub(super) struct Saved {
        policy: libc::c_int,
        param: libc::sched_param,
        affinity: Option<libc::cpu_set_t>,
    }

    const CAP_SYS_NICE: u32 = 23;
    const CAP_IPC_LOCK: u32 = 14;

    #[allow(unsafe_code)]
    fn effective_caps() -> u64 {
        #[repr(C)]
        struct Header {
            version: u32,
            pid: i32,
        }
        #[repr(C)]
        #[derive(Clone, Copy, Default)]
        struct Data {
            effective: u32,
            permitted: u32,
            inheritable: u32,
        }
        let mut h = Header {
            version: 0x2008_0522, // _LINUX_CAPABILITY_VERSION_3
            pid: 0,
        };
        let mut d = [Data::default(); 2];
        // SAFETY: capget(2) reads two Data blocks for version 3 into `d`, which has two.
        let r = unsafe { libc::syscall(libc::SYS_capget, &mut h as *mut Header, d.as_mut_ptr()) };
        if r != 0 {
            return 0;
        }
        u64::from(d[0].effective) | (u64::from(d[1].effective) << 32)
    }

    fn has_cap(bit: u32) -> bool {
        effective_caps() >> bit & 1 == 1
    }

    #[allow(unsafe_code)]
    fn rlimit(res: libc::__rlimit_resource_t) -> Option<u64> {
        let mut r = libc::rlimit {
            rlim_cur: 0,
            rlim_max: 0,
        };
        // SAFETY: getrlimit writes one rlimit into `r`.
        if unsafe { libc::getrlimit(res, &mut r) } != 0 || r.rlim_cur == libc::RLIM_INFINITY {
            return None;
        }
        Some(r.rlim_cur)
    }

    fn errno() -> i32 {
        std::io::Error::last_os_error().raw_os_error().unwrap_or(0)
    }

    #[allow(unsafe_code)]
    pub(super) fn current_fifo_priority() -> Option<u8> {
        // SAFETY: queries of the calling thread (pid 0), writing into a local sched_param.
        let policy = unsafe { libc::sched_getscheduler(0) };
        if policy & !libc::SCHED_RESET_ON_FORK != libc::SCHED_FIFO {
            return None;
        }
        let mut p = libc::sched_param { sched_priority: 0 };
        // SAFETY: as above.
        if unsafe { libc::sched_getparam(0, &mut p) } != 0 {
            return None;
        }
        u8::try_from(p.sched_priority).ok()
    }

    #[allow(unsafe_code)]
    pub(super) fn enter(req: &RtRequest) -> (RtStatus, Saved) {
        let mut st = RtStatus {
            requested: true,
            ..RtStatus::default()
        };
        // SAFETY: queries of the calling thread, writing into locals.
        let saved = unsafe {
            let policy = libc::sched_getscheduler(0);
            let mut param = libc::sched_param { sched_priority: 0 };
            libc::sched_getparam(0, &mut param);
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            let affinity =
                (libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) == 0)
                    .then_some(set);
            Saved {
                policy,
                param,
                affinity,
            }
        };
        // SCHED_FIFO, with threads this one starts reset to the normal scheduler.
        let param = libc::sched_param {
            sched_priority: i32::from(req.priority),
        };
        // SAFETY: sets the calling thread's policy from a local sched_param.
        let r = unsafe {
            libc::sched_setscheduler(0, libc::SCHED_FIFO | libc::SCHED_RESET_ON_FORK, &param)
        };
        if r == 0 {
            st.priority = Some(req.priority);
        } else {
            let e = errno();
            st.sched_refused = Some(if e == libc::EPERM {
                let allowed = has_cap(CAP_SYS_NICE)
                    || rlimit(libc::RLIMIT_RTPRIO).is_none_or(|l| l >= u64::from(req.priority));
                if allowed {
                    Refusal::NoRuntime
                } else {
                    Refusal::NoPermission
                }
            } else {
                Refusal::Errno(e)
            });
        }
        if req.lock_memory {
            if has_cap(CAP_IPC_LOCK) || rlimit(libc::RLIMIT_MEMLOCK).is_none() {
                // MCL_ONFAULT: lock pages as they are touched, never populate them here (the
                // allocator's kept memory made a lock that populated it take 250 ms in the
                // wheel, long enough for a bridged device's first samples to be lost).
                // SAFETY: mlockall takes flags only.
                if unsafe {
                    libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE | libc::MCL_ONFAULT)
                } == 0
                {
                    st.memory_locked = true;
                } else {
                    st.lock_refused = Some(Refusal::Errno(errno()));
                }
            } else {
                st.lock_refused = Some(Refusal::MemlockLimit);
            }
        }
        // Pinned only with SCHED_FIFO: at normal priority a pinned thread could not move away
        // from a busy core.
        if req.pin
            && st.priority.is_some()
            && let Some(set) = saved.affinity
        {
            // SAFETY: CPU_COUNT/CPU_ISSET read a local cpu_set_t.
            let allowed: Vec<usize> = (0..libc::CPU_SETSIZE as usize)
                .filter(|&c| unsafe { libc::CPU_ISSET(c, &set) })
                .collect();
            if allowed.len() > 1
                && let Some(&last) = allowed.last()
            {
                // SAFETY: builds a local set with one CPU and applies it to this thread.
                let ok = unsafe {
                    let mut one: libc::cpu_set_t = std::mem::zeroed();
                    libc::CPU_SET(last, &mut one);
                    libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &one) == 0
                };
                if ok {
                    st.cpu = u16::try_from(last).ok();
                }
            }
        }
        (st, saved)
    }

    #[allow(unsafe_code)]
    pub(super) fn restore(st: &RtStatus, saved: Saved) {
        // SAFETY: restores this thread's own saved settings from locals.
        unsafe {
            if st.priority.is_some() {
                libc::sched_setscheduler(0, saved.policy, &saved.param);
            }
            if st.cpu.is_some()
                && let Some(set) = saved.affinity
            {
                libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
            }
            if st.memory_locked {
                libc::munlockall();
            }
        }
    }

    pub(super) fn permissions() -> Permissions {
        let read = |p: &str| std::fs::read_to_string(p).ok();
        let version = read("/proc/sys/kernel/version").unwrap_or_default();
        let preemption = ["PREEMPT_RT", "PREEMPT_DYNAMIC", "PREEMPT"]
            .into_iter()
            .find(|k| version.contains(k))
            .unwrap_or("none")
            .to_string();
        Permissions {
            cap_sys_nice: has_cap(CAP_SYS_NICE),
            cap_ipc_lock: has_cap(CAP_IPC_LOCK),
            rlimit_rtprio: rlimit(libc::RLIMIT_RTPRIO),
            rlimit_memlock_bytes: rlimit(libc::RLIMIT_MEMLOCK),
            rt_runtime_us: read("/proc/sys/kernel/sched_rt_runtime_us")
                .and_then(|s| s.trim().parse().ok()),
            preemption,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// docs/realtime.md: `SCHED_FIFO` priority 50 by default, memory locked, the thread pinned.
    #[test]
    fn the_default_request_is_fifo_50_locked_and_pinned() {
        assert_eq!(DEFAULT_PRIORITY, 50);
        assert_eq!(
            RtRequest::default(),
            RtRequest {
                priority: 50,
                lock_memory: true,
                pin: true,
            }
        );
    }

    #[test]
    fn priority_outside_1_to_99_is_refused_by_name() {
        assert_eq!(RtRequest::with_priority(80).map(|r| r.priority), Ok(80));
        let e = RtRequest::with_priority(0).unwrap_err().to_string();
        assert_eq!(e, "rt-priority = 0 is out of range: allowed 1 to 99");
        assert!(RtRequest::with_priority(100).is_err());
    }

    #[test]
    fn advice_names_the_fix_only_when_something_was_refused() {
        let granted = RtStatus {
            requested: true,
            priority: Some(50),
            memory_locked: true,
            cpu: Some(1),
            ..RtStatus::default()
        };
        assert_eq!(granted.advice(), None);
        assert_eq!(granted.policy(), "fifo");
        assert_eq!(
            granted.describe(),
            "SCHED_FIFO 50, memory locked, pinned to CPU 1"
        );
        let refused = RtStatus {
            requested: true,
            sched_refused: Some(Refusal::NoPermission),
            lock_refused: Some(Refusal::MemlockLimit),
            ..RtStatus::default()
        };
        let a = refused.advice().unwrap();
        assert!(
            a.contains("rtprio 95") && a.contains("setcap cap_sys_nice"),
            "{a}"
        );
        assert!(a.contains("--no-rt"), "{a}");
        assert_eq!(refused.policy(), "normal");
        let md: std::collections::BTreeMap<_, _> = refused.metadata().into_iter().collect();
        assert_eq!(md["rt_policy"], "normal");
        assert_eq!(md["rt_priority"], "none");
        assert_eq!(RtStatus::default().policy(), "off");
        assert_eq!(RtStatus::default().advice(), None);
        let container = RtStatus {
            requested: true,
            sched_refused: Some(Refusal::NoRuntime),
            ..RtStatus::default()
        };
        assert!(container.advice().unwrap().contains("--cap-add SYS_NICE"));
        // docs/realtime.md's container fix, to the figure.
        assert!(
            container
                .advice()
                .unwrap()
                .contains("--ulimit rtprio=95 --cpu-rt-runtime=950000"),
            "{:?}",
            container.advice()
        );
    }

    /// Whatever the system grants, the guard puts the thread back as it was, and a thread the
    /// real-time thread starts runs at normal priority.
    #[test]
    fn guard_restores_and_children_do_not_inherit() {
        std::thread::spawn(|| {
            let before = current_fifo_priority();
            assert_eq!(before, None);
            let g = enter(&RtRequest {
                priority: 10,
                lock_memory: false,
                pin: true,
            });
            let st = g.status();
            assert_eq!(current_fifo_priority(), st.priority);
            if st.priority.is_some() {
                let child = std::thread::spawn(current_fifo_priority).join().unwrap();
                assert_eq!(
                    child, None,
                    "a child of the tick thread inherited SCHED_FIFO"
                );
            } else {
                assert!(st.sched_refused.is_some());
            }
            drop(g);
            assert_eq!(current_fifo_priority(), None);
        })
        .join()
        .unwrap();
    }
}
