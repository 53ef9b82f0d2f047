//! The play bench (docs/bench/play.md): real sessions served to headless Chromium pages on
//! loopback, measured from both ends.
//!
//! `cargo run --release -p nanohaptics-play --example play-bench -- [--seconds S] [--pages N]
//! [--input mixed|pointer|wheel|keys] [--out FILE]` (`--pages N`: only the rows with N pages;
//! `--input`: the hand moved by the pointer and the wheel in turn, the default, or by one
//! alone; `NH_BENCH_NO_RT=1` in the environment: the tick thread without real-time scheduling,
//! for comparison)
//! runs, each for S seconds (default 10) of play:
//! 0. brickworld with a Rust WebSocket client as the hand and no browser (the baseline);
//! 1. brickworld, one page that plays (the pointer circles at 60 events/s);
//! 2. nanoworld, one page that plays (the same);
//! 3. brickworld, one page that plays and two more that watch (and again with the browsers at
//!    `nice 19`).
//!
//! The playing page's pointer circles and its wheel lowers and raises the hand about four times
//! a second, so the hand taps what is under it (the sounds whose latency is measured); the
//! pointer and the wheel take turns, 60 events/s in all.
//!
//! Figures: browser input → force (the page's event time to the tick whose force used it,
//! from the server), frames drawn per second by each page (requestAnimationFrame draws with a
//! frame in hand, over the session), sound latency (for each sound, the wall time its first
//! sample leaves the page's audio output minus the wall time of its tick: the AudioWorklet's
//! render time of that sample plus the context's `baseLatency` and `outputLatency`; and, as a
//! cross-check, the sample's context time mapped through `AudioContext.getOutputTimestamp()`),
//! and missed 1 ms deadlines.

#[path = "../tests/common/cdp.rs"]
mod cdp;

use bench_harness::Verdict;
use cdp::Browser;
use haptic_loop::session::SceneSource;
use play::{LatencyMs, PlayConfig, Running, start};
use serde_json::Value;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

struct Outcome {
    scene: &'static str,
    #[allow(dead_code)]
    pages: usize,
    input: Option<LatencyMs>,
    fps: Vec<f64>,
    sound: Option<LatencyMs>,
    sound_ts: Option<LatencyMs>,
    /// Per sound: tick → the worklet has it, queued in the worklet, the output's latency, and
    /// the page's own part (the first two added).
    sound_parts: [Option<LatencyMs>; 4],
    output_latency_s: Option<f64>,
    base_latency_s: Option<f64>,
    sample_rate: Option<f64>,
    lead_ms: Option<f64>,
    /// The worklet's arrival jitter over its last 4 s at the end, ms.
    late_ms: Option<f64>,
    underruns: u64,
    samples_dropped: u64,
    ticks: u64,
    /// Missed deadlines, with the real time the tick thread got and its wake-up latency.
    missed: String,
    missed_n: u64,
    tick_p99_us: f64,
    dropped: u64,
}

/// The input-path probe the playing page is given (see `session`).
const PROBE: &str = "(() => { const q = { wheel: [], move: [], send: [], long: [], frame: [] }; \
    window.__probe = q; \
    const raf = window.requestAnimationFrame.bind(window); \
    window.requestAnimationFrame = (cb) => raf((t) => { const a = performance.now(); \
      try { cb(t); } finally { q.frame.push(performance.now() - a); } }); \
    const at = (list) => (e) => list.push(performance.now() - e.timeStamp); \
    window.addEventListener('wheel', at(q.wheel), { capture: true, passive: true }); \
    for (const k of ['pointermove', 'pointerrawupdate']) window.addEventListener(k, at(q.move), { capture: true }); \
    const post = Worker.prototype.postMessage; \
    Worker.prototype.postMessage = function (m, t) { \
      if (m && typeof m.send === 'string' && m.send.startsWith('{\"type\":\"input\"')) { \
        const w = JSON.parse(m.send).t_ms; q.send.push(performance.timeOrigin + performance.now() - w); } \
      return post.call(this, m, t); }; \
    const t0 = performance.now(); \
    new PerformanceObserver((l) => { for (const e of l.getEntries()) if (e.startTime >= t0) q.long.push(e.duration); }) \
      .observe({ type: 'longtask' }); \
    return 0; })()";

/// What the playing page's hand is moved with (`--input`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Input {
    /// The pointer and the wheel in turn (the default).
    Mixed,
    /// The pointer alone, circling.
    Pointer,
    /// The wheel alone.
    Wheel,
    /// PageDown and PageUp held in turn.
    Keys,
}

fn session(
    scene: &'static str,
    pages: usize,
    nice: i32,
    seconds: f64,
    input: Input,
) -> Result<Outcome, String> {
    let out = std::env::temp_dir().join(format!("nh-play-bench-{}.mcap", std::process::id()));
    let mut c = PlayConfig::new(
        SceneSource::resolve(scene.as_ref()).map_err(|e| e.to_string())?,
        out.clone(),
    );
    c.port = 0;
    c.keep_serving_s = Some(0.0);
    // NH_BENCH_NO_RT=1: the tick thread asks for no real time (`--no-rt`), for comparison.
    if std::env::var_os("NH_BENCH_NO_RT").is_some() {
        c.rt = None;
    }
    let stop = Arc::new(AtomicBool::new(false));
    let Running { url, handle } = start(c, stop.clone()).map_err(|e| e.to_string())?;
    let mut browsers = Vec::new();
    for _ in 0..pages {
        let mut b = Browser::launch_nice(1280, 760, nice)?;
        b.open(&url)?;
        b.wait_for("window.__play.hello !== null", 10.0)?;
        browsers.push(b);
    }
    // The first page plays; the others watch (their Start makes them watchers).
    for b in browsers.iter_mut() {
        b.eval("document.getElementById('go').click(); 0")?;
    }
    browsers[0].wait_for("window.__play.role === 'hand'", 10.0)?;
    // Where the hand's time goes on the page (issue 43 item 3): each input event's wait from
    // its timestamp to its dispatch (the capture listener runs first), by kind; the input
    // messages' wait from the event to their hand-over to the link's Worker (which sends them
    // on its socket as they come); and the main thread's long tasks.
    browsers[0].eval(PROBE)?;
    let r = browsers[0].eval("(() => { const r = document.getElementById('view').getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2, 0.46 * Math.min(r.width, r.height)]; })()")?;
    let (cx, cy, k) = (
        r[0].as_f64().unwrap_or(0.0),
        r[1].as_f64().unwrap_or(0.0),
        r[2].as_f64().unwrap_or(0.0),
    );
    let t0 = Instant::now();
    let mut i = 0u64;
    let mut key_down: Option<&str> = None;
    while t0.elapsed().as_secs_f64() < seconds {
        let a = i as f64 * 0.05;
        let rr = 0.4 * k;
        let (x, y) = (cx + rr * a.cos(), cy + rr * a.sin());
        // The wheel's step, for its n-th event: 0.5 of the ball's radius (the wheel's 0.0015
        // per unit) down twice, up twice, between heights -0.7 and 0.3 (the first step is up
        // 0.3): the hand taps the ground, or what lies on it, about four times a second.
        let wheel = |w: u64| {
            if w == 0 {
                -200.0
            } else if (w - 1) % 4 < 2 {
                333.3
            } else {
                -333.3
            }
        };
        match input {
            Input::Mixed if i % 2 == 0 => browsers[0].mouse("mouseMoved", x, y, false, 0.0)?,
            Input::Mixed => browsers[0].mouse("mouseWheel", x, y, false, wheel(i / 2))?,
            Input::Pointer => browsers[0].mouse("mouseMoved", x, y, false, 0.0)?,
            Input::Wheel => browsers[0].mouse("mouseWheel", cx, cy, false, wheel(i / 2))?,
            // The keys: PageDown and PageUp held in turn for a quarter of a second each (the
            // page moves the hand by the keys held each frame and sends it then).
            Input::Keys if i % 15 == 0 => {
                let next = if (i / 15) % 2 == 0 {
                    "PageDown"
                } else {
                    "PageUp"
                };
                if let Some(k) = key_down {
                    browsers[0].key(k, false, false)?;
                }
                browsers[0].key(next, true, false)?;
                key_down = Some(next);
            }
            Input::Keys => {}
        }
        i += 1;
        let next = Duration::from_secs_f64(i as f64 / 60.0);
        if let Some(w) = next.checked_sub(t0.elapsed()) {
            std::thread::sleep(w);
        }
    }
    let probe = browsers[0].eval(
        "(() => { const q = window.__probe; return [q.wheel, q.move, q.send, q.long, q.frame]; })()",
    )?;
    let ms = |i: usize| -> Vec<f64> {
        probe[i]
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_f64).collect())
            .unwrap_or_default()
    };
    let long = ms(3);
    eprintln!(
        "{scene}: the page's input path: event → dispatch, wheel {}; pointer moves {}; event → \
         the link's worker {}; each animation frame's work (its callbacks: drawing, the keys) {}; \
         long tasks (≥ 50 ms) {} totalling {:.0} ms, the longest {:.0} ms",
        fmt(LatencyMs::of(&ms(0))),
        fmt(LatencyMs::of(&ms(1))),
        fmt(LatencyMs::of(&ms(2))),
        fmt(LatencyMs::of(&ms(4))),
        long.len(),
        long.iter().fold(0.0, |a, b| a + b),
        long.iter().copied().fold(0.0, f64::max),
    );
    let mut fps = Vec::new();
    let mut audio = Vec::new();
    let mut audio_ts = Vec::new();
    let mut parts: [Vec<f64>; 4] = Default::default();
    let (mut out_lat, mut base_lat, mut rate, mut lead, mut late) = (None, None, None, None, None);
    let (mut underruns, mut samples_dropped) = (0, 0);
    // Let the last sounds play out.
    std::thread::sleep(Duration::from_millis(500));
    for b in browsers.iter_mut() {
        let v = b.eval("(() => { const P = window.__play, S = P.sound; return [P.draws, performance.now() - P.drawT0, S.latencyMs, S.outputLatencyS, S.underruns, S.parts, S.latencyTsMs, S.baseLatencyS, S.sampleRate, S.dropped, S.leadMs, S.sounds, S.ticks, S.jitterMs, S.pageMs, S.linkMs, S.cadence, S.spread, S.guesses, S.concealed, S.skipped, S.waited]; })()")?;
        for p in v[5].as_array().into_iter().flatten() {
            for (k, part) in parts.iter_mut().take(3).enumerate() {
                if let Some(x) = p[k].as_f64() {
                    part.push(x);
                }
            }
            if let (Some(a), Some(q)) = (p[0].as_f64(), p[1].as_f64()) {
                parts[3].push(a + q);
            }
        }
        fps.push(v[0].as_f64().unwrap_or(0.0) / (v[1].as_f64().unwrap_or(1.0) * 1e-3));
        if let Some(a) = v[2].as_array() {
            audio.extend(a.iter().filter_map(Value::as_f64));
        }
        if let Some(a) = v[6].as_array() {
            audio_ts.extend(a.iter().filter_map(Value::as_f64));
        }
        out_lat = v[3].as_f64().or(out_lat);
        base_lat = v[7].as_f64().or(base_lat);
        rate = v[8].as_f64().or(rate);
        underruns += v[4].as_u64().unwrap_or(0);
        samples_dropped += v[9].as_u64().unwrap_or(0);
        lead = v[10].as_f64().or(lead);
        late = v[13].as_f64().or(late);
        let list = |v: &Value| -> Vec<f64> {
            v.as_array()
                .map(|a| a.iter().filter_map(Value::as_f64).collect())
                .unwrap_or_default()
        };
        eprintln!(
            "{scene}: a page got {} sounds in {} ticks; tick → the page's link worker {}, → the page's main thread {}",
            v[11].as_u64().unwrap_or(0),
            v[12].as_u64().unwrap_or(0),
            fmt(LatencyMs::of(&list(&v[15]))),
            fmt(LatencyMs::of(&list(&v[14])))
        );
        let c = &v[16];
        if c.is_object() {
            eprintln!(
                "{scene}: the audio thread rendered {} quanta a callback (largest {}), one every {} ms p50, {} ms p99 ({} callbacks)",
                c["quanta"][0], c["quanta"][1], c["ms"][0], c["ms"][1], c["callbacks"]
            );
        }
        let sp = &v[17];
        if sp.is_object() {
            eprintln!(
                "{scene}: each sound-ticks message's lateness past its 4 s window's earliest (what sizes the lead) p50 {} ms, p99 {} ms, p99.9 {} ms, largest {} ms ({} messages; 0.5 ms bins)",
                sp["ms"][0], sp["ms"][1], sp["ms"][2], sp["ms"][3], sp["messages"]
            );
        }
        eprintln!(
            "{scene}: the worklet guessed over {} late messages; {} samples played were not the track's (concealed), {} underruns, {} samples dropped, {} silent ones skipped and {} waited to follow the lead",
            v[18].as_u64().unwrap_or(0),
            v[19].as_u64().unwrap_or(0),
            v[4].as_u64().unwrap_or(0),
            v[9].as_u64().unwrap_or(0),
            v[20].as_u64().unwrap_or(0),
            v[21].as_u64().unwrap_or(0)
        );
        b.check()?;
    }
    browsers[0].key("e", true, false)?;
    browsers[0].key("e", false, false)?;
    let s = handle
        .join()
        .map_err(|_| "the session panicked")?
        .map_err(|e| e.to_string())?;
    stop.store(true, Ordering::Relaxed);
    let _ = std::fs::remove_file(&out);
    Ok(Outcome {
        scene,
        pages,
        input: s.session.input_latency_ms,
        fps,
        sound: LatencyMs::of(&audio),
        sound_ts: LatencyMs::of(&audio_ts),
        sound_parts: [
            LatencyMs::of(&parts[0]),
            LatencyMs::of(&parts[1]),
            LatencyMs::of(&parts[2]),
            LatencyMs::of(&parts[3]),
        ],
        output_latency_s: out_lat,
        base_latency_s: base_lat,
        sample_rate: rate,
        lead_ms: lead,
        late_ms: late,
        underruns,
        samples_dropped,
        ticks: s.session.stats.ticks,
        missed: missed_text(&s.session.stats),
        missed_n: s.session.stats.missed,
        tick_p99_us: s.session.stats.compute.p99_ns as f64 * 1e-3,
        dropped: s.messages_dropped,
    })
}

/// The same session with a Rust WebSocket client as the hand and no browser: what the loop
/// and the server cost alone on this machine.
fn no_browser(scene: &'static str, seconds: f64) -> Result<Outcome, String> {
    let out = std::env::temp_dir().join(format!("nh-play-bench0-{}.mcap", std::process::id()));
    let mut c = PlayConfig::new(
        SceneSource::resolve(scene.as_ref()).map_err(|e| e.to_string())?,
        out.clone(),
    );
    c.port = 0;
    c.keep_serving_s = Some(0.0);
    // NH_BENCH_NO_RT=1: the tick thread asks for no real time (`--no-rt`), for comparison.
    if std::env::var_os("NH_BENCH_NO_RT").is_some() {
        c.rt = None;
    }
    let stop = Arc::new(AtomicBool::new(false));
    let Running { url, handle } = start(c, stop.clone()).map_err(|e| e.to_string())?;
    let ws_url = format!("{}ws", url.replace("http://", "ws://"));
    let (mut ws, _) = tungstenite::connect(ws_url.as_str()).map_err(|e| e.to_string())?;
    if let tungstenite::stream::MaybeTlsStream::Plain(s) = ws.get_ref() {
        s.set_read_timeout(Some(Duration::from_millis(1)))
            .map_err(|e| e.to_string())?;
    }
    let send = |ws: &mut tungstenite::WebSocket<_>, m: String| {
        ws.send(tungstenite::Message::text(m))
            .map_err(|e: tungstenite::Error| e.to_string())
    };
    // Wait for the hello, then start.
    loop {
        match ws.read() {
            Ok(tungstenite::Message::Text(t)) if t.as_str().contains("\"hello\"") => break,
            Ok(_) => {}
            Err(tungstenite::Error::Io(_)) => {}
            Err(e) => return Err(e.to_string()),
        }
    }
    send(&mut ws, r#"{"type":"start"}"#.into())?;
    std::thread::sleep(Duration::from_millis(100));
    let t0 = Instant::now();
    let mut i = 0u64;
    while t0.elapsed().as_secs_f64() < seconds {
        let a = i as f64 * 0.05;
        let now_ms = haptic_loop::session::now_unix_ns() as f64 * 1e-6;
        let m = format!(
            r#"{{"type":"input","seq":{i},"pos":[{},{},0],"buttons":0,"t_ms":{now_ms}}}"#,
            0.4 * a.cos(),
            0.4 * a.sin()
        );
        send(&mut ws, m)?;
        // Drain what the server sent (frames, sound) as a page would.
        while ws.read().is_ok() {}
        i += 1;
        let next = Duration::from_secs_f64(i as f64 / 60.0);
        while t0.elapsed() < next {
            let _ = ws.read();
        }
    }
    send(&mut ws, r#"{"type":"end"}"#.into())?;
    let s = loop {
        let _ = ws.read();
        if handle.is_finished() {
            break handle
                .join()
                .map_err(|_| "the session panicked")?
                .map_err(|e| e.to_string())?;
        }
    };
    stop.store(true, Ordering::Relaxed);
    let _ = std::fs::remove_file(&out);
    Ok(Outcome {
        scene,
        pages: 0,
        input: s.session.input_latency_ms,
        fps: Vec::new(),
        sound: None,
        sound_ts: None,
        sound_parts: [None, None, None, None],
        output_latency_s: None,
        base_latency_s: None,
        sample_rate: None,
        lead_ms: None,
        late_ms: None,
        underruns: 0,
        samples_dropped: 0,
        ticks: s.session.stats.ticks,
        missed: missed_text(&s.session.stats),
        missed_n: s.session.stats.missed,
        tick_p99_us: s.session.stats.compute.p99_ns as f64 * 1e-3,
        dropped: s.messages_dropped,
    })
}

fn fmt(l: Option<LatencyMs>) -> String {
    l.map_or("–".into(), |l| {
        format!("{:.1} / {:.1} / {:.1} (n = {})", l.p50, l.p99, l.max, l.n)
    })
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// Missed deadlines, with the real time the tick thread got and its wake-up p99 and max.
fn missed_text(st: &haptic_engine::pacing::TickStats) -> String {
    format!(
        "{} ({}; wake-up p99 {:.0} µs, max {:.0} µs)",
        st.missed,
        st.realtime.describe(),
        st.wakeup.p99_ns as f64 * 1e-3,
        st.wakeup.max_ns as f64 * 1e-3
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let seconds: f64 = opt("--seconds")
        .and_then(|s| s.parse().ok())
        .unwrap_or(10.0);
    // `--pages N`: only the rows with N pages (and the browsers at normal nice), e.g. the three
    // runs of 60 s with three pages behind issue 33's deadline target.
    let only_pages: Option<usize> = opt("--pages").and_then(|s| s.parse().ok());
    // `--input pointer|wheel|keys`: the playing page's hand moved by that alone (default: the
    // pointer and the wheel in turn), to tell where input → force goes (issue 43 item 3).
    let input = match opt("--input").as_deref() {
        None | Some("mixed") => Input::Mixed,
        Some("pointer") => Input::Pointer,
        Some("wheel") => Input::Wheel,
        Some("keys") => Input::Keys,
        Some(other) => {
            eprintln!("--input `{other}`: allowed mixed, pointer, wheel, keys");
            std::process::exit(2);
        }
    };
    let load0 = loadavg();
    let t0 = Instant::now();
    // (scene, pages, nice of the browsers)
    let all_runs = [
        ("brickworld", 0, 0),
        ("brickworld", 1, 0),
        ("nanoworld", 1, 0),
        ("brickworld", 3, 0),
        ("brickworld", 3, 19),
    ];
    let runs: Vec<_> = all_runs
        .into_iter()
        .filter(|&(_, p, nice)| only_pages.is_none_or(|n| n == p && nice == 0))
        .collect();
    let mut md = String::new();
    let mut line = |s: String| {
        println!("{s}");
        md.push_str(&s);
        md.push('\n');
    };
    let mut rows = Vec::new();
    let mut parts = Vec::new();
    let mut outcomes = Vec::new();
    for (scene, pages, nice) in runs {
        let o = if pages == 0 {
            no_browser(scene, seconds)
        } else {
            session(scene, pages, nice, seconds, input)
        };
        let label = if nice != 0 {
            format!("{pages} (nice {nice})")
        } else {
            pages.to_string()
        };
        match o {
            Ok(o) => {
                if o.sound.is_some() {
                    parts.push((o.scene, label.clone(), o.sound_parts));
                }
                rows.push(format!(
                    "| {} | {} | {} | {} | {} | {} | {} | {} | {} / {} / {} ({}) | {} | {} | {:.0} | {} |",
                    o.scene,
                    label,
                    fmt(o.input),
                    if o.fps.is_empty() {
                        "–".into()
                    } else {
                        o.fps
                            .iter()
                            .map(|f| format!("{f:.1}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    },
                    fmt(o.sound),
                    o.sound_ts
                        .map_or("–".into(), |l| format!("{:.1} / {:.1}", l.p50, l.p99)),
                    match (o.output_latency_s, o.base_latency_s) {
                        (Some(a), Some(b)) => format!("{:.1} + {:.1}", a * 1e3, b * 1e3),
                        _ => "–".into(),
                    },
                    o.sample_rate.map_or("–".into(), |r| format!("{r:.0}")),
                    o.underruns,
                    o.samples_dropped,
                    o.lead_ms.map_or("–".into(), |l| format!("{l:.1}")),
                    o.late_ms.map_or("–".into(), |l| format!("{l:.1}")),
                    o.ticks,
                    o.missed,
                    o.tick_p99_us,
                    o.dropped
                ));
                outcomes.push((label, o));
            }
            Err(e) => rows.push(format!("| {scene} | {label} | failed: {e} |")),
        }
    }
    let load1 = loadavg();
    line("## play — the game in a browser (loopback, headless Chromium)".into());
    line(String::new());
    line(format!(
        "Machine: {} cores, shared. Load average (1, 5, 15 min) at start `{load0}`, at end `{load1}`; the report ran {:.0} s. \
         Command: `cargo run --release -p nanohaptics-play --example play-bench -- --seconds {seconds} --out docs/bench/play.md`.",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        t0.elapsed().as_secs_f64()
    ));
    line(String::new());
    line(format!(
        "Each row is one real-time session of {seconds} s of the built-in scene at 1 kHz, served by `play::run` on 127.0.0.1 to \
         Debian's `chromium --headless=new` pages driven through the DevTools Protocol. The first page plays: its pointer circles \
         and its wheel lowers and raises the hand about four times a second, tapping the ground or what lies on it (pointer \
         and wheel take turns, 60 events/s in all; the page sends each at once); the other pages watch and listen. Pages 0: a Rust WebSocket client \
         sends the same moves instead of a browser (the loop and the server alone)."
    ));
    line(String::new());
    line(
        "- **input → force**: the page's event time (`performance.timeOrigin + event.timeStamp`) to the wall time the force of \
         the first tick that used it was sent; the server measures it (same machine, same clock; nearest-rank percentiles).".into(),
    );
    line(
        "- **frames/s drawn**: the page's `requestAnimationFrame` draws of a frame in hand over the session (the server sends \
         62.5 frames/s).".into(),
    );
    line(
        "- **sound tick → output**: for every sound (the hand's taps, impacts, snaps, pull-offs), the wall time its first \
         sample leaves the page's audio output minus the wall time of its tick at the server: the AudioWorklet's render time \
         of that sample (`Date.now()` on the audio thread at its render quantum, plus the sample's place in the quantum) plus \
         the AudioContext's `outputLatency` and `baseLatency` (`latencyHint: 0.001`, the smallest buffer the device offers; the context's own sample rate). \
         The next column maps the sample's context time through `AudioContext.getOutputTimestamp()` instead, as a \
         cross-check. Headless Chromium plays into a fake output device.".into(),
    );
    line(
        "- **missed deadlines**: ticks whose force was not ready before the next tick's start (zero force was sent; \
         recorded, so replay reproduces them).".into(),
    );
    line(String::new());
    line("| scene | pages | input → force p50 / p99 / max (ms) | frames/s drawn (per page) | sound tick → output p50 / p99 / max (ms) | by output timestamp p50 / p99 (ms) | outputLatency + baseLatency (ms) | sample rate (Hz) | underruns / samples dropped / lead at the end (the arrivals' jitter over its last 4 s) (ms) | ticks | missed deadlines | tick work p99 (µs) | frames dropped |".into());
    line("|---|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|".into());
    for r in rows {
        line(r);
    }
    line(String::new());
    line("Where the sound's latency goes (per sound):".into());
    line(String::new());
    line("| scene | pages | tick → the worklet has it p50 / p99 (ms) | queued in the worklet until rendered p50 / p99 (ms) | the page's own part (the two added) p50 / p99 / max (ms) | outputLatency + baseLatency p50 / p99 (ms) |".into());
    line("|---|---|---|---|---|---|".into());
    for (scene, pages, p) in parts {
        let f = |l: Option<LatencyMs>| {
            l.map_or("–".into(), |l| format!("{:.1} / {:.1}", l.p50, l.p99))
        };
        line(format!(
            "| {scene} | {pages} | {} | {} | {} / {:.1} | {} |",
            f(p[0]),
            f(p[1]),
            f(p[3]),
            p[3].map_or(f64::NAN, |l| l.max),
            f(p[2])
        ));
    }
    line(String::new());
    let find = |scene: &str, label: &str| {
        outcomes
            .iter()
            .find(|(l, o)| o.scene == scene && l == label)
            .map(|(_, o)| o)
    };
    let verdict = |v: Verdict| v.bold();
    if let Some(o) = find("brickworld", "1") {
        let p99 = o.input.map_or(f64::INFINITY, |l| l.p99);
        line(format!(
            "- Browser input → applied force p99 ≤ 20 ms: {} ({p99:.1} ms with one page; {} without a browser).",
            verdict(Verdict::at_most(p99, 20.0)),
            find("brickworld", "0")
                .and_then(|o| o.input)
                .map_or("–".into(), |l| format!("{:.1} ms", l.p99))
        ));
        let s99 = o.sound.map_or(f64::INFINITY, |l| l.p99);
        let s50 = o.sound.map_or(f64::INFINITY, |l| l.p50);
        line(format!(
            "- Sound within 50 ms of its tick, the browser's output latency included: {} (p50 {s50:.1} ms, p99 {s99:.1} ms over {} sounds with one page; the output latency is the last column above).",
            verdict(Verdict::at_most(s99, 50.0)),
            o.sound.map_or(0, |l| l.n)
        ));
    }
    let fps: Vec<f64> = ["brickworld", "nanoworld"]
        .iter()
        .filter_map(|s| find(s, "1"))
        .flat_map(|o| o.fps.clone())
        .collect();
    if !fps.is_empty() {
        let min = fps.iter().copied().fold(f64::INFINITY, f64::min);
        line(format!(
            "- 60 frames/s drawn for the brick and nano worlds: {} (lowest {min:.1} frames/s with one page; 59.5 or more counts as 60).",
            verdict(Verdict::at_least(min, 59.5)),
        ));
    }
    if let Some(o) = find("brickworld", "3") {
        line(format!(
            "- 0 missed 1 kHz deadlines with three browsers watching one session: {} ({} of {} ticks; {} with no browser on the same machine).",
            verdict(Verdict::from_bool(o.missed_n == 0)),
            o.missed,
            o.ticks,
            find("brickworld", "0").map_or("–".into(), |b| b.missed.to_string())
        ));
    }
    line(String::new());
    line(
        "Notes. The sound is synthesised on the page (an AudioWorklet running `render --audio`'s synthesis) from \
         the ticks' sound input, which the server sends at once for a tick with a sound; the worklet plays a lead behind its own clock, \
         sized from the ticks' measured arrival jitter. The sound's own path is the first two columns of the second table; the rest is the browser's output \
         latency, here headless Chromium's fake output device; a real sound card's latency takes its place. Missed \
         deadlines: the real-time loop waits for each period by sleeping and then spinning on one core; on this shared \
         2-core machine the browsers (software rendering, no GPU), the DevTools driver of this bench and other jobs take \
         the cores too, so the tick thread is preempted (the row with no browser is the loop and the server alone). A \
         missed deadline sends zero force that tick and is recorded, so the session still replays bit for bit. The \
         deadline target needs a core the browsers do not share.".into(),
    );
    if let Some(path) = opt("--out") {
        if let Err(e) = std::fs::write(&path, md) {
            eprintln!("error: cannot write {path}: {e}");
            std::process::exit(1);
        }
    }
}
