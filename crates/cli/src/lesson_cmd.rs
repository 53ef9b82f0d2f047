//! `nanohaptics lesson`: the macro-vs-nano lesson report (see `lesson`).

use crate::status;
use haptic_types::value::ValueError;
use indicatif::{ProgressBar, ProgressStyle};
use lesson::{LessonOptions, report::si, run_lesson};
use std::path::PathBuf;

/// Arguments of `nanohaptics lesson`.
#[derive(clap::Args)]
pub struct LessonArgs {
    /// Folder for the report (`lesson.md`, PNG figures, recordings, `lesson.json`).
    #[arg(long, default_value = "nanohaptics-lesson")]
    pub out: PathBuf,
    /// Width of the figures, px (200–4000; height is half of it).
    #[arg(long, default_value_t = 1200)]
    pub width: u32,
    /// Sample rate of the house tasks' sounds (WAV), Hz (8000–192000).
    #[arg(long, default_value_t = 44_100)]
    pub sample_rate: u32,
    /// Print the measured numbers as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs the lesson and prints where the report is.
pub fn cmd(args: &LessonArgs) -> Result<u8, String> {
    if !(200..=4000).contains(&args.width) {
        return Err(
            ValueError::out_of_range("--width", f64::from(args.width), "200–4000 px").to_string(),
        );
    }
    if !(8_000..=192_000).contains(&args.sample_rate) {
        return Err(ValueError::out_of_range(
            "--sample-rate",
            f64::from(args.sample_rate),
            "8000–192000 Hz",
        )
        .to_string());
    }
    let pb = (!args.json).then(|| {
        let pb = ProgressBar::new(1);
        let style = ProgressStyle::with_template("{prefix:>10} [{bar:30}] {pos}/{len} runs: {msg}")
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| ProgressStyle::default_bar());
        pb.set_style(style);
        pb.set_prefix("lesson");
        pb
    });
    let opts = LessonOptions {
        out: args.out.clone(),
        width_px: args.width,
        sample_rate_hz: args.sample_rate,
    };
    let s = run_lesson(&opts, &mut |done, total, run| {
        if let Some(pb) = &pb {
            pb.set_length(total as u64);
            pb.set_position(done as u64);
            pb.set_message(run.to_string());
        }
    })
    .map_err(|e| e.to_string())?;
    if let Some(pb) = pb {
        pb.finish_and_clear();
    }
    if args.json {
        println!("{}", serde_json::to_string(&s).map_err(|e| e.to_string())?);
        return Ok(status::SUCCESS);
    }
    println!(
        "bricks: {} of 4 slots, score {:.1}; atoms: {} of 7 slots, score {:.1}",
        s.macro_house.filled, s.macro_house.score, s.nano_house.filled, s.nano_house.score
    );
    println!(
        "brick weight felt {}, carry inertia {}; snap {}, pull-off {} ({:.2}×)",
        si(-s.lift_weight_n[0], "N"),
        si(s.lift_inertia_n[0], "N"),
        si(s.hysteresis.snap_force_n, "N"),
        si(s.hysteresis.pull_off_n, "N"),
        s.hysteresis.ratio
    );
    println!(
        "a thrown brick lands {} away; an atom {} (it would need {} of hand acceleration)",
        si(s.brick_throw.distance_m, "m"),
        if s.atom_stayed {
            "stays on the tip"
        } else {
            "left the tip"
        },
        si(s.atom_threshold_hand_m_per_s2, "m/s²")
    );
    println!(
        "report: {} ({} files)",
        args.out.join("lesson.md").display(),
        s.files.len()
    );
    Ok(status::SUCCESS)
}
