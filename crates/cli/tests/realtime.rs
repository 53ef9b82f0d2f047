//! Real-time scheduling as the program asks for it: granted where permitted, refused with its
//! fix (said once) where not, off with `--no-rt`, recorded either way; and `doctor`.
//!
//! The refusal is tested as an unprivileged user, made by the test itself (no tool needed): as
//! root, a copy of the program (readable wherever the checkout is) is started as `nobody`
//! (uid and gid 65534, no supplementary groups, so no capability) with `RLIMIT_RTPRIO` 0; as any
//! other user without `CAP_SYS_NICE`, the program is started with `RLIMIT_RTPRIO` lowered to 0.
//! The grant is checked wherever the system permits real time. A part this machine cannot run
//! (a user with `CAP_SYS_NICE` who is not root; a container that permits `SCHED_FIFO` but gives
//! it no run time) fails, unless `NANOHAPTICS_SKIP_REALTIME=1` (README.md, docs/testing.md):
//! then it prints that it skipped.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_nanohaptics")
}

fn scratch(name: &str) -> PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-rt-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[allow(unsafe_code)]
fn is_root() -> bool {
    // SAFETY: geteuid takes no arguments and cannot fail.
    unsafe { libc::geteuid() == 0 }
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn info_session(rec: &Path) -> Value {
    let o = Command::new(bin())
        .args(["info", "--json"])
        .arg(rec)
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    let j: Value = serde_json::from_slice(&o.stdout).unwrap();
    j["session_metadata"].clone()
}

/// A part of a test this machine cannot run: a failure, unless `NANOHAPTICS_SKIP_REALTIME=1`
/// says to skip it (then it says so).
fn cannot_run_here(why: &str) {
    if std::env::var("NANOHAPTICS_SKIP_REALTIME").is_ok_and(|v| v == "1") {
        eprintln!("SKIPPED (NANOHAPTICS_SKIP_REALTIME=1): {why}");
    } else {
        panic!(
            "{why}; set NANOHAPTICS_SKIP_REALTIME=1 to skip it on this machine (README.md, \
             docs/testing.md)"
        );
    }
}

/// The program as a user the system refuses real time, started in `dir` (which that user can
/// write); `Err` when this machine cannot make one.
#[allow(unsafe_code)]
fn unprivileged(dir: &Path) -> Result<Command, String> {
    use std::os::unix::process::CommandExt;
    let mut c = if is_root() {
        // `nobody` may not reach the build's folder (a checkout under /root): a copy in `dir`.
        let copy = dir.join("nanohaptics");
        std::fs::copy(bin(), &copy).map_err(|e| format!("copying the program: {e}"))?;
        std::fs::set_permissions(&copy, std::os::unix::fs::PermissionsExt::from_mode(0o755))
            .unwrap();
        let mut c = Command::new(copy);
        // Root setting a uid drops the supplementary groups too; the new uid has no capability.
        c.uid(65534).gid(65534);
        c
    } else if haptic_engine::realtime::permissions().cap_sys_nice {
        return Err(
            "not root, and this user has CAP_SYS_NICE: the test cannot start the \
                    program without it"
                .into(),
        );
    } else {
        Command::new(bin())
    };
    // SAFETY: setrlimit is async-signal-safe and reads only a local struct.
    unsafe {
        c.pre_exec(|| {
            let none = libc::rlimit {
                rlim_cur: 0,
                rlim_max: 0,
            };
            if libc::setrlimit(libc::RLIMIT_RTPRIO, &none) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    c.current_dir(dir);
    Ok(c)
}

#[test]
fn a_refused_request_is_said_once_with_its_fix_and_the_session_runs_as_before() {
    let dir = scratch("refused");
    // The unprivileged user writes the recording here.
    std::fs::set_permissions(&dir, std::os::unix::fs::PermissionsExt::from_mode(0o777)).unwrap();
    let mut cmd = match unprivileged(&dir) {
        Ok(c) => c,
        Err(why) => {
            cannot_run_here(&why);
            return;
        }
    };
    let rec = dir.join("refused.mcap");
    let o = cmd
        .args([
            "run",
            "brickworld",
            "--realtime",
            "--seconds",
            "0.3",
            "--json",
        ])
        .arg("--out")
        .arg(&rec)
        .output()
        .unwrap();
    let (out, err) = text(&o);
    assert!(o.status.success(), "{out}\n{err}");
    // Said once, on standard error, with what was refused and the fix.
    assert_eq!(err.matches("nanohaptics: real time:").count(), 1, "{err}");
    assert!(
        err.contains(
            "normal priority, SCHED_FIFO refused: no CAP_SYS_NICE, and RLIMIT_RTPRIO is below \
             the priority asked for"
        ),
        "{err}"
    );
    for fix in ["rtprio 95", "setcap cap_sys_nice", "rtkit", "--no-rt"] {
        assert!(err.contains(fix), "{fix}: {err}");
    }
    // The summary and the recording say what it got; the session ran every tick.
    let j: Value = serde_json::from_str(&out).unwrap();
    let rt = &j["tick_stats"]["realtime"];
    assert_eq!(rt["requested"], true);
    assert_eq!(rt["priority"], Value::Null);
    assert_eq!(rt["sched_refused"], "no_permission");
    assert_eq!(rt["cpu"], Value::Null, "pinned without SCHED_FIFO");
    assert_eq!(j["ticks"], 300);
    let s = info_session(&rec);
    assert_eq!(s["rt_policy"], "normal");
    assert_eq!(s["rt_priority"], "none");
    assert!(
        s["rt_refused"]
            .as_str()
            .unwrap()
            .starts_with("no CAP_SYS_NICE"),
        "{s}"
    );
    // It replays bit for bit like any session.
    let o = Command::new(bin())
        .args(["replay", "--verify"])
        .arg(&rec)
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn granted_where_permitted_off_with_no_rt_and_the_priority_checked() {
    let dir = scratch("granted");
    let p = haptic_engine::realtime::permissions();
    let permitted = p.cap_sys_nice || p.rlimit_rtprio.is_none_or(|l| l >= 50);
    let rec = dir.join("rt.mcap");
    let o = Command::new(bin())
        .args([
            "run",
            "brickworld",
            "--realtime",
            "--seconds",
            "0.3",
            "--json",
        ])
        .arg("--out")
        .arg(&rec)
        .output()
        .unwrap();
    let (out, err) = text(&o);
    assert!(o.status.success(), "{out}\n{err}");
    let j: Value = serde_json::from_str(&out).unwrap();
    let rt = &j["tick_stats"]["realtime"];
    let s = info_session(&rec);
    // Wake-ups were measured (300 ticks, nearly all slept) and recorded.
    assert!(j["tick_stats"]["wakeup"]["max_ns"].as_u64().unwrap() > 0);
    assert!(s["wakeup_p99_ns"].as_str().unwrap().parse::<u64>().unwrap() > 0);
    if !permitted {
        // Refused, said so with the reason, and the session ran as before.
        assert_eq!(rt["sched_refused"], "no_permission", "{rt}");
        assert_eq!(rt["priority"], Value::Null, "{rt}");
        assert_eq!(err.matches("nanohaptics: real time:").count(), 1, "{err}");
        assert_eq!(s["rt_policy"], "normal");
    } else if rt["sched_refused"] == "no_runtime" {
        cannot_run_here(&format!(
            "the system permits SCHED_FIFO here but gives real-time tasks no run time (a \
             container, or a cgroup with cpu.rt_runtime_us 0), so the grant cannot be checked: \
             {rt}"
        ));
    } else {
        assert_eq!(rt["priority"], 50, "{rt}");
        assert_eq!(rt["sched_refused"], Value::Null, "{rt}");
        assert!(!err.contains("nanohaptics: real time:"), "{err}");
        assert_eq!(s["rt_policy"], "fifo");
        assert_eq!(s["rt_priority"], "50");
        if p.cores > 1 {
            assert!(rt["cpu"].is_u64(), "{rt}");
        }
    }
    // --no-rt asks for nothing and says nothing.
    let o = Command::new(bin())
        .args([
            "run",
            "brickworld",
            "--realtime",
            "--seconds",
            "0.2",
            "--json",
            "--no-rt",
        ])
        .output()
        .unwrap();
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains("real time"), "{err}");
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["tick_stats"]["realtime"]["requested"], false);
    assert_eq!(j["tick_stats"]["realtime"]["priority"], Value::Null);
    // Batch runs never ask.
    let o = Command::new(bin())
        .args(["run", "brickworld", "--seconds", "0.1", "--json"])
        .output()
        .unwrap();
    let j: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["tick_stats"]["realtime"]["requested"], false);
    // The priority's range, by name.
    for cmd in [&["run", "brickworld"][..], &["play"], &["classroom"]] {
        let o = Command::new(bin())
            .args(cmd)
            .args(["--rt-priority", "0"])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{cmd:?}");
        assert_eq!(
            text(&o).1.trim(),
            "error: --rt-priority = 0 is out of range: allowed 1 to 99",
            "{cmd:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn doctor_measures_both_ways_and_judges_each_rate_by_its_wakeups() {
    let o = Command::new(bin())
        .args(["doctor", "--seconds", "0.4", "--json"])
        .output()
        .unwrap();
    let (out, err) = text(&o);
    assert!(o.status.success(), "{out}\n{err}");
    let j: Value = serde_json::from_str(&out).unwrap();
    for half in ["normal", "realtime"] {
        let m = &j[half];
        // 0.2 s of wake-ups every 500 µs: half the time over the interval (docs/realtime.md's
        // example, `--seconds 4`, shows 4000 a half by the same rule).
        assert_eq!(m["samples"], 400, "{half}");
        let l = &m["latency"];
        let (p50, p99, p999, max) = (
            l["p50_ns"].as_u64().unwrap(),
            l["p99_ns"].as_u64().unwrap(),
            l["p999_ns"].as_u64().unwrap(),
            l["max_ns"].as_u64().unwrap(),
        );
        assert!(p50 <= p99 && p99 <= p999 && p999 <= max, "{half}: {l}");
        // A rate whose half period exceeds the largest wake-up holds.
        for r in j["rates"].as_array().unwrap() {
            let hz = r["rate_hz"].as_u64().unwrap();
            let key = if half == "normal" {
                "normal"
            } else {
                "realtime"
            };
            if max <= 500_000_000 / hz {
                assert_eq!(r[key]["verdict"], "holds", "{hz} Hz {half}: {r}");
            } else {
                assert_eq!(r[key]["verdict"], "misses", "{hz} Hz {half}: {r}");
                assert!(r[key]["per_minute"].as_f64().unwrap() > 0.0);
            }
        }
    }
    assert_eq!(j["normal"]["realtime"]["requested"], false);
    assert_eq!(j["realtime"]["realtime"]["requested"], true);
    assert!(j["permissions"]["cores"].as_u64().unwrap() >= 1);
    // The text report names every rate.
    let o = Command::new(bin())
        .args(["doctor", "--seconds", "0.2"])
        .output()
        .unwrap();
    let (out, _) = text(&o);
    for rate in ["1 kHz", "4 kHz", "10 kHz", "p99.9"] {
        assert!(out.contains(rate), "{rate}: {out}");
    }
    let o = Command::new(bin())
        .args(["doctor", "--seconds", "0"])
        .output()
        .unwrap();
    assert_eq!(
        text(&o).1.trim(),
        "error: --seconds = 0 is out of range: allowed 0.1–3600 s"
    );
}

/// The value clap prints as `flag`'s default in `nanohaptics <cmd> --help`.
fn default_of(cmd: &str, flag: &str) -> String {
    let o = Command::new(bin()).args([cmd, "--help"]).output().unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    let (out, _) = text(&o);
    let line = out
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{flag} ")))
        .unwrap_or_else(|| panic!("{cmd} --help has no {flag}: {out}"));
    let (_, d) = line
        .rsplit_once("[default: ")
        .unwrap_or_else(|| panic!("{line}"));
    d.trim_end_matches(']').to_string()
}

/// The defaults docs/realtime.md and docs/lesson.md state, as the program's parser has them:
/// `--rt-priority` 50 for every command with a tick thread and for `doctor`; `doctor`
/// measures 10 s with a wake-up every 500 µs; `lesson` draws 1200 px figures and 44 100 Hz
/// sounds.
#[test]
fn the_defaults_the_docs_state_are_the_parsers() {
    for cmd in ["run", "play", "classroom", "doctor"] {
        assert_eq!(default_of(cmd, "--rt-priority"), "50", "{cmd}");
    }
    assert_eq!(default_of("doctor", "--seconds"), "10");
    assert_eq!(default_of("doctor", "--interval-us"), "500");
    assert_eq!(default_of("lesson", "--width"), "1200");
    assert_eq!(default_of("lesson", "--sample-rate"), "44100");
}

/// The peak resident memory of process `pid` so far, KiB (`None` once it has exited).
fn peak_resident_kib(pid: u32) -> Option<u64> {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// With its memory locked (`mlockall`, so no tick waits on a page fault), a real-time session
/// stays small: the allocator commits its arenas as it uses them, so the lock makes resident
/// only what the program uses (for the brick world 13 MiB on one machine, 39 MiB on another;
/// docs/realtime.md states only the bounds held here, over 4 MiB and under 256 MiB),
/// not the allocator's whole 1 GiB reserve (which also took 4 s to lock before the first tick).
#[test]
fn a_locked_session_keeps_only_what_it_uses_resident() {
    let dir = scratch("locked");
    let mut child = Command::new(bin())
        .args([
            "run",
            "brickworld",
            "--realtime",
            "--seconds",
            "1",
            "--json",
        ])
        .arg("--out")
        .arg(dir.join("rt.mcap"))
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut peak = 0;
    while child.try_wait().unwrap().is_none() {
        if let Some(k) = peak_resident_kib(child.id()) {
            peak = peak.max(k);
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success());
    let j: Value = serde_json::from_slice(&o.stdout).unwrap();
    let rt = &j["tick_stats"]["realtime"];
    if rt["memory_locked"] != true {
        cannot_run_here(&format!(
            "the memory could not be locked here, so what locking makes resident cannot be \
             checked: {rt}"
        ));
        return;
    }
    assert!(
        peak > 4 * 1024 && peak < 256 * 1024,
        "{peak} KiB resident with the memory locked"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
