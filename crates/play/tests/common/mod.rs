//! Helpers shared by the browser tests and the play bench.
pub mod cdp;
pub mod class;
pub mod live;
pub mod module;
pub mod pilot;
