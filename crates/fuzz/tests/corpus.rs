//! Every input of the committed libFuzzer corpus (`fuzz/corpus/<target>/`) through the same
//! in-process entry points libFuzzer calls, without libFuzzer: no panic, no property broken.
//! The corpus holds the campaigns' edge cover and one regression input per finding, so each
//! fixed finding stays fixed in the default test run.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;

fn each(target: &str, run: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in &files {
        let data = std::fs::read(f).unwrap();
        run(&data);
    }
    files.len()
}

#[test]
fn the_committed_corpus_passes_every_target() {
    use nanohaptics_fuzz::libfuzzer as lf;
    let n = [
        each("bridge", lf::bridge),
        each("script", lf::script),
        each("params", lf::params),
        each("recording", lf::recording),
        each("verify", lf::verify),
        each("scene", lf::scene),
        each("page", lf::page),
    ];
    // Each target has its seeds and what the campaign kept (docs/bench/fuzz.md).
    assert!(n.iter().all(|&k| k >= 5), "corpus sizes {n:?}");
    // The regression inputs of this wave's findings are there.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus");
    for f in [
        "bridge/regress-subnormal-force-limit",
        "params/regress-empty-envelope.toml",
        "scene/regress-deep-trap-slow-envelope.toml",
        "page/regress-canonical-head-over-limit",
    ] {
        assert!(root.join(f).exists(), "{f}");
    }
}
