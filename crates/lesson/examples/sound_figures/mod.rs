//! The teaching report's sound figures that do not depend on the clock, shared by the report
//! (`teaching_report.rs`) and the test that holds them (`tests/sound_figures.rs`).
#![allow(dead_code)]

use haptic_loop::session::SessionArrays;

/// Largest |onset − event time| over the impacts with 150 ms of silence before them, s, and
/// the count checked (onset: first sample at 10 % of the next 25 ms's peak).
pub fn onset_error(a: &SessionArrays, samples: &[f32], rate: f64) -> (f64, usize) {
    let hits: Vec<f64> = a
        .events
        .iter()
        .filter(|e| e.1 == "brick.impact")
        .map(|e| e.0 as f64 / f64::from(a.rate_hz))
        .collect();
    let mut worst: f64 = 0.0;
    let mut n = 0;
    for t in &hits {
        if hits.iter().any(|u| u < t && t - u < 0.15) {
            continue;
        }
        let k = (t * rate).round() as usize;
        let lo = k.saturating_sub((0.001 * rate) as usize);
        let win = &samples[lo..(k + (0.025 * rate) as usize).min(samples.len())];
        let peak = win.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let first = win.iter().position(|v| v.abs() >= 0.1 * peak).unwrap_or(0);
        worst = worst.max(((lo + first) as f64 / rate - t).abs());
        n += 1;
    }
    (worst, n)
}
