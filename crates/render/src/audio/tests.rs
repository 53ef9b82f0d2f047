//! Tests of the synthesis (`audio.rs`): onsets, loudness, the sound table, the documented
//! constants, sample-rate independence and the WAV writer.

use super::*;

fn impact(t_s: f64, impulse: f64) -> SoundEvent {
    SoundEvent {
        t_s,
        sound: Sound::Impact {
            kind: Impact::BrickGround,
            amplitude: amplitude(impulse, 0.2),
        },
    }
}

/// First sample whose |value| reaches 10 % of the track's peak after `from`.
fn onset(s: &[f32], from: usize) -> usize {
    let peak = s[from..].iter().fold(0.0f32, |m, v| m.max(v.abs()));
    from + s[from..]
        .iter()
        .position(|v| v.abs() >= 0.1 * peak)
        .unwrap_or(0)
}

#[test]
fn onsets_land_within_a_millisecond() {
    for t in [0.1, 0.2503, 1.0] {
        let s = synthesize(&[impact(t, 0.5)], None, 1.5, SAMPLE_RATE_HZ).unwrap();
        let got = onset(&s, 0) as f64 / f64::from(SAMPLE_RATE_HZ);
        assert!((got - t).abs() <= 1e-3, "onset {got} for {t}");
        assert!(got >= t - 1.0 / f64::from(SAMPLE_RATE_HZ));
    }
}

#[test]
fn louder_with_a_larger_impulse_and_never_clipping() {
    let peaks: Vec<f32> = [0.01, 0.05, 0.2, 1.0, 5.0]
        .iter()
        .map(|j| {
            let s = synthesize(&[impact(0.01, *j)], None, 0.5, SAMPLE_RATE_HZ).unwrap();
            s.iter().fold(0.0f32, |m, v| m.max(v.abs()))
        })
        .collect();
    assert!(peaks.windows(2).all(|w| w[1] > w[0]), "{peaks:?}");
    assert!(peaks.iter().all(|p| f64::from(*p) <= A_MAX + 1e-6));
    // 200 loud overlapping impacts: scaled down to the ceiling, not clipped.
    let many: Vec<SoundEvent> = (0..200)
        .map(|i| impact(0.1 + i as f64 * 1e-4, 10.0))
        .collect();
    let s = synthesize(&many, None, 0.5, SAMPLE_RATE_HZ).unwrap();
    let peak = s.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!((f64::from(peak) - CEILING).abs() < 1e-6, "{peak}");
}

#[test]
fn the_proximity_tone_rises_as_the_cursor_nears_and_is_silent_when_far() {
    assert_eq!(tone_hz(0.2, 0.1), None);
    assert_eq!(tone_hz(f64::INFINITY, 0.1), None);
    assert_eq!(tone_hz(0.0, 0.1), Some(880.0));
    let f: Vec<f64> = [0.09, 0.05, 0.01]
        .iter()
        .map(|d| tone_hz(*d, 0.1).unwrap())
        .collect();
    assert!(f.windows(2).all(|w| w[1] > w[0]));
    // Far for 0.5 s, near for 0.5 s at 1 kHz ticks: silence, then a tone.
    let mut d = vec![1.0; 500];
    d.extend(vec![0.0; 500]);
    let p = Proximity {
        dt_s: 1e-3,
        distance_m: d,
        on_distance_m: 0.1,
    };
    let s = synthesize(&[], Some(&p), 1.0, SAMPLE_RATE_HZ).unwrap();
    assert!(s[..22_000].iter().all(|v| *v == 0.0));
    let near = &s[23_000..44_000];
    let peak = near.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!((f64::from(peak) - TONE_AMPLITUDE).abs() < 1e-3);
    // 880 Hz: count zero crossings over 21 000 samples (0.476 s): about 2 · 880 · 0.476.
    let crossings = near
        .windows(2)
        .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
        .count();
    assert!(
        (crossings as f64 - 2.0 * 880.0 * 21_000.0 / 44_100.0).abs() < 4.0,
        "{crossings}"
    );
}

#[test]
fn deterministic_and_bad_settings_named() {
    let e = [impact(0.1, 0.3)];
    assert_eq!(
        synthesize(&e, None, 0.5, SAMPLE_RATE_HZ).unwrap(),
        synthesize(&e, None, 0.5, SAMPLE_RATE_HZ).unwrap()
    );
    assert_eq!(
        synthesize(&e, None, 0.5, 100).unwrap_err().to_string(),
        "sample_rate_hz = 100 is out of range: allowed 8000–192000 Hz"
    );
    assert_eq!(
        synthesize(&e, None, f64::NAN, SAMPLE_RATE_HZ)
            .unwrap_err()
            .to_string(),
        "duration_s = NaN is out of range: allowed 0–3600 s"
    );
}

#[test]
fn a_wav_file_reads_back() {
    // Under target/, beside the test binary.
    let dir = std::env::current_exe().unwrap().with_file_name("test-tmp");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("nh-audio-{}.wav", std::process::id()));
    let s = synthesize(&[impact(0.01, 0.3)], None, 0.1, SAMPLE_RATE_HZ).unwrap();
    write_wav(&p, &s, SAMPLE_RATE_HZ).unwrap();
    let r = hound::WavReader::open(&p).unwrap();
    assert_eq!(r.spec().sample_rate, SAMPLE_RATE_HZ);
    assert_eq!(r.len() as usize, s.len());
}

#[test]
fn the_stream_equals_the_offline_track_sample_for_sample() {
    // 3 s at 1 kHz ticks: overlapping sounds of every kind (one at tick 0, two on one
    // tick, one near the end cut by the duration) and a cursor that nears and leaves.
    let dt = 1e-3;
    let ticks = 3000usize;
    let d: Vec<f64> = (0..ticks)
        .map(|i| match i {
            0..=399 => f64::INFINITY,
            400..=1999 => 0.15 - 0.1 * (i as f64 * 3e-3).sin().abs(),
            _ => 0.5,
        })
        .collect();
    let at = |tick: u64, sound: Sound| SoundEvent {
        t_s: tick as f64 * dt,
        sound,
    };
    let events = vec![
        at(0, Sound::Snap { amplitude: 0.3 }),
        at(
            417,
            Sound::Impact {
                kind: Impact::BrickGround,
                amplitude: 0.5,
            },
        ),
        at(
            417,
            Sound::Impact {
                kind: Impact::Cursor,
                amplitude: 0.2,
            },
        ),
        at(
            430,
            Sound::Impact {
                kind: Impact::BrickBrick,
                amplitude: 0.25,
            },
        ),
        at(1201, Sound::PullOff { amplitude: 0.4 }),
        at(
            2990,
            Sound::Impact {
                kind: Impact::BrickGround,
                amplitude: 0.6,
            },
        ),
    ];
    for sr in [SAMPLE_RATE_HZ, 48_000, 8_000] {
        let p = Proximity {
            dt_s: dt,
            distance_m: d.clone(),
            on_distance_m: 0.1,
        };
        let offline = synthesize(&events, Some(&p), ticks as f64 * dt, sr).unwrap();
        let mut s = StreamSynth::new(sr, dt, Some(0.1)).unwrap();
        let mut out = Vec::new();
        for (i, di) in d.iter().enumerate() {
            for e in events.iter().filter(|e| (e.t_s / dt).round() as usize == i) {
                s.push(e);
            }
            s.tick(*di, &mut out);
            // Never more than two ticks behind.
            assert!(out.len() as f64 >= (i as f64 - 1.0) * dt * f64::from(sr) - 1.0);
        }
        s.finish(ticks as f64 * dt, &mut out);
        assert_eq!(s.limited(), 0);
        assert_eq!(out.len(), offline.len());
        let differ = out
            .iter()
            .zip(&offline)
            .filter(|(a, b)| a.to_bits() != b.to_bits());
        assert_eq!(differ.count(), 0, "at {sr} Hz");
        assert!(out.iter().any(|v| *v != 0.0));
    }
    // Without the tone as well.
    let offline = synthesize(&events, None, 1.0, SAMPLE_RATE_HZ).unwrap();
    let mut s = StreamSynth::new(SAMPLE_RATE_HZ, dt, None).unwrap();
    let mut out = Vec::new();
    for i in 0..1000 {
        for e in events.iter().filter(|e| (e.t_s / dt).round() as usize == i) {
            s.push(e);
        }
        s.tick(0.0, &mut out);
    }
    s.finish(1.0, &mut out);
    assert_eq!(out, offline);
    assert_eq!(
        StreamSynth::new(100, dt, None).unwrap_err().to_string(),
        "sample_rate_hz = 100 is out of range: allowed 8000–192000 Hz"
    );
    assert_eq!(
        StreamSynth::new(SAMPLE_RATE_HZ, 0.0, None)
            .unwrap_err()
            .to_string(),
        "dt_s = 0 is out of range: allowed 0 < dt_s ≤ 1 s"
    );
}

#[test]
fn a_stream_too_loud_is_limited_and_says_so() {
    let loud: Vec<SoundEvent> = (0..20).map(|_| impact(0.01, 10.0)).collect();
    let mut s = StreamSynth::new(SAMPLE_RATE_HZ, 1e-3, None).unwrap();
    let mut out = Vec::new();
    for i in 0..100 {
        if i == 10 {
            for e in &loud {
                s.push(e);
            }
        }
        s.tick(0.0, &mut out);
    }
    s.finish(0.1, &mut out);
    assert!(s.limited() > 0);
    let peak = out.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert_eq!(f64::from(peak), CEILING as f32 as f64);
}

/// `voice`'s waveform sampled at 1 MHz over its whole length (noise seed 1).
fn wave_1mhz(sound: &Sound) -> Vec<f64> {
    let (len_s, mut w) = voice(sound, 1);
    (0..(len_s * 1e6) as usize)
        .map(|k| w(k as f64 * 1e-6))
        .collect()
}

/// Magnitude of the DFT of `x` (sampled at `sr`) at `f` Hz.
fn dft(x: &[f64], sr: f64, f: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let a = std::f64::consts::TAU * f * k as f64 / sr;
        re += v * a.cos();
        im += v * a.sin();
    }
    re.hypot(im)
}

/// The frequency (1 Hz steps) in `lo..=hi` where `x`'s spectrum is largest.
fn spectral_peak(x: &[f64], sr: f64, lo: u32, hi: u32) -> f64 {
    (lo..=hi)
        .map(f64::from)
        .map(|f| (f, dft(x, sr, f)))
        .fold((0.0, -1.0), |b, c| if c.1 > b.1 { c } else { b })
        .0
}

/// Decay time, s, of `x` (sampled at 1 MHz) between `from_s` and `to_s`: a least-squares
/// line through the logarithm of the local maxima of |x| (one per half period).
fn decay_s(x: &[f64], from_s: f64, to_s: f64) -> f64 {
    let pts: Vec<(f64, f64)> = (1..x.len() - 1)
        .filter(|&k| {
            let t = k as f64 * 1e-6;
            t >= from_s && t <= to_s && x[k].abs() > x[k - 1].abs() && x[k].abs() >= x[k + 1].abs()
        })
        .map(|k| (k as f64 * 1e-6, x[k].abs().ln()))
        .collect();
    let n = pts.len() as f64;
    let (mt, my) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, y)| (a + t / n, b + y / n));
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(a, b), (t, y)| {
        (a + (t - mt) * (y - my), b + (t - mt) * (t - mt))
    });
    -sxx / sxy
}

/// docs/render.md's sound table: the carriers and decays of each sound, measured on the
/// waveforms: the impacts' two carriers as the peaks of their spectra (1 Hz steps) and
/// their decay as their length (6 decay times); the snap's 2.4 kHz by its zero crossings
/// and its 2 ms decay from its peaks; the pull-off's 900 → 300 Hz from its first and last
/// half periods and its 8 ms decay from its peaks.
#[test]
fn the_sound_table_carriers_and_decays() {
    let sr = 44_100.0;
    for (kind, f1, f2, decay) in [
        (Impact::BrickGround, 140.0, 310.0, 0.060),
        (Impact::BrickBrick, 520.0, 1250.0, 0.040),
        (Impact::Cursor, 900.0, 2100.0, 0.015),
    ] {
        let e = SoundEvent {
            t_s: 0.0,
            sound: Sound::Impact {
                kind,
                amplitude: 0.5,
            },
        };
        let (start, x) = event_samples(&e, 0, sr).unwrap();
        assert_eq!(start, 0);
        // the last nonzero sample closes 6 decay times
        let last = x.iter().rposition(|v| *v != 0.0).unwrap();
        assert_eq!(last + 1, (6.0 * decay * sr).ceil() as usize, "{kind:?}");
        // the carriers: the spectrum's peaks within ±35 % of each
        let p1 = spectral_peak(&x, sr, (f1 * 0.65) as u32, (f1 * 1.35) as u32);
        let p2 = spectral_peak(&x, sr, (f2 * 0.8) as u32, (f2 * 1.2) as u32);
        assert!((p1 - f1).abs() <= 2.0, "{kind:?}: {p1} Hz, not {f1}");
        assert!((p2 - f2).abs() <= 2.0, "{kind:?}: {p2} Hz, not {f2}");
    }
    // the snap: 2.4 kHz, 2 ms
    let snap = wave_1mhz(&Sound::Snap { amplitude: 0.5 });
    assert_eq!(snap.len(), 12_000);
    let crossings = snap
        .windows(2)
        .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
        .count();
    let f = crossings as f64 / 2.0 / 0.012;
    assert!((f - 2400.0).abs() < 50.0, "snap at {f} Hz");
    let d = decay_s(&snap, 1e-3, 10e-3);
    assert!((d - 2e-3).abs() < 0.05e-3, "snap decay {d} s");
    // the pull-off: 900 → 300 Hz, 8 ms
    let pop = wave_1mhz(&Sound::PullOff { amplitude: 0.5 });
    let zeros: Vec<usize> = (1..pop.len())
        .filter(|&k| (pop[k - 1] < 0.0) != (pop[k] < 0.0))
        .collect();
    let half = |a: usize, b: usize| 1e6 / 2.0 / (b - a) as f64;
    let (first, last) = (
        half(0, zeros[0]),
        half(zeros[zeros.len() - 2], zeros[zeros.len() - 1]),
    );
    eprintln!("pull-off: first half period {first} Hz, last {last} Hz");
    assert!(
        (first - 900.0).abs() < 50.0,
        "pull-off starts at {first} Hz"
    );
    assert!((last - 300.0).abs() < 50.0, "pull-off ends at {last} Hz");
    let d = decay_s(&pop, 1e-3, 40e-3);
    eprintln!("pull-off decay {d} s");
    assert!((d - 8e-3).abs() < 0.5e-3, "pull-off decay {d} s");
}

/// docs/render.md: a sound starts at sample `round(t · rate)` and its envelope rises over
/// `ATTACK_S` = 0.5 ms (a linear ramp from 0); the waveform's own peak comes later, at a
/// crest of its carrier (the doc once said "peaks within 0.5 ms").
#[test]
fn a_sound_starts_on_its_sample_and_rises_over_half_a_millisecond() {
    assert_eq!(ATTACK_S, 5e-4);
    let sr = f64::from(SAMPLE_RATE_HZ);
    for sound in [
        Sound::Impact {
            kind: Impact::BrickGround,
            amplitude: 0.5,
        },
        Sound::Snap { amplitude: 0.5 },
        Sound::PullOff { amplitude: 0.5 },
    ] {
        let t = 0.2503;
        let (start, x) = event_samples(&SoundEvent { t_s: t, sound }, 0, sr).unwrap();
        assert_eq!(start, (t * sr).round() as usize);
        assert_eq!(start, 11_038);
        // the ramp starts at 0
        assert_eq!(x[0], 0.0);
        let peak_at = x
            .iter()
            .enumerate()
            .fold(
                (0, 0.0f64),
                |b, (k, v)| if v.abs() > b.1 { (k, v.abs()) } else { b },
            )
            .0 as f64
            / sr;
        eprintln!("{sound:?}: peak at {:.3} ms", peak_at * 1e3);
        assert!(peak_at > ATTACK_S, "{sound:?}: peak at {peak_at} s");
    }
}

/// docs/render.md: the loudness law `0.8 · (1 − exp(−x / x_ref))`, never above 0.8; the
/// anti-clipping ceiling 0.98; the proximity tone `220 · 4^(1 − d/d_on)` Hz, 220 Hz at the
/// edge and 880 Hz in contact, at amplitude 0.12; WAV 16-bit PCM mono, 44 100 Hz default.
#[test]
fn the_documented_constants() {
    assert_eq!((A_MAX, CEILING, TONE_AMPLITUDE), (0.8, 0.98, 0.12));
    assert_eq!(SAMPLE_RATE_HZ, 44_100);
    assert_eq!(amplitude(1.0, 1.0), 0.8 * (1.0 - (-1.0f64).exp()));
    assert!(amplitude(1e6, 1.0) <= 0.8);
    let edge = tone_hz(0.1 * (1.0 - 1e-12), 0.1).unwrap();
    assert!((edge - 220.0).abs() < 1e-6, "{edge}");
    assert_eq!(tone_hz(0.1, 0.1), None);
    assert_eq!(tone_hz(0.0, 0.1), Some(880.0));
    assert_eq!(tone_hz(0.05, 0.1), Some(440.0));
    assert_eq!(tone_at(Some(0.05), 0.1), (440.0, 0.12));
    let dir = std::env::current_exe().unwrap().with_file_name("test-tmp");
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("nh-audio-spec-{}.wav", std::process::id()));
    write_wav(&p, &[0.0, 0.5], SAMPLE_RATE_HZ).unwrap();
    let spec = hound::WavReader::open(&p).unwrap().spec();
    assert_eq!(
        (spec.channels, spec.bits_per_sample, spec.sample_format),
        (1, 16, hound::SampleFormat::Int)
    );
    std::fs::remove_file(&p).ok();
}
