//! The one benchmark harness of the nanohaptics workspace (unpublished).
//!
//! Every report example (`crates/*/examples/bench_report.rs` and the haptic loop's live and
//! teaching reports) measures its own cases and leaves everything else to this crate:
//!
//! * [`timer`]: wall-clock and thread-CPU time of a closure, one sample per call
//!   ([`timer::Timings`]), a single span ([`timer::span`]) or the best of repeated blocks
//!   ([`timer::best_block_cpu_s`]);
//! * [`stats`]: the ONE percentile definition of the workspace, with median, p99 and max;
//! * [`table`]: a Markdown table builder (header, column alignment, rows);
//! * [`report`]: the frame of a report section: the workspace root, where the section
//!   (`docs/bench/<name>.md`) and its figures (`docs/figures/`) go, and the machine facts
//!   stated at the top of every section (CPU model, core count, load average at the start and
//!   at the end of the run);
//! * [`verdict`]: the rules that turn a measured figure into "met" or "not met" against its
//!   target (inclusive or strict, NaN never met), tested on both sides of a target;
//! * [`chart`]: the workspace's one chart engine, the `chart` crate re-exported (line, dot and
//!   bar charts on linear or log axes, reference lines, legends, rows and grids of charts),
//!   drawn with tiny-skia and the embedded font: no system fonts, the same PNG bytes
//!   everywhere.
//!
//! # The percentile definition
//!
//! **Nearest rank on the sorted samples**: the q-quantile of n samples sorted ascending is the
//! sample of 1-based rank ⌈q·n⌉, clamped to 1…n. So p50 of [1, 2, 3, 4] is 2 (rank 2), p99 of
//! 100 samples is the 99th smallest, of 1000 samples the 990th, and p100 is the maximum. Every
//! percentile is a measured sample (no interpolation), and this is the definition
//! `haptic_engine::timing::Percentiles` uses for the session statistics, so a report's own
//! percentiles and the loop's agree.
//!
//! What this crate is not: a micro-benchmark framework (criterion does that, under
//! `crates/*/benches/`), nor a place for any physics.

pub mod machine;
pub mod report;
pub mod stats;
pub mod table;
pub mod timer;
pub mod verdict;

pub use chart;
pub use report::Report;
pub use stats::{Summary, percentile};
pub use table::{Align, Table};
pub use timer::{Span, Timings, best_block_cpu_s, span};
pub use verdict::Verdict;
