//! The `nanohaptics` command-line program.
fn main() {}
