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

fn corpus_file(f: &str) -> Vec<u8> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus")
        .join(f);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// docs/fuzzing.md: the committed bridge corpus holds two version-3 force packets (a bond alone;
/// a full model with a bond) and the version-4 force packet (a follower with a 12-vertex
/// envelope, 470 bytes).
#[test]
fn the_corpus_holds_the_force_packets_docs_fuzzing_md_names() {
    use haptic_devices::bridge::protocol::{MAGIC, Packet};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/corpus/bridge");
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    // (version, bytes, the model's parts) of each force packet (type 4) that decodes.
    let mut v3 = Vec::new();
    let mut v4 = Vec::new();
    for n in &names {
        let b = corpus_file(&format!("bridge/{n}"));
        let Ok(Packet::Force(f)) = Packet::decode(&b) else {
            continue;
        };
        assert_eq!(b[..4], MAGIC);
        let m = f.local.as_deref();
        match b[4] {
            3 => {
                let m = m.unwrap();
                assert!(m.bond.is_some() && m.follower.is_none(), "{n}");
                v3.push((n.clone(), b.len(), m.body.is_some(), m.planes.len()));
            }
            4 => {
                let fo = m.unwrap().follower.as_ref().unwrap();
                v4.push((n.clone(), b.len(), fo.reach_m.len()));
            }
            _ => {}
        }
    }
    // A bond alone (no planes, no body) and a full model (a plane, a carried body) with a bond.
    v3.sort_by_key(|p| p.1);
    assert_eq!(
        v3,
        [
            (
                "e0b07fc5b300562e142dfe0bb5b345ee873e2269".to_string(),
                292,
                false,
                0
            ),
            (
                "e9ccb764f5ca70447e2b4f29bd38fe4027e041e1".to_string(),
                512,
                true,
                1
            ),
        ]
    );
    assert_eq!(
        v4,
        [(
            "1002bb177fc746fbe0b67053b99f4e4ed9f1640d".to_string(),
            470,
            12
        )]
    );
}

/// docs/fuzzing.md: `page/regress-canonical-head-over-limit` is a selector byte and a head of
/// 8,180 bytes with 61 headers, under the 8 KiB limit as read, over it in its canonical form
/// (`name: value`, a byte more a header: 8,241 bytes), where the parser answers `TooLong`.
#[test]
fn the_canonical_head_regression_is_as_docs_fuzzing_md_describes() {
    use webguard::{HeadError, MAX_HEAD_BYTES, parse_head};
    let b = corpus_file("page/regress-canonical-head-over-limit");
    assert_eq!(b.len(), 8181);
    assert_eq!(b[0] % 4, 0, "the selector byte picks the HTTP head");
    let head = &b[1..];
    assert_eq!((head.len(), MAX_HEAD_BYTES), (8180, 8192));
    let h = parse_head(head).unwrap();
    assert_eq!(h.headers.len(), 61);
    let mut canon = format!("{} {} HTTP/1.1\r\n", h.method, h.target);
    for (n, v) in &h.headers {
        canon.push_str(&format!("{n}: {v}\r\n"));
    }
    canon.push_str("\r\n");
    assert_eq!(canon.len(), 8241);
    assert_eq!(
        parse_head(canon.as_bytes()),
        Err(HeadError::TooLong {
            limit: MAX_HEAD_BYTES
        })
    );
    // The property takes that answer: the input passes.
    assert_eq!(
        nanohaptics_fuzz::page::run_page(&b),
        nanohaptics_fuzz::outcome::Outcome::Accepted
    );
}
