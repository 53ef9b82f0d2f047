//! The sound of a recorded session (`nanohaptics render REC --audio OUT.wav`): the
//! recording's events and state become the sounds of [`render::audio`], a pure function of the
//! recording (nothing is re-simulated; the same file gives the same samples).
//!
//! | event | sound | loudness from |
//! |---|---|---|
//! | `brick.impact` (brick–ground, brick–obstacle) | low thud | `impulse_n_s`, reference 1 N·s |
//! | `brick.impact` (brick–brick) | wooden clack | `impulse_n_s`, reference 1 N·s |
//! | `brick.impact` (cursor–anything) | short tap | `impulse_n_s`, reference 1 N·s |
//! | `nano.snap` | bright click | `snap_force_n`, reference 0.5 nN |
//! | `nano.pull_off` | falling pop | `pull_off_n`, reference 0.5 nN |
//!
//! With `proximity`, the state column `nearest_m` drives the proximity tone: it sounds within
//! 0.1 m of the nearest object in the brick world and within 1 nm in the nano world (about
//! 5–7 mm of stylus travel in the built-in scenes), rising from 220 Hz to 880 Hz at contact.

use crate::session::SessionArrays;
use render::audio::{self, Impact, Proximity, Sound, SoundEvent};

/// Loudness reference of impacts, N·s.
pub const IMPULSE_REF_N_S: f64 = 1.0;
/// Loudness reference of nano contact clicks, N.
pub const CONTACT_FORCE_REF_N: f64 = 0.5e-9;

/// Why a recording cannot be turned into sound.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SoundError {
    /// An event whose detail is not the JSON the sound needs.
    #[error("tick {tick}: event `{event}`: detail {message}")]
    Detail {
        /// Tick of the event.
        tick: u64,
        /// Its name.
        event: String,
        /// What is wrong with the detail.
        message: String,
    },
    /// `proximity` for a scene without a `nearest_m` state column.
    #[error(
        "--proximity: the {kind} scene records no distance to the nearest object \
         (allowed: brickworld, nanoworld)"
    )]
    NoProximity {
        /// The scene kind.
        kind: String,
    },
    /// Synthesis or writing.
    #[error(transparent)]
    Render(#[from] render::RenderError),
}

/// A session's sound.
#[derive(Clone, Debug, PartialEq)]
pub struct SessionSound {
    /// Mono samples, |s| ≤ 0.98.
    pub samples: Vec<f32>,
    /// Sample rate, Hz.
    pub sample_rate_hz: u32,
    /// The sounds placed (impacts and clicks; the proximity tone not counted).
    pub sounds: Vec<SoundEvent>,
}

impl SessionSound {
    /// Writes the samples as a 16-bit PCM mono WAV file.
    pub fn write_wav(&self, path: &std::path::Path) -> Result<(), SoundError> {
        Ok(audio::write_wav(path, &self.samples, self.sample_rate_hz)?)
    }
}

fn field(v: &serde_json::Value, key: &str, tick: u64, event: &str) -> Result<f64, SoundError> {
    v.get(key)
        .and_then(serde_json::Value::as_f64)
        .ok_or_else(|| SoundError::Detail {
            tick,
            event: event.to_string(),
            message: format!("has no number `{key}`"),
        })
}

/// The impact's timbre from its two bodies.
fn impact_kind(v: &serde_json::Value) -> Impact {
    let is = |k: &str, what: &str| v.get(k).is_some_and(|b| b == what);
    let brick = |k: &str| v.get(k).is_some_and(|b| b.get("brick").is_some());
    if is("a", "cursor") || is("b", "cursor") {
        Impact::Cursor
    } else if brick("a") && brick("b") {
        Impact::BrickBrick
    } else {
        Impact::BrickGround
    }
}

/// The sounds of a session's events, in event order.
pub fn sound_events(a: &SessionArrays) -> Result<Vec<SoundEvent>, SoundError> {
    let dt = 1.0 / f64::from(a.rate_hz.max(1));
    let mut out = Vec::new();
    for (tick, name, detail) in &a.events {
        if !matches!(
            name.as_str(),
            "brick.impact" | "nano.snap" | "nano.pull_off"
        ) {
            continue;
        }
        let v: serde_json::Value =
            serde_json::from_str(detail).map_err(|e| SoundError::Detail {
                tick: *tick,
                event: name.clone(),
                message: format!("is not JSON ({e})"),
            })?;
        let sound = match name.as_str() {
            "brick.impact" => Sound::Impact {
                kind: impact_kind(&v),
                amplitude: audio::amplitude(
                    field(&v, "impulse_n_s", *tick, name)?,
                    IMPULSE_REF_N_S,
                ),
            },
            "nano.snap" => Sound::Snap {
                amplitude: audio::amplitude(
                    field(&v, "snap_force_n", *tick, name)?,
                    CONTACT_FORCE_REF_N,
                ),
            },
            _ => Sound::PullOff {
                amplitude: audio::amplitude(
                    field(&v, "pull_off_n", *tick, name)?,
                    CONTACT_FORCE_REF_N,
                ),
            },
        };
        out.push(SoundEvent {
            t_s: *tick as f64 * dt,
            sound,
        });
    }
    Ok(out)
}

/// Distance at which the proximity tone starts for a scene kind, m.
pub fn proximity_on_distance_m(kind: &str) -> Option<f64> {
    match kind {
        "brickworld" => Some(0.1),
        "nanoworld" => Some(1e-9),
        _ => None,
    }
}

/// The sound of a session of scene kind `kind`: its events, and the proximity tone when asked.
pub fn session_sound(
    a: &SessionArrays,
    kind: &str,
    proximity: bool,
    sample_rate_hz: u32,
) -> Result<SessionSound, SoundError> {
    let sounds = sound_events(a)?;
    let dt = 1.0 / f64::from(a.rate_hz.max(1));
    let prox = if proximity {
        let (Some(on), Some(d)) = (proximity_on_distance_m(kind), a.state_column("nearest_m"))
        else {
            return Err(SoundError::NoProximity {
                kind: kind.to_string(),
            });
        };
        Some(Proximity {
            dt_s: dt,
            distance_m: d,
            on_distance_m: on,
        })
    } else {
        None
    };
    let duration = a.tick.len() as f64 * dt;
    let samples = audio::synthesize(&sounds, prox.as_ref(), duration, sample_rate_hz)?;
    Ok(SessionSound {
        samples,
        sample_rate_hz,
        sounds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arrays(events: &[(u64, &str, &str)]) -> SessionArrays {
        let mut a = SessionArrays::new(1000, vec!["nearest_m".into()]);
        for t in 0..1000u64 {
            a.tick.push(t);
            a.state.push(if t < 500 { 1.0 } else { 0.01 });
        }
        a.events = events
            .iter()
            .map(|(t, n, d)| (*t, n.to_string(), d.to_string()))
            .collect();
        a
    }

    #[test]
    fn events_become_sounds_with_their_strength() {
        let a = arrays(&[
            (
                100,
                "brick.impact",
                r#"{"type":"impact","a":"ground","b":{"brick":0},"impulse_n_s":0.4}"#,
            ),
            (
                200,
                "brick.impact",
                r#"{"type":"impact","a":{"brick":0},"b":{"brick":1},"impulse_n_s":0.1}"#,
            ),
            (
                300,
                "brick.impact",
                r#"{"type":"impact","a":"cursor","b":"ground","impulse_n_s":0.05}"#,
            ),
            (400, "nano.snap", r#"{"type":"snap","snap_force_n":3e-10}"#),
            (450, "brick.grabbed", "{}"),
            (
                500,
                "nano.pull_off",
                r#"{"type":"pull_off","pull_n":3e-9,"pull_off_n":3e-9}"#,
            ),
        ]);
        let s = sound_events(&a).unwrap();
        assert_eq!(s.len(), 5);
        assert_eq!(s[0].t_s, 0.1);
        assert_eq!(
            s[0].sound,
            Sound::Impact {
                kind: Impact::BrickGround,
                amplitude: audio::amplitude(0.4, 1.0)
            }
        );
        assert!(matches!(
            s[1].sound,
            Sound::Impact {
                kind: Impact::BrickBrick,
                ..
            }
        ));
        assert!(matches!(
            s[2].sound,
            Sound::Impact {
                kind: Impact::Cursor,
                ..
            }
        ));
        // docs/render.md: "x_ref = 1 N·s for impacts and 0.5 nN for nano clicks"
        assert_eq!(IMPULSE_REF_N_S, 1.0);
        assert_eq!(CONTACT_FORCE_REF_N, 0.5e-9);
        // a 0.3 nN snap and a 3 nN pull-off: 0.8 · (1 − exp(−x / 0.5 nN))
        assert_eq!(
            s[3].sound,
            Sound::Snap {
                amplitude: audio::amplitude(3e-10, 0.5e-9)
            }
        );
        assert_eq!(
            s[4].sound,
            Sound::PullOff {
                amplitude: audio::amplitude(3e-9, 0.5e-9)
            }
        );
        let Sound::Snap { amplitude: snap } = s[3].sound else {
            unreachable!()
        };
        assert!(
            (snap - 0.8 * (1.0 - (-0.6f64).exp())).abs() < 1e-12,
            "{snap}"
        );
        assert!((snap - 0.36095).abs() < 5e-6, "{snap}");
        let out = session_sound(&a, "brickworld", true, 8000).unwrap();
        assert_eq!(out.samples.len(), 8000);
    }

    #[test]
    fn bad_details_and_missing_proximity_are_named() {
        let a = arrays(&[(7, "brick.impact", "Impact { a: Ground }")]);
        let e = sound_events(&a).unwrap_err().to_string();
        assert!(
            e.starts_with("tick 7: event `brick.impact`: detail is not JSON ("),
            "{e}"
        );
        let a = arrays(&[(7, "nano.snap", r#"{"type":"snap"}"#)]);
        assert_eq!(
            sound_events(&a).unwrap_err().to_string(),
            "tick 7: event `nano.snap`: detail has no number `snap_force_n`"
        );
        let a = arrays(&[]);
        assert_eq!(
            session_sound(&a, "wall", true, 8000)
                .unwrap_err()
                .to_string(),
            "--proximity: the wall scene records no distance to the nearest object \
             (allowed: brickworld, nanoworld)"
        );
    }

    /// docs/render.md: the tone sounds "within 0.1 m of the nearest object in the brick world
    /// (5 mm of stylus) or 1 nm in the nano world (6.7 mm of stylus)", with the built-in
    /// scenes' `workspace_scale` (world metres per stylus metre).
    #[test]
    fn the_proximity_distances_in_stylus_millimetres() {
        let scale = |name: &str| {
            let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../scenes")
                .join(name);
            let text = std::fs::read_to_string(p).unwrap();
            crate::scene::file::load_scene(&text, None)
                .unwrap()
                .config
                .mapping
                .workspace_scale
        };
        let brick = proximity_on_distance_m("brickworld").unwrap();
        let nano = proximity_on_distance_m("nanoworld").unwrap();
        assert_eq!((brick, nano), (0.1, 1e-9));
        assert_eq!(scale("brickworld.toml"), 20.0);
        assert_eq!(scale("nanoworld.toml"), 1.5e-7);
        let brick_mm = brick / scale("brickworld.toml") * 1e3;
        let nano_mm = nano / scale("nanoworld.toml") * 1e3;
        assert!((brick_mm - 5.0).abs() < 0.05, "{brick_mm} mm");
        assert!((nano_mm - 6.7).abs() < 0.05, "{nano_mm} mm");
        assert_eq!(proximity_on_distance_m("wall"), None);
        assert_eq!(proximity_on_distance_m("optical_tweezers"), None);
    }

    /// docs/recording-format.md: "`brick.impact` is a collision: a contact that began this step
    /// between bodies approaching at 0.05 m/s or faster", with the example's fields; every
    /// impact of the golden brick recording.
    #[test]
    fn every_recorded_impact_approaches_at_the_threshold_speed_or_faster() {
        assert_eq!(brickworld::impact::IMPACT_MIN_SPEED_M_PER_S, 0.05);
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../recordings/brickworld.mcap");
        let rec = recording::read_recording_file(&p, false).unwrap();
        let a = SessionArrays::from_recording(&rec).unwrap();
        let mut n = 0;
        let mut slowest = f64::INFINITY;
        for (_, name, detail) in &a.events {
            if name != "brick.impact" {
                continue;
            }
            let v: serde_json::Value = serde_json::from_str(detail).unwrap();
            let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
            keys.sort_unstable();
            assert_eq!(
                keys,
                ["a", "b", "impulse_n_s", "point_m", "speed_m_per_s", "type"]
            );
            let speed = v["speed_m_per_s"].as_f64().unwrap();
            assert!(speed >= 0.05, "{detail}");
            slowest = slowest.min(speed);
            n += 1;
        }
        eprintln!("{n} impacts, slowest {slowest} m/s");
        assert!(n > 5, "{n} impacts");
    }
}
