//! The harness catches what it promises: a panic (caught in the worker), an abort (the worker
//! dies; the batch is re-run one input per process to name it), a hang (the watchdog), and a
//! non-finite result, each at the input where it happens, and carries on after each.
#![allow(clippy::unwrap_used)]

use std::process::Command;

#[test]
fn panics_aborts_hangs_and_non_finite_results_are_named_by_input() {
    let out = Command::new(env!("CARGO_BIN_EXE_nanohaptics-fuzz"))
        .args(["--target", "selftest", "--inputs", "200", "--batch", "50"])
        .args(["--timeout-ms", "300", "--json", "--findings"])
        .arg(
            std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
                .join(format!("fuzz-selftest-{}", std::process::id())),
        )
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "findings give status 1");
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["inputs"], 200);
    assert_eq!(
        (j["panics"].as_u64(), j["aborts"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(
        (j["hangs"].as_u64(), j["non_finite"].as_u64()),
        (Some(2), Some(2))
    );
    assert_eq!(j["accepted"], 192);
    let mut at: Vec<(String, u64)> = j["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["kind"].as_str().unwrap().to_string(),
                f["index"].as_u64().unwrap(),
            )
        })
        .collect();
    at.sort_by_key(|f| f.1);
    let want: Vec<(String, u64)> = [3, 5, 7, 9, 103, 105, 107, 109]
        .iter()
        .zip(["panic", "abort", "hang", "non-finite"].iter().cycle())
        .map(|(i, k)| (k.to_string(), *i))
        .collect();
    assert_eq!(at, want);
    let panic = j["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["kind"] == "panic")
        .unwrap();
    assert!(
        panic["detail"]
            .as_str()
            .unwrap()
            .starts_with("selftest panic at input 3 at crates/fuzz/src/targets/mod.rs:"),
        "{panic}"
    );
}
