//! The in-process entry points of the libFuzzer targets (`fuzz/fuzz_targets/*.rs`). Each runs
//! one input and panics on a finding, which libFuzzer reports as a crash with the input saved;
//! refusing an input is the expected answer to most of them.
//!
//! The properties are the in-tree driver's: no panic, no non-finite or over-limit force, no
//! altered recording that verifies; and for recordings read from raw bytes, nothing accepted
//! whose CRCs and summary were not checked.

use crate::targets::{
    Outcome, OutputChange, run_bridge, run_scene, run_script, seed_recording, verified_outputs,
    verify_changed, work_dir,
};
use haptic_loop::SessionArrays;
use recording::{Recording, read_recording};
use std::sync::OnceLock;

fn check(o: Outcome) {
    if let Outcome::Finding(kind, what) = o {
        panic!("finding ({kind}): {what}");
    }
}

/// A scene file: parsed for a Falcon; an accepted scene is ticked 40 times along a path.
pub fn scene(data: &[u8]) {
    check(run_scene(data));
}

/// A script file: parsed; an accepted script is sampled at 51 times.
pub fn script(data: &[u8]) {
    check(run_script(data));
}

/// A bridge datagram: decoded, re-encoded (the same packet), its sample or device
/// specifications driven into the wall scene.
pub fn bridge(data: &[u8]) {
    check(run_bridge(data));
}

/// What the page servers read from the network (an HTTP head, a page message, a student's
/// name): see [`crate::page`].
pub fn page(data: &[u8]) {
    check(crate::page::run_page(data));
}

/// A world parameter table (the Python wheel's dicts): see [`crate::params`].
pub fn params(data: &[u8]) {
    check(crate::params::run_params(data));
}

/// Recording bytes: read strictly and with salvage. What salvage accepts builds its arrays;
/// what the strict reader accepts had every chunk CRC, the data and summary CRCs, the summary
/// and the tick count checked.
pub fn recording(data: &[u8]) {
    if let Ok(r) = read_recording(data, true) {
        if let Err(e) = SessionArrays::from_recording(&r) {
            panic!("finding (inconsistent): read with salvage, but its arrays do not build: {e}");
        }
    }
    if let Ok(r) = read_recording(data, false) {
        let i = &r.integrity;
        assert!(
            r.truncated.is_none()
                && i.data_crc
                && i.summary_crc
                && i.summary
                && i.ticks_match_metadata,
            "finding (unchecked): the strict reader accepted a file without checking it whole \
             (data CRC {}, summary CRC {}, summary {}, tick count {})",
            i.data_crc,
            i.summary_crc,
            i.summary,
            i.ticks_match_metadata
        );
    }
}

fn seed() -> &'static Recording {
    static SEED: OnceLock<Recording> = OnceLock::new();
    SEED.get_or_init(|| {
        let dir = work_dir();
        std::fs::create_dir_all(&dir).expect("fuzz work folder");
        let b = seed_recording(&dir).expect("the seed recording");
        read_recording(&b, false).expect("the seed recording reads")
    })
}

/// The seed recording with one recorded output changed as `data` says (first byte even) —
/// which must not verify — or `data` itself read with salvage and verified (first byte odd),
/// which must give the same answer twice.
pub fn verify(data: &[u8]) {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    if mode % 2 == 1 {
        let Ok(rec) = read_recording(rest, true) else {
            return;
        };
        let a = haptic_loop::replay::verify(&rec).map(|v| v.ok());
        let b = haptic_loop::replay::verify(&rec).map(|v| v.ok());
        assert_eq!(
            a.as_ref().ok(),
            b.as_ref().ok(),
            "finding (nondeterministic): verify answered differently twice"
        );
        return;
    }
    let seed = seed();
    let outputs = verified_outputs(seed);
    let num = |k: usize| {
        let mut b = [0u8; 4];
        for (j, x) in rest.iter().skip(k).take(4).enumerate() {
            b[j] = *x;
        }
        u32::from_le_bytes(b) as usize
    };
    let i = outputs[num(0) % outputs.len()];
    let len = seed.messages[i].data.len();
    let change = match rest.get(4).copied().unwrap_or(0) % 4 {
        0 | 1 if len > 0 => OutputChange::Xor {
            byte: num(5) % len,
            mask: rest.get(9).copied().unwrap_or(1).max(1),
        },
        2 => OutputChange::Remove,
        _ => OutputChange::Repeat,
    };
    check(verify_changed(seed, i, change));
}
