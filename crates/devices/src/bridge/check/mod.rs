//! `nanohaptics device-check`: a conformance check of a lab's device adapter against
//! `docs/device-bridge.md` ("Checking your adapter before the first session").
//!
//! The check plays the simulator's side of the bridge: it binds the address, waits for the
//! device's hello and drives the device through a fixed sequence of [`Stage`]s (handshake, a
//! wall, a carried brick, loss of answers, silence, bye), then judges every rule the simulator
//! side can observe from the device's datagrams and the stylus positions they carry
//! ([`rules`]), each with its figure and its bound ([`report`]).
//!
//! - [`stages`]: the sequence, its timing and what the hand is asked to do;
//! - [`world`]: the check's own world (a plane, a brick on a coupling), answered as the
//!   simulator answers (protocol 1's force and stiffness, protocol 2's local model);
//! - [`session`]: the socket: handshake, answers (delayed, dropped, withheld), the bye;
//! - [`observed`]: what the check saw; [`rules`]: the rules and their judgement;
//!   [`verdict`]: one rule's result; [`report`]: the whole result, as text or JSON;
//! - [`error`]: what stops the check before it can judge anything.

pub mod error;
pub mod observed;
pub mod report;
pub mod rules;
pub mod session;
pub mod stages;
pub mod verdict;
pub mod world;

pub use error::CheckError;
pub use report::Report;
pub use session::{CheckConfig, run_check, run_check_on};
pub use stages::Stage;
pub use verdict::{RuleResult, Verdict};
