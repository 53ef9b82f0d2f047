//! The `nanohaptics` binary: the program of this crate's library
//! ([`nanohaptics_cli::main_with_args`]) with the process's arguments and exit status.

/// The allocator: mimalloc frees another thread's memory without taking a lock its owner waits
/// on, so the classroom's real-time tick workers never wait on a page's or a recorder's thread
/// (glibc's arena locks did: BENCHMARKS.md, "classroom").
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> std::process::ExitCode {
    std::process::ExitCode::from(nanohaptics_cli::main_with_args(std::env::args_os()))
}
