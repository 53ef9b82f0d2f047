//! A rule's verdict and its result: the figure measured and the bound it is judged against.

use serde::Serialize;

/// A rule's verdict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The device behaves as the document says.
    Pass,
    /// It does not (or the stage that shows it was not reached).
    Fail,
    /// The rule does not apply to this device (a version-1 device has no two-port count).
    NotApplicable,
}

impl Verdict {
    /// `PASS`, `FAIL` or `n/a`, as the text report writes it.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Pass => "PASS",
            Verdict::Fail => "FAIL",
            Verdict::NotApplicable => "n/a",
        }
    }
}

/// One rule's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuleResult {
    /// The rule's name (`sample.seq`, `render.planes`, …; the table in
    /// `docs/device-bridge.md`).
    pub rule: &'static str,
    /// The section of `docs/device-bridge.md` that states it.
    pub section: &'static str,
    /// The verdict.
    pub verdict: Verdict,
    /// What was measured, in words with units.
    pub figure: String,
    /// The bound it is judged against, in words with units.
    pub bound: String,
    /// The figure as a number in SI units (m, s, Hz, a count, a ratio), where it is one.
    pub value: Option<f64>,
}
