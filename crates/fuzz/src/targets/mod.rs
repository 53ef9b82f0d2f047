//! The fuzz targets: their seed corpora, how an input is made from a seed, and what counts as a
//! finding (besides a panic, an abort or a hang, which the driver catches). One module per
//! family of targets: `recordings` (`recording`, `verify`), `cli`, `physics` (`scene`,
//! `script`, `bridge`); `params` lives in [`crate::params`].

mod cli;
pub use cli::KILL_AT;
mod physics;
mod recordings;

use crate::mutate::{self, Rng};
use ::recording::{Recording, read_recording};
use cli::{CLI_SEEDS, argv, mutate_argv};
use haptic_devices::bridge::protocol::ForceReply;
use haptic_devices::bridge::protocol::{Packet, Sample};
use haptic_types::DeviceModel;
use haptic_types::DeviceSpecs;
use recordings::mutate_recording;
use std::path::PathBuf;
use std::time::Duration;

pub use physics::{run_bridge, run_scene, run_script};
pub use recordings::{OutputChange, seed_recording, verified_outputs, verify_changed};

/// The targets, by name.
pub const TARGETS: &[&str] = &[
    "scene",
    "script",
    "recording",
    "verify",
    "bridge",
    "params",
    "page",
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
            "page" => t.seeds = crate::page::seeds(),
            "bridge" => t.seeds = bridge_seeds(),
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

    /// Input `index` of a campaign with `seed`: a seed with 1 to [`max_mutations`] mutations.
    pub fn input(&self, seed: u64, index: u64) -> Vec<u8> {
        let mut r = Rng::for_input(seed, index);
        let mut b = r.pick(&self.seeds).clone();
        let n = 1 + r.below(max_mutations(self.name));
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
            "page" => crate::page::run_page(input),
            "selftest" => selftest(index, self.timeout),
            _ => self.run_cli(input),
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

/// The bridge target's seeds: hellos of versions 1 and 2, answers of versions 2 and 3, a
/// welcome, a sample and a bye.
fn bridge_seeds() -> Vec<Vec<u8>> {
    let sample = Sample {
        seq: 7,
        device_time_ns: 1_000_000,
        position_m: [0.001, -0.002, -0.006],
        buttons: 1,
        two_port_periods: None,
    };
    vec![
        Packet::Hello {
            version: 1,
            rate_hz: 1000,
            specs: falcon().clone(),
        }
        .encode(),
        Packet::Hello {
            version: 2,
            rate_hz: 1000,
            specs: DeviceModel::Touch.specs().clone(),
        }
        .encode(),
        Packet::Force(ForceReply {
            seq: 7,
            tick: 7,
            force_n: [0.0, 0.0, 1.0],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(seed_local_model())),
        })
        .encode(),
        // A version-3 answer: the model with the nano world's bond.
        Packet::Force(ForceReply {
            seq: 8,
            tick: 8,
            force_n: [0.0, 0.0, -0.2],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(haptic_types::local::LocalModel {
                bond: Some(haptic_types::local::Bond {
                    anchor_m: [0.0, 0.0, -0.001],
                    normal: [0.0, 0.0, 1.0],
                    stiffness_n_per_m: 200.0,
                    break_m: 0.004,
                }),
                ..Default::default()
            })),
        })
        .encode(),
        // A version-4 answer: the optical tweezers' held particle and its envelope.
        Packet::Force(ForceReply {
            seq: 9,
            tick: 9,
            force_n: [-0.4, 0.1, 0.0],
            stiffness_n_per_m: [0.0; 9],
            status: 0,
            local: Some(Box::new(haptic_types::local::LocalModel {
                follower: Some(haptic_types::local::Follower {
                    position_m: [0.001, -0.002],
                    drift_m: [1e-5, 0.0],
                    reach_m: (0..12)
                        .map(|k| {
                            let th = std::f64::consts::TAU * f64::from(k) / 12.0;
                            [6e-5 * th.cos(), 3e-5 * th.sin()]
                        })
                        .collect(),
                    retain: 0.1,
                    stiffness_n_per_m: 800.0,
                }),
                ..Default::default()
            })),
        })
        .encode(),
        seed_welcome(),
        Packet::Sample(sample).encode(),
        Packet::Bye { reason: 0 }.encode(),
    ]
}

/// A protocol-2 local model for the bridge target's seeds: a floor plane, a carried body on its
/// coupling, the floor under the body.
fn seed_local_model() -> haptic_types::local::LocalModel {
    use haptic_types::local::{Body, LocalModel, Plane};
    let floor = |offset_m, stiffness_n_per_m| Plane {
        normal: [0.0, 0.0, 1.0],
        offset_m,
        stiffness_n_per_m,
    };
    LocalModel {
        residual_force_n: [0.0, 0.0, 0.1],
        residual_stiffness_n_per_m: [0.0; 9],
        planes: vec![floor(-0.01, 2500.0)],
        body: Some(Body {
            position_m: [0.0, 0.0, -0.001],
            velocity_m_per_s: [0.0; 3],
            mass_kg: 1.25,
            stiffness_n_per_m: 900.0,
            series_stiffness_n_per_m: 900.0,
            damping_n_s_per_m: 60.0,
            damper_m: [0.0; 3],
            external_force_n: [0.0, 0.0, -0.6],
            substeps: 4,
            restitution: 0.2,
        }),
        body_planes: vec![floor(-0.02, 0.0)],
        world_energy_j: 0.0,
        bond: None,
        follower: None,
    }
}

/// A seed of the bridge target: a version-2 welcome with the Falcon's button roles.
fn seed_welcome() -> Vec<u8> {
    Packet::Welcome {
        version: 2,
        rate_hz: 1000,
        start_time_ns: 1_795_000_000_000_000_000,
        scene: "wall".into(),
        roles: Some([0, 1, 2, 3]),
    }
    .encode()
}

/// Most mutations an input of the target `name` gets (each gets 1 to this many): 4, and 2 for
/// `cli`, whose every input is a process.
pub fn max_mutations(name: &str) -> usize {
    if name == "cli" { 2 } else { 4 }
}
