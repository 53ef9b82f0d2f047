//! What one fuzz input did: accepted, refused, or a finding.

/// What one input did.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Accepted (and, where checked, its results were finite and within limits).
    Accepted,
    /// Refused with an error (the expected answer to most mutated inputs).
    Refused,
    /// A defect: its kind (`non-finite`, `accepted-modified`, `hang`, `bad-exit`, …) and what
    /// happened.
    Finding(&'static str, String),
}
