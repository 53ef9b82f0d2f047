//! The classroom bench (docs/bench/classroom.md): N students on one machine, each a page
//! client on loopback playing the brick world, measured from both ends.
//!
//! `cargo run --release -p nanohaptics-play --example classroom-bench -- [--students N]
//! [--seconds S] [--runs R] [--workers W] [--no-rt] [--out FILE]` (defaults 30 students, 20 s,
//! 3 runs, the class's own number of workers, real time asked for).
//!
//! The server (`play::classroom::run`) runs in this process; the students run in a child
//! process (this program with `--clients`), so the server's CPU time is this process's alone.
//! Each student joins by name, opens its page link, presses Start and moves its hand at 60
//! inputs/s (each stamped with its wall time) while it reads every frame and sound-ticks message.
//!
//! Figures per run: missed 1 ms deadlines over every session's ticks, input → force (the
//! input's wall time to the tick whose force used it, from the server), frames/s each page
//! received, the server's and the students' CPU use (user + system, in cores), each worker's
//! cycles (how late they began, their work, the cost of one session's tick), and whether every
//! recording replays bit for bit.

/// The programs' allocator, as the `nanohaptics` binary's (crates/cli/src/main.rs).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use haptic_loop::session::SceneSource;
use play::classroom::{ClassConfig, run};
use serde_json::json;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::Command;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn unix_ms() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64() * 1e3)
        .unwrap_or(0.0)
}

/// One student: joins, plays for `secs`, returns the frames it received per second of play.
fn student(host: &str, name: &str, secs: f64) -> Result<f64, String> {
    let mut s = TcpStream::connect(host).map_err(|e| e.to_string())?;
    s.write_all(
        format!(
            "POST /join HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\n\
             Content-Type: application/x-www-form-urlencoded\r\n\
             Content-Length: {}\r\n\r\nname={name}",
            name.len() + 5
        )
        .as_bytes(),
    )
    .map_err(|e| e.to_string())?;
    let mut r = String::new();
    s.read_to_string(&mut r).map_err(|e| e.to_string())?;
    let token = r
        .lines()
        .find_map(|l| l.strip_prefix("Location: /play?s="))
        .ok_or_else(|| format!("{name} could not join: {}", r.lines().next().unwrap_or("")))?
        .trim()
        .to_string();
    let (mut ws, _) = tungstenite::connect(format!("ws://{host}/ws?s={token}").as_str())
        .map_err(|e| e.to_string())?;
    if let MaybeTlsStream::Plain(s) = ws.get_ref() {
        let _ = s.set_read_timeout(Some(Duration::from_millis(2)));
    }
    let send = |ws: &mut WebSocket<MaybeTlsStream<TcpStream>>, v: serde_json::Value| {
        ws.send(Message::text(v.to_string()))
            .map_err(|e| e.to_string())
    };
    send(&mut ws, json!({"type": "start"}))?;
    let t0 = Instant::now();
    let mut next = t0;
    let mut k = 0u64;
    let mut frames = 0u64;
    let mut first_frame: Option<Instant> = None;
    while t0.elapsed().as_secs_f64() < secs {
        if Instant::now() >= next {
            k += 1;
            next += Duration::from_micros(16_667);
            let a = k as f64 * 0.02;
            let pos = [0.3 * a.cos(), 0.3 * a.sin(), -0.2 + 0.2 * (0.5 * a).sin()];
            send(
                &mut ws,
                json!({"type": "input", "seq": k, "pos": pos, "buttons": 0, "t_ms": unix_ms()}),
            )?;
        }
        // Read until the next input is due (a page's own loop: it sleeps between events).
        let wait = next.saturating_duration_since(Instant::now());
        if let MaybeTlsStream::Plain(s) = ws.get_ref() {
            let _ = s.set_read_timeout(Some(wait.max(Duration::from_micros(500))));
        }
        match ws.read() {
            Ok(Message::Text(t)) if t.as_str().starts_with(r#"{"type":"frame""#) => {
                frames += 1;
                first_frame.get_or_insert_with(Instant::now);
            }
            _ => {}
        }
    }
    let played = first_frame.map_or(0.0, |f| f.elapsed().as_secs_f64());
    Ok(if played > 0.0 {
        frames as f64 / played
    } else {
        0.0
    })
}

/// The child process: `n` students on `host` for `secs`; prints each one's frames/s.
fn clients(host: &str, n: usize, secs: f64) {
    let handles: Vec<_> = (0..n)
        .map(|i| {
            let h = host.to_string();
            std::thread::spawn(move || student(&h, &format!("student{i:02}"), secs))
        })
        .collect();
    for h in handles {
        match h.join() {
            Ok(Ok(fps)) => println!("fps {fps}"),
            Ok(Err(e)) => println!("error {e}"),
            Err(_) => println!("error a student thread panicked"),
        }
    }
}

/// The sum of two adjacent time fields of this process's `/proc/self/stat`, s: `first` is
/// the field's index after the command's closing parenthesis (clock ticks of 100 Hz).
fn stat_pair_s(first: usize) -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (t(first) + t(first + 1)) / 100.0
}

/// This process's CPU time (user + system: fields 14 and 15 of stat, utime and stime), s.
fn cpu_s() -> f64 {
    stat_pair_s(11)
}

struct RunFigures {
    ticks: u64,
    missed: u64,
    worst_missed_pct: f64,
    p99_ms: f64,
    worst_p99_ms: f64,
    fps_min: f64,
    fps_median: f64,
    cpu_cores: f64,
    sessions: usize,
    errors: usize,
    workers: usize,
    client_cores: f64,
    steal_ms: f64,
    late_cycles: u64,
    began_late: u64,
    cycles: u64,
    start_p99_us: f64,
    start_max_us: f64,
    work_p99_us: f64,
    per_session_us: f64,
    replayed: usize,
    policy: &'static str,
}

/// The machine's stolen time so far (the hypervisor ran other guests on its cores), s summed
/// over the cores: `/proc/stat`'s steal, in clock ticks of 100 Hz.
fn steal_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    stat.lines()
        .find(|l| l.starts_with("cpu "))
        .and_then(|l| l.split_whitespace().nth(8))
        .and_then(|v| v.parse::<f64>().ok())
        .map_or(0.0, |t| t / 100.0)
}

/// The students' process's CPU time (user + system of waited-for children: fields 16 and 17
/// of stat, cutime and cstime), s.
fn children_cpu_s() -> f64 {
    stat_pair_s(13)
}

/// How many of `summary`'s recordings replay bit for bit.
fn replaying(summary: &play::classroom::ClassSummary) -> usize {
    summary
        .students
        .iter()
        .filter(|s| {
            recording::read_recording_file(&s.session.recording, false)
                .ok()
                .and_then(|r| haptic_loop::replay::verify(&r).ok())
                .is_some_and(|v| v.ok())
        })
        .count()
}

fn one_run(n: usize, secs: f64, workers: Option<usize>, rt: bool) -> RunFigures {
    let dir = std::env::temp_dir().join(format!("nh-class-bench-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut c = ClassConfig::new(
        SceneSource::resolve("brickworld".as_ref()).expect("the built-in brick world"),
        dir.clone(),
    );
    c.port = 0;
    c.max_students = n;
    c.workers = workers;
    if !rt {
        c.rt = None;
    }
    let stop = Arc::new(AtomicBool::new(false));
    let s2 = stop.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    let server = std::thread::spawn(move || {
        run(&c, &s2, &mut |a| {
            let _ = tx.send(a.student_url.clone());
        })
    });
    let url = rx
        .recv_timeout(Duration::from_secs(30))
        .expect("the class serves");
    let host = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let exe = std::env::current_exe().expect("this program");
    let cpu0 = cpu_s();
    let ccpu0 = children_cpu_s();
    let steal0 = steal_s();
    let w0 = Instant::now();
    let nice = std::env::var("CLIENT_NICE").unwrap_or_else(|_| "0".into());
    let out = Command::new("nice")
        .args(["-n", &nice])
        .arg(exe)
        .args([
            "--clients",
            &n.to_string(),
            "--host",
            &host,
            "--seconds",
            &secs.to_string(),
        ])
        .output()
        .expect("the students' process");
    let wall = w0.elapsed().as_secs_f64();
    let cpu = cpu_s() - cpu0;
    let client_cores = (children_cpu_s() - ccpu0) / wall;
    let steal_ms = (steal_s() - steal0) * 1e3;
    stop.store(true, Ordering::Relaxed);
    let summary = server
        .join()
        .expect("the class thread")
        .expect("the class ran");
    let text = String::from_utf8_lossy(&out.stdout);
    let mut fps: Vec<f64> = text
        .lines()
        .filter_map(|l| l.strip_prefix("fps "))
        .filter_map(|v| v.parse().ok())
        .collect();
    let errors = text.lines().filter(|l| l.starts_with("error")).count();
    for l in text.lines().filter(|l| l.starts_with("error")) {
        eprintln!("{l}");
    }
    fps.sort_by(f64::total_cmp);
    let ticks: u64 = summary.students.iter().map(|s| s.session.stats.ticks).sum();
    let missed: u64 = summary
        .students
        .iter()
        .map(|s| s.session.stats.missed)
        .sum();
    let worst_missed_pct = summary
        .students
        .iter()
        .map(|s| 100.0 * s.session.stats.missed as f64 / s.session.stats.ticks.max(1) as f64)
        .fold(0.0, f64::max);
    let p99s: Vec<f64> = summary
        .students
        .iter()
        .filter_map(|s| s.session.input_latency_ms.map(|l| l.p99))
        .collect();
    let mut p99_sorted = p99s.clone();
    p99_sorted.sort_by(f64::total_cmp);
    let replayed = replaying(&summary);
    let _ = std::fs::remove_dir_all(&dir);
    let us = |ns: u64| ns as f64 / 1e3;
    let sched = &summary.schedule;
    let session_ticks: u64 = sched.iter().map(|c| c.session_ticks).sum();
    RunFigures {
        client_cores,
        steal_ms,
        late_cycles: sched.iter().map(|c| c.late_cycles).sum(),
        began_late: sched.iter().map(|c| c.began_late).sum(),
        cycles: sched.iter().map(|c| c.cycles).sum(),
        start_p99_us: us(sched.iter().map(|c| c.started().p99_ns).max().unwrap_or(0)),
        start_max_us: us(sched.iter().map(|c| c.started().max_ns).max().unwrap_or(0)),
        work_p99_us: us(sched.iter().map(|c| c.work().p99_ns).max().unwrap_or(0)),
        per_session_us: sched
            .iter()
            .map(|c| c.per_session_ns() * c.session_ticks as f64)
            .sum::<f64>()
            / session_ticks.max(1) as f64
            / 1e3,
        replayed,
        policy: summary.realtime.policy(),
        ticks,
        missed,
        worst_missed_pct,
        p99_ms: p99_sorted
            .get(p99_sorted.len() / 2)
            .copied()
            .unwrap_or(f64::NAN),
        worst_p99_ms: p99_sorted.last().copied().unwrap_or(f64::NAN),
        fps_min: fps.first().copied().unwrap_or(0.0),
        fps_median: fps.get(fps.len() / 2).copied().unwrap_or(0.0),
        cpu_cores: cpu / wall,
        sessions: summary.students.len(),
        errors,
        workers: summary.workers,
    }
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_default()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--clients") {
        let n = args.get(i + 1).and_then(|v| v.parse().ok()).unwrap_or(1);
        let host: String = arg(&args, "--host", String::new());
        let secs = arg(&args, "--seconds", 10.0);
        clients(&host, n, secs);
        return;
    }
    let n = arg(&args, "--students", 30usize);
    let secs = arg(&args, "--seconds", 20.0);
    let runs = arg(&args, "--runs", 3usize);
    let workers: Option<usize> = args
        .iter()
        .position(|a| a == "--workers")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok());
    let rt = !args.iter().any(|a| a == "--no-rt");
    let out: String = arg(&args, "--out", String::new());
    let load0 = load();
    let mut rows = Vec::new();
    for r in 0..runs {
        eprintln!("run {}/{runs}: {n} students for {secs} s …", r + 1);
        let f = one_run(n, secs, workers, rt);
        eprintln!(
            "  {} sessions on {} workers ({}), missed {:.3} % (worst session {:.3} %), input → force p99 {:.1} ms, \
             {:.1} frames/s (min), server {:.2} cores, students {:.2} cores; cycles {} late of {} \
             ({} begun a period late), start p99/max {:.0}/{:.0} µs, work p99 {:.0} µs, one \
             session's tick {:.1} µs; {} of {} recordings replay; {:.0} ms stolen",
            f.sessions,
            f.workers,
            f.policy,
            100.0 * f.missed as f64 / f.ticks.max(1) as f64,
            f.worst_missed_pct,
            f.worst_p99_ms,
            f.fps_min,
            f.cpu_cores,
            f.client_cores,
            f.late_cycles,
            f.cycles,
            f.began_late,
            f.start_p99_us,
            f.start_max_us,
            f.work_p99_us,
            f.per_session_us,
            f.replayed,
            f.sessions,
            f.steal_ms
        );
        rows.push(f);
    }
    let load1 = load();
    let wflag = workers.map_or(String::new(), |w| format!(" --workers {w}"));
    let rtflag = if rt { "" } else { " --no-rt" };
    let mut md = format!(
        "# Classroom bench: {n} students on one machine\n\n\
         Machine: {} cores, shared. Load average (1, 5, 15 min) at start `{load0}`, at end \
         `{load1}`. Command: `cargo run --release -p nanohaptics-play --example classroom-bench \
         -- --students {n} --seconds {secs} --runs {runs}{wflag}{rtflag} --out docs/bench/classroom.md`.\n\n\
         Each run serves one class (`play::classroom::run`, the built-in brick world at 1 kHz, \
         loopback) to {n} students in a second process: each joins by name, presses Start and \
         moves its hand at 60 inputs/s for {secs} s while reading every frame and sound-ticks message. \
         Missed deadlines are over every tick of every session (a missed tick sends zero force \
         and is recorded, so each session replays bit for bit); input → force is the input's \
         wall time to the tick whose force used it, per session (median and worst session's \
         p99); frames/s is what each page received; CPU is the server process's and the \
         students' process's user + system time over the run's wall time, in cores; the workers' \
         cycles: how many ran past their deadline (of them, begun a whole period late), how late \
         they began (p99 / max) and one session's tick (the cycles' work over the sessions they \
         ticked); stolen: the time the hypervisor gave the machine's cores to other guests during \
         the run (`/proc/stat`'s steal, summed over the cores); replayed: the recordings that \
         replay bit for bit.\n\n\
         | run | sessions | workers (scheduler) | ticks | missed deadlines | worst session | input → force p99, median session (ms) | worst session (ms) | frames/s per page, min / median | CPU server / students (cores) | late cycles (begun late) of all | cycle start p99 / max (µs) | one session's tick (µs) | stolen (ms) | replayed | client errors |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        std::thread::available_parallelism().map_or(0, |n| n.get())
    );
    for (i, f) in rows.iter().enumerate() {
        md.push_str(&format!(
            "| {} | {} | {} ({}) | {} | {} ({:.3} %) | {:.3} % | {:.1} | {:.1} | {:.1} / {:.1} | {:.2} / {:.2} | {} ({}) of {} | {:.0} / {:.0} | {:.1} | {:.0} | {} of {} | {} |\n",
            i + 1,
            f.sessions,
            f.workers,
            f.policy,
            f.ticks,
            f.missed,
            100.0 * f.missed as f64 / f.ticks.max(1) as f64,
            f.worst_missed_pct,
            f.p99_ms,
            f.worst_p99_ms,
            f.fps_min,
            f.fps_median,
            f.cpu_cores,
            f.client_cores,
            f.late_cycles,
            f.began_late,
            f.cycles,
            f.start_p99_us,
            f.start_max_us,
            f.per_session_us,
            f.steal_ms,
            f.replayed,
            f.sessions,
            f.errors
        ));
    }
    md.push_str(
        "\nTargets (issue 32): every session at 1 kHz with ≤ 0.1 % missed deadlines, input → \
         force p99 ≤ 20 ms, 60 frames/s to each page.\n",
    );
    if out.is_empty() {
        print!("{md}");
    } else if let Err(e) = std::fs::write(&out, &md) {
        eprintln!("cannot write {out}: {e}");
        std::process::exit(1);
    } else {
        eprintln!("wrote {out}");
    }
}
