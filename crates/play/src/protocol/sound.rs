//! The binary sound ticks (server → page): what the page's sound synthesis needs of each tick,
//! and their wire layout ([`SoundTicks::encode`]).

/// Bytes of a [`SoundTicks`] message's header: the first tick (u64), the proximity tone's
/// on-distance (f64, m; NaN: no tone), the number of ticks (u32) and of sounds (u32).
pub const SOUND_TICKS_HEADER_BYTES: usize = 24;
/// Bytes per tick of a [`SoundTicks`] message: its wall time (f64, ms since the Unix epoch)
/// and its distance to the nearest object (f64, m; NaN: nothing near or no such state).
pub const SOUND_TICK_BYTES: usize = 16;
/// Bytes per sound of a [`SoundTicks`] message: its tick (u64), its index in the session's
/// list of sounds (u32), its kind (u32, [`SoundKind`]) and its peak amplitude (f64).
pub const SOUND_ON_BYTES: usize = 24;

/// The timbre of a sound on the wire (the `kind` of a [`SoundOn`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoundKind {
    /// 0: a brick on the ground (`thud`).
    Thud = 0,
    /// 1: a brick on a brick (`clack`).
    Clack = 1,
    /// 2: the hand on a brick or the ground (`tap`).
    Tap = 2,
    /// 3: snap-to-contact (`snap`).
    Snap = 3,
    /// 4: pull-off (`pull_off`).
    PullOff = 4,
}

impl SoundKind {
    /// The kind with wire code `code`, if any.
    pub fn from_code(code: u32) -> Option<SoundKind> {
        Some(match code {
            0 => SoundKind::Thud,
            1 => SoundKind::Clack,
            2 => SoundKind::Tap,
            3 => SoundKind::Snap,
            4 => SoundKind::PullOff,
            _ => return None,
        })
    }

    /// The kind of a synthesised sound and its peak amplitude (0–1 of full scale).
    pub fn of(s: &render::audio::Sound) -> (SoundKind, f64) {
        use render::audio::{Impact, Sound};
        match *s {
            Sound::Impact { kind, amplitude } => (
                match kind {
                    Impact::BrickGround => SoundKind::Thud,
                    Impact::BrickBrick => SoundKind::Clack,
                    Impact::Cursor => SoundKind::Tap,
                },
                amplitude,
            ),
            Sound::Snap { amplitude } => (SoundKind::Snap, amplitude),
            Sound::PullOff { amplitude } => (SoundKind::PullOff, amplitude),
        }
    }

    /// The synthesised sound of this kind at peak amplitude `amplitude`.
    pub fn sound(self, amplitude: f64) -> render::audio::Sound {
        use render::audio::{Impact, Sound};
        let impact = |kind| Sound::Impact { kind, amplitude };
        match self {
            SoundKind::Thud => impact(Impact::BrickGround),
            SoundKind::Clack => impact(Impact::BrickBrick),
            SoundKind::Tap => impact(Impact::Cursor),
            SoundKind::Snap => Sound::Snap { amplitude },
            SoundKind::PullOff => Sound::PullOff { amplitude },
        }
    }

    /// The page's name of the sound (a frame's `sounds`).
    pub fn name(self) -> &'static str {
        match self {
            SoundKind::Thud => "thud",
            SoundKind::Clack => "clack",
            SoundKind::Tap => "tap",
            SoundKind::Snap => "snap",
            SoundKind::PullOff => "pull_off",
        }
    }
}

/// One tick's input to the sound synthesis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundTick {
    /// When the tick's force was sent, by the server's clock, ms since the Unix epoch.
    pub wall_ms: f64,
    /// Distance to the nearest object after the tick, m (NaN: none).
    pub nearest_m: f64,
}

/// A sound that starts on a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoundOn {
    /// The tick it starts on (its onset is `tick / rate_hz` s).
    pub tick: u64,
    /// Its place in the session's list of sounds, from 0 (it seeds the noise of impacts).
    pub index: u32,
    /// Its timbre.
    pub kind: SoundKind,
    /// Its peak amplitude, 0–1 of full scale.
    pub amplitude: f64,
}

/// The binary sound message: consecutive ticks `first_tick ..` with what the synthesis needs
/// of each, and the sounds that start on them, in order.
///
/// Wire layout, all little-endian: [`SOUND_TICKS_HEADER_BYTES`] of header (`first_tick` u64,
/// `tone_on_distance_m` f64 with NaN for none, the number of ticks u32, the number of sounds
/// u32), then [`SOUND_TICK_BYTES`] per tick (`wall_ms` f64, `nearest_m` f64), then
/// [`SOUND_ON_BYTES`] per sound (`tick` u64, `index` u32, `kind` u32, `amplitude` f64).
#[derive(Clone, Debug, PartialEq)]
pub struct SoundTicks {
    /// The first tick's index.
    pub first_tick: u64,
    /// Distance below which the proximity tone sounds, m (`None`: no tone in this scene).
    pub tone_on_distance_m: Option<f64>,
    /// Ticks `first_tick`, `first_tick + 1`, ….
    pub ticks: Vec<SoundTick>,
    /// The sounds starting on those ticks, in the session's order.
    pub sounds: Vec<SoundOn>,
}

/// Why bytes are not a [`SoundTicks`] message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("sound ticks message: {0}")]
pub struct SoundTicksError(String);

impl SoundTicks {
    /// The message's bytes (the layout above).
    pub fn encode(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(
            SOUND_TICKS_HEADER_BYTES
                + SOUND_TICK_BYTES * self.ticks.len()
                + SOUND_ON_BYTES * self.sounds.len(),
        );
        b.extend_from_slice(&self.first_tick.to_le_bytes());
        b.extend_from_slice(&self.tone_on_distance_m.unwrap_or(f64::NAN).to_le_bytes());
        b.extend_from_slice(&(self.ticks.len() as u32).to_le_bytes());
        b.extend_from_slice(&(self.sounds.len() as u32).to_le_bytes());
        for t in &self.ticks {
            b.extend_from_slice(&t.wall_ms.to_le_bytes());
            b.extend_from_slice(&t.nearest_m.to_le_bytes());
        }
        for s in &self.sounds {
            b.extend_from_slice(&s.tick.to_le_bytes());
            b.extend_from_slice(&s.index.to_le_bytes());
            b.extend_from_slice(&(s.kind as u32).to_le_bytes());
            b.extend_from_slice(&s.amplitude.to_le_bytes());
        }
        b
    }

    /// Reads a message; wrong lengths and unknown kinds are errors.
    pub fn decode(b: &[u8]) -> Result<SoundTicks, SoundTicksError> {
        fn u64_at(b: &[u8], at: usize) -> Option<u64> {
            Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
        }
        fn u32_at(b: &[u8], at: usize) -> Option<u32> {
            Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
        }
        let f64_at = |at| u64_at(b, at).map(f64::from_bits);
        let short = || SoundTicksError(format!("{} bytes is too short", b.len()));
        let first_tick = u64_at(b, 0).ok_or_else(short)?;
        let on = f64_at(8).ok_or_else(short)?;
        let nt = u32_at(b, 16).ok_or_else(short)? as usize;
        let ns = u32_at(b, 20).ok_or_else(short)? as usize;
        let want = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * nt + SOUND_ON_BYTES * ns;
        if b.len() != want {
            return Err(SoundTicksError(format!(
                "{} bytes for {nt} ticks and {ns} sounds (allowed: {want})",
                b.len()
            )));
        }
        let mut ticks = Vec::with_capacity(nt);
        for i in 0..nt {
            let at = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * i;
            ticks.push(SoundTick {
                wall_ms: f64_at(at).ok_or_else(short)?,
                nearest_m: f64_at(at + 8).ok_or_else(short)?,
            });
        }
        let mut sounds = Vec::with_capacity(ns);
        for i in 0..ns {
            let at = SOUND_TICKS_HEADER_BYTES + SOUND_TICK_BYTES * nt + SOUND_ON_BYTES * i;
            let code = u32_at(b, at + 12).ok_or_else(short)?;
            sounds.push(SoundOn {
                tick: u64_at(b, at).ok_or_else(short)?,
                index: u32_at(b, at + 8).ok_or_else(short)?,
                kind: SoundKind::from_code(code)
                    .ok_or_else(|| SoundTicksError(format!("sound kind {code} (allowed: 0–4)")))?,
                amplitude: f64_at(at + 16).ok_or_else(short)?,
            });
        }
        Ok(SoundTicks {
            first_tick,
            tone_on_distance_m: (!on.is_nan()).then_some(on),
            ticks,
            sounds,
        })
    }
}
