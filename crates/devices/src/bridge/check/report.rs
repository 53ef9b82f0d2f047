//! The check's result, rule by rule: the verdict, the figure measured and the bound, as text
//! (one line per rule) or JSON.

use super::observed::Observed;
use super::verdict::{RuleResult, Verdict};
use serde::Serialize;

/// The whole check.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// The address the check listened on.
    pub address: String,
    /// The device's name from its hello (empty when no hello was accepted).
    pub device: String,
    /// The session's protocol version (0: no session).
    pub version: u8,
    /// The welcome's rate, Hz.
    pub rate_hz: u32,
    /// Every rule, in the order of the document's table.
    pub rules: Vec<RuleResult>,
    /// Samples received.
    pub samples: usize,
    /// Answers sent, and dropped on purpose in the loss stage.
    pub answers_sent: u64,
    /// Answers dropped in the loss stage.
    pub answers_dropped: u64,
}

impl Report {
    /// Judges what was observed by every rule.
    pub fn judge(obs: &Observed) -> Report {
        Report {
            address: format!("udp:{}", obs.bind),
            device: obs
                .hello
                .as_ref()
                .map_or(String::new(), |h| h.specs.name.to_string()),
            version: obs.version,
            rate_hz: obs.rate_hz,
            rules: super::rules::judge(obs),
            samples: obs.samples.len(),
            answers_sent: obs.answers_sent,
            answers_dropped: obs.answers_dropped,
        }
    }

    /// Whether no rule failed.
    pub fn passed(&self) -> bool {
        self.rules.iter().all(|r| r.verdict != Verdict::Fail)
    }

    /// The rules that failed, by name.
    pub fn failed(&self) -> Vec<&'static str> {
        self.rules
            .iter()
            .filter(|r| r.verdict == Verdict::Fail)
            .map(|r| r.rule)
            .collect()
    }

    /// The rule named `rule`.
    pub fn rule(&self, rule: &str) -> Option<&RuleResult> {
        self.rules.iter().find(|r| r.rule == rule)
    }

    /// The report as text: a heading, one line per rule, and the count.
    pub fn text(&self) -> String {
        let mut s = format!(
            "device-check of `{}` on {}: session version {} at {} Hz, {} samples, {} answers sent \
             ({} dropped on purpose)\n",
            self.device,
            self.address,
            self.version,
            self.rate_hz,
            self.samples,
            self.answers_sent,
            self.answers_dropped
        );
        for r in &self.rules {
            s.push_str(&format!(
                "{:<4}  {:<16} {}; bound: {}\n",
                r.verdict.label(),
                r.rule,
                r.figure,
                r.bound
            ));
        }
        let count = |v: Verdict| self.rules.iter().filter(|r| r.verdict == v).count();
        s.push_str(&format!(
            "{} rules: {} passed, {} failed, {} not applicable",
            self.rules.len(),
            count(Verdict::Pass),
            count(Verdict::Fail),
            count(Verdict::NotApplicable)
        ));
        let failed = self.failed();
        if !failed.is_empty() {
            s.push_str(&format!(" (failed: {})", failed.join(", ")));
        }
        s.push('\n');
        s
    }
}
