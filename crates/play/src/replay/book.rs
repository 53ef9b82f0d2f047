//! A recording made ready for the replay page: its session re-simulated from its inputs
//! (`haptic_loop::replay::Resimulation`, the path of `replay --verify` and `render`) through
//! the live page's own sink and publisher ([`crate::publish`]), so every frame is the
//! `frame` message a live page would have been sent, bit for bit; and its sound, the track of
//! `nanohaptics render --audio` at [`SAMPLE_RATE_HZ`], with `--proximity` where the live page
//! plays the proximity tone (the brick and nano worlds).

use crate::protocol::ServerMsg;
use crate::publish::{Outlet, PlaySink, ToPublisher, publish};
use crate::server::Shared;
use haptic_loop::replay::Resimulation;
use haptic_loop::session::{SessionArrays, SessionError};
use std::path::Path;
use std::sync::{Arc, Mutex};
use tungstenite::Message;

/// The replay's sound, samples per second (`render --audio`'s rate).
pub const SAMPLE_RATE_HZ: u32 = render::audio::SAMPLE_RATE_HZ;

/// Everything the replay page is served: the `hello`, every frame and the sound.
pub struct ReplayBook {
    /// The `hello` message (JSON), as a live page is sent it (no page is the hand).
    pub hello: String,
    /// Every `frame` message (JSON) in tick order; the last one has no drawing.
    pub frames: Vec<String>,
    /// The tick each frame draws (the last frame's: the session's last tick).
    pub frame_ticks: Vec<u64>,
    /// Tick rate, Hz.
    pub rate_hz: u32,
    /// Ticks recorded.
    pub ticks: u64,
    /// The sound track, mono, |s| ≤ 0.98, at [`SAMPLE_RATE_HZ`].
    pub sound: Vec<f32>,
    /// The recording's file name (its download).
    pub file_name: String,
}

/// The publisher's messages kept in order: the frames (text); the sound ticks (binary) are
/// the live synthesis's input, which the replay replaces by the whole track.
#[derive(Default)]
struct Kept(Mutex<Vec<String>>);

impl Outlet for Kept {
    fn broadcast(&self, m: &Message) {
        if let (Message::Text(t), Ok(mut v)) = (m, self.0.lock()) {
            v.push(t.to_string());
        }
    }
    fn send_to(&self, _page: u64, _m: Message) {}
    fn switched(&self, _name: &str, _value: f64) {}
}

impl ReplayBook {
    /// Reads and re-simulates the recording at `path`. A damaged or foreign file is refused
    /// with the recording reader's error; a recording whose scene no longer loads, with the
    /// re-simulation's.
    pub fn from_file(path: &Path) -> Result<ReplayBook, SessionError> {
        let rec = recording::read_recording_file(path, false)?;
        let resim = Resimulation::prepare(&rec)?;
        let lp = resim.haptic_loop();
        let (rate_hz, ticks) = (lp.config().rate_hz, resim.ticks());
        let kind = lp.scene().kind().to_string();
        let fields = lp.scene().state_fields();
        let specs = rec.description.device_specs();
        let seconds = ticks as f64 / f64::from(rate_hz.max(1));
        let hello = crate::session::hello_message(
            &resim.scene_file().scene.name,
            lp,
            &specs,
            false,
            Some(seconds),
        )
        .to_json();
        let prox = haptic_loop::sound::proximity_on_distance_m(&kind)
            .filter(|_| fields.iter().any(|f| f == "nearest_m"));
        let tone = prox.is_some();
        let kept = Arc::new(Kept::default());
        let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
        let out: Arc<dyn Outlet> = kept.clone();
        let ran = std::thread::scope(|s| {
            let publisher = s.spawn(move || publish(rx, out, rate_hz, fields, prox));
            let mut sink = PlaySink::new(tx, Arc::new(Shared::default()));
            let ran = resim.run(vec![&mut sink]);
            drop(sink);
            let _ = publisher.join();
            ran
        });
        ran?;
        let frames = std::mem::take(&mut *kept.0.lock().map_err(|_| poisoned())?);
        let frame_ticks = frames.iter().map(|f| frame_tick(f)).collect();
        let arrays = SessionArrays::from_recording(&rec)?;
        let sound = haptic_loop::sound::session_sound(&arrays, &kind, tone, SAMPLE_RATE_HZ)
            .map_err(|e| SessionError::Io {
                path: path.display().to_string(),
                message: format!("the sound: {e}"),
            })?
            .samples;
        Ok(ReplayBook {
            hello,
            frames,
            frame_ticks,
            rate_hz,
            ticks,
            sound,
            file_name: path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "recording.mcap".into()),
        })
    }

    /// The index of the frame drawn at tick `tick`: the last frame at or before it.
    pub fn frame_at(&self, tick: u64) -> usize {
        self.frame_ticks
            .partition_point(|&t| t <= tick)
            .saturating_sub(1)
    }

    /// The page's index: the session's figures and the frames' ticks (JSON).
    pub fn index_json(&self) -> String {
        serde_json::json!({
            "rate_hz": self.rate_hz,
            "ticks": self.ticks,
            "frame_ticks": self.frame_ticks,
            "sample_rate_hz": SAMPLE_RATE_HZ,
            "sound_samples": self.sound.len(),
            "file": self.file_name,
        })
        .to_string()
    }
}

/// A frame message's tick (every frame the publisher writes has one).
fn frame_tick(json: &str) -> u64 {
    match serde_json::from_str::<ServerMsg>(json) {
        Ok(ServerMsg::Frame(f)) => f.tick,
        _ => 0,
    }
}

fn poisoned() -> SessionError {
    SessionError::Io {
        path: String::new(),
        message: "the replay's frame list lock was poisoned".into(),
    }
}
