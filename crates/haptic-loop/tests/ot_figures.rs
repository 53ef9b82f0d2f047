//! The optical-tweezers tick's figures in `docs/ot-envelope.md` ("Measured") and BENCHMARKS.md
//! ("Work per tick", "Accuracy reached"), held: a batch session of each scene on its default
//! script (6 s, as `examples/ot_tick.rs` runs it), the world's steering replayed from the
//! recorded particle states (bit for bit against the recorded trap), its `TickStats` exactly,
//! and the served envelope's Hausdorff distance from converged dynamics at the ticks served
//! while a spread build was under way (every one of them) and at every `every`-th grabbed tick.
#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

#[path = "../examples/ot_replay/mod.rs"]
mod ot_replay;

use haptic_loop::scene::SceneFile;
use haptic_loop::scene::optical::OtParams;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use ot_envelope::tick::TickStats;
use ot_replay::Replay;
use std::path::Path;

/// A batch session of `scene` on its default script for 6 s, its steering replayed
/// (`examples/ot_replay`) with every `every`-th grabbed tick checked.
fn figures(scene: &str, every: u64) -> Replay {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("scenes").join(scene)).unwrap();
    let mut src = SceneSource::from_text(&text, scene);
    src.dir = Some(root.join("scenes"));
    let mut o = SessionOptions::new(src);
    o.seconds = Some(6.0);
    let r = run_session(&o, &mut |_, _| {}).unwrap();

    let p: OtParams = SceneFile::parse(&text).unwrap().world().unwrap().unwrap();
    assert!(p.warm_start && p.spread_build && p.rk4_substeps.is_none());
    let f = ot_replay::replay(&text, &r, every).unwrap();
    eprintln!(
        "{scene}: {} grabbed, {} checked ({} during a spread build), worst {:.4} nm \
         (a whole build {:.4} nm), max slice {}, {:?}",
        f.grabbed, f.checked, f.checked_spread, f.worst_nm, f.worst_cold_nm, f.max_slice, f.stats
    );
    f
}

/// `x` rounds to `printed` at `decimals` decimals (two-sided).
fn assert_printed(what: &str, x: f64, printed: f64, decimals: i32) {
    let half = 0.5 * 10f64.powi(-decimals);
    assert!(
        (x - printed).abs() <= half + 1e-12,
        "{what}: {x} does not print as {printed:.*}",
        decimals as usize
    );
}

/// The counters every session of both scenes shares: no whole build, no dropped build, no
/// failed fold check, no grid solve, every grabbed tick a continued Newton step (the first one
/// included), the largest slice 256 + one work item.
fn expected(ticks: u64, spread_builds: u64, build_slices: u64) -> TickStats {
    TickStats {
        ticks,
        // the prebuild (particle at rest, before the grab) and the spread builds
        rebuilds: 1 + spread_builds,
        spread_builds,
        build_slices,
        max_slice_evals: 280,
        dropped_builds: 0,
        verify_failures: 0,
        continued: ticks,
        fold_seeded: 0,
        full_solves: 0,
        parked: 0,
    }
}

/// One scene's printed figures: `grabbed` ticks, `spread_builds` in `build_slices` slices, the
/// largest 280 evaluations, `checked` ticks of which `checked_spread` served during a spread
/// build, the served envelope's and a whole build's worst Hausdorff distance (nm, 3 decimals).
struct Printed {
    grabbed: u64,
    spread_builds: u64,
    build_slices: u64,
    checked: u64,
    checked_spread: u64,
    served_nm: f64,
    whole_nm: f64,
}

/// `scene`'s session, every `every`-th grabbed tick checked, gives the `want` figures.
fn holds(scene: &str, every: u64, want: &Printed) {
    let f = figures(scene, every);
    assert_eq!(f.mismatches, 0);
    assert_eq!(
        f.stats,
        expected(want.grabbed, want.spread_builds, want.build_slices)
    );
    assert_eq!(f.max_slice, 280);
    assert_eq!(
        (f.grabbed, f.checked, f.checked_spread),
        (want.grabbed, want.checked, want.checked_spread)
    );
    assert_printed("served envelope (nm)", f.worst_nm, want.served_nm, 3);
    assert_printed("whole build (nm)", f.worst_cold_nm, want.whole_nm, 3);
}

/// docs/ot-envelope.md "Measured"; BENCHMARKS.md "Work per tick" and "Accuracy reached",
/// 1 kHz row: 5,000 grabbed ticks, 14 spread builds in 126 slices, the largest 280
/// evaluations; every 10th grabbed tick and all 126 served during a spread build checked (612):
/// served envelope 0.062 nm, a whole build at the same ticks 0.060 nm.
#[test]
fn scene_1khz_default_script() {
    let want = Printed {
        grabbed: 5000,
        spread_builds: 14,
        build_slices: 126,
        checked: 612,
        checked_spread: 126,
        served_nm: 0.062,
        whole_nm: 0.060,
    };
    holds("optical_tweezers.toml", 10, &want);
}

/// BENCHMARKS.md "Work per tick" and "Accuracy reached", 10 kHz row: 50,000 grabbed ticks,
/// 7 spread builds in 63 slices, the largest 280 evaluations; every 50th grabbed tick and all 63
/// served during a spread build checked (1,062): served envelope 0.061 nm, a whole build at the
/// same ticks 0.060 nm.
#[test]
fn scene_10khz_default_script() {
    let want = Printed {
        grabbed: 50_000,
        spread_builds: 7,
        build_slices: 63,
        checked: 1062,
        checked_spread: 63,
        served_nm: 0.061,
        whole_nm: 0.060,
    };
    holds("optical_tweezers_10khz.toml", 50, &want);
}
