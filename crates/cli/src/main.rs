//! `nanohaptics`: the program of the project — run scenes (batch, real time, against a device
//! in another process), play the teaching game in a browser, teach the lesson, record to MCAP,
//! replay and verify, draw and sound recordings.
//!
//! ```text
//! nanohaptics run SCENE [--script S] [--operator rigid|hand|hand:key=value,...]
//!                 [--device falcon|touch|udp:HOST:PORT|udp:PORT] [--wait-s S] [--seconds T]
//!                 [--out REC.mcap] [--realtime] [--live ws:HOST:PORT] [--live-hz N] [--json]
//! nanohaptics play [SCENE] [--port P] [--device udp:HOST:PORT|udp:PORT] [--out REC.mcap]
//!                 [--seconds T]
//! nanohaptics classroom [SCENE] [--port P] [--listen ADDR] [--max-students N] [--out-dir DIR]
//!                 [--seconds T] [--device udp:HOST:PORT|udp:PORT] [--device-name NAME]
//! nanohaptics lesson [--out DIR] [--width W] [--sample-rate HZ] [--json]
//! nanohaptics fake-device udp:HOST:PORT|udp:PORT [--script S] [--operator rigid|hand|hand:k=v,...]
//!                 [--model falcon|touch|delta3|inverse3] [--grip loose|firm|k=...,b=...[,m=...]]
//!                 [--ideal] [--protocol 1|2] [--loss P] [--jitter-ms J] [--latency-ms L]
//!                 [--seed N] [--seconds T] [--outage START:SECONDS] [--wait-s S] [--json]
//! nanohaptics replay REC.mcap [--verify] [--salvage] [--json]
//! nanohaptics info REC.mcap [--salvage] [--json]
//! nanohaptics render REC.mcap --out DIR|FILE.png|FILE.gif [--every N] [--width W] [--gif FILE]
//!                 [--view top|side|oblique] [--audio FILE.wav [--proximity] [--sample-rate HZ]]
//! nanohaptics render SCENE --out FILE.png [--width W] [--view V]
//! nanohaptics scenes [export DIR]
//! nanohaptics demo [--scenes DIR] [--out DIR] [--json]
//! ```
//! Every command's own `--help` gives each option's unit, range and default. Exit status: 0
//! success, 1 error (bad input, unreadable file), 2 replay diverged, 130 stopped by Ctrl-C.

mod classroom_cmd;
mod demo_cmd;
mod fake_cmd;
mod lesson_cmd;
mod play_cmd;
mod recording_cmd;
mod render_cmd;
mod run_cmd;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

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
    /// The macro-vs-nano lesson: run both house tasks and the lesson's experiments, write a
    /// Markdown report with figures (`--out DIR`).
    Lesson(lesson_cmd::LessonArgs),
    /// Play the teaching game in a browser: serves one page on loopback (pointer, keyboard or
    /// gamepad as the hand, live sound, the menu, the score) and records the session.
    Play(play_cmd::PlayArgs),
    /// One server for a whole class: each student joins by name and plays their own world
    /// with their own recording; a teacher page watches, switches, ends and collects.
    Classroom(classroom_cmd::ClassroomArgs),
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
fn main() -> ExitCode {
    // A closed pipe (`nanohaptics info REC | head`) ends the program quietly with the shell's
    // status 141, as for any Unix filter, instead of a panic on the next print.
    let _ = signal_hook::flag::register_conditional_shutdown(
        signal_hook::consts::SIGPIPE,
        141,
        Arc::new(AtomicBool::new(true)),
    );
    let cli = Cli::parse();
    let res = match cli.cmd {
        Cmd::Run(args) => run_cmd::cmd(args),
        Cmd::Render(args) => render_cmd::cmd(&args),
        Cmd::Replay {
            rec,
            verify,
            salvage,
            json,
        } => recording_cmd::replay(&rec, verify, salvage, json),
        Cmd::Info { rec, salvage, json } => recording_cmd::info(&rec, salvage, json),
        Cmd::Lesson(a) => lesson_cmd::cmd(&a),
        Cmd::Play(a) => play_cmd::cmd(&a),
        Cmd::Classroom(a) => classroom_cmd::cmd(&a),
        Cmd::Demo { scenes, out, json } => demo_cmd::demo(scenes.as_deref(), &out, json),
        Cmd::Scenes { action, dir } => demo_cmd::scenes(action.as_deref(), dir.as_deref()),
        Cmd::FakeDevice(a) => fake_cmd::cmd(a),
    };
    match res {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// The usage block of this crate's doc names every command the program has.
    #[test]
    fn the_usage_text_lists_every_command() {
        let usage = include_str!("main.rs")
            .lines()
            .take_while(|l| l.starts_with("//!"))
            .collect::<Vec<_>>()
            .join("\n");
        for c in Cli::command().get_subcommands() {
            let name = c.get_name();
            assert!(
                usage.contains(&format!("//! nanohaptics {name} ")),
                "the usage text in main.rs does not list `nanohaptics {name}`"
            );
        }
    }
}
