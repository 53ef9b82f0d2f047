//! The fuzz targets: their seed corpora, how an input is made from a seed, and what counts as a
//! finding (besides a panic, an abort or a hang, which the driver catches).

use crate::mutate::{self, Rng};
use haptic_devices::Script;
use haptic_devices::bridge::protocol::{Packet, Sample};
use haptic_loop::scene::load_scene_for;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use haptic_loop::{Buttons, DeviceModel, DeviceSample, DeviceSpecs, HapticLoop, SessionArrays};
use recording::channels::messages::Channel;
use recording::{Recording, read_recording};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The targets, by name.
pub const TARGETS: &[&str] = &[
    "scene",
    "script",
    "recording",
    "verify",
    "bridge",
    "params",
    "cli",
];

pub use crate::outcome::Outcome;

/// A target with its seeds, ready to make and run inputs.
pub struct Target {
    /// Name.
    pub name: &'static str,
    seeds: Vec<Vec<u8>>,
    /// For `verify`: the seed recording, read.
    seed_rec: Option<Recording>,
    /// For `cli`: the program and the folder it runs in.
    cli: Option<(PathBuf, PathBuf)>,
    /// Per-input time limit (the CLI target kills its child process at it).
    pub timeout: Duration,
}

fn falcon() -> &'static DeviceSpecs {
    DeviceModel::Falcon.specs()
}

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

/// The folder the fuzzer works in (seed files, the CLI's working folder).
pub fn work_dir() -> PathBuf {
    std::env::temp_dir().join(format!("nanohaptics-fuzz-{}", std::process::id()))
}

impl Target {
    /// The target `name`, its seeds built (the CLI target needs the `nanohaptics` program next
    /// to this one).
    pub fn new(name: &str, timeout: Duration) -> Result<Target, String> {
        let name = *TARGETS
            .iter()
            .chain(&["selftest"])
            .find(|t| **t == name)
            .ok_or_else(|| format!("unknown target `{name}` (targets: {})", TARGETS.join(", ")))?;
        let dir = work_dir();
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let builtins = haptic_loop::builtin::SCENES;
        let mut t = Target {
            name,
            seeds: Vec::new(),
            seed_rec: None,
            cli: None,
            timeout,
        };
        match name {
            "selftest" => t.seeds = vec![b"selftest".to_vec()],
            "scene" => {
                t.seeds = builtins
                    .iter()
                    .map(|b| b.scene.as_bytes().to_vec())
                    .collect()
            }
            "script" => {
                t.seeds = builtins
                    .iter()
                    .map(|b| b.script.as_bytes().to_vec())
                    .collect()
            }
            "recording" | "verify" => {
                let b = seed_recording(&dir)?;
                t.seed_rec = Some(read_recording(&b, false).map_err(|e| e.to_string())?);
                t.seeds = vec![b];
            }
            "params" => t.seeds = crate::params::seeds(),
            "bridge" => {
                let sample = Sample {
                    seq: 7,
                    device_time_ns: 1_000_000,
                    position_m: [0.001, -0.002, -0.006],
                    buttons: 1,
                };
                t.seeds = vec![
                    Packet::Hello {
                        rate_hz: 1000,
                        specs: falcon().clone(),
                    }
                    .encode(),
                    Packet::Hello {
                        rate_hz: 1000,
                        specs: DeviceModel::Touch.specs().clone(),
                    }
                    .encode(),
                    Packet::Welcome {
                        rate_hz: 1000,
                        start_time_ns: 1_795_000_000_000_000_000,
                        scene: "wall".into(),
                    }
                    .encode(),
                    Packet::Sample(sample).encode(),
                    Packet::Bye { reason: 0 }.encode(),
                ];
            }
            _ => {
                let exe = std::env::current_exe().map_err(|e| e.to_string())?;
                let prog =
                    exe.with_file_name(format!("nanohaptics{}", std::env::consts::EXE_SUFFIX));
                if !prog.exists() {
                    return Err(format!(
                        "the cli target runs {}, which is not built (cargo build --release -p \
                         haptic-loop --bin nanohaptics)",
                        prog.display()
                    ));
                }
                std::fs::write(dir.join("seed.mcap"), seed_recording(&dir)?)
                    .map_err(|e| e.to_string())?;
                t.seeds = CLI_SEEDS
                    .iter()
                    .map(|args| args.join("\u{1f}").into_bytes())
                    .collect();
                t.cli = Some((prog, dir));
            }
        }
        Ok(t)
    }

    /// The seed inputs, unmutated.
    pub fn seeds(&self) -> &[Vec<u8>] {
        &self.seeds
    }

    /// Input `index` of a campaign with `seed`: a seed with 1–4 mutations.
    pub fn input(&self, seed: u64, index: u64) -> Vec<u8> {
        let mut r = Rng::for_input(seed, index);
        let mut b = r.pick(&self.seeds).clone();
        let n = 1 + r.below(if self.name == "cli" { 2 } else { 4 });
        for _ in 0..n {
            match self.name {
                "scene" | "script" | "params" => mutate::mutate_text(&mut r, &mut b, &self.seeds),
                "recording" | "verify" => mutate_recording(&mut r, &mut b),
                "cli" => mutate_argv(&mut r, &mut b),
                _ => mutate::mutate_bytes(&mut r, &mut b, &self.seeds),
            }
        }
        b
    }

    /// Runs one input.
    pub fn run(&self, input: &[u8], index: u64) -> Outcome {
        match self.name {
            "scene" => run_scene(input),
            "script" => run_script(input),
            "recording" => self.run_recording(input),
            "verify" => self.run_verify(input, index),
            "bridge" => run_bridge(input),
            "params" => crate::params::run_params(input),
            "selftest" => selftest(index, self.timeout),
            _ => self.run_cli(input),
        }
    }

    fn run_recording(&self, input: &[u8]) -> Outcome {
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

    fn run_verify(&self, input: &[u8], index: u64) -> Outcome {
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

    fn run_cli(&self, input: &[u8]) -> Outcome {
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
        let limit = self.timeout.mul_f64(0.8);
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

    /// A human-readable form of an input (for reports): the text, the argument list, or the
    /// byte count.
    pub fn show(&self, input: &[u8]) -> String {
        match self.name {
            "scene" | "script" | "params" => String::from_utf8_lossy(input).into_owned(),
            "cli" => {
                let a: Vec<String> = argv(input)
                    .iter()
                    .map(|a| format!("'{}'", String::from_utf8_lossy(a)))
                    .collect();
                format!("nanohaptics {}", a.join(" "))
            }
            _ => format!("{} bytes", input.len()),
        }
    }
}

fn pad8(b: &[u8]) -> [u8; 8] {
    let mut a = [0u8; 8];
    for (i, x) in b.iter().take(8).enumerate() {
        a[i] = *x;
    }
    a
}

fn mutate_recording(r: &mut Rng, b: &mut Vec<u8>) {
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

/// Arguments are kept as one byte string separated by 0x1f.
fn argv(b: &[u8]) -> Vec<Vec<u8>> {
    b.split(|&c| c == 0x1f)
        .map(|a| {
            a.iter()
                .map(|&c| if c == b'/' || c == 0 { b'_' } else { c })
                .collect()
        })
        .collect()
}

const CLI_SEEDS: &[&[&str]] = &[
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

fn mutate_argv(r: &mut Rng, b: &mut Vec<u8>) {
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

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Ticks a loop along a short path (with the first button pressed half-way), checking that every
/// force is finite and the device force within the device's limit.
fn drive(lp: &mut HapticLoop, specs: &DeviceSpecs, start: [f64; 3], ticks: u64) -> Outcome {
    let r = 0.5 * specs.workspace_radius_m.clamp(0.0, 0.2);
    for k in 0..ticks {
        let a = k as f64 * 0.2;
        let p = [
            start[0] + 0.1 * r * a.cos(),
            start[1] + 0.1 * r * a.sin(),
            start[2] - 0.2 * r * (k as f64 / ticks as f64),
        ];
        let s = DeviceSample {
            position_m: p,
            buttons: Buttons(u32::from(k > ticks / 2)),
            seq: k,
            age_ticks: 0,
        };
        let t = lp.tick(s, false);
        if !finite3(t.world_force_n) || !finite3(t.device_force_n) {
            return Outcome::Finding(
                "non-finite",
                format!(
                    "tick {k}: world force ({}, {}, {}) N, device force ({}, {}, {}) N",
                    t.world_force_n[0],
                    t.world_force_n[1],
                    t.world_force_n[2],
                    t.device_force_n[0],
                    t.device_force_n[1],
                    t.device_force_n[2]
                ),
            );
        }
        let f = norm(t.device_force_n);
        if f > specs.limits.max_force_n * (1.0 + 1e-9) {
            return Outcome::Finding(
                "over-limit",
                format!(
                    "tick {k}: device force {f} N over the limit {} N",
                    specs.limits.max_force_n
                ),
            );
        }
    }
    Outcome::Accepted
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

/// A scene file for a Falcon; an accepted scene is ticked 40 times along a path.
pub fn run_scene(input: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(input);
    match load_scene_for(&text, falcon().clone()) {
        Err(_) => Outcome::Refused,
        Ok(l) => {
            let mut lp = HapticLoop::new(l.config, l.scene);
            drive(&mut lp, falcon(), [0.0, 0.0, 0.0], 40)
        }
    }
}

/// A script file; an accepted script is sampled at 51 times (finite positions and velocities).
pub fn run_script(input: &[u8]) -> Outcome {
    let text = String::from_utf8_lossy(input);
    match Script::from_toml(&text, falcon()) {
        Err(_) => Outcome::Refused,
        Ok(s) => {
            if !s.duration_s.is_finite() {
                return Outcome::Finding("non-finite", format!("duration {} s", s.duration_s));
            }
            for k in 0..=50 {
                let t = s.duration_s * f64::from(k) / 50.0;
                let p = s.position(t);
                if !finite3(p) || !finite3(s.velocity(t)) {
                    return Outcome::Finding(
                        "non-finite",
                        format!("position ({}, {}, {}) m at t = {t} s", p[0], p[1], p[2]),
                    );
                }
            }
            Outcome::Accepted
        }
    }
}

/// A bridge datagram: decode, re-encode, decode; samples and announced specifications drive the
/// wall scene (finite forces within the limit).
pub fn run_bridge(input: &[u8]) -> Outcome {
    let Ok(p) = Packet::decode(input) else {
        return Outcome::Refused;
    };
    // Encoding what was decoded and decoding it again gives the same packet.
    let once = p.encode();
    match Packet::decode(&once).map(|q| q.encode()) {
        Ok(twice) if twice == once => {}
        Ok(_) => {
            return Outcome::Finding("round-trip", "re-encoding changes the packet".into());
        }
        Err(e) => {
            return Outcome::Finding(
                "round-trip",
                format!("an accepted packet, re-encoded, is refused: {e}"),
            );
        }
    }
    let wall = haptic_loop::builtin::SCENES
        .iter()
        .find(|b| b.name == "wall")
        .map(|b| b.scene)
        .unwrap_or_default();
    match p {
        Packet::Sample(s) => {
            // A device sample straight into the loop: the force stays finite and bounded.
            let Ok(l) = load_scene_for(wall, falcon().clone()) else {
                return Outcome::Finding("seed", "the wall scene does not load".into());
            };
            let mut lp = HapticLoop::new(l.config, l.scene);
            for k in 0..3 {
                let t = lp.tick(
                    DeviceSample {
                        position_m: s.position_m,
                        buttons: Buttons(s.buttons),
                        seq: s.seq,
                        age_ticks: k,
                    },
                    false,
                );
                if !finite3(t.device_force_n)
                    || norm(t.device_force_n) > falcon().limits.max_force_n
                {
                    return Outcome::Finding(
                        "non-finite",
                        format!(
                            "sample at ({}, {}, {}) m gives device force ({}, {}, {}) N",
                            s.position_m[0],
                            s.position_m[1],
                            s.position_m[2],
                            t.device_force_n[0],
                            t.device_force_n[1],
                            t.device_force_n[2]
                        ),
                    );
                }
            }
            Outcome::Accepted
        }
        Packet::Hello { specs, .. } => {
            // Announced specifications drive a session: its forces respect them.
            match load_scene_for(wall, specs.clone()) {
                Err(_) => Outcome::Refused,
                Ok(l) => {
                    let mut lp = HapticLoop::new(l.config, l.scene);
                    drive(&mut lp, &specs, [0.0, 0.0, 0.0], 20)
                }
            }
        }
        _ => Outcome::Accepted,
    }
}

/// The harness's own check (`--target selftest`, not part of `--all`): input 3 of every 100
/// panics, input 5 aborts, input 7 hangs, input 9 gives a non-finite force; the rest pass.
fn selftest(index: u64, timeout: Duration) -> Outcome {
    match index % 100 {
        3 => panic!("selftest panic at input {index}"),
        5 => std::process::abort(),
        7 => {
            std::thread::sleep(timeout * 3);
            Outcome::Accepted
        }
        9 => Outcome::Finding("non-finite", "selftest force NaN".into()),
        _ => Outcome::Accepted,
    }
}
