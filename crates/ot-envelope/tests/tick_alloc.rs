//! Zero heap allocations in a steady-state steering tick, counted by a
//! global allocator that counts only on the test's own thread while armed.
#![allow(unsafe_code)] // a counting GlobalAlloc is unsafe by definition
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

mod common;
use common::*;
use nalgebra::Vector2;
use ot_envelope::ClipMode;
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickParams};
use ot_physics::budget::choose_tick_map;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
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

type V2 = Vector2<f64>;

#[test]
fn a_steady_state_tick_allocates_nothing() {
    let prop = choose_tick_map(paper_model([600e-9, 300e-9]), 0.2e-6, 1e-11, 0.1)
        .unwrap()
        .0;
    let mut c = TickController::new(TickParams::new(SteerParams {
        stiffness: 0.8,
        mode: ClipMode::Radial,
        tol: 0.5e-9,
        margin_waists: 3.0,
    }))
    .unwrap();
    let mut s = ParticleState {
        position: V2::zeros(),
        velocity: V2::zeros(),
    };
    let (radius, step) = (2e-6, 2e-9);
    let mut window = (0u64, 0u64); // (ticks, allocations) in warm ticks
    let mut rebuilt_allocs = 0u64; // allocations of rebuild ticks (reported only)
    for k in 0..3000 {
        let a = f64::from(k) * step / radius;
        let cursor = V2::new(radius * (a.cos() - 1.0), radius * a.sin());
        ALLOCS.store(0, Ordering::Relaxed);
        ARMED.with(|x| x.set(true));
        let out = c.step(&prop, &s, &cursor).unwrap();
        ARMED.with(|x| x.set(false));
        let n = ALLOCS.load(Ordering::Relaxed);
        if k >= 500 {
            if out.rebuilt {
                rebuilt_allocs += n;
            } else {
                window.0 += 1;
                window.1 += n;
            }
        }
        let (d, v, _) = prop.flow(&(out.trap - s.position), &s.velocity).unwrap();
        s.position += d;
        s.velocity = v * 0.1;
    }
    let st = c.stats();
    eprintln!(
        "{} warm ticks: {} allocations; rebuild ticks allocated {rebuilt_allocs}; {st:?}",
        window.0, window.1
    );
    assert!(window.0 >= 2000, "steady state reached: {st:?}");
    assert_eq!(window.1, 0, "allocations in warm ticks");
    // the counter counts: one armed allocation is seen
    ALLOCS.store(0, Ordering::Relaxed);
    ARMED.with(|x| x.set(true));
    let v: Vec<u64> = std::hint::black_box(Vec::with_capacity(16));
    ARMED.with(|x| x.set(false));
    drop(v);
    assert_eq!(ALLOCS.load(Ordering::Relaxed), 1);
}
