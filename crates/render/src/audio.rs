//! Sound from a session: impacts, contact clicks and a proximity tone, synthesised sample by
//! sample (a pure function of its inputs: the same events give the same samples), and WAV
//! writing (16-bit PCM mono, via the `hound` crate).
//!
//! - **Onsets**: a sound at time `t` starts at sample `round(t · sample_rate)` and its envelope
//!   rises from 0 over [`ATTACK_S`] (0.5 ms; its loudest sample comes later, on a crest of its
//!   carrier): onsets land on their event's tick within ±1 ms.
//! - **Loudness**: a sound of strength `x` (an impulse in N·s, a force in N) over its reference
//!   `x_ref` has peak amplitude `A = A_MAX · (1 − exp(−x / x_ref))`: it grows strictly with `x`
//!   and never exceeds [`A_MAX`].
//! - **No clipping**: sounds add up; if the sum would exceed [`CEILING`] anywhere, the whole
//!   track is scaled by `CEILING / peak` (so relative loudness is kept and |sample| ≤ 0.98).
//! - **Proximity tone** (an aid for blind students): while the distance to the nearest object
//!   is below the world's `on_distance`, a sine whose pitch rises from 220 Hz (at that distance)
//!   to 880 Hz (in contact), `f = 220 · 4^(1 − d/d_on)` Hz, at amplitude [`TONE_AMPLITUDE`];
//!   silent beyond it. Amplitude and pitch change smoothly between ticks (no clicks).

use std::path::Path;

use crate::error::{RenderError, out_of_range};

/// Largest peak amplitude of one sound.
pub const A_MAX: f64 = 0.8;
/// Largest |sample| of a track after the anti-clipping rule.
pub const CEILING: f64 = 0.98;
/// Rise time of every sound, s.
pub const ATTACK_S: f64 = 5e-4;
/// Amplitude of the proximity tone.
pub const TONE_AMPLITUDE: f64 = 0.12;
/// Default sample rate, Hz.
pub const SAMPLE_RATE_HZ: u32 = 44_100;

/// What made a collision sound (its timbre).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Impact {
    /// A brick on the ground: a low thud.
    BrickGround,
    /// A brick on a brick: a wooden clack.
    BrickBrick,
    /// The hand (cursor) on a brick or the ground: a short tap.
    Cursor,
}

/// A sound at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sound {
    /// A collision with its loudness (0–[`A_MAX`]).
    Impact {
        /// Which pair.
        kind: Impact,
        /// Peak amplitude.
        amplitude: f64,
    },
    /// Snap-to-contact: a bright click.
    Snap {
        /// Peak amplitude.
        amplitude: f64,
    },
    /// Pull-off: a lower pop with a falling pitch.
    PullOff {
        /// Peak amplitude.
        amplitude: f64,
    },
}

/// A sound and when it starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundEvent {
    /// Onset, s from the start of the session.
    pub t_s: f64,
    /// The sound.
    pub sound: Sound,
}

/// The loudness law: peak amplitude of a sound of strength `x` with reference `x_ref`.
pub fn amplitude(x: f64, x_ref: f64) -> f64 {
    if !(x.is_finite() && x > 0.0 && x_ref > 0.0) {
        return 0.0;
    }
    A_MAX * (1.0 - (-x / x_ref).exp())
}

/// The proximity tone's input: the distance to the nearest object per tick.
#[derive(Clone, Debug, PartialEq)]
pub struct Proximity {
    /// Tick length, s.
    pub dt_s: f64,
    /// Distance per tick, m (non-finite: nothing near).
    pub distance_m: Vec<f64>,
    /// Distance from which the tone sounds, m.
    pub on_distance_m: f64,
}

/// Pitch of the proximity tone at distance `d` (Hz), `None` when silent.
pub fn tone_hz(d: f64, on_distance_m: f64) -> Option<f64> {
    if !(d.is_finite() && d < on_distance_m && on_distance_m > 0.0) {
        return None;
    }
    let x = (1.0 - d.max(0.0) / on_distance_m).clamp(0.0, 1.0);
    Some(220.0 * 4f64.powf(x))
}

/// A tiny deterministic noise source (xorshift64*), for the noisy part of impacts.
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        let v = x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        v as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// One sound's waveform: (length s, sample at time τ after the onset, normalised to peak 1).
fn voice(sound: &Sound, seed: u64) -> (f64, Box<dyn FnMut(f64) -> f64>) {
    let attack = |tau: f64| (tau / ATTACK_S).min(1.0);
    let mut noise = Noise(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let tau2 = std::f64::consts::TAU;
    match *sound {
        Sound::Impact { kind, .. } => {
            let (f1, f2, decay, noise_mix) = match kind {
                Impact::BrickGround => (140.0, 310.0, 0.060, 0.35),
                Impact::BrickBrick => (520.0, 1250.0, 0.040, 0.25),
                Impact::Cursor => (900.0, 2100.0, 0.015, 0.15),
            };
            (
                6.0 * decay,
                Box::new(move |tau| {
                    let env = attack(tau) * (-tau / decay).exp();
                    let tone = 0.65 * (tau2 * f1 * tau).sin() + 0.35 * (tau2 * f2 * tau).sin();
                    env * ((1.0 - noise_mix) * tone + noise_mix * noise.next())
                }),
            )
        }
        Sound::Snap { .. } => (
            0.012,
            Box::new(move |tau| {
                let env = attack(tau) * (-tau / 0.002).exp();
                env * (tau2 * 2400.0 * tau).sin()
            }),
        ),
        Sound::PullOff { .. } => (
            0.05,
            Box::new(move |tau| {
                let env = attack(tau) * (-tau / 0.008).exp();
                // A falling chirp: 900 Hz → 300 Hz; phase = ∫ f dt.
                let phase = tau2 * (300.0 * tau + 600.0 * 0.01 * (1.0 - (-tau / 0.01).exp()));
                env * phase.sin()
            }),
        ),
    }
}

fn peak_of(sound: &Sound) -> f64 {
    match *sound {
        Sound::Impact { amplitude, .. }
        | Sound::Snap { amplitude }
        | Sound::PullOff { amplitude } => amplitude.clamp(0.0, A_MAX),
    }
}

/// The samples one sound adds to the track: its first sample index and `g · wave(k / sr)` for
/// each sample `k` of its voice (`None` for a sound that adds nothing). `index` is the sound's
/// place in the session's list of sounds (it seeds the noise of impacts).
fn event_samples(e: &SoundEvent, index: usize, sr: f64) -> Option<(usize, Vec<f64>)> {
    if !(e.t_s.is_finite() && e.t_s >= 0.0) {
        return None;
    }
    let a = peak_of(&e.sound);
    if a == 0.0 {
        return None;
    }
    let start = (e.t_s * sr).round() as usize;
    let (len_s, mut wave) = voice(&e.sound, index as u64 + 1);
    let len = (len_s * sr).ceil() as usize;
    // Normalise the waveform's peak to 1 (it depends on the timbre only).
    let mut norm = 0.0f64;
    let samples: Vec<f64> = (0..len)
        .map(|k| {
            let v = wave(k as f64 / sr);
            norm = norm.max(v.abs());
            v
        })
        .collect();
    let g = if norm > 0.0 { a / norm } else { 0.0 };
    Some((start, samples.iter().map(|v| g * v).collect()))
}

/// Synthesises `duration_s` of sound at `sample_rate_hz`: the events, and the proximity tone
/// when given. Deterministic; |sample| ≤ [`CEILING`].
pub fn synthesize(
    events: &[SoundEvent],
    proximity: Option<&Proximity>,
    duration_s: f64,
    sample_rate_hz: u32,
) -> Result<Vec<f32>, RenderError> {
    if !(8_000..=192_000).contains(&sample_rate_hz) {
        return Err(out_of_range(
            "sample_rate_hz",
            f64::from(sample_rate_hz),
            "8000–192000 Hz",
        ));
    }
    if !(duration_s.is_finite() && (0.0..=3600.0).contains(&duration_s)) {
        return Err(out_of_range("duration_s", duration_s, "0–3600 s"));
    }
    let sr = f64::from(sample_rate_hz);
    let n = (duration_s * sr).round() as usize;
    let mut out = vec![0.0f64; n];
    for (i, e) in events.iter().enumerate() {
        if let Some((start, samples)) = event_samples(e, i, sr) {
            for (k, v) in samples.iter().enumerate() {
                if let Some(o) = out.get_mut(start + k) {
                    *o += v;
                }
            }
        }
    }
    if let Some(p) = proximity {
        tone(&mut out, p, sr);
    }
    let peak = out.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scale = if peak > CEILING { CEILING / peak } else { 1.0 };
    Ok(out.iter().map(|v| (v * scale) as f32).collect())
}

/// The proximity tone's running state: phase (rad) and the pitch last sounded (Hz).
#[derive(Clone, Copy, Debug)]
struct ToneState {
    phase: f64,
    last_f: f64,
}

impl ToneState {
    fn new() -> Self {
        ToneState {
            phase: 0.0,
            last_f: 220.0,
        }
    }

    /// The tone's sample `k`; `at(i)` is (pitch Hz, amplitude) at tick `i` ((0, 0): silent).
    fn sample(&mut self, k: usize, sr: f64, dt_s: f64, at: &dyn Fn(usize) -> (f64, f64)) -> f64 {
        let t = k as f64 / sr / dt_s;
        let i = t.floor() as usize;
        let w = t - t.floor();
        let ((f0, a0), (f1, a1)) = (at(i), at(i + 1));
        let amp = a0 * (1.0 - w) + a1 * w;
        // While fading in or out, keep the pitch of the sounding side.
        let f = match (a0 > 0.0, a1 > 0.0) {
            (true, true) => f0 * (1.0 - w) + f1 * w,
            (true, false) => f0,
            (false, true) => f1,
            (false, false) => self.last_f,
        };
        self.last_f = f;
        self.phase = (self.phase + std::f64::consts::TAU * f / sr) % std::f64::consts::TAU;
        amp * self.phase.sin()
    }
}

/// Pitch and amplitude of the tone at distance `d` ((0, 0) when silent).
fn tone_at(d: Option<f64>, on_distance_m: f64) -> (f64, f64) {
    match d.and_then(|d| tone_hz(d, on_distance_m)) {
        Some(f) => (f, TONE_AMPLITUDE),
        None => (0.0, 0.0),
    }
}

/// Adds the proximity tone: pitch and amplitude interpolated linearly between tick centres,
/// phase continuous.
fn tone(out: &mut [f64], p: &Proximity, sr: f64) {
    if p.distance_m.is_empty() || p.dt_s.is_nan() || p.dt_s <= 0.0 {
        return;
    }
    let at = |i: usize| tone_at(p.distance_m.get(i).copied(), p.on_distance_m);
    let mut state = ToneState::new();
    for (k, o) in out.iter_mut().enumerate() {
        *o += state.sample(k, sr, p.dt_s, &at);
    }
}

/// The same synthesis as [`synthesize`], fed tick by tick during a live session: the sounds
/// and distances of each tick go in as the tick ends, and every sample whose inputs are all
/// known comes out.
///
/// A streamed track equals [`synthesize`]'s over the same sounds, distances and duration
/// sample for sample (the same `f64` sums in the same order, then the cast to `f32`), as long
/// as the whole track needs no anti-clipping scale (its peak ≤ [`CEILING`]). When it does, the
/// offline track is scaled as a whole, which a live stream cannot know in advance: the
/// streamed samples beyond ±[`CEILING`] are limited to it instead, and
/// [`StreamSynth::limited`] counts them.
///
/// Latency: sample `k` needs the distance of the tick after the one it falls in (the tone is
/// interpolated between tick centres), so it comes out at most two ticks after its time.
///
/// The browser game synthesises its sound with a port of this type, formula for formula, at
/// the page's sample rate: `crates/play/src/page/synth.js` (an AudioWorklet processor). A
/// change here is a change there; `crates/play/tests/browser_sound.rs` compares the two sample
/// by sample on the golden recordings.
#[derive(Debug)]
pub struct StreamSynth {
    sr: f64,
    dt_s: f64,
    on_distance_m: Option<f64>,
    /// Sounds placed so far (the next one's index).
    placed: usize,
    /// Index of the next sample to emit.
    next_sample: usize,
    /// Sums of the sounds from `next_sample` on (grown as sounds are placed).
    pending: std::collections::VecDeque<f64>,
    /// Distances of ticks `base_tick ..`, m (non-finite: nothing near).
    distances: std::collections::VecDeque<f64>,
    base_tick: usize,
    ticks: usize,
    tone: ToneState,
    limited: u64,
}

impl StreamSynth {
    /// A stream at `sample_rate_hz` (8000–192000) for ticks of `dt_s` s (> 0, finite); with
    /// `proximity_on_distance_m`, the proximity tone sounds below that distance, m.
    pub fn new(
        sample_rate_hz: u32,
        dt_s: f64,
        proximity_on_distance_m: Option<f64>,
    ) -> Result<Self, RenderError> {
        if !(8_000..=192_000).contains(&sample_rate_hz) {
            return Err(out_of_range(
                "sample_rate_hz",
                f64::from(sample_rate_hz),
                "8000–192000 Hz",
            ));
        }
        if !(dt_s.is_finite() && dt_s > 0.0 && dt_s <= 1.0) {
            return Err(out_of_range("dt_s", dt_s, "0 < dt_s ≤ 1 s"));
        }
        Ok(StreamSynth {
            sr: f64::from(sample_rate_hz),
            dt_s,
            on_distance_m: proximity_on_distance_m,
            placed: 0,
            next_sample: 0,
            pending: std::collections::VecDeque::new(),
            distances: std::collections::VecDeque::new(),
            base_tick: 0,
            ticks: 0,
            tone: ToneState::new(),
            limited: 0,
        })
    }

    /// Places a sound (call for each sound of a tick, in order, before [`StreamSynth::tick`]
    /// of that tick). A sound whose onset was already emitted loses its emitted part.
    pub fn push(&mut self, e: &SoundEvent) {
        let i = self.placed;
        self.placed += 1;
        let Some((start, samples)) = event_samples(e, i, self.sr) else {
            return;
        };
        for (k, v) in samples.iter().enumerate() {
            let Some(rel) = (start + k).checked_sub(self.next_sample) else {
                continue;
            };
            if self.pending.len() <= rel {
                self.pending.resize(rel + 1, 0.0);
            }
            self.pending[rel] += v;
        }
    }

    /// Ends a tick with its distance to the nearest object, m (ignored without the tone), and
    /// appends the samples now complete to `out`.
    pub fn tick(&mut self, distance_m: f64, out: &mut Vec<f32>) {
        self.distances.push_back(distance_m);
        self.ticks += 1;
        self.emit(None, out);
    }

    /// Ends the stream after `duration_s` s (the offline track's length: `ticks · dt_s`) and
    /// appends the remaining samples to `out`.
    pub fn finish(&mut self, duration_s: f64, out: &mut Vec<f32>) {
        let n = (duration_s * self.sr).round() as usize;
        self.emit(Some(n), out);
    }

    /// Samples emitted so far.
    pub fn emitted(&self) -> usize {
        self.next_sample
    }

    /// Samples limited to ±[`CEILING`] so far (0 when the stream equals the offline track).
    pub fn limited(&self) -> u64 {
        self.limited
    }

    fn emit(&mut self, end: Option<usize>, out: &mut Vec<f32>) {
        let (sr, dt) = (self.sr, self.dt_s);
        loop {
            let k = self.next_sample;
            if end.is_some_and(|n| k >= n) {
                break;
            }
            let t = k as f64 / sr / dt;
            let i = t.floor() as usize;
            // The tone reads ticks i and i + 1: wait for both (unless the stream ended).
            if end.is_none() && i + 1 >= self.ticks {
                break;
            }
            let mut v = self.pending.pop_front().unwrap_or(0.0);
            if let Some(on) = self.on_distance_m {
                let base = self.base_tick;
                let d = &self.distances;
                let at = |j: usize| {
                    let d = j.checked_sub(base).and_then(|r| d.get(r).copied());
                    tone_at(d, on)
                };
                v += self.tone.sample(k, sr, dt, &at);
            }
            if v.abs() > CEILING {
                self.limited += 1;
                v = CEILING.copysign(v);
            }
            out.push(v as f32);
            self.next_sample += 1;
            // Drop distances no later sample reads.
            while self.base_tick < i && !self.distances.is_empty() {
                self.distances.pop_front();
                self.base_tick += 1;
            }
        }
    }
}

/// Writes samples as a 16-bit PCM mono WAV file.
pub fn write_wav(path: &Path, samples: &[f32], sample_rate_hz: u32) -> Result<(), RenderError> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: sample_rate_hz,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let err = |e: hound::Error| RenderError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let mut w = hound::WavWriter::create(path, spec).map_err(err)?;
    for s in samples {
        let v = (f64::from(*s).clamp(-1.0, 1.0) * 32767.0).round() as i16;
        w.write_sample(v).map_err(err)?;
    }
    w.finalize().map_err(err)
}

#[cfg(test)]
#[path = "audio/tests.rs"]
mod tests;
