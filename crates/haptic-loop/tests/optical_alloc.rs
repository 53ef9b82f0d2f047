//! The optical-tweezers scene's steady-state tick allocates nothing (counted
//! by a global allocator armed only around `Scene::step` on this thread).
#![allow(unsafe_code)] // a counting GlobalAlloc is unsafe by definition
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_engine::scene::{Scene, SceneInput, SceneOutput};
use haptic_loop::scene::SceneFile;
use haptic_loop::scene::optical::OpticalScene;
use haptic_types::Buttons;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

struct Counting;
static ALLOCS: AtomicU64 = AtomicU64::new(0);
thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if ARMED.with(Cell::get) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if ARMED.with(Cell::get) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn steady_state_optical_tick_allocates_nothing() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/optical_tweezers.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let file = SceneFile::parse(&text).unwrap();
    let config = file.loop_config(file.device.model).unwrap();
    let params = file.world().unwrap().expect("an optical scene");
    let mut scene = OpticalScene::new(params, &config.world_limits()).unwrap();
    let mut out = SceneOutput::default();
    out.events.reserve(8);
    let mut state = Vec::with_capacity(64);
    let dt = config.dt_s();
    // (warm ticks, their allocations, their events, rebuild ticks)
    let mut warm = (0u64, 0u64, 0u64, 0u64);
    for k in 0..4000u64 {
        // grab at the particle, then a slow circle of 2 µm radius (1 nm per tick)
        let a = k as f64 * 1e-9 / 2e-6;
        let cursor = [2e-6 * (a.cos() - 1.0), 2e-6 * a.sin(), 0.0];
        let input = SceneInput {
            tick: k,
            dt_s: dt,
            cursor_m: cursor,
            buttons: Buttons(1),
            input_valid: true,
        };
        out.clear();
        state.clear();
        let rebuilds = scene.tick_stats().rebuilds;
        ALLOCS.store(0, Ordering::Relaxed);
        ARMED.with(|x| x.set(true));
        scene.step(&input, &mut out);
        scene.state(&mut state);
        ARMED.with(|x| x.set(false));
        if k >= 1000 {
            if scene.tick_stats().rebuilds == rebuilds {
                warm.0 += 1;
                warm.1 += ALLOCS.load(Ordering::Relaxed);
                warm.2 += u64::from(!out.events.is_empty());
            } else {
                warm.3 += 1;
            }
        }
    }
    eprintln!("{warm:?} {:?}", scene.tick_stats());
    assert!(warm.0 >= 2500, "steady state: {warm:?}");
    assert_eq!(warm.2, 0, "no events in the steady drag");
    assert_eq!(warm.1, 0, "allocations in {} steady-state ticks", warm.0);
}
