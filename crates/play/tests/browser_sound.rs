//! The page's sound synthesis against `render --audio --proximity`: the AudioWorklet processor
//! the page plays with (`synth.js`), run in headless Chromium's `OfflineAudioContext` on the
//! golden recordings' sound ticks (the binary messages the publisher sends, 5 ticks each, the
//! sounds on their ticks), sample by sample against the Rust synthesis of the same recording at
//! the same sample rate.
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
use haptic_loop::session::{SceneSource, SessionArrays, read_arrays};
use play::PlayConfig;
use play::protocol::{SoundKind, SoundOn, SoundTick, SoundTicks};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Standard base64 with padding.
fn base64(b: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(b.len().div_ceil(3) * 4);
    for c in b.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= c.len() {
                s.push(A[(n >> (18 - 6 * i)) as usize & 63] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// The recording's sound ticks as the publisher sends them: blocks of 5 ticks, each tick's
/// distance, the sounds on their ticks with their index in the session's list.
fn sound_ticks(a: &SessionArrays, on_m: f64) -> Vec<SoundTicks> {
    let dt = 1.0 / f64::from(a.rate_hz);
    let sounds = haptic_loop::sound::sound_events(a).unwrap();
    let nearest = a.state_column("nearest_m").unwrap();
    let ticks = a.tick.len() as u64;
    let mut out = Vec::new();
    let mut first = 0;
    while first < ticks {
        let end = (first + 5).min(ticks);
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
    let blocks: Vec<String> = sound_ticks(&a, on)
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
    // A server for the page's files (the session waits for a Start that never comes).
    let out = std::env::temp_dir().join(format!("nh-sound-{}.mcap", std::process::id()));
    let mut c = PlayConfig::new(SceneSource::resolve("wall".as_ref()).unwrap(), out);
    c.port = 0;
    let stop = Arc::new(AtomicBool::new(false));
    let play::Running { url, handle } = play::start(c, stop.clone()).unwrap();
    let mut b = Browser::launch(800, 600).unwrap();
    b.open(&url).unwrap();
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
    stop.store(true, Ordering::Relaxed);
    let _ = handle.join();
    assert_eq!(report.len(), 4);
}
