//! The page as a haptic device: the hand the page sends (pointer, keyboard, gamepad) is held
//! between messages and sampled at every tick.
//!
//! - **Mapping**: the page sends a point `n` of the unit ball (right, away, up); the device
//!   position is `n · 0.999 · r`, m, with `r` the workspace radius of the scene's device model
//!   (4 cm for a Falcon), so every point the page can send is inside the workspace.
//! - **Sampling** (zero-order hold): tick `k` reads the latest input that arrived before it; the
//!   recording holds each tick's reading, so a replay feeds the same readings back whatever the
//!   network did.
//! - **Watchdog**: a page sends its hand at its frame rate (about 60 Hz) and at least every
//!   100 ms while it is open. A reading counts as fresh (age 0) while the last message is at most
//!   [`PAGE_LIVENESS_MS`] old; after that the age counts the ticks since, so the loop's watchdog
//!   ramps the force to zero within its timeout (10 ms at 1 kHz) when the page goes away, and
//!   soft engagement restarts when it comes back, as for a bridged device whose packets stop.

use haptic_types::DeviceError;

use haptic_types::DeviceSample;

use haptic_types::DeviceSpecs;

use haptic_types::ForceCommand;

use haptic_types::Buttons;
use haptic_types::HapticDevice;
use haptic_types::TickTime;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// How long the last page message keeps the hand fresh, ms.
pub const PAGE_LIVENESS_MS: u64 = 250;

/// Fraction of the workspace radius the unit ball maps onto.
pub const WORKSPACE_FILL: f64 = 0.999;

/// The device position, m, for a point `n` of the unit ball sent by the page, on a device of
/// workspace radius `radius_m`.
pub fn page_to_device(n: [f64; 3], radius_m: f64) -> [f64; 3] {
    let s = WORKSPACE_FILL * radius_m;
    [n[0] * s, n[1] * s, n[2] * s]
}

/// The latest hand from the page.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LatestInput {
    /// Device position, m.
    pub position_m: [f64; 3],
    /// Button bits.
    pub buttons: u32,
    /// Number of inputs received (the sample's `seq`: 0 before the first).
    pub count: u64,
    /// The page's clock of the input, ms since the Unix epoch.
    pub t_ms: f64,
}

#[derive(Debug, Default)]
struct Inner {
    latest: LatestInput,
    last_at: Option<Instant>,
}

/// The hand shared between the WebSocket threads (writers) and the tick (reader).
#[derive(Debug, Default)]
pub struct SharedInput {
    inner: Mutex<Inner>,
    arrived: Condvar,
}

impl SharedInput {
    /// Stores a hand from the page (already mapped to the device, m).
    pub fn set(&self, position_m: [f64; 3], buttons: u32, t_ms: f64) {
        if let Ok(mut g) = self.inner.lock() {
            g.latest.position_m = position_m;
            g.latest.buttons = buttons;
            g.latest.t_ms = t_ms;
            g.latest.count += 1;
            g.last_at = Some(Instant::now());
        }
        self.arrived.notify_all();
    }

    /// The latest hand and when it arrived.
    pub fn latest(&self) -> (LatestInput, Option<Instant>) {
        match self.inner.lock() {
            Ok(g) => (g.latest, g.last_at),
            Err(_) => (LatestInput::default(), None),
        }
    }

    /// Waits until a first hand arrives or `stop` is raised; true when a hand arrived.
    pub fn wait_first(&self, stop: &AtomicBool) -> bool {
        let Ok(mut g) = self.inner.lock() else {
            return false;
        };
        while g.last_at.is_none() {
            if stop.load(Ordering::Relaxed) {
                return false;
            }
            match self.arrived.wait_timeout(g, Duration::from_millis(50)) {
                Ok((ng, _)) => g = ng,
                Err(_) => return false,
            }
        }
        true
    }
}

/// The page as a [`HapticDevice`] with the specifications of the scene's device model.
pub struct PageDevice {
    specs: DeviceSpecs,
    shared: Arc<SharedInput>,
    liveness: Duration,
    stale_ticks: u32,
    received: u64,
}

impl PageDevice {
    /// A page device with `specs` reading `shared`.
    pub fn new(specs: DeviceSpecs, shared: Arc<SharedInput>) -> Self {
        PageDevice {
            specs,
            shared,
            liveness: Duration::from_millis(PAGE_LIVENESS_MS),
            stale_ticks: 0,
            received: 0,
        }
    }

    /// The sample of a tick from the latest hand, whether it is fresh (`last_at` within the
    /// liveness) and the count of stale ticks before it: (sample, new stale count).
    pub fn sample_of(latest: &LatestInput, fresh: bool, stale_ticks: u32) -> (DeviceSample, u32) {
        let age = if fresh {
            0
        } else {
            stale_ticks.saturating_add(1)
        };
        (
            DeviceSample {
                position_m: latest.position_m,
                buttons: Buttons(latest.buttons),
                seq: latest.count,
                age_ticks: age,
            },
            age,
        )
    }
}

impl HapticDevice for PageDevice {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn sample(&mut self, _time: TickTime) -> Result<DeviceSample, DeviceError> {
        let (latest, at) = self.shared.latest();
        let fresh = at.is_some_and(|t| t.elapsed() <= self.liveness);
        let (s, stale) = Self::sample_of(&latest, fresh, self.stale_ticks);
        self.stale_ticks = stale;
        self.received = latest.count;
        Ok(s)
    }

    fn set_force(&mut self, _cmd: &ForceCommand) -> Result<(), DeviceError> {
        // The page feels the force through the frames (arrow, rumble), not here.
        Ok(())
    }

    fn link_counters(&self) -> Vec<(&'static str, u64)> {
        vec![("page_inputs_received", self.received)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::device::FALCON;

    #[test]
    fn the_unit_ball_maps_inside_the_workspace() {
        let r = FALCON.workspace_radius_m;
        assert_eq!(page_to_device([0.0; 3], r), [0.0; 3]);
        let p = page_to_device([1.0, 0.0, 0.0], r);
        assert_eq!(p, [0.04 * 0.999, 0.0, 0.0]);
        // The brick script's grab point, 22.5 mm left, 2.5 mm away, 6.8 mm down.
        let n = [
            -0.0225 / (0.999 * r),
            0.0025 / (0.999 * r),
            -0.0068 / (0.999 * r),
        ];
        let p = page_to_device(n, r);
        for (a, b) in p.iter().zip([-0.0225, 0.0025, -0.0068]) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
        // Every point of the unit sphere is a valid sample for the loop.
        for k in 0..1000 {
            let th = k as f64 * 0.0137;
            let ph = k as f64 * 0.731;
            let n = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let s = DeviceSample::new(page_to_device(n, r), Buttons(1));
            assert_eq!(haptic_engine::HapticLoop::check_sample(&FALCON, &s), None);
        }
    }

    #[test]
    fn the_hand_is_held_and_goes_stale_when_the_page_goes_away() {
        let l = LatestInput {
            position_m: [0.01, 0.0, 0.0],
            buttons: 1,
            count: 5,
            t_ms: 0.0,
        };
        let (s, st) = PageDevice::sample_of(&l, true, 7);
        assert_eq!((s.age_ticks, st, s.seq, s.buttons), (0, 0, 5, Buttons(1)));
        let (s, st) = PageDevice::sample_of(&l, false, 0);
        assert_eq!((s.age_ticks, st), (1, 1));
        let (s, _) = PageDevice::sample_of(&l, false, 9);
        assert_eq!(s.age_ticks, 10);
        assert_eq!(s.position_m, [0.01, 0.0, 0.0]);

        // Through the device: fresh after a message, stale ticks counted once it is old.
        let shared = Arc::new(SharedInput::default());
        let mut d = PageDevice::new(FALCON.clone(), shared.clone());
        d.liveness = Duration::from_millis(0);
        shared.set([0.0, 0.0, 0.01], 0, 1.0);
        std::thread::sleep(Duration::from_millis(2));
        let ages: Vec<u32> = (0..3)
            .map(|k| {
                d.sample(TickTime::new(k, 1000))
                    .map(|s| s.age_ticks)
                    .unwrap_or(99)
            })
            .collect();
        assert_eq!(ages, [1, 2, 3]);
        d.liveness = Duration::from_secs(60);
        shared.set([0.0, 0.0, 0.02], 1, 2.0);
        let s = d.sample(TickTime::new(3, 1000)).unwrap();
        assert_eq!((s.age_ticks, s.position_m[2], s.seq), (0, 0.02, 2));
        assert_eq!(d.link_counters(), vec![("page_inputs_received", 2)]);
    }

    #[test]
    fn the_watchdog_zeroes_the_force_when_the_page_is_gone() {
        use haptic_loop::session::SceneSource;
        let scene = SceneSource::builtin("wall").unwrap();
        let loaded = haptic_loop::scene::load_scene_for(&scene.text, FALCON.clone()).unwrap();
        let mut lp = haptic_engine::HapticLoop::new(loaded.config, loaded.scene);
        let l = LatestInput {
            position_m: [0.0, 0.0, -0.01],
            buttons: 0,
            count: 1,
            t_ms: 0.0,
        };
        let mut stale = 0;
        let mut forces = Vec::new();
        for k in 0..600 {
            let fresh = k < 500;
            let (s, st) = PageDevice::sample_of(&l, fresh, stale);
            stale = st;
            forces.push(lp.tick(s, false).device_force_n[2]);
        }
        assert!(forces[499] > 1.0, "pressed into the wall: {}", forces[499]);
        // Zero from the watchdog's timeout on (10 ms at 1 kHz).
        assert!(forces[510..].iter().all(|f| *f == 0.0));
    }
}
