//! The wheel's `nanohaptics` command: the program of the `nanohaptics-cli` crate, run inside
//! the Python process (`pip install nanohaptics` gives the command, `python -m nanohaptics`
//! runs it too; both go through `nanohaptics/__main__.py`).
//!
//! One maturin wheel cannot hold a binary beside the extension module, so the extension holds
//! the program: one build, the sdist builds the same thing, and the command and the module are
//! always the same version.

use pyo3::prelude::*;
use std::ffi::OsString;

/// Runs the `nanohaptics` program with `argv` (its first item is the program's name, as in
/// `sys.argv`) in this process with the GIL released, and returns its exit status: 0 success,
/// 1 error, 2 replay diverged or a bad argument, 130 stopped by Ctrl-C.
///
/// It is the binary's `main` in every respect: it prints to the process's stdout and stderr,
/// and it installs the program's signal handlers (`run` and `play` stop cleanly on the first
/// SIGINT or SIGTERM and end the process on a second). It is meant to be the whole of a
/// process: `nanohaptics.__main__.main` sets SIGINT back to the default first, so Ctrl-C ends
/// the other commands as it ends the binary.
#[pyfunction(name = "_cli")]
pub fn run_cli(py: Python<'_>, argv: Vec<OsString>) -> u8 {
    py.detach(|| nanohaptics_cli::main_with_args(argv))
}
