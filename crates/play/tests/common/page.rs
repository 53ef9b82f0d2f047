//! The page server and the sound messages the clock-free page tests drive the page's own
//! modules with (browser_sound.rs, sound_ring.rs).
#![allow(dead_code)]

use super::cdp::Browser;
use haptic_loop::session::SceneSource;
use play::PlayConfig;
use play::protocol::{SoundKind, SoundOn, SoundTick, SoundTicks};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Standard base64 with padding.
pub fn base64(b: &[u8]) -> String {
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

/// A play server for the page's files (its session waits for a Start that never comes), its
/// recording `name` under the target folder, and a browser on its page.
pub struct PageServer {
    stop: Arc<AtomicBool>,
    handle: std::thread::JoinHandle<Result<play::PlaySummary, play::PlayError>>,
}

impl PageServer {
    pub fn open(name: &str) -> (Browser, PageServer) {
        let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
        let mut c = PlayConfig::new(SceneSource::resolve("wall".as_ref()).unwrap(), out);
        c.port = 0;
        let stop = Arc::new(AtomicBool::new(false));
        let play::Running { url, handle } = play::start(c, stop.clone()).unwrap();
        let mut b = Browser::launch(800, 600).unwrap();
        b.open(&url).unwrap();
        (b, PageServer { stop, handle })
    }

    pub fn close(self) {
        self.stop.store(true, Ordering::Relaxed);
        let _ = self.handle.join();
    }
}

/// A sound-ticks message from `first` of `walls.len()` ticks (their wall times, ms), with a
/// thud on each tick of `sounds` ([tick, index]), base64.
pub fn block(first: u64, walls: &[f64], sounds: &[[u64; 2]]) -> String {
    let m = SoundTicks {
        first_tick: first,
        tone_on_distance_m: None,
        ticks: walls
            .iter()
            .map(|&wall_ms| SoundTick {
                wall_ms,
                nearest_m: 1.0,
            })
            .collect(),
        sounds: sounds
            .iter()
            .map(|&[tick, index]| SoundOn {
                tick,
                index: index as u32,
                kind: SoundKind::Thud,
                amplitude: 0.5,
            })
            .collect(),
    };
    base64(&m.encode())
}
