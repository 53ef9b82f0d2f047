//! # ot-py — the Python wheel `nanohaptics`
//!
//! numpy bindings to the nanohaptics crates, built with maturin
//! (`import nanohaptics`). SI units throughout (J, m, kg, s, Pa·s, K, N).
//!
//! What it is for: driving the simulators from Python — the optical-trap
//! flow map, trajectories and thermal runs of `ot-physics`
//! ([`trap::GaussianTrap`]), the inverse solver and working envelope of
//! `ot-envelope` ([`envelope`]), the nano world of `nanoworld`
//! ([`nano::NanoWorld`]), the brick world of `brickworld`
//! ([`brick::BrickWorld`]) and the sessions and recordings of `haptic-loop`
//! ([`session`]).
//!
//! What it is not: it holds no physics. Every number comes from the wrapped
//! crates; this crate only converts arrays, checks their shapes, releases
//! the GIL during batch work, and raises the crates' typed errors as
//! `ValueError` with their text (which names the field and the allowed
//! range). The user guide is `docs/python.md`; the type stub is
//! `crates/ot-py/nanohaptics.pyi`.
//!
//! Layout (maturin's mixed layout): this crate is the extension module
//! `nanohaptics.nanohaptics`; the package `nanohaptics` is the Python source under
//! `crates/ot-py/python/nanohaptics/` (`pyproject.toml`'s `python-source`), whose
//! `__init__.py` re-exports the extension's names and adds the Python modules
//! `bridge`, `sweeps` and `closed_loop`.
//!
//! The wheel also carries the whole `nanohaptics` program ([`cli`]): its console script
//! `nanohaptics` and `python -m nanohaptics` call `nanohaptics.nanohaptics._cli`, which runs
//! the `nanohaptics-cli` crate's `main_with_args` in the Python process.

pub mod brick;
pub mod cli;
mod convert;
pub mod device_model;
pub mod envelope;
mod interrupt;
mod json;
pub mod live;
pub mod nano;
mod params_dict;
pub mod session;
pub mod trap;

use pyo3::prelude::*;

/// The extension's allocator, as the `nanohaptics` binary's (crates/cli/src/main.rs): the wheel's
/// `nanohaptics classroom` runs its real-time tick workers in this library, and glibc's arena
/// locks made them wait on the threads that free their memory.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Haptic manipulation at the nanoscale, from Python: optical-trap dynamics
/// (GaussianTrap), the inverse trap solver and working envelope (solve_trap,
/// working_envelope, clip_command), the nano world (NanoWorld) and the brick
/// world (BrickWorld), haptic-loop sessions and recordings (run_scene,
/// read_recording, resolve_scene), and parameter studies (sweep, grid,
/// run_seed). SI units throughout (J, m, kg, s, Pa·s, K, N).
#[pymodule]
fn nanohaptics(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<trap::GaussianTrap>()?;
    m.add_function(wrap_pyfunction!(trap::paper_trap, m)?)?;
    m.add_class::<nano::NanoWorld>()?;
    m.add_class::<brick::BrickWorld>()?;
    m.add_function(wrap_pyfunction!(nano::nano_params, m)?)?;
    m.add_function(wrap_pyfunction!(nano::force_distance_curve, m)?)?;
    m.add_function(wrap_pyfunction!(envelope::solve_trap, m)?)?;
    m.add_function(wrap_pyfunction!(envelope::working_envelope, m)?)?;
    m.add_function(wrap_pyfunction!(envelope::clip_command, m)?)?;
    m.add_function(wrap_pyfunction!(envelope::working_envelope_3d, m)?)?;
    m.add_function(wrap_pyfunction!(envelope::polygon_radius, m)?)?;
    m.add_function(wrap_pyfunction!(session::run_scene, m)?)?;
    m.add_function(wrap_pyfunction!(session::read_recording, m)?)?;
    m.add_function(wrap_pyfunction!(session::render_audio, m)?)?;
    m.add_function(wrap_pyfunction!(session::resolve_scene, m)?)?;
    m.add_class::<live::Session>()?;
    m.add_class::<device_model::DeviceModel>()?;
    m.add_function(wrap_pyfunction!(device_model::check_closed_loop, m)?)?;
    // The program behind the `nanohaptics` command: a private name, set without `add_function`
    // so it stays out of `__all__` (and so out of `from nanohaptics import *` and the stub).
    m.setattr("_cli", wrap_pyfunction!(cli::run_cli, m)?)?;
    m.add("DEFAULT_RTOL", ot_physics::DEFAULT_RTOL)?;
    m.add("PAPER_DT", ot_physics::paper::DT)?;
    let [vx, vy] = ot_physics::paper::V0_MOVING;
    m.add("PAPER_V0_MOVING", (vx, vy))?;
    Ok(())
}
