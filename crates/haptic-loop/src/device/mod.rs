//! The headless devices (scripted, simulated operator, modelled device); the device interface
//! itself is `haptic_types::device`, re-exported here.

pub mod modelled;
pub mod operator;
pub mod script;

pub use haptic_types::device::*;
pub use modelled::ModelledDevice;
pub use operator::SimulatedOperator;
pub use script::OperatorParams;
pub use script::{Script, ScriptError, ScriptedDevice};
