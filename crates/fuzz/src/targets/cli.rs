//! The `cli` target: one `nanohaptics` process per input (an argument list mutated from real
//! command lines), judged by its exit status and its messages (no panic, no signal, no Rust
//! Debug text, an error message on failure, finite forces in its JSON).

use super::{Outcome, Target};
use crate::mutate::{self, Rng};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The share of the time limit after which a `cli` input's process is killed (and counted
/// as a hang): the harness's own limit then still catches a stuck worker.
pub const KILL_AT: f64 = 0.8;

impl Target {
    pub(super) fn run_cli(&self, input: &[u8]) -> Outcome {
        let Some((prog, dir)) = &self.cli else {
            return Outcome::Refused;
        };
        let args = argv(input);
        let mut cmd = Command::new(prog);
        {
            use std::os::unix::ffi::OsStrExt;
            for a in &args {
                cmd.arg(std::ffi::OsStr::from_bytes(a));
            }
        }
        let child = cmd
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn();
        let Ok(mut child) = child else {
            return Outcome::Refused;
        };
        let limit = self.timeout.mul_f64(KILL_AT);
        let t0 = Instant::now();
        let status = loop {
            match child.try_wait() {
                Ok(Some(s)) => break s,
                Ok(None) if t0.elapsed() > limit => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Outcome::Finding(
                        "hang",
                        format!("still running after {:.1} s (killed)", limit.as_secs_f64()),
                    );
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(2)),
                Err(e) => return Outcome::Finding("bad-exit", format!("wait: {e}")),
            }
        };
        let out = child.wait_with_output().map(|o| (o.stdout, o.stderr));
        let (stdout, stderr) = out.unwrap_or_default();
        let stderr = String::from_utf8_lossy(&stderr);
        use std::os::unix::process::ExitStatusExt;
        if let Some(sig) = status.signal() {
            return Outcome::Finding("abort", format!("killed by signal {sig}: {stderr}"));
        }
        match status.code() {
            Some(0) => {
                let stdout = String::from_utf8_lossy(&stdout);
                for line in stdout.lines().filter(|l| l.starts_with('{')) {
                    if let Ok(j) = serde_json::from_str::<serde_json::Value>(line) {
                        if let Some(p) = j.get("peak_device_force_n") {
                            if !p.as_f64().is_some_and(f64::is_finite) {
                                return Outcome::Finding(
                                    "non-finite",
                                    format!("peak_device_force_n = {p}"),
                                );
                            }
                        }
                    }
                }
                Outcome::Accepted
            }
            Some(101) => Outcome::Finding("panic", stderr.trim().to_string()),
            Some(1 | 2) => {
                if ["Some(", "Ok(", "Err("].iter().any(|d| stderr.contains(d)) {
                    Outcome::Finding("debug-text", stderr.trim().to_string())
                } else if !stderr.contains("error") {
                    Outcome::Finding("bad-exit", format!("failed without an error: {stderr}"))
                } else {
                    Outcome::Refused
                }
            }
            Some(c) => Outcome::Finding("bad-exit", format!("exit status {c}: {stderr}")),
            None => Outcome::Finding("abort", stderr.to_string()),
        }
    }
}

/// Arguments are kept as one byte string separated by 0x1f.
pub(super) fn argv(b: &[u8]) -> Vec<Vec<u8>> {
    b.split(|&c| c == 0x1f)
        .map(|a| {
            a.iter()
                .map(|&c| if c == b'/' || c == 0 { b'_' } else { c })
                .collect()
        })
        .collect()
}

pub(super) const CLI_SEEDS: &[&[&str]] = &[
    &["run", "wall", "--seconds", "0.02", "--json"],
    &[
        "run",
        "wall",
        "--seconds",
        "0.02",
        "--operator",
        "hand:mass_kg=0.3,stiffness_n_per_m=300,damping_n_s_per_m=12",
        "--json",
    ],
    &[
        "run",
        "nanoworld",
        "--seconds",
        "0.01",
        "--operator",
        "rigid",
        "--device",
        "touch",
        "--json",
    ],
    &["run", "brickworld", "--seconds", "0.01", "--json"],
    &["run", "optical_tweezers", "--seconds", "0.002", "--json"],
    &[
        "run",
        "wall",
        "--seconds",
        "0.02",
        "--out",
        "o.mcap",
        "--json",
    ],
    &["replay", "seed.mcap", "--verify", "--json"],
    &["replay", "seed.mcap", "--salvage"],
    &["info", "seed.mcap", "--json"],
    &[
        "render",
        "seed.mcap",
        "--audio",
        "a.wav",
        "--sample-rate",
        "8000",
    ],
    &["scenes"],
];

const FLAGS: &[&str] = &[
    "--seconds",
    "--operator",
    "--device",
    "--out",
    "--json",
    "--verify",
    "--salvage",
    "--script",
    "--every",
    "--width",
    "--live-hz",
    "--wait-s",
    "--audio",
    "--proximity",
    "--sample-rate",
    "rigid",
    "hand",
    "hand:mass_kg=1",
    "falcon",
    "touch",
    "wall",
    "seed.mcap",
    "",
    "-",
    "--",
];

pub(super) fn mutate_argv(r: &mut Rng, b: &mut Vec<u8>) {
    let mut a = argv(b);
    match r.below(6) {
        0 | 1 => {
            // A number (in any argument) replaced by an extreme.
            let i = r.below(a.len());
            let mut x = std::mem::take(&mut a[i]);
            mutate::mutate_text(r, &mut x, &[]);
            a[i] = x;
        }
        2 if a.len() > 1 => {
            let i = 1 + r.below(a.len() - 1);
            a.remove(i);
        }
        3 => {
            let i = r.below(a.len() + 1).max(1).min(a.len());
            a.insert(i, r.pick(FLAGS).as_bytes().to_vec());
        }
        4 => {
            let i = r.below(a.len());
            let x = a[i].clone();
            a.insert(i, x);
        }
        _ => {
            let i = r.below(a.len());
            mutate::mutate_bytes(r, &mut a[i], &[]);
        }
    }
    *b = a.join(&0x1f);
}
