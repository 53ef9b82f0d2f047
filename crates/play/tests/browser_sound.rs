//! The page's sound synthesis against `render --audio --proximity`: the AudioWorklet processor
//! the page plays with (`synth.js`), run in headless Chromium's `OfflineAudioContext` on the
//! golden recordings' sound ticks (the binary messages the publisher sends, 5 ticks each, the
//! sounds on their ticks), sample by sample against the Rust synthesis of the same recording at
//! the same sample rate.
//!
//! The live path (the FIFO, the lead sized from the arrivals' jitter, the guesses over late
//! messages, the underrun and drop logic, which the offline path skips): the same processor,
//! not offline, driven one 128-sample render quantum at a time by an audio clock in the page
//! (one quantum per device callback, as on the page's smallest output buffer), its sound ticks
//! delivered by a schedule of arrival times (the `play` publisher's blocks of
//! `PLAY_SOUND_BLOCK_TICKS` ticks, each sent when its last tick ends). No wall clock is
//! involved, so the schedule can promise what real time in headless Chromium on two shared
//! cores cannot: an idle page (each block arriving 2 ms after its last tick, plus up to 3 ms of
//! jitter) must play with 0 underruns and 0 drops, every sound sent, every sample of the track
//! but the few a guess over its latest messages concealed, every sound's own part the same,
//! its lead a few ms past the earliest arrival; a 50 ms stall is guessed over with no underrun;
//! a sound whose message is 20 ms late plays 20 ms plus at most a quantum after its tick; when
//! the jitter rises to 12 ms the lead follows it, the output waiting in silence, with no
//! underrun, and when it falls back the lead comes back and the output skips silent samples
//! to follow it (every sample played, concealed or skipped, each skip silence in the track);
//! eight 50 ms stalls are guessed over with no underrun and the lead is the idle page's after
//! them; a 300 ms stall over the first sound underruns, drops the backlog and still plays only
//! the track's samples, each sound played or lost once; a 355 ms start-up backlog is dropped
//! at once and is not taken for jitter; a restart (a lesson's next world) plays as an idle
//! page. The following itself is checked on a processor whose FIFO the test fills: it skips
//! and waits only in silence.
//!
//! The link worker's route (route.js), also clock-free: fed the server's own messages in a
//! lesson's order, it sends the worklet the first world's ticks, its finish, the restart and
//! the second world's ticks in that order, and counts what the page reads.
//!
//! Tolerance: none. The worklet computes in f64 as the Rust code does, with the same formulas
//! in the same order, and writes Float32 (the same round-to-nearest as Rust's `as f32`); only
//! the transcendental functions could differ (V8's `Math.sin`/`exp`/`pow` against glibc's,
//! each within an ulp of f64), and an f64 difference would show only where it straddles an
//! f32 rounding boundary, as a 1-ulp difference. On these recordings no sample differs at all
//! (Chromium 156, glibc 2.36), so the test asks for the same bits (0 ulp); should
//! another browser's libm differ in a last f64 bit, the bound to allow is 1 f32 ulp, about
//! 6e-8 of full scale.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::{Browser, base64_decode};
use common::live;
use common::page::{PageServer, base64, block};
use haptic_engine::runner::EndReason;
use haptic_loop::session::{SessionArrays, read_arrays};
use play::protocol::{ServerMsg, SoundKind, SoundOn, SoundTick, SoundTicks};
use serde_json::json;
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The recording's sound ticks as the `play` publisher sends them: blocks of
/// `PLAY_SOUND_BLOCK_TICKS` ticks (the offline test: 5), each tick's distance, the sounds on
/// their ticks with their index in the session's list.
fn sound_ticks(a: &SessionArrays, on_m: f64, block: u64) -> Vec<SoundTicks> {
    let dt = 1.0 / f64::from(a.rate_hz);
    let sounds = haptic_loop::sound::sound_events(a).unwrap();
    let nearest = a.state_column("nearest_m").unwrap();
    let ticks = a.tick.len() as u64;
    let mut out = Vec::new();
    let mut first = 0;
    while first < ticks {
        let end = (first + block).min(ticks);
        out.push(SoundTicks {
            first_tick: first,
            tone_on_distance_m: Some(on_m),
            ticks: (first..end)
                .map(|t| SoundTick {
                    wall_ms: 0.0,
                    nearest_m: nearest[t as usize],
                })
                .collect(),
            sounds: sounds
                .iter()
                .enumerate()
                .filter_map(|(i, e)| {
                    let tick = (e.t_s / dt).round() as u64;
                    let (kind, amplitude) = SoundKind::of(&e.sound);
                    (first..end).contains(&tick).then_some(SoundOn {
                        tick,
                        index: i as u32,
                        kind,
                        amplitude,
                    })
                })
                .collect(),
        });
        first = end;
    }
    out
}

/// Distance in f32 ulps between two finite samples (0: the same bits).
fn ulps(a: f32, b: f32) -> u32 {
    let key = |x: f32| {
        let i = x.to_bits() as i32;
        if i < 0 { i32::MIN - i } else { i }
    };
    key(a).abs_diff(key(b))
}

/// Renders the recording's sound in the page's worklet at `sr` Hz and compares it with
/// `render --audio --proximity` at `sr` Hz. Returns (samples, samples differing, max ulps,
/// max |difference|).
fn compare(b: &mut Browser, rec: &Path, kind: &str, sr: u32) -> (usize, usize, u32, f64) {
    let a = read_arrays(rec, false).unwrap();
    let on = haptic_loop::sound::proximity_on_distance_m(kind).unwrap();
    let want = haptic_loop::sound::session_sound(&a, kind, true, sr)
        .unwrap()
        .samples;
    let peak = want.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!(
        f64::from(peak) <= render::audio::CEILING,
        "no anti-clipping scale"
    );
    // The recording's sounds: the brick world's impacts, the nano world's snap and pull-off.
    let names: std::collections::BTreeSet<&str> = haptic_loop::sound::sound_events(&a)
        .unwrap()
        .iter()
        .map(|e| SoundKind::of(&e.sound).0.name())
        .collect();
    let expected: &[&str] = if kind == "nanoworld" {
        &["snap", "pull_off"]
    } else {
        &["thud"]
    };
    for n in expected {
        assert!(names.contains(n), "{kind}: {names:?}");
    }
    let blocks: Vec<String> = sound_ticks(&a, on, 5)
        .iter()
        .map(|m| base64(&m.encode()))
        .collect();
    let js = format!(
        r#"(async () => {{
  const ab = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0)).buffer;
  const blocks = {blocks}.map(ab);
  const ctx = new OfflineAudioContext(1, {n}, {sr});
  await ctx.audioWorklet.addModule('/synth.js');
  const node = new AudioWorkletNode(ctx, 'nh-synth', {{ numberOfInputs: 0, numberOfOutputs: 1,
    outputChannelCount: [1], processorOptions: {{ rateHz: {rate}, offline: {{ blocks, ticks: {ticks} }} }} }});
  node.connect(ctx.destination);
  const buf = await ctx.startRendering();
  const d = new Uint8Array(buf.getChannelData(0).buffer);
  let s = '';
  for (let i = 0; i < d.length; i += 0x8000) s += String.fromCharCode.apply(null, d.subarray(i, i + 0x8000));
  return btoa(s);
}})()"#,
        blocks = json!(blocks),
        n = want.len(),
        rate = a.rate_hz,
        ticks = a.tick.len(),
    );
    let got = base64_decode(b.eval(&js).unwrap().as_str().unwrap()).unwrap();
    let got: Vec<f32> = got
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(got.len(), want.len());
    let (mut differ, mut max_ulps, mut max_abs) = (0, 0, 0.0f64);
    for (g, w) in got.iter().zip(&want) {
        assert!(g.is_finite());
        if g.to_bits() != w.to_bits() {
            differ += 1;
        }
        max_ulps = max_ulps.max(ulps(*g, *w));
        max_abs = max_abs.max((f64::from(*g) - f64::from(*w)).abs());
    }
    // Not silence: the recording's impacts or snaps and its tone are in it.
    assert!(peak > 0.1, "{peak}");
    (want.len(), differ, max_ulps, max_abs)
}

#[test]
fn the_pages_worklet_makes_the_samples_of_render_audio() {
    let (mut b, server) = PageServer::open("nh-sound.mcap");
    let mut report = Vec::new();
    for (rec, kind) in [("brickworld", "brickworld"), ("nanoworld", "nanoworld")] {
        let path = workspace().join(format!("recordings/{rec}.mcap"));
        for sr in [48_000, 44_100] {
            let (n, differ, max_ulps, max_abs) = compare(&mut b, &path, kind, sr);
            let line = format!(
                "{rec} at {sr} Hz: {n} samples, {differ} differ from the Rust f32 samples, \
                 largest difference {max_ulps} ulp ({max_abs:.3e} of full scale)"
            );
            println!("{line}");
            // The same bits: no difference at all (see the tolerance above).
            assert_eq!((differ, max_ulps), (0, 0), "{line}");
            report.push(line);
        }
    }
    b.check().unwrap();
    server.close();
    assert_eq!(report.len(), 4);
}

/// How the live test's sound ticks reach the worklet: each block `delay_ms` after its last
/// tick ends, plus a jitter in [0, `jitter_ms`) (a fixed sequence; blocks keep their order;
/// from `from_ms` on, while a `phases` entry (from, to, jitter ms) covers it, that jitter
/// instead), and the blocks sent during a stall (from, to, ms) held until its end. With
/// `restart_ms`, the blocks due before it are a first stream, a restart comes then, and the
/// session's blocks again are the second, from that time on (a lesson's next world).
struct Link {
    delay_ms: f64,
    jitter_ms: f64,
    phases: Vec<(f64, f64, f64)>,
    stalls: Vec<(f64, f64)>,
    restart_ms: Option<f64>,
}

impl Link {
    fn idle() -> Link {
        Link {
            delay_ms: 2.0,
            jitter_ms: 3.0,
            phases: Vec::new(),
            stalls: Vec::new(),
            restart_ms: None,
        }
    }
}

/// The arrival time, ms, of each block (`ends`: when each block's last tick ends, ms).
fn arrivals(ends: &[f64], link: &Link) -> Vec<f64> {
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut last = 0.0f64;
    ends.iter()
        .map(|&end| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let jitter = link
                .phases
                .iter()
                .find(|p| (p.0..p.1).contains(&end))
                .map_or(link.jitter_ms, |p| p.2);
            let j = (x >> 11) as f64 / (1u64 << 53) as f64 * jitter;
            let mut t = end + link.delay_ms + j;
            for &(from, to) in &link.stalls {
                if (from..to).contains(&end) {
                    t = t.max(to);
                }
            }
            last = last.max(t);
            last
        })
        .collect()
}

/// What the live path heard, and its lead and jitter (ms) every 0.5 s of its clock: [clock
/// ms, lead past the earliest arrival ms, jitter ms].
struct LivePath {
    heard: live::Heard,
    leads: Vec<[f64; 3]>,
    lead_ms: f64,
    /// The messages' lateness past their window's earliest, ms: p50, p99, p99.9, the largest
    /// (each its 0.5 ms bin's start).
    spread_ms: [f64; 4],
    /// Each sound played: its tick, and its tick → first sample played, ms (the page's own
    /// part, on the schedule's clock).
    own_ms: Vec<(u64, f64)>,
}

/// Plays the recording's sound ticks through the worklet's live path at `sr` Hz over `link`,
/// checks what it heard against `render --audio --proximity` (common/live.rs) and returns it.
fn live_path(b: &mut Browser, rec: &Path, kind: &str, sr: u32, link: &Link) -> LivePath {
    let a = read_arrays(rec, false).unwrap();
    let on = haptic_loop::sound::proximity_on_distance_m(kind).unwrap();
    let msgs = sound_ticks(&a, on, play::publish::PLAY_SOUND_BLOCK_TICKS);
    let dt_ms = 1000.0 / f64::from(a.rate_hz);
    let ends: Vec<f64> = msgs
        .iter()
        .map(|m| (m.first_tick + m.ticks.len() as u64) as f64 * dt_ms)
        .collect();
    let at = arrivals(&ends, link);
    let blocks: Vec<String> = msgs.iter().map(|m| base64(&m.encode())).collect();
    let sent: Vec<[u64; 2]> = msgs
        .iter()
        .flat_map(|m| m.sounds.iter().map(|s| [s.tick, u64::from(s.index)]))
        .collect();
    let js = format!(
        r#"(async () => {{
  const ab = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0)).buffer;
  const blocks = {blocks}.map(ab), at = {at}, sr = {sr}, restartMs = {restart};
  // What reaches the port, when (ms): with a restart, the blocks due before it, the restart,
  // then every block again, that much later.
  const sched = [], off = restartMs === null ? 0 : restartMs;
  if (restartMs !== null) {{
    for (let i = 0; i < blocks.length && at[i] < restartMs; i++) sched.push([at[i], blocks[i]]);
    sched.push([restartMs, {{ restart: true }}]);
  }}
  for (let i = 0; i < blocks.length; i++) sched.push([at[i] + off, blocks[i]]);
  const src = await (await fetch('/synth.js')).text();
  // The AudioWorkletGlobalScope the processor sees: its base class and port, the context's
  // sample rate and time, registerProcessor.
  const reports = [];
  let Proc = null;
  globalThis.sampleRate = sr; globalThis.currentTime = 0;
  globalThis.AudioWorkletProcessor = class {{
    constructor() {{ this.port = {{ postMessage: (m) => reports.push({{ ...m, q: globalThis.quantum }}), onmessage: null }}; }}
  }};
  globalThis.registerProcessor = (name, cls) => {{ Proc = cls; }};
  new Function(src)();
  const p = new Proc({{ processorOptions: {{ rateHz: {rate}, leadS: {lead}, leadMaxS: {lead_max} }} }});
  const out = new Float32Array(128);
  let m = 0, finished = false;
  const leads = [], every = Math.round(sr / 2 / 128);
  for (let q = 0; q < 1e7 && !p.done; q++) {{
    const ms = q * 128 / sr * 1000;
    for (; m < sched.length && sched[m][0] <= ms; m++) p.port.onmessage({{ data: sched[m][1] }});
    // The page's `end` follows the last sound ticks.
    if (m === sched.length && !finished) {{ p.port.onmessage({{ data: {{ finish: {ticks} }} }}); finished = true; }}
    globalThis.currentTime = q * 128 / sr; globalThis.quantum = q;
    p.process([], [[out]]);
    if (q % every === 0) {{ const r = p.leadReport(); if (r.leadMs !== null) leads.push([ms - off, r.leadMs, r.jitterMs]); }}
  }}
  // The last stream's (the reports after a restart's `stream`).
  const last = reports.findIndex((r) => r.kind === 'stream');
  const onsets = reports.slice(last + 1).filter((r) => r.kind === 'onset');
  return {{
    leads,
    live: reports.find((r) => r.kind === 'done') || null,
    sound: {{
      sent: {sent},
      played: onsets.map((r) => [r.tick, r.index]),
      lost: reports.slice(last + 1).filter((r) => r.kind === 'lost').map((r) => [r.tick, r.index]),
      latencyMs: onsets.map(() => 0),
    }},
    // Each sound played: its tick, and when its first sample played, ms of the clock.
    onsetMs: onsets.map((r) => [r.tick, (r.q * 128 + r.frame) / sr * 1000 - off]),
  }};
}})()"#,
        blocks = json!(blocks),
        at = json!(at),
        rate = a.rate_hz,
        lead = LEAD_S,
        lead_max = LEAD_MAX_S,
        ticks = a.tick.len(),
        sent = json!(sent),
        restart = json!(link.restart_ms),
    );
    let v = b.eval(&js).unwrap();
    let restarts = u64::from(link.restart_ms.is_some());
    let heard = live::check_stream(&a, kind, &v["live"], &v["sound"], restarts);
    let leads = v["leads"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| [0, 1, 2].map(|k| r[k].as_f64().unwrap()))
        .collect();
    LivePath {
        heard,
        leads,
        lead_ms: v["live"]["leadMs"].as_f64().unwrap(),
        spread_ms: [0, 1, 2, 3].map(|k| v["live"]["spread"]["ms"][k].as_f64().unwrap()),
        own_ms: v["onsetMs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                let tick = r[0].as_u64().unwrap();
                (tick, r[1].as_f64().unwrap() - tick as f64 * dt_ms)
            })
            .collect(),
    }
}

/// The page's lead before the jitter is measured and its cap past the earliest arrival, s
/// (sound.js's LEAD_S and LEAD_MAX_S).
const LEAD_S: f64 = 0.005;
const LEAD_MAX_S: f64 = 0.03;
/// The worklet's margin over the largest lateness, ms (synth.js's MARGIN_S).
const MARGIN_MS: f64 = 1.0;

/// The lead past the earliest arrival the schedule's jitter calls for, ms: the jitter, the
/// arrival's wait for the next quantum (up to one, 128 samples), the margin.
fn lead_for(jitter_ms: f64, sr: u32) -> (f64, f64) {
    let quantum_ms = 128.0 / f64::from(sr) * 1000.0;
    (
        0.8 * jitter_ms + MARGIN_MS,
        jitter_ms + quantum_ms + MARGIN_MS + 0.01,
    )
}

/// The least and the most lead sampled with the clock in [from, to) ms.
fn lead_in(p: &LivePath, from: f64, to: f64) -> (f64, f64) {
    let v: Vec<f64> = p
        .leads
        .iter()
        .filter(|r| (from..to).contains(&r[0]))
        .map(|r| r[1])
        .collect();
    assert!(!v.is_empty(), "no lead sampled in {from}..{to} ms");
    (
        v.iter().copied().fold(f64::INFINITY, f64::min),
        v.iter().copied().fold(0.0, f64::max),
    )
}

/// A live path that played as the idle page `idle` did: every sound, each sound's own part
/// within a quantum of the idle page's, every sample of the track accounted for once, no
/// lead past the cap.
fn as_idle(p: &LivePath, idle: &LivePath, sr: u32) {
    let quantum_ms = 128.0 / f64::from(sr) * 1000.0;
    assert_eq!(p.own_ms.len(), idle.own_ms.len());
    for (&(tick, own), &(_, own_idle)) in p.own_ms.iter().zip(&idle.own_ms) {
        assert!(
            (own - own_idle).abs() <= quantum_ms,
            "tick {tick}: {own} ms, idle {own_idle} ms"
        );
    }
    let h = &p.heard;
    assert_eq!(h.accounted(), h.track_samples as u64);
    assert_eq!((h.played, h.lost), (h.sent, 0));
    capped(p);
}

/// Every lead sampled is at most the cap.
fn capped(p: &LivePath) {
    for &[ms, lead, _] in &p.leads {
        assert!(lead <= LEAD_MAX_S * 1000.0 + 1e-9, "{lead} ms at {ms} ms");
    }
}

#[test]
fn the_worklets_live_path_plays_the_samples_of_render_audio() {
    let sound_js = include_str!("../src/page/sound.js");
    for (name, v) in [("LEAD_S", LEAD_S), ("LEAD_MAX_S", LEAD_MAX_S)] {
        assert!(
            sound_js.contains(&format!("const {name} = {v};")),
            "the page's {name} is the test's"
        );
    }
    assert!(
        include_str!("../src/page/synth.js")
            .contains(&format!("MARGIN_S = {}", MARGIN_MS / 1000.0))
    );
    let (mut b, server) = PageServer::open("nh-sound-live.mcap");
    let stalled = || Link {
        stalls: vec![(1000.0, 1050.0)],
        ..Link::idle()
    };
    for (rec, kind, sr) in [
        ("brickworld", "brickworld", 48_000),
        ("nanoworld", "nanoworld", 44_100),
    ] {
        let path = workspace().join(format!("recordings/{rec}.mcap"));
        let idle = live_path(&mut b, &path, kind, sr, &Link::idle());
        let p = &idle;
        let h = &p.heard;
        println!(
            "{rec}, idle page, {sr} Hz: {h:?}, lead {} ms, spread {:?} ms, own part {:?} ms",
            p.lead_ms, p.spread_ms, p.own_ms
        );
        // An idle page: every sound, no underrun, no drop.
        assert_eq!((h.underruns, h.dropped), (0, 0), "{rec}: {h:?}");
        // The messages' lateness past their window's earliest (the probe, in 0.5 ms bins):
        // the 3 ms jitter plus the wait for the next quantum at most, most of the jitter at
        // least; the median within it.
        let (lo, hi) = lead_for(3.0, sr);
        let [p50, _, _, largest] = p.spread_ms;
        assert!(
            (lo - MARGIN_MS - 0.5..=hi - MARGIN_MS).contains(&largest),
            "{rec}: {:?}",
            p.spread_ms
        );
        assert!((0.5..=largest).contains(&p50), "{rec}: {:?}", p.spread_ms);
        // The messages later than the lead (the window's 95th percentile of lateness; the
        // nano world's 3 s are all the first lead's 5 ms, which its 5.5 ms jitter passes) are
        // guessed over: the brick world has none; the nano world's guesses, its tone moving,
        // differ from the track in a few samples, less than a quantum each.
        if kind == "brickworld" {
            assert_eq!((h.guesses, h.concealed), (0, 0), "{rec}: {h:?}");
        } else {
            assert!((1..=20).contains(&h.guesses), "{rec}: {h:?}");
            assert!(h.concealed < h.guesses * 128, "{rec}: {h:?}");
        }
        assert_eq!(h.accounted(), h.track_samples as u64);
        assert_eq!((h.played, h.lost), (h.sent, 0));
        assert!(h.sent > 0);
        // Its lead: the 3 ms jitter's once 4 s are measured (the brick world's 22 s); before
        // (the nano world's 3 s), at least the first lead, and at most the jitter's.
        let (lo, hi) = if h.track_samples as f64 / f64::from(sr) > 5.0 {
            lead_for(3.0, sr)
        } else {
            let first = (LEAD_S * f64::from(sr)).round() / f64::from(sr) * 1000.0;
            (first - 1e-9, lead_for(3.0, sr).1.max(first + 1e-9))
        };
        assert!((lo..=hi).contains(&p.lead_ms), "{rec}: {} ms", p.lead_ms);
        capped(p);
        // Each sound's own part (tick → its first sample played): the same for every sound,
        // to the sample (nothing moves the output on an idle page), and within the latest
        // arrival the schedule makes (the block's 2 ticks, the synthesis's one tick behind,
        // the 2 ms delay, the 3 ms jitter, a quantum) plus the first lead.
        let quantum_ms = 128.0 / f64::from(sr) * 1000.0;
        let own0 = idle.own_ms[0].1;
        for &(tick, own) in &idle.own_ms {
            assert!(
                (own - own0).abs() <= 1000.0 / f64::from(sr),
                "{rec}: tick {tick}: {own} ms, the first {own0} ms"
            );
        }
        assert!(
            (0.0..=5.0 + 3.0 + quantum_ms + LEAD_S * 1000.0).contains(&own0),
            "{rec}: {own0} ms"
        );
        let p = live_path(&mut b, &path, kind, sr, &stalled());
        let h = &p.heard;
        println!(
            "{rec}, a 50 ms stall, {sr} Hz: {h:?}, own part {:?} ms",
            p.own_ms
        );
        // A 50 ms stall: the worklet guessed over it (the last tick held), once more than the
        // idle page, and did not underrun; the brick world, silent then, was guessed to the
        // bit; the nano world's tone moves, so what was played while it stalled is concealed,
        // no more than the stall; every other
        // sample is the track's (checked in live_path).
        assert_eq!(
            (h.underruns, h.guesses),
            (0, idle.heard.guesses + 1),
            "{rec}: {h:?}"
        );
        let stall = (0.05 + 128.0 / f64::from(sr)) * f64::from(sr);
        let more = (h.concealed - idle.heard.concealed) as f64;
        if kind == "brickworld" {
            assert_eq!(h.concealed, 0, "{rec}: {h:?}");
        } else {
            assert!((1.0..=stall).contains(&more), "{rec}: {h:?}");
        }
        assert_eq!(h.accounted(), h.track_samples as u64);
        assert_eq!(h.played + h.lost, h.sent);
        capped(&p);
        // A 300 ms stall from 240 ms before the first sound: the backlog (about 300 ms, less
        // the lead's cap) is dropped at the end of the first whole 0.1 s window after it
        // arrives, from a playhead at most two windows (203 ms) past the stall's start, so
        // the drop covers the sound's first sample.
        let a = read_arrays(&path, false).unwrap();
        let first_ms = haptic_loop::sound::sound_events(&a).unwrap()[0].t_s * 1000.0;
        // The message with the first sound 20 ms late (the blocks ending in the 20 ms from its
        // tick held until then), its samples due before: the worklet guessed over it, then
        // played the sound at once, on the first sample not yet played, so its own part is
        // the 20 ms plus at most one quantum (waiting for the lead instead would have lost
        // its start or underrun); what it spans is concealed; every later sound's own part is
        // the idle page's.
        let late = Link {
            stalls: vec![(first_ms, first_ms + 20.0)],
            ..Link::idle()
        };
        let p = live_path(&mut b, &path, kind, sr, &late);
        let h = &p.heard;
        println!(
            "{rec}, its first sound's message 20 ms late, {sr} Hz: {h:?}, own part {:?} ms",
            p.own_ms
        );
        assert!(
            own0 < 20.0,
            "{rec}: the sound was due before its message came"
        );
        let own = p.own_ms[0].1;
        assert!(
            (20.0..=20.0 + quantum_ms + 1e-9).contains(&own),
            "{rec}: {own} ms"
        );
        assert_eq!(&p.own_ms[1..], &idle.own_ms[1..], "{rec}");
        assert_eq!((h.underruns, h.dropped, h.lost), (0, 0, 0), "{rec}: {h:?}");
        assert!(h.guesses >= 1 && h.concealed > 0, "{rec}: {h:?}");
        assert_eq!(h.accounted(), h.track_samples as u64);
        let over = Link {
            stalls: vec![(first_ms - 240.0, first_ms + 60.0)],
            ..Link::idle()
        };
        let p = live_path(&mut b, &path, kind, sr, &over);
        let h = &p.heard;
        println!(
            "{rec}, a 300 ms stall over its first sound (at {first_ms} ms), {sr} Hz: {h:?} own {:?} idle {:?}",
            p.own_ms, idle.own_ms
        );
        assert!(h.lost >= 1, "{rec}: {h:?}");
        assert!(h.underruns >= 1 && h.guesses >= 1, "{rec}: {h:?}");
        assert_eq!(h.played + h.lost, h.sent);
        capped(&p);
    }
    b.check().unwrap();
    server.close();
}

#[test]
fn the_worklets_lead_follows_the_arrivals_jitter_and_a_stall_is_guessed_over() {
    let (mut b, server) = PageServer::open("nh-sound-lead.mcap");
    let (rec, kind, sr) = ("brickworld", "brickworld", 44_100);
    let path = workspace().join(format!("recordings/{rec}.mcap"));
    let (idle_lo, idle_hi) = lead_for(3.0, sr);
    let (high_lo, high_hi) = lead_for(12.0, sr);
    // The jitter rises from 3 ms to 12 ms for 6 s, then falls back: the lead follows it up
    // within the 6 s and comes back 4 s after (the window), the excess then dropped.
    let jumpy = Link {
        phases: vec![(6000.0, 12_000.0, 12.0)],
        ..Link::idle()
    };
    let p = live_path(&mut b, &path, kind, sr, &jumpy);
    let h = &p.heard;
    let before = lead_in(&p, 4500.0, 6000.0);
    let high = lead_in(&p, 9000.0, 12_000.0);
    let after = lead_in(&p, 17_000.0, 21_000.0);
    println!(
        "jitter 3 → 12 → 3 ms: {h:?}; lead (least, most) {before:?} ms before, {high:?} ms at 12 ms, {after:?} ms after"
    );
    assert!(
        before.0 >= idle_lo && before.1 <= idle_hi,
        "{before:?} vs {idle_lo}..{idle_hi}"
    );
    assert!(
        high.0 >= high_lo && high.1 <= high_hi,
        "{high:?} vs {high_lo}..{high_hi}"
    );
    assert!(
        after.0 >= idle_lo && after.1 <= idle_hi,
        "{after:?} vs {idle_lo}..{idle_hi}"
    );
    // The rise: the late messages are guessed over while the window learns it, and the
    // output follows the lead's growth by waiting in the silence between the bricks' sounds,
    // so nothing underruns (it did, once or a few times, when only an underrun moved it);
    // the fall is skipped in silence, nothing dropped; every sample is played (the track's,
    // or concealed) or skipped.
    assert_eq!((h.underruns, h.dropped), (0, 0), "{h:?}");
    assert!(h.guesses > 0 && h.waited > 0 && h.skipped > 0, "{h:?}");
    assert_eq!(h.accounted(), h.track_samples as u64);
    assert_eq!(h.played + h.lost, h.sent);
    capped(&p);

    // The nano world with the jitter rising to 12 ms for its last second, while its tone
    // sounds and its two sounds start: no underrun; the guesses over its late messages are checked, each
    // sample played concealed at most once (a late sound's samples were concealed as played
    // up to the quantum's end, into the guess that followed, and again when its ticks came).
    let npath = workspace().join("recordings/nanoworld.mcap");
    let jumpy = Link {
        phases: vec![(2000.0, 3000.0, 12.0)],
        ..Link::idle()
    };
    let p = live_path(&mut b, &npath, "nanoworld", sr, &jumpy);
    let h = &p.heard;
    println!(
        "the nano world, jitter 3 -> 12 ms from 2 s: {h:?}, own {:?}",
        p.own_ms
    );
    assert!(h.guesses > 0 && h.concealed > 0, "{h:?}");
    assert_eq!(h.accounted(), h.track_samples as u64);
    assert_eq!((h.played, h.lost), (h.sent, 0));
    // The lead grows while the tone sounds: the output, ahead of it, guesses over the late
    // messages until the next silence (it underran once when the growth's underrun moved it).
    assert_eq!(h.underruns, 0, "{h:?}");

    // Eight 50 ms stalls, 2 s apart: each is guessed over and none underruns, the output
    // staying at its lead; 4 s after the last the lead is the idle page's again.
    let stalls: Vec<(f64, f64)> = (1..=8)
        .map(|k| (2000.0 * f64::from(k), 2000.0 * f64::from(k) + 50.0))
        .collect();
    let stalled = Link {
        stalls,
        ..Link::idle()
    };
    let p = live_path(&mut b, &path, kind, sr, &stalled);
    let h = &p.heard;
    let after = lead_in(&p, 20_600.0, 21_900.0);
    println!(
        "eight 50 ms stalls: {h:?}; lead {:?} ms after the last",
        after
    );
    assert_eq!(h.underruns, 0, "{h:?}");
    assert!(h.guesses >= 8, "{h:?}");
    // What a stall over a sounding brick guessed (the sound's decay, or a sound starting in
    // it played at once) is concealed: at most the stalls' own samples; the rest is the
    // track's to the bit.
    assert_eq!(h.dropped, 0, "{h:?}");
    assert!(h.concealed as f64 <= 8.0 * 0.05 * f64::from(sr), "{h:?}");
    assert_eq!(h.accounted(), h.track_samples as u64);
    assert_eq!(h.played + h.lost, h.sent);
    assert!(
        after.0 >= idle_lo && after.1 <= idle_hi,
        "{after:?} vs {idle_lo}..{idle_hi}"
    );
    capped(&p);

    // The worklet loading for the session's first 355 ms (three loaded pages measured that):
    // the ticks the link kept meanwhile come at once, the first 355 ms late, and a message
    // 20 ms late at 1 s. The backlog is dropped at once, up to a lead behind the clock (not
    // left to the trim, which keeps a quantum queued and leaves the output up to 5 ms behind
    // the lead), and is not the link's jitter: the late message is guessed over, not
    // underrun; from the first sound on, the lead is the idle page's, and every sound's own
    // part is the idle page's within a quantum.
    let idle = live_path(&mut b, &path, kind, sr, &Link::idle());
    let backlog = Link {
        stalls: vec![(0.0, 355.0), (1000.0, 1020.0)],
        ..Link::idle()
    };
    let p = live_path(&mut b, &path, kind, sr, &backlog);
    let h = &p.heard;
    let first_ms = idle.own_ms[0].0 as f64;
    println!(
        "a 355 ms start-up backlog: {h:?}; lead {:?} ms from the first sound at {first_ms} ms, {:?} ms after 4.5 s; own part {:?} ms (idle {:?} ms)",
        lead_in(&p, first_ms, 4500.0),
        lead_in(&p, 4500.0, 21_900.0),
        p.own_ms,
        idle.own_ms,
    );
    assert_eq!(h.underruns, 0, "{h:?}");
    assert!(h.guesses >= 1, "{h:?}");
    let (at, n) = h.drops[0];
    let n_ms = n as f64 / f64::from(sr) * 1000.0;
    assert!(
        at == 0 && (355.0 - 12.0..=355.0).contains(&n_ms),
        "{:?}",
        h.drops
    );
    let first_lead = (LEAD_S * f64::from(sr)).round() / f64::from(sr) * 1000.0;
    let (lo, hi) = lead_in(&p, first_ms, 4500.0);
    assert!(
        lo >= idle_lo.min(first_lead) && hi <= idle_hi.max(first_lead + 1e-9),
        "{lo}..{hi} ms vs {idle_lo}..{idle_hi} ms"
    );
    as_idle(&p, &idle, sr);

    // A lesson's next world: a restart after 2 s of a first stream, the session again from
    // its tick 0 (its lateness counted from another origin). The second stream is the idle
    // page's: its lead from 4.5 s on, every sound's own part within a quantum, nothing
    // guessed over, no underrun.
    let restarted = Link {
        restart_ms: Some(2000.0),
        ..Link::idle()
    };
    let p = live_path(&mut b, &path, kind, sr, &restarted);
    let h = &p.heard;
    println!(
        "a restart at 2 s: {h:?}; lead {:?} ms after 4.5 s; own part {:?} ms",
        lead_in(&p, 4500.0, 21_900.0),
        p.own_ms,
    );
    assert_eq!((h.underruns, h.dropped, h.concealed), (0, 0, 0), "{h:?}");
    let (lo, hi) = lead_in(&p, 4500.0, 21_900.0);
    assert!(
        lo >= idle_lo && hi <= idle_hi,
        "{lo}..{hi} ms vs {idle_lo}..{idle_hi} ms"
    );
    as_idle(&p, &idle, sr);
    b.check().unwrap();
    server.close();
}

/// The link's route (route.js), driven in the page with no socket and no clock: what reaches
/// the worklet's port, in order, and the counts the page reads. A lesson's second world
/// restarts the stream after the first world's finish and before its own first ticks; a
/// stopped session finishes after the last tick heard; a play session's second hello restarts
/// nothing; a gap is counted; ticks before the audio opens are counted but not kept; while the
/// worklet loads 2000 tick messages wait, and the finish after them; with no audio nothing does.
#[test]
fn the_links_route_keeps_restarts_and_finishes_in_the_order_of_the_ticks() {
    let (mut b, server) = PageServer::open("nh-sound-route.mcap");
    let msgs = ServerMsg::examples();
    let [hello, frame, stopped, lesson] = [0, 3, 6, 7].map(|i| msgs[i].to_json());
    assert!(
        stopped.contains(r#""end":"stopped","ticks":2000"#),
        "{stopped}"
    );
    let ServerMsg::End(mut e) = msgs[6].clone() else {
        panic!("the sixth example is an end")
    };
    e.end = EndReason::Completed;
    e.ticks = 4;
    let completed = ServerMsg::End(e).to_json();
    let js = format!(
        r#"(async () => {{
  const {{ SoundRoute }} = await import('/route.js');
  const ab = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0)).buffer;
  const [A, B, C, D] = [{a}, {b}, {c}, {d}];
  const [hello, frame, stopped, lesson, completed] = [{hello}, {frame}, {stopped}, {lesson}, {completed}];
  // The worklet's port: what it was sent, in order (a tick message by its first tick).
  const port = () => {{
    const got = [];
    return {{ got, postMessage: (m) => got.push(m instanceof ArrayBuffer ? `ticks ${{Number(new DataView(m).getBigUint64(0, true))}}` : JSON.stringify(m)) }};
  }};
  // A lesson: two worlds.
  const r = new SoundRoute(), p = port();
  const l = [r.text(lesson), r.text(hello), r.binary(ab(A), 1005), r.report()];
  r.audioOn();
  l.push(r.binary(ab(B), 1010), r.text(frame));
  r.connect(p);
  l.push(r.text(completed), r.text(lesson), r.text(hello), r.binary(ab(C), 2003), r.text(stopped), r.report(), r.report());
  // A play session: a gap, a second hello, an end.
  const r2 = new SoundRoute(), p2 = port();
  r2.text(hello); r2.audioOn(); r2.connect(p2);
  r2.binary(ab(A), 1001); r2.binary(ab(D), 1006); r2.text(hello); r2.text(completed);
  // The worklet loads: 2000 tick messages (B: ticks 2 and 3) wait of 2001, and the finish
  // after them, after tick 3.
  const r3 = new SoundRoute(), p3 = port();
  r3.text(hello); r3.audioOn();
  for (let i = 0; i < 2001; i++) r3.binary(ab(B), 0);
  r3.text(stopped); r3.connect(p3);
  // No audio in this browser: nothing is kept, nothing sent.
  const r4 = new SoundRoute(), p4 = port();
  r4.audioOn(); r4.binary(ab(A), 0); r4.audioNone(); r4.binary(ab(B), 0); r4.text(stopped); r4.connect(p4);
  return {{ lesson: [l, p.got], play: [p2.got, r2.report()], loading: [p3.got.length, p3.got[1999], p3.got[2000]], none: [p4.got, r4.report().messages] }};
}})()"#,
        a = json!(block(0, &[1000.0, 1001.0], &[[1, 0]])),
        b = json!(block(2, &[1002.0, 1003.0], &[])),
        c = json!(block(0, &[2000.0, 2001.0], &[[0, 0]])),
        d = json!(block(5, &[1005.0], &[])),
        hello = json!(hello),
        frame = json!(frame),
        stopped = json!(stopped),
        lesson = json!(lesson),
        completed = json!(completed),
    );
    let v = b.eval(&js).unwrap();
    // (Whole milliseconds come back from the page as integers.)
    let counts = |messages, ticks, sounds, first: i64, next, gaps, restarts, sent, link| {
        json!({"messages": messages, "ticks": ticks, "sounds": sounds, "firstTick": first,
            "nextTick": next, "gaps": gaps, "restarts": restarts, "overflow": 0, "sent": sent,
            "linkMs": link})
    };
    assert_eq!(
        v["lesson"],
        json!([
            [
                // The first lesson message and hello; A (its sound's tick 1 at 1001 ms) before
                // the audio: counted, not kept.
                true,
                true,
                1001,
                counts(1, 2, 1, 0, 2, 0, 0, json!([[1, 0]]), json!([4])),
                // B waits; a frame is no stream's start or end.
                null,
                false,
                // The step's end, the next lesson message, the next world's hello, its ticks
                // C, the lesson stopped.
                true,
                true,
                true,
                2000,
                true,
                counts(3, 6, 2, 0, 2, 0, 1, json!([[0, 0]]), json!([3])),
                null
            ],
            [
                "ticks 2",
                r#"{"finish":4}"#,
                r#"{"restart":true}"#,
                "ticks 0",
                r#"{"finish":2}"#
            ]
        ])
    );
    assert_eq!(
        v["play"],
        json!([
            ["ticks 0", "ticks 5", r#"{"finish":6}"#],
            counts(2, 3, 1, 0, 6, 1, 0, json!([[1, 0]]), json!([0]))
        ])
    );
    assert_eq!(v["loading"], json!([2001, "ticks 2", r#"{"finish":4}"#]));
    assert_eq!(v["none"], json!([[], 2]));
    b.check().unwrap();
    server.close();
}

/// The worklet's render-cadence probe, with the times given (no clock): quanta within 1 ms of
/// the one before are one callback; it reports the most frequent and the largest callback in
/// quanta and the ms between callbacks, p50 and p99.
#[test]
fn the_worklets_cadence_counts_the_quanta_of_each_callback_and_the_ms_between_them() {
    let (mut b, _server) = PageServer::open("nh-sound-cadence.mcap");
    let js = r#"(async () => {
  const src = await (await fetch('/synth.js')).text();
  globalThis.sampleRate = 44100; globalThis.currentTime = 0;
  globalThis.AudioWorkletProcessor = class {};
  globalThis.registerProcessor = () => {};
  const Cadence = new Function(src + '; return Cadence;')();
  // A device that renders 3 quanta every 9 ms, 98 times, then once 10 quanta after 40 ms.
  const c = new Cadence(), before = c.report();
  let t = 1000;
  for (let k = 0; k < 99; k++, t += 9) { c.quantum(t); c.quantum(t); c.quantum(t + 1); }
  t += 31;
  for (let q = 0; q < 10; q++) c.quantum(t + Math.floor(q / 2));
  c.quantum(t + 100);
  // One quantum every 3 ms (a regular clock, Date.now()'s whole ms: 2.9 ms steps).
  const r = new Cadence();
  for (let q = 0; q < 1000; q++) r.quantum(Math.floor(q * 128 / 44.1));
  return { before, bursts: c.report(), regular: r.report() };
})()"#;
    let v = b.eval(js).unwrap();
    assert_eq!(v["before"], serde_json::Value::Null);
    // 99 callbacks of 3 and one of 10 closed; 98 gaps of 9 ms, one of 40 and one of 100: the
    // p99 is the 99th of the 100 (nearest rank), 40.
    assert_eq!(
        v["bursts"],
        json!({"quanta": [3, 10], "ms": [9, 40], "callbacks": 100})
    );
    assert_eq!(
        v["regular"],
        json!({"quanta": [1, 1], "ms": [3, 3], "callbacks": 999})
    );
}

/// The output's following of the lead in silence (synth.js's `follow`), on a processor whose
/// FIFO, clock and lead the test sets, with no clock of its own: where the lead fell behind
/// the output by at most 5 ms, the silent samples queued are skipped, and no further than the
/// first sample that sounds (a tone starting, which no onset marks) or the next sound's first
/// sample; further behind, nothing is skipped (the trim's job); where the lead grew past the
/// output, it waits, up to the rest of the quantum, unless the next sample sounds.
#[test]
fn the_worklet_skips_and_waits_only_in_silence_to_follow_the_lead() {
    let (mut b, _server) = PageServer::open("nh-sound-follow.mcap");
    let js = r#"(async () => {
  const src = await (await fetch('/synth.js')).text();
  globalThis.sampleRate = 44100; globalThis.currentTime = 0;
  globalThis.AudioWorkletProcessor = class {
    constructor() { this.port = { postMessage: () => {}, onmessage: null }; }
  };
  let Proc = null;
  globalThis.registerProcessor = (name, cls) => { Proc = cls; };
  new Function(src)();
  // A processor whose FIFO holds `queued` from session sample 1000, its clock `behind`
  // samples past where the lead puts the output, `onset` the next sound's first sample.
  const run = (queued, behind, onset, at) => {
    const p = new Proc({ processorOptions: { rateHz: 1000, leadS: 0.005, leadMaxS: 0.03 } });
    p.fifo.clear(1000);
    for (const v of queued) p.fifo.push(v);
    p.lead = 220; p.clock = 1000 + 220 + behind - at;
    if (onset !== null) p.onsets = [[onset, 0, 0, 0, 0]];
    const out = new Float32Array(128).fill(7).fill(0, 0, at);
    const from = p.follow(out, at);
    return { from, first: p.fifo.first, skipped: p.skipped, waited: p.waited, dropped: p.dropped,
             skips: p.heard.skips, zeros: out.slice(0, from).every((v) => v === 0), untouched: out.slice(from).every((v) => v === 7) };
  };
  const z = (n) => new Array(n).fill(0);
  return {
    toTone: run([...z(3), 0.25, ...z(20)], 10, null, 0),
    toOnset: run(z(24), 10, 1002, 0),
    allSilent: run(z(24), 10, null, 0),
    tooFar: run(z(400), 222, null, 0),
    grew: run(z(24), -50, null, 0),
    grewPastQuantum: run(z(24), -300, null, 28),
    grewBeforeTone: run([0.25, ...z(23)], -50, null, 0),
  };
})()"#;
    let v = b.eval(js).unwrap();
    let get = |k: &str| {
        let r = &v[k];
        (
            r["from"].as_u64().unwrap(),
            r["first"].as_u64().unwrap(),
            r["skipped"].as_u64().unwrap(),
            r["waited"].as_u64().unwrap(),
        )
    };
    // (the frame it plays the FIFO from, the FIFO's first, skipped, waited)
    assert_eq!(get("toTone"), (0, 1003, 3, 0), "{v}");
    assert_eq!(v["toTone"]["skips"], json!([[1000, 3]]));
    assert_eq!(get("toOnset"), (0, 1002, 2, 0), "{v}");
    assert_eq!(get("allSilent"), (0, 1010, 10, 0), "{v}");
    // 222 samples (5.03 ms) behind: past TRIM_S (221 samples), left to the trim.
    assert_eq!(get("tooFar"), (0, 1000, 0, 0), "{v}");
    assert_eq!(get("grew"), (50, 1000, 0, 50), "{v}");
    assert_eq!(get("grewPastQuantum"), (128, 1000, 0, 100), "{v}");
    assert_eq!(get("grewBeforeTone"), (0, 1000, 0, 0), "{v}");
    for k in [
        "toTone",
        "toOnset",
        "allSilent",
        "tooFar",
        "grew",
        "grewPastQuantum",
        "grewBeforeTone",
    ] {
        assert_eq!(v[k]["dropped"], 0, "{k}");
        assert_eq!(
            (&v[k]["zeros"], &v[k]["untouched"]),
            (&json!(true), &json!(true)),
            "{k}: {v}"
        );
    }
}
