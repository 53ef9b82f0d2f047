//! The `nanohaptics` binary: the program of this crate's library
//! ([`nanohaptics_cli::main_with_args`]) with the process's arguments and exit status.

fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(nanohaptics_cli::main_with_args(std::env::args_os()))
}
