//! The page's live sound against `render --audio --proximity`: what the worklet heard (its
//! `done` report, `P.sound.live`) and the sounds it was sent, played and lost, checked against
//! the recording's track at the page's sample rate.
//!
//! What the worklet hashes: every sample it played from its FIFO, in the order played (FNV-1a
//! over the Float32 little-endian bytes), from the first one (`first`, a session sample index)
//! on; the silence of its wait for the lead and of an underrun is not the session's and is not
//! hashed; samples it dropped are listed (`drops`, [session index, count]), and so are the
//! samples it played that are not the track's (`concealed`: a guess over a late message that
//! the ticks, when they came, did not bear out, or a late sound played at once), which are not
//! hashed. So the samples it hashed are exactly the track from `first` on without the dropped
//! and concealed ranges, whatever the
//! machine's load, and the test asks for them bit for bit (the standard of the offline test,
//! `browser_sound.rs`: 0 ulp). The start offset: `first` is 0, the page being there from the
//! session's first tick (docs/play.md); the output's own start (the lead, the context's time
//! before the first ticks) is the output's and not in the comparison.
#![allow(dead_code)]

use super::cdp::fnv1a;
use haptic_loop::session::SessionArrays;
use serde_json::Value;
use std::collections::BTreeSet;

/// What the live check measured.
#[derive(Debug)]
pub struct Heard {
    /// The page's sample rate, Hz.
    pub sample_rate_hz: u32,
    /// Samples of the track, and the samples the worklet played (the same bits).
    pub track_samples: usize,
    pub played_samples: usize,
    /// Underruns (the worklet's life's), and this stream's samples dropped, and each drop
    /// ([session index, samples]).
    pub underruns: u64,
    pub dropped: u64,
    pub drops: Vec<(u64, u64)>,
    /// Silent samples skipped (this stream's), and silence waited (the worklet's life's), to
    /// follow the lead.
    pub skipped: u64,
    pub waited: u64,
    /// Guesses over late messages (the worklet's life's), and this stream's samples played
    /// that were not the track's.
    pub guesses: u64,
    pub concealed: u64,
    /// Sounds sent to the page, played (first sample rendered), lost in a drop.
    pub sent: usize,
    pub played: usize,
    pub lost: usize,
}

impl Heard {
    /// Every sample of the track, accounted for once: played (the track's bits), played but
    /// concealed, dropped, or skipped.
    pub fn accounted(&self) -> u64 {
        self.played_samples as u64 + self.concealed + self.dropped + self.skipped
    }
}

fn u64s(v: &Value) -> Vec<u64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|x| x.as_u64().unwrap_or_else(|| panic!("not a count: {x}")))
        .collect()
}

fn pairs(v: &Value) -> Vec<(u64, u64)> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(|p| {
            let p = u64s(p);
            (p[0], p[1])
        })
        .collect()
}

/// The samples the worklet should have hashed: `track` from `first` on without the dropped
/// ranges and the concealed ones ([session index, count] each; a concealed range may run past
/// the track's end, a guess played after its last tick).
pub fn expected_played(
    track: &[f32],
    first: usize,
    drops: &[(u64, u64)],
    concealed: &[(u64, u64)],
) -> Vec<f32> {
    let mut out = Vec::with_capacity(track.len());
    let mut at = first;
    let mut cut: Vec<(u64, u64, bool)> = drops
        .iter()
        .map(|&(d, n)| (d, n, true))
        .chain(concealed.iter().map(|&(d, n)| (d, n, false)))
        .collect();
    cut.sort_unstable();
    for (d, n, drop) in cut {
        let (d, n) = (d as usize, n as usize);
        assert!(
            d >= at && (d + n <= track.len() || (!drop && d <= track.len())),
            "{} [{d}, +{n}) from {at}",
            if drop { "drop" } else { "concealed" }
        );
        out.extend_from_slice(&track[at..d]);
        at = (d + n).min(track.len());
    }
    out.extend_from_slice(&track[at.min(track.len())..]);
    out
}

/// FNV-1a of samples' Float32 little-endian bytes (the worklet's hash).
pub fn hash(samples: &[f32]) -> u32 {
    fnv1a(samples.iter().flat_map(|s| s.to_le_bytes()))
}

/// The samples one stream of the worklet played (its report `r`: `done`, or `stream` when a
/// restart ended it) against the recording `a` of scene kind `kind`: from the track's first
/// sample, bit for bit, without the dropped ranges; all of them when `complete`, else (a
/// stream a restart cut) the first of them. Returns the sample rate, the track, its drops and
/// the samples played.
pub fn check_samples(
    a: &SessionArrays,
    kind: &str,
    r: &Value,
    complete: bool,
) -> (u32, Vec<f32>, Vec<(u64, u64)>, usize) {
    let sr = r["sampleRate"].as_f64().unwrap();
    assert!(sr >= 8000.0 && sr.fract() == 0.0, "{sr}");
    let sr = sr as u32;
    let track = haptic_loop::sound::session_sound(a, kind, true, sr)
        .unwrap()
        .samples;
    // The offline track is scaled down as a whole only past the ceiling; live, samples past
    // it are limited: neither happened, so the two are comparable sample for sample.
    let peak = track.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!(f64::from(peak) <= render::audio::CEILING, "{peak}");
    assert_eq!(r["limited"], 0);
    let emitted = r["emitted"].as_u64().unwrap();
    if complete {
        assert_eq!(
            emitted,
            track.len() as u64,
            "the stream ends where the track does"
        );
    } else {
        assert!(
            emitted <= track.len() as u64,
            "{emitted} of {}",
            track.len()
        );
    }
    // The start offset: none in session samples.
    assert_eq!(
        r["first"], 0,
        "the first sample played is the track's first"
    );
    let drops = pairs(&r["drops"]);
    // What was skipped to follow the lead was silence: the track is 0 throughout each range.
    let skips = pairs(&r["skips"]);
    for &(d, n) in &skips {
        let (d, n) = (d as usize, n as usize);
        assert!(
            d + n <= track.len() && track[d..d + n].iter().all(|&v| v == 0.0),
            "the skip [{d}, +{n}) is not silence"
        );
    }
    let cut: Vec<(u64, u64)> = drops.iter().chain(&skips).copied().collect();
    let concealed = pairs(&r["concealed"]);
    let mut want = expected_played(&track, 0, &cut, &concealed);
    let played = r["played"].as_u64().unwrap() as usize;
    if complete {
        assert_eq!(
            played,
            want.len(),
            "samples hashed: every sample of the track once, but those dropped, skipped or concealed"
        );
    } else {
        assert!(played <= want.len(), "{played} of {}", want.len());
        want.truncate(played);
    }
    if r["hash"].as_u64() != Some(u64::from(hash(&want))) {
        // Where it first differs: the worklet's hash after each second played.
        let mut at = "after the last checkpoint".to_string();
        for c in r["checkpoints"].as_array().unwrap() {
            let (n, h) = (c[0].as_u64().unwrap() as usize, c[1].as_u64().unwrap());
            if u64::from(hash(&want[..n])) != h {
                at = format!("within the {n} first samples played");
                break;
            }
        }
        panic!("the samples the page played differ from render --audio's ({at})");
    }
    (sr, track, drops, played)
}

/// Checks the worklet's `done` report `live` and the sounds `sent`/`played`/`lost` (arrays of
/// [tick, index]) against the recording `a` of scene kind `kind`.
pub fn check(a: &SessionArrays, kind: &str, live: &Value, sound: &Value) -> Heard {
    check_stream(a, kind, live, sound, 0)
}

/// [`check`] for the stream after `restarts` restarts (a lesson's next world; 0: the first).
/// The counts the worklet keeps across them (underruns, drops, guesses) are its whole life's.
pub fn check_stream(
    a: &SessionArrays,
    kind: &str,
    live: &Value,
    sound: &Value,
    restarts: u64,
) -> Heard {
    assert_eq!(live["kind"], "done", "the worklet ended its stream: {live}");
    assert_eq!(live["restarts"], restarts, "the streams restarted");
    let (sr, track, drops, played) = check_samples(a, kind, live, true);
    // Every drop, skip and concealed sample listed (after a restart the counts are the
    // worklet's life's, the lists the stream's, which the Heard reports).
    let listed = |v: &Value| pairs(v).iter().map(|d| d.1).sum::<u64>();
    let [dropped, skipped, concealed] = [
        ("drops", "dropped"),
        ("skips", "skipped"),
        ("concealed", "concealedSamples"),
    ]
    .map(|(list, count)| {
        let (here, life) = (listed(&live[list]), live[count].as_u64().unwrap());
        if restarts == 0 {
            assert_eq!(here, life, "every one of the {count} listed");
        } else {
            assert!(here <= life, "{here} {list} listed of {life} {count}");
        }
        here
    });
    // The sounds: the page was sent the recording's, each once; each was played (its first
    // sample rendered) or lost in a drop (its first sample in a dropped range), once.
    let rate = f64::from(a.rate_hz);
    let events = haptic_loop::sound::sound_events(a).unwrap();
    let recorded: Vec<(u64, u64)> = events
        .iter()
        .enumerate()
        .map(|(i, e)| ((e.t_s * rate).round() as u64, i as u64))
        .collect();
    let sent = pairs(&sound["sent"]);
    assert_eq!(sent, recorded, "the sounds sent are the recording's");
    let in_drop = |tick: u64| {
        let k = (tick as f64 / rate * f64::from(sr)).round() as u64;
        drops.iter().any(|&(d, n)| (d..d + n).contains(&k))
    };
    let played_sounds = pairs(&sound["played"]);
    let lost = pairs(&sound["lost"]);
    let once = |v: &[(u64, u64)]| v.iter().copied().collect::<BTreeSet<_>>();
    assert_eq!(
        once(&played_sounds).len(),
        played_sounds.len(),
        "played twice"
    );
    let want_played: Vec<(u64, u64)> = recorded.iter().copied().filter(|s| !in_drop(s.0)).collect();
    let want_lost: Vec<(u64, u64)> = recorded.iter().copied().filter(|s| in_drop(s.0)).collect();
    assert_eq!(
        once(&played_sounds),
        once(&want_played),
        "the sounds played"
    );
    assert_eq!(once(&lost), once(&want_lost), "the sounds lost in a drop");
    assert_eq!(lost.len(), want_lost.len());
    // Each sound played had its tick → output latency measured once.
    assert_eq!(
        sound["latencyMs"].as_array().unwrap().len(),
        played_sounds.len(),
        "one latency per sound played"
    );
    Heard {
        sample_rate_hz: sr,
        track_samples: track.len(),
        played_samples: played,
        underruns: live["underruns"].as_u64().unwrap(),
        dropped,
        drops,
        skipped,
        waited: live["waited"].as_u64().unwrap(),
        guesses: live["guesses"].as_u64().unwrap(),
        concealed,
        sent: sent.len(),
        played: played_sounds.len(),
        lost: lost.len(),
    }
}
