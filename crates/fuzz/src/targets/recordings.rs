//! The `recording` and `verify` targets: a short recording of the wall scene as the seed,
//! structural mutations (a record removed, repeated, swapped or cut), the strict reader with and
//! without salvage, and recorded outputs changed in memory that must not verify.

use super::{Outcome, Target};
use crate::mutate::{self, Rng};
use haptic_loop::SessionArrays;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use recording::channels::messages::Channel;
use recording::{Recording, read_recording};
use std::path::Path;

/// A short deterministic recording of the wall scene (the seed of `recording` and `verify`).
pub fn seed_recording(dir: &Path) -> Result<Vec<u8>, String> {
    let p = dir.join("seed.mcap");
    let mut o = SessionOptions::new(
        SceneSource::resolve(Path::new("wall")).map_err(|e| format!("seed scene: {e}"))?,
    );
    o.seconds = Some(0.25);
    o.start_time_ns = Some(1_795_000_000_000_000_000);
    o.out = Some(p.clone());
    run_session(&o, &mut |_, _| {}).map_err(|e| format!("seed recording: {e}"))?;
    std::fs::read(&p).map_err(|e| format!("seed recording {}: {e}", p.display()))
}

/// Top-level MCAP record boundaries of `b` (for structural mutations).
fn records(b: &[u8]) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    let mut at = 8usize;
    while let Some(h) = b.get(at..at + 9) {
        let mut l = [0u8; 8];
        l.copy_from_slice(&h[1..]);
        let Some(end) = usize::try_from(u64::from_le_bytes(l))
            .ok()
            .and_then(|l| (at + 9).checked_add(l))
            .filter(|&e| e <= b.len())
        else {
            break;
        };
        v.push((at, end));
        at = end;
    }
    v
}

impl Target {
    pub(super) fn run_recording(&self, input: &[u8]) -> Outcome {
        let modified = self.seeds.first().is_some_and(|s| s != input);
        let strict = read_recording(input, false);
        let salvaged = read_recording(input, true);
        if let Ok(r) = &salvaged {
            if let Err(e) = SessionArrays::from_recording(r) {
                return Outcome::Finding(
                    "inconsistent",
                    format!("read with salvage, but its arrays do not build: {e}"),
                );
            }
        }
        match strict {
            Ok(_) if modified => Outcome::Finding(
                "accepted-modified",
                "a changed recording read without error".into(),
            ),
            Ok(_) => Outcome::Accepted,
            Err(_) => Outcome::Refused,
        }
    }

    pub(super) fn run_verify(&self, input: &[u8], index: u64) -> Outcome {
        // Half the inputs: changed bytes through the reader (salvage) and the verifier. The
        // other half: one recorded output changed in memory, which must not verify.
        if index % 2 == 0 {
            let Ok(rec) = read_recording(input, true) else {
                return Outcome::Refused;
            };
            let changed = self.seeds.first().is_some_and(|s| s != input);
            return match haptic_loop::replay::verify(&rec) {
                Ok(v) if v.ok() && changed && rec.truncated.is_none() => Outcome::Finding(
                    "accepted-modified",
                    "a changed recording read and verified".into(),
                ),
                Ok(v) if v.ok() => Outcome::Accepted,
                _ => Outcome::Refused,
            };
        }
        let Some(seed) = &self.seed_rec else {
            return Outcome::Refused;
        };
        let mut r = Rng::for_input(u64::from_le_bytes(pad8(input)), index);
        let outputs = verified_outputs(seed);
        let i = *r.pick(&outputs);
        let change = match r.below(3) {
            0 if !seed.messages[i].data.is_empty() => OutputChange::Xor {
                byte: r.below(seed.messages[i].data.len()),
                mask: 1 << r.below(8),
            },
            1 => OutputChange::Remove,
            _ => OutputChange::Repeat,
        };
        verify_changed(seed, i, change)
    }
}

fn pad8(b: &[u8]) -> [u8; 8] {
    let mut a = [0u8; 8];
    for (i, x) in b.iter().take(8).enumerate() {
        a[i] = *x;
    }
    a
}

pub(super) fn mutate_recording(r: &mut Rng, b: &mut Vec<u8>) {
    let recs = records(b);
    if recs.len() < 2 || r.below(3) != 0 {
        return mutate::mutate_bytes(r, b, &[]);
    }
    let (s, e) = *r.pick(&recs);
    match r.below(4) {
        0 => {
            b.drain(s..e);
        }
        1 => {
            let piece = b[s..e].to_vec();
            b.splice(e..e, piece);
        }
        2 => {
            // Swap with the next record.
            if let Some(&(s2, e2)) = recs.iter().find(|x| x.0 == e) {
                let a = b[s..e].to_vec();
                let c = b[s2..e2].to_vec();
                let mut both = c;
                both.extend_from_slice(&a);
                b.splice(s..e2, both);
            }
        }
        _ => b.truncate(e),
    }
}

/// One change to a recorded output message (the `verify` targets' alteration).
pub enum OutputChange {
    /// Byte `byte` of the message xored with `mask` (≠ 0).
    Xor {
        /// Byte index, < the message's length.
        byte: usize,
        /// Bits to flip.
        mask: u8,
    },
    /// The message removed.
    Remove,
    /// The message repeated.
    Repeat,
}

/// Indices of `rec`'s verified (output) messages.
pub fn verified_outputs(rec: &Recording) -> Vec<usize> {
    (0..rec.messages.len())
        .filter(|&i| rec.messages[i].channel.verified())
        .collect()
}

/// `seed` with message `i` changed, verified: a finding when it still verifies; refused when
/// it does not (or has no device input left to re-run).
pub fn verify_changed(seed: &Recording, i: usize, change: OutputChange) -> Outcome {
    let mut rec = seed.clone();
    let m = &mut rec.messages[i];
    let topic = m.channel.topic();
    let what = match change {
        OutputChange::Xor { byte, mask } => {
            m.data[byte] ^= mask;
            format!("byte {byte} of a {topic} message xored with {mask}")
        }
        OutputChange::Remove => {
            rec.messages.remove(i);
            format!("a {topic} message removed")
        }
        OutputChange::Repeat => {
            let dup = m.clone();
            rec.messages.insert(i, dup);
            format!("a {topic} message repeated")
        }
    };
    if rec
        .messages
        .iter()
        .all(|m| m.channel != Channel::DeviceInput)
    {
        return Outcome::Refused;
    }
    match haptic_loop::replay::verify(&rec) {
        Ok(v) if v.ok() => Outcome::Finding(
            "accepted-modified",
            format!("a recording with {what} verified"),
        ),
        _ => Outcome::Refused,
    }
}
