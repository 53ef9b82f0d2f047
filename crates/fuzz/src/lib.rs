//! Fuzz targets of nanohaptics' input surfaces, shared by two engines:
//!
//! - **libFuzzer** through cargo-fuzz (`fuzz/`, coverage-guided, a growing corpus): the
//!   in-process targets of [`libfuzzer`] — scene and script files, recordings (read, salvage,
//!   verify), bridge packets, and the world parameter tables the Python wheel parses;
//! - **the in-tree driver** (`nanohaptics-fuzz`, stable Rust, no tools to install), which keeps
//!   what libFuzzer's in-process model lacks: the `cli` target, one `nanohaptics` process per
//!   input, judged by its exit status and its messages.
//!
//! Not for: unit tests of the parsers (each crate has its own) or performance measurement.

pub mod libfuzzer;
pub mod mutate;
pub mod outcome;
pub mod page;
pub mod params;
pub mod targets;
