//! `nanohaptics`: the program of the project — run scenes (batch, real time, against a device
//! in another process), play the teaching game in a browser, teach the lesson, record to MCAP,
//! replay and verify, draw and sound recordings.
//!
//! ```text
//! nanohaptics run SCENE [--script S] [--operator rigid|hand|hand:key=value,...]
//!                 [--device falcon|touch|udp:HOST:PORT|udp:PORT] [--wait-s S] [--seconds T]
//!                 [--out REC.mcap] [--realtime] [--live ws:HOST:PORT] [--live-hz N] [--json]
//!                 [--no-rt] [--rt-priority N]
//! nanohaptics play [SCENE] [--port P] [--device udp:HOST:PORT|udp:PORT] [--out REC.mcap]
//!                 [--seconds T] [--lesson [FILE]] [--no-rt] [--rt-priority N]
//! nanohaptics classroom [SCENE] [--port P] [--listen ADDR] [--max-students N] [--out-dir DIR]
//!                 [--seconds T] [--device udp:HOST:PORT|udp:PORT] [--device-name NAME]
//!                 [--lesson [FILE]] [--no-rt] [--rt-priority N]
//! nanohaptics doctor [--seconds T] [--interval-us N] [--rt-priority N] [--json]
//! nanohaptics lesson [--out DIR] [--width W] [--sample-rate HZ] [--json]
//! nanohaptics fake-device udp:HOST:PORT|udp:PORT [--script S] [--operator rigid|hand|hand:k=v,...]
//!                 [--model falcon|touch|delta3|inverse3] [--grip loose|firm|k=...,b=...[,m=...]]
//!                 [--ideal] [--protocol 1|2] [--loss P] [--jitter-ms J] [--latency-ms L]
//!                 [--seed N] [--seconds T] [--outage START:SECONDS] [--wait-s S]
//!                 [--button-names a,b,c] [--check-hand] [--fault NAME] [--json]
//! nanohaptics device-check udp:HOST:PORT|udp:PORT [--rate HZ] [--wait-s S] [--json]
//! nanohaptics replay REC.mcap [--verify] [--salvage] [--json]
//! nanohaptics info REC.mcap [--salvage] [--json]
//! nanohaptics render REC.mcap --out DIR|FILE.png|FILE.gif [--every N] [--width W] [--gif FILE]
//!                 [--view top|side|oblique] [--audio FILE.wav [--proximity] [--sample-rate HZ]]
//! nanohaptics render SCENE --out FILE.png [--width W] [--view V]
//! nanohaptics scenes [export DIR]
//! nanohaptics demo [--scenes DIR] [--out DIR] [--json]
//! ```
//! Every command's own `--help` gives each option's unit, range and default. Exit status
//! ([`status`]): 0 success, 1 error (bad input, unreadable file), 2 replay diverged or a device
//! failed `device-check` (or a bad argument, clap's usage error), 130 stopped by Ctrl-C, 141
//! ended by a closed pipe.
//!
//! This library is the whole program: [`main_with_args`] parses the arguments, runs the
//! command and returns the exit status. The `nanohaptics` binary (`src/main.rs`) calls it with
//! the process's arguments, and the Python wheel (`crates/ot-py`) calls it for its own
//! `nanohaptics` command (`pip install nanohaptics`, `python -m nanohaptics`), so both are the
//! same program. A command is one module here and one arm of `Cmd`.

mod classroom_cmd;
mod demo_cmd;
mod device_check_cmd;
mod doctor_cmd;
mod fake_cmd;
mod lesson_cmd;
mod play_cmd;
mod recording_cmd;
mod render_cmd;
mod rt_args;
mod run_cmd;

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

/// The program's exit statuses: what [`main_with_args`] returns and the process exits with.
pub mod status {
    /// The command did what was asked.
    pub const SUCCESS: u8 = 0;
    /// An error (bad input, an unreadable file): the message is on stderr after `error: `.
    pub const ERROR: u8 = 1;
    /// A replay diverged (`replay --verify`, `demo`) or a device failed a rule of
    /// `device-check`; clap's usage errors (a bad argument) exit with 2 as well.
    pub const DIVERGED: u8 = 2;
    /// Stopped by Ctrl-C (SIGINT) or SIGTERM, the recording finished (the shell's 128 + 2).
    pub const INTERRUPTED: u8 = 130;
    /// Ended by a closed pipe (`nanohaptics info REC | head`): the shell's 128 + SIGPIPE.
    pub const BROKEN_PIPE: u8 = 141;
}

#[derive(Parser)]
#[command(
    name = "nanohaptics",
    version,
    about = "Deterministic haptic sessions: run, play, teach, record, replay, verify, draw"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a scene with a script (batch by default) and optionally record it.
    Run(run_cmd::RunArgs),
    /// Draw a recording (PNG frames, animated GIF) or a scene's initial state (PNG).
    Render(render_cmd::RenderArgs),
    /// Recompute a recording from its inputs and compare every output bit for bit.
    Replay {
        /// Recording (MCAP).
        rec: PathBuf,
        /// Exit with status 2 on the first divergence.
        #[arg(long)]
        verify: bool,
        /// Accept a truncated recording and replay its complete part.
        #[arg(long)]
        salvage: bool,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
        /// Instead of comparing, serve the recording as a page to watch in a browser: play
        /// and pause, speed, a timeline to scrub, the world drawn as in the game, the events
        /// and the sound (Ctrl-C ends). A damaged file is refused as `--verify` refuses it.
        #[arg(long, conflicts_with_all = ["verify", "salvage", "json"])]
        serve: bool,
        /// With --serve: the page's port on 127.0.0.1 (0: any free port).
        #[arg(long, default_value_t = 8766, requires = "serve")]
        port: u16,
    },
    /// Channels, duration and tick statistics of a recording.
    Info {
        /// Recording (MCAP).
        rec: PathBuf,
        /// Accept a truncated recording.
        #[arg(long)]
        salvage: bool,
        /// Print as JSON.
        #[arg(long)]
        json: bool,
    },
    /// List the built-in scenes, or `scenes export DIR` to write editable copies.
    Scenes {
        /// `export` to write the scenes and their scripts.
        action: Option<String>,
        /// Folder for `export`.
        dir: Option<PathBuf>,
    },
    /// A stand-in haptic device process: plays a script over the UDP bridge to `nanohaptics run
    /// --device udp:HOST:PORT`, with injectable loss, jitter, latency and an outage.
    FakeDevice(fake_cmd::FakeArgs),
    /// Check a lab's device adapter against the bridge document before its first session:
    /// listen as the simulator does, drive the device through a fixed 6 s sequence (a wall, a
    /// carried brick, lost answers, silence, bye) and report rule by rule, with the figures.
    DeviceCheck(device_check_cmd::DeviceCheckArgs),
    /// The macro-vs-nano lesson: run both house tasks and the lesson's experiments, write a
    /// Markdown report with figures (`--out DIR`).
    Lesson(lesson_cmd::LessonArgs),
    /// Play the teaching game in a browser: serves one page on loopback (pointer, keyboard or
    /// gamepad as the hand, live sound, the menu, the score) and records the session.
    Play(play_cmd::PlayArgs),
    /// One server for a whole class: each student joins by name and plays their own world
    /// with their own recording; a teacher page watches, switches, ends and collects.
    Classroom(classroom_cmd::ClassroomArgs),
    /// What this machine allows a tick thread: real-time permissions, wake-up latency with
    /// and without real-time priority, the tick rates it can hold, and what to change.
    Doctor(doctor_cmd::DoctorArgs),
    /// Run every scene with its default script, record, verify, and summarise.
    Demo {
        /// Folder of scene files (default: `./scenes` if it exists, else the built-in scenes,
        /// which `scenes export DIR` writes out for editing).
        #[arg(long)]
        scenes: Option<PathBuf>,
        /// Folder for the recordings.
        #[arg(long, default_value = "target/demo")]
        out: PathBuf,
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
    },
}
/// Runs the program with `args` (the first item is the program's name, as in `std::env::args_os`
/// or Python's `sys.argv`) and returns its exit status ([`status`]); the caller exits with it.
///
/// This is what the `nanohaptics` binary does, in whatever process calls it: it installs the
/// program's signal handlers there (a closed pipe ends the process with status 141 while the
/// command runs; `run` and `play` watch SIGINT and SIGTERM, and a second one ends the process
/// with status 130), prints to the process's stdout and stderr, and flushes stdout before it
/// returns. `--help`, `--version` and a bad argument print clap's text and return 0, 0 and 2
/// (clap's statuses) without ending the process.
pub fn main_with_args<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    // A closed pipe (`nanohaptics info REC | head`) ends the program quietly with the shell's
    // status 141, as for any Unix filter, instead of a panic on the next print.
    let pipe = signal_hook::flag::register_conditional_shutdown(
        signal_hook::consts::SIGPIPE,
        i32::from(status::BROKEN_PIPE),
        Arc::new(AtomicBool::new(true)),
    );
    let code = parse_and_run(args);
    // Rust's stdout is flushed when a Rust `main` returns, not when a Python process exits.
    let _ = std::io::stdout().flush();
    // Back to the process's own disposition (the binary and Python both ignore SIGPIPE, so a
    // write to a closed pipe or socket is an error again, not the end of the process).
    if let Ok(id) = pipe {
        signal_hook::low_level::unregister(id);
    }
    code
}

/// Parses `args` and runs the command: the exit status.
fn parse_and_run<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // What `Cli::parse` prints (help and version on stdout, errors on stderr), with
            // clap's status, returned rather than exiting the process.
            let _ = e.print();
            return u8::try_from(e.exit_code()).unwrap_or(status::DIVERGED);
        }
    };
    let res = match cli.cmd {
        Cmd::Run(args) => run_cmd::cmd(args),
        Cmd::Render(args) => render_cmd::cmd(&args),
        Cmd::Replay {
            rec,
            serve: true,
            port,
            ..
        } => recording_cmd::serve(&rec, port),
        Cmd::Replay {
            rec,
            verify,
            salvage,
            json,
            ..
        } => recording_cmd::replay(&rec, verify, salvage, json),
        Cmd::Info { rec, salvage, json } => recording_cmd::info(&rec, salvage, json),
        Cmd::Lesson(a) => lesson_cmd::cmd(&a),
        Cmd::Play(a) => play_cmd::cmd(&a),
        Cmd::Doctor(a) => doctor_cmd::cmd(&a),
        Cmd::Classroom(a) => classroom_cmd::cmd(&a),
        Cmd::Demo { scenes, out, json } => demo_cmd::demo(scenes.as_deref(), &out, json),
        Cmd::Scenes { action, dir } => demo_cmd::scenes(action.as_deref(), dir.as_deref()),
        Cmd::FakeDevice(a) => fake_cmd::cmd(a),
        Cmd::DeviceCheck(a) => device_check_cmd::cmd(&a),
    };
    match res {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            status::ERROR
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Cli, main_with_args, status};
    use clap::CommandFactory;

    /// `--help`, `--version` and clap's usage errors return clap's status instead of ending the
    /// process (the wheel runs the program inside the Python interpreter).
    #[test]
    fn clap_outcomes_are_returned_not_exited() {
        assert_eq!(
            main_with_args(["nanohaptics", "--version"]),
            status::SUCCESS
        );
        assert_eq!(
            main_with_args(["nanohaptics", "replay", "--help"]),
            status::SUCCESS
        );
        assert_eq!(main_with_args(["nanohaptics", "run", "--no-such-flag"]), 2);
        assert_eq!(main_with_args(["nanohaptics"]), 2);
    }

    /// A command's error is status 1 (its message on stderr after `error: `).
    #[test]
    fn a_command_error_is_status_1() {
        let missing = std::env::temp_dir().join("nanohaptics-no-such-recording.mcap");
        let rec = missing.to_string_lossy().to_string();
        assert_eq!(
            main_with_args(["nanohaptics", "info", rec.as_str()]),
            status::ERROR
        );
        assert_eq!(
            main_with_args(["nanohaptics", "run", "no-such-scene"]),
            status::ERROR
        );
    }

    /// The usage block of this crate's doc names every command the program has.
    #[test]
    fn the_usage_text_lists_every_command() {
        let usage = include_str!("lib.rs")
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .collect::<Vec<_>>()
            .join("\n");
        for c in Cli::command().get_subcommands() {
            let name = c.get_name();
            assert!(
                usage.contains(&format!("//! nanohaptics {name} ")),
                "the usage text in lib.rs does not list `nanohaptics {name}`"
            );
        }
    }
}
