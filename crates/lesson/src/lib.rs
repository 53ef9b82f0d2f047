//! # nanohaptics-lesson: the macro-vs-nano lesson of the teaching game (`nanohaptics lesson --out DIR`)
//!
//! It runs the house task in both worlds with the same operator (a rigid stylus playing each
//! world's house script), then the short experiments a teacher shows next to it — lifting a
//! brick (weight and inertia), the nano approach–retract cycle (snap and tenfold pull-off), the
//! same motions with gravity off, inertia off and adhesion halved (switches), a throw in each
//! world and the hand acceleration an atom would need to leave the tip — and writes
//! `DIR/lesson.md` with PNG figures, the two house sessions as recordings (`*.mcap`, open them
//! in Foxglove or replay them) and a JSON file of every number (`lesson.json`). Every number
//! in the report is measured from these runs or read from the scenes' parameters.
//!
//! What it is not: no physics and no loop of its own. It drives the engine (`haptic-loop`)
//! through its sessions, draws its figures with the one chart engine (`chart`), and knows the
//! worlds only through their scenes' state fields and events.

pub mod measure;
pub mod report;
pub mod scripts;

use haptic_devices::source::OperatorChoice;
use haptic_loop::session::{SceneSource, SessionArrays, SessionError, SessionOptions};
use measure::{BrickThrow, HouseOutcome, Hysteresis};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Errors of the lesson.
#[derive(Debug, thiserror::Error)]
pub enum LessonError {
    /// A run failed.
    #[error("lesson run `{run}`: {error}")]
    Run {
        /// The run's name.
        run: String,
        /// Why.
        error: Box<SessionError>,
    },
    /// A run did not show what the lesson measures (an event that did not happen).
    #[error("lesson run `{run}`: {what}")]
    Missing {
        /// The run's name.
        run: String,
        /// What was expected.
        what: String,
    },
    /// Writing the report.
    #[error("cannot write {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        message: String,
    },
    /// Drawing a figure.
    #[error("figure {figure}: {message}")]
    Figure {
        /// The figure's file name.
        figure: String,
        /// What went wrong.
        message: String,
    },
}

/// Options of the lesson.
#[derive(Clone, Debug)]
pub struct LessonOptions {
    /// Folder for the report (created if missing).
    pub out: PathBuf,
    /// Width of the figures, px (200–4000).
    pub width_px: u32,
    /// Sample rate of the house tasks' sounds, Hz (8000–192000).
    pub sample_rate_hz: u32,
}

/// One run of the lesson: its name and what it produced.
pub struct Run {
    /// Short name (`macro_house`, `lift_gravity_off`, …).
    pub name: &'static str,
    /// Its per-tick arrays.
    pub arrays: SessionArrays,
}

/// The throws of a heavy atom at increasing hand accelerations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ThrowSweep {
    /// The atom's mass in these runs, kg.
    pub mass_kg: f64,
    /// The tip's hold (tip–atom pull-off force), N.
    pub hold_n: f64,
    /// Predicted hand acceleration to throw it off, m/s² (hold / mass / workspace scale).
    pub predicted_hand_m_per_s2: f64,
    /// Each run: (swing time s, measured peak hand acceleration m/s², thrown off).
    pub runs: Vec<(f64, f64, bool)>,
    /// Largest hand acceleration that kept the atom, m/s².
    pub kept_below_m_per_s2: f64,
    /// Smallest hand acceleration that threw it off, m/s².
    pub thrown_from_m_per_s2: f64,
}

/// Everything the report shows, measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LessonSummary {
    /// The macro house task.
    pub macro_house: HouseOutcome,
    /// The nano house task.
    pub nano_house: HouseOutcome,
    /// Lifting a brick: weight felt while held still, N (world), per run
    /// (normal, gravity off, inertia off).
    pub lift_weight_n: [f64; 3],
    /// Peak sideways (inertial) force while carrying, N (world), per run.
    pub lift_inertia_n: [f64; 3],
    /// The brick's mass, kg, and gravity, m/s² (the scene's).
    pub brick_mass_kg: f64,
    /// Gravity of the brick world, m/s².
    pub gravity_m_per_s2: f64,
    /// Predicted peak inertial force of the carry, N: M · 5.7735 · D / T² (minimum-jerk move
    /// of D = 0.45 m in T = 0.9 s).
    pub lift_inertia_predicted_n: f64,
    /// Approach–retract, normal adhesion.
    pub hysteresis: Hysteresis,
    /// Approach–retract, adhesion halved.
    pub hysteresis_half: Hysteresis,
    /// The brick throw.
    pub brick_throw: BrickThrow,
    /// Peak hand acceleration of the throw motion, m/s² (device).
    pub throw_hand_m_per_s2: f64,
    /// Whether the real atom stayed on the tip through the same motion.
    pub atom_stayed: bool,
    /// Peak load on the atom in that motion (its inertia and weight), N.
    pub atom_load_n: f64,
    /// Peak inertial force on the atom in that motion, m·a, N.
    pub atom_inertia_n: f64,
    /// The tip's hold on it (tip–atom pull-off force), N.
    pub atom_hold_n: f64,
    /// The atom's mass, kg.
    pub atom_mass_kg: f64,
    /// Hand acceleration that would throw the real atom off, m/s² (device).
    pub atom_threshold_hand_m_per_s2: f64,
    /// The heavy-atom throws that show the threshold.
    pub sweep: ThrowSweep,
    /// Sizes: brick edge lengths (m), cursor sphere radius (m), atom radius (m), tip radius (m).
    pub sizes_m: [(String, f64); 5],
    /// Files written.
    pub files: Vec<String>,
}

/// The brick scene (built in).
fn source(name: &str) -> Result<SceneSource, LessonError> {
    SceneSource::builtin(name).ok_or_else(|| LessonError::Missing {
        run: name.to_string(),
        what: format!("no built-in scene `{name}`"),
    })
}

/// Runs a scene with a script text (`None`: its house script) through a rigid stylus.
fn run(
    name: &'static str,
    scene: &str,
    script: Option<String>,
    out: Option<PathBuf>,
) -> Result<Run, LessonError> {
    let mut o = SessionOptions::new(source(scene)?);
    o.script_origin = script.as_ref().map(|_| format!("lesson script `{name}`"));
    o.script = script;
    o.operator = OperatorChoice::Rigid;
    o.out = out;
    o.start_time_ns = Some(0);
    let report = haptic_loop::session::run_session(&o, &mut |_, _| {}).map_err(|error| {
        LessonError::Run {
            run: name.to_string(),
            error: Box::new(error),
        }
    })?;
    Ok(Run {
        name,
        arrays: report.arrays,
    })
}

fn missing(run: &str, what: &str) -> LessonError {
    LessonError::Missing {
        run: run.to_string(),
        what: what.to_string(),
    }
}

/// Swing times of the heavy-atom throws, s (hand peak accelerations 1.9–17 m/s² for 30 mm).
pub const SWEEP_SWING_S: [f64; 7] = [0.3, 0.24, 0.2, 0.17, 0.15, 0.12, 0.1];
/// Mass of the heavy "atom" of the threshold demonstration, kg (3 g, gravity off): its
/// threshold is within a hand's reach.
pub const SWEEP_MASS_KG: f64 = 3e-3;

/// Runs the lesson and writes its report into `opts.out`; `progress(done, total, run)` is
/// called before each run.
pub fn run_lesson(
    opts: &LessonOptions,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Result<LessonSummary, LessonError> {
    std::fs::create_dir_all(&opts.out).map_err(|e| LessonError::Io {
        path: opts.out.display().to_string(),
        message: e.to_string(),
    })?;
    let total = 10 + SWEEP_SWING_S.len();
    let mut done = 0;
    let mut step = |name: &str| {
        progress(done, total, name);
        done += 1;
    };
    let runs = run_all(opts, &mut step)?;
    step("report");
    let mut summary = summarize(&runs)?;
    summary.files = report::write(&opts.out, opts.width_px, &summary, &runs)?;
    let json = serde_json::to_string_pretty(&summary).map_err(|e| LessonError::Io {
        path: "lesson.json".into(),
        message: e.to_string(),
    })?;
    write_file(&opts.out.join("lesson.json"), json.as_bytes())?;
    summary.files.push("lesson.json".into());
    // The sounds of the two house tasks, from their recordings (with the proximity tone).
    for name in ["macro_house", "nano_house"] {
        let rec = opts.out.join(format!("{name}.mcap"));
        let wav = format!("{name}.wav");
        let sound = sound_of(&rec, opts.sample_rate_hz).map_err(|what| LessonError::Missing {
            run: name.to_string(),
            what,
        })?;
        sound
            .write_wav(&opts.out.join(&wav))
            .map_err(|e| LessonError::Io {
                path: opts.out.join(&wav).display().to_string(),
                message: e.to_string(),
            })?;
        summary.files.push(format!("{name}.mcap"));
        summary.files.push(wav);
    }
    Ok(summary)
}

/// The lesson's sessions, in order (`step(name)` before each); the two house tasks are
/// recorded into `opts.out`.
fn run_all(opts: &LessonOptions, step: &mut dyn FnMut(&str)) -> Result<Runs, LessonError> {
    let rec = |f: &str| Some(opts.out.join(f));
    step("macro_house");
    let macro_house = run("macro_house", "brickworld", None, rec("macro_house.mcap"))?;
    step("nano_house");
    let nano_house = run("nano_house", "nanoworld", None, rec("nano_house.mcap"))?;
    let mut lifts = Vec::new();
    for (name, sw) in [
        ("lift", vec![]),
        ("lift_gravity_off", vec![("gravity_m_per_s2", 0.0)]),
        ("lift_inertia_off", vec![("inertia", 0.0)]),
    ] {
        step(name);
        let (text, _) = scripts::brick_lift(&sw);
        lifts.push(run(name, "brickworld", Some(text), None)?);
    }
    let mut cycles = Vec::new();
    for (name, sw) in [
        ("approach_retract", vec![]),
        ("approach_retract_half", vec![("adhesion_scale", 0.5)]),
    ] {
        step(name);
        cycles.push(run(
            name,
            "nanoworld",
            Some(scripts::approach_retract(&sw)),
            None,
        )?);
    }
    step("brick_throw");
    let (text, _) = scripts::brick_throw(0.3);
    let brick_throw = run("brick_throw", "brickworld", Some(text), None)?;
    step("atom_throw");
    let atom_throw = run(
        "atom_throw",
        "nanoworld",
        Some(scripts::atom_throw(0.3, &[])),
        None,
    )?;
    let mut sweep = Vec::new();
    for swing in SWEEP_SWING_S {
        step("heavy_atom_throw");
        let text = scripts::atom_throw(
            swing,
            &[("gravity_m_per_s2", 0.0), ("atom_mass_kg", SWEEP_MASS_KG)],
        );
        sweep.push((
            swing,
            run("heavy_atom_throw", "nanoworld", Some(text), None)?,
        ));
    }
    Ok(Runs {
        macro_house,
        nano_house,
        lifts,
        cycles,
        brick_throw,
        atom_throw,
        sweep,
    })
}

/// The nano scene's workspace scale, m of world per m of stylus.
const NANO_WORKSPACE_SCALE: f64 = 1.5e-7;

/// The threshold demonstration: each heavy-atom throw's peak hand acceleration and whether the
/// atom was thrown off, against the predicted threshold.
fn throw_sweep(sweep: &[(f64, Run)], hold: f64) -> ThrowSweep {
    let mut runs = Vec::new();
    for (swing, r) in sweep {
        let thrown = measure::events(&r.arrays, "nano.atoms_thrown_off")
            .next()
            .is_some();
        runs.push((*swing, measure::peak_hand_acceleration(&r.arrays), thrown));
    }
    let kept_below = runs
        .iter()
        .filter(|r| !r.2)
        .map(|r| r.1)
        .fold(0.0, f64::max);
    let thrown_from = runs
        .iter()
        .filter(|r| r.2)
        .map(|r| r.1)
        .fold(f64::INFINITY, f64::min);
    ThrowSweep {
        mass_kg: SWEEP_MASS_KG,
        hold_n: hold,
        predicted_hand_m_per_s2: hold / SWEEP_MASS_KG / NANO_WORKSPACE_SCALE,
        runs,
        kept_below_m_per_s2: kept_below,
        thrown_from_m_per_s2: thrown_from,
    }
}

/// The lesson's figures from its runs (no files written yet).
fn summarize(runs: &Runs) -> Result<LessonSummary, LessonError> {
    let brick_params = brickworld::Params::default();
    let nano_params = nanoworld::Params::game_default();
    let m = brick_params.brick_mass_kg;
    let g = brick_params.gravity_m_per_s2;
    let (hold_w, carry_w) = ((1.5, 2.1), (2.1, 3.0));
    let mut lift_weight_n = [0.0; 3];
    let mut lift_inertia_n = [0.0; 3];
    for (i, r) in runs.lifts.iter().enumerate() {
        let a = &r.arrays;
        lift_weight_n[i] = measure::mean_force(a, measure::window(a, hold_w.0, hold_w.1), 2);
        lift_inertia_n[i] = measure::peak_force(a, measure::window(a, carry_w.0, carry_w.1), 0);
    }
    let hyst = |r: &Run| {
        measure::hysteresis(&r.arrays).ok_or_else(|| missing(r.name, "no snap and pull-off"))
    };
    let brick_throw = measure::brick_throw(&runs.brick_throw.arrays)
        .ok_or_else(|| missing("brick_throw", "no release followed by an impact"))?;
    let scale = NANO_WORKSPACE_SCALE;
    let hold = tip_atom_hold_n(&nano_params);
    let atom_m = nano_params.atoms.mass_kg;
    let atom_hand = measure::peak_hand_acceleration(&runs.atom_throw.arrays);
    let atom_load =
        atom_m * ((atom_hand * scale).powi(2) + nano_params.gravity_m_per_s2.powi(2)).sqrt();
    let carried_end = measure::last(&runs.atom_throw.arrays, "carried_atoms").unwrap_or(0.0);
    let e = brick_params.brick_half_extents_m;
    Ok(LessonSummary {
        macro_house: measure::house_outcome(&runs.macro_house.arrays, "slots_filled"),
        nano_house: measure::house_outcome(&runs.nano_house.arrays, "house_score"),
        lift_weight_n,
        lift_inertia_n,
        brick_mass_kg: m,
        gravity_m_per_s2: g,
        lift_inertia_predicted_n: m * 5.773_502_691_896_258 * 0.45 / (0.9 * 0.9),
        hysteresis: hyst(&runs.cycles[0])?,
        hysteresis_half: hyst(&runs.cycles[1])?,
        brick_throw,
        throw_hand_m_per_s2: measure::peak_hand_acceleration(&runs.brick_throw.arrays),
        atom_stayed: carried_end >= 1.0,
        atom_load_n: atom_load,
        atom_inertia_n: atom_m * atom_hand * scale,
        atom_hold_n: hold,
        atom_mass_kg: atom_m,
        atom_threshold_hand_m_per_s2: hold / atom_m / scale,
        sweep: throw_sweep(&runs.sweep, hold),
        sizes_m: [
            ("brick, longest edge".into(), 2.0 * e[0].max(e[1]).max(e[2])),
            (
                "cursor sphere, diameter".into(),
                2.0 * brick_params.proxy_radius_m,
            ),
            ("AFM tip, diameter".into(), 2.0 * nano_params.tip.radius_m),
            ("atom, diameter".into(), 2.0 * nano_params.atoms.radius_m),
            ("substrate spacing".into(), nano_params.substrate.spacing_m),
        ],
        files: Vec::new(),
    })
}

/// The lesson's runs, for the figures.
pub struct Runs {
    /// The macro house task.
    pub macro_house: Run,
    /// The nano house task.
    pub nano_house: Run,
    /// Lift and carry: normal, gravity off, inertia off.
    pub lifts: Vec<Run>,
    /// Approach–retract: normal, adhesion halved.
    pub cycles: Vec<Run>,
    /// The brick throw.
    pub brick_throw: Run,
    /// The same motion in the nano world.
    pub atom_throw: Run,
    /// Heavy-atom throws: (swing time s, run).
    pub sweep: Vec<(f64, Run)>,
}

/// The sound of a recording, with the proximity tone.
fn sound_of(rec: &Path, sample_rate_hz: u32) -> Result<haptic_loop::sound::SessionSound, String> {
    let r = recording::read_recording_file(rec, false).map_err(|e| e.to_string())?;
    let a = SessionArrays::from_recording(&r).map_err(|e| e.to_string())?;
    haptic_loop::sound::session_sound(&a, &r.description.scene_kind, true, sample_rate_hz)
        .map_err(|e| e.to_string())
}

/// The tip's hold on a carried atom: the tip–atom pull-off force, N.
pub fn tip_atom_hold_n(p: &nanoworld::Params) -> f64 {
    nanoworld::PairLaws::from_params(p)
        .get(nanoworld::PairKind::TipAtom)
        .pull_off_n
}

/// Writes `bytes` to `path`, naming the file on error.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), LessonError> {
    std::fs::write(path, bytes).map_err(|e| LessonError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })
}
