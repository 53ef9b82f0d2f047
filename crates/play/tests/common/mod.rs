//! Helpers shared by the browser tests and the play bench.
pub mod cdp;
pub mod class;
pub mod live;
pub mod module;
pub mod page;
pub mod pilot;

use std::path::PathBuf;

/// Where the screenshots go: under the target folder, so a test run leaves the tracked tree as
/// it was; `scripts/figures.sh` names `docs/figures/play` in `NANOHAPTICS_FIGURES_DIR` to
/// regenerate the docs' figures.
#[allow(dead_code)]
pub fn figures() -> PathBuf {
    match std::env::var_os("NANOHAPTICS_FIGURES_DIR") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("figures/play"),
    }
}
