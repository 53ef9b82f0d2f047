//! `nanohaptics render`: PNG frames and an animated GIF of a recording (recomputed from its
//! logged inputs, as `replay` does), or one picture of a scene's initial state; drawn by the
//! engine's media module. Also the one-picture-per-recording step of `demo`.

use haptic_loop::media::{self, FramesOptions, MediaError};
use haptic_loop::session::SceneSource;
use haptic_types::value::ValueError;
use recording::{RecordingError, read_recording_file};
use render::View;
use std::path::{Path, PathBuf};

/// Arguments of `nanohaptics render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// A recording (`.mcap`) or a scene file (`.toml`).
    pub input: PathBuf,
    /// What to write, chosen by the name's extension: `NAME.png` one picture (a scene's
    /// initial state, a recording's last tick); `NAME.gif` a recording as an animation; a
    /// name without extension (or an existing folder) a recording's frames as PNG files.
    /// Optional with `--audio`.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Draw every N-th tick of a recording (default: tick rate / 30, i.e. 30 frames per second
    /// of session).
    #[arg(long)]
    pub every: Option<u64>,
    /// Image width, px (height is 3/4 of it). Allowed: 64–4096.
    #[arg(long, default_value_t = 640)]
    pub width: u32,
    /// Also write the frames of a recording as an animated GIF (with `--out FOLDER`).
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Camera: top, side or oblique (default: top for a flat world, oblique otherwise).
    #[arg(long)]
    pub view: Option<String>,
    /// Write the recording's sound to this WAV file (16-bit mono): an impact sound per
    /// collision (loudness from its impulse), a click at snap-to-contact and another at
    /// pull-off (docs/render.md, "Sound").
    #[arg(long)]
    pub audio: Option<PathBuf>,
    /// With `--audio`: add the proximity tone, whose pitch rises as the cursor nears the
    /// nearest object (brick and nano worlds).
    #[arg(long)]
    pub proximity: bool,
    /// With `--audio`: sample rate, Hz (8000–192000).
    #[arg(long, default_value_t = render::audio::SAMPLE_RATE_HZ)]
    pub sample_rate: u32,
}

/// Why `render` failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderCmdError {
    /// A command-line value out of its range, named by its flag (`--width`).
    #[error(transparent)]
    Arg(ValueError),
    /// A flag given without the flag it works with.
    #[error("--{flag} is allowed only with {needs}")]
    Needs {
        /// The flag, without dashes.
        flag: &'static str,
        /// What it needs, e.g. `--audio FILE.wav`.
        needs: &'static str,
    },
    /// The input is neither `.mcap` nor `.toml`.
    #[error("{0}: expected a recording (.mcap) or a scene file (.toml)")]
    InputKind(PathBuf),
    /// `--out` names something this input cannot become.
    #[error("--out {out}: {problem} (allowed: {allowed})")]
    OutKind {
        /// The name given.
        out: PathBuf,
        /// What is wrong with it.
        problem: String,
        /// What the input can become.
        allowed: &'static str,
    },
    /// The recording.
    #[error(transparent)]
    Recording(#[from] RecordingError),
    /// Drawing: the scene, the replay, the pictures.
    #[error(transparent)]
    Media(MediaError),
    /// The scene file, with where in it.
    #[error(transparent)]
    Input(#[from] haptic_loop::session::SessionError),
    /// Turning the recording into sound.
    #[error("--audio: {0}")]
    Sound(#[from] haptic_loop::sound::SoundError),
    /// Neither `--out` nor `--audio`.
    #[error("nothing to write: pass --out FILE (pictures) and/or --audio FILE.wav (sound)")]
    NoOutput,
}

impl From<MediaError> for RenderCmdError {
    /// A media option out of range is the flag's error (`--width`, `--every`).
    fn from(e: MediaError) -> Self {
        match e {
            MediaError::Range(v) => {
                RenderCmdError::Arg(v.map_field(|option| format!("--{option}")))
            }
            e => RenderCmdError::Media(e),
        }
    }
}

fn parse_view(v: &Option<String>) -> Result<Option<View>, RenderCmdError> {
    v.as_deref()
        .map(str::parse)
        .transpose()
        .map_err(|e: render::RenderError| RenderCmdError::Media(e.into()))
}

/// What `render` wrote.
#[derive(Debug, serde::Serialize)]
pub struct RenderSummary {
    /// Pictures written.
    pub frames: u64,
    /// Ticks in the recording (recomputed, or read when drawn from the recorded state).
    pub ticks: u64,
    /// Whether the frames were drawn from the recorded state (optical tweezers) instead of
    /// recomputing the session.
    pub from_recorded_state: bool,
    /// GIF size, bytes (0 without `--gif`).
    pub gif_bytes: u64,
    /// What was written, one line per file or folder.
    pub written: Vec<String>,
}

/// What `--out` names, chosen by its extension.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Output {
    /// A folder of `frame_NNNNN.png` files (a recording).
    Frames(PathBuf),
    /// An animated GIF (a recording).
    Gif(PathBuf),
    /// One PNG picture: a scene's initial state, a recording's last tick.
    Png(PathBuf),
}

const SCENE_OUTPUTS: &str = "NAME.png, the scene's initial state";
const RECORDING_OUTPUTS: &str = "NAME.gif an animation, NAME.png the last tick, or a folder name without extension for PNG frames";

/// Chooses the output from `out`'s extension for a recording (`recording`) or a scene file.
pub fn output_for(recording: bool, out: &Path) -> Result<Output, RenderCmdError> {
    let allowed = if recording {
        RECORDING_OUTPUTS
    } else {
        SCENE_OUTPUTS
    };
    let refuse = |problem: String| RenderCmdError::OutKind {
        out: out.to_path_buf(),
        problem,
        allowed,
    };
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match (ext.as_deref(), recording) {
        (Some("png"), _) => Ok(Output::Png(out.to_path_buf())),
        (Some("gif"), true) => Ok(Output::Gif(out.to_path_buf())),
        (Some("gif"), false) => Err(refuse(
            "a scene file is one picture, not an animation".into(),
        )),
        (None, true) => Ok(Output::Frames(out.to_path_buf())),
        _ if recording && out.is_dir() => Ok(Output::Frames(out.to_path_buf())),
        (None, false) => Err(refuse("a scene file renders to one PNG picture".into())),
        (Some(e), _) => Err(refuse(format!("cannot write .{e} files"))),
    }
}

/// Runs `nanohaptics render`.
pub fn run(args: &RenderArgs) -> Result<RenderSummary, RenderCmdError> {
    media::check_width(args.width)?;
    if args.proximity && args.audio.is_none() {
        return Err(RenderCmdError::Needs {
            flag: "proximity",
            needs: "--audio FILE.wav",
        });
    }
    let mut summary = match &args.out {
        Some(out) => pictures(args, out)?,
        None if args.audio.is_some() => RenderSummary {
            frames: 0,
            ticks: 0,
            from_recorded_state: false,
            gif_bytes: 0,
            written: Vec::new(),
        },
        None => return Err(RenderCmdError::NoOutput),
    };
    if let Some(wav) = &args.audio {
        summary.written.push(write_audio(args, wav)?);
    }
    Ok(summary)
}

/// The sound of a recording into a WAV file; the summary line.
fn write_audio(args: &RenderArgs, wav: &Path) -> Result<String, RenderCmdError> {
    if args.input.extension().and_then(|e| e.to_str()) != Some("mcap") {
        return Err(RenderCmdError::OutKind {
            out: wav.to_path_buf(),
            problem: "a scene file has no sound; --audio needs a recording (.mcap)".into(),
            allowed: SCENE_OUTPUTS,
        });
    }
    if !(8_000..=192_000).contains(&args.sample_rate) {
        return Err(RenderCmdError::Arg(ValueError::out_of_range(
            "--sample-rate",
            f64::from(args.sample_rate),
            "8000–192000 Hz",
        )));
    }
    let rec = read_recording_file(&args.input, false)?;
    let arrays = haptic_loop::session::SessionArrays::from_recording(&rec)?;
    let s = haptic_loop::sound::session_sound(
        &arrays,
        &rec.description.scene_kind,
        args.proximity,
        args.sample_rate,
    )?;
    render::audio::write_wav(wav, &s.samples, s.sample_rate_hz)
        .map_err(|e| RenderCmdError::Media(e.into()))?;
    let secs = s.samples.len() as f64 / f64::from(s.sample_rate_hz);
    Ok(format!(
        "{} ({secs:.3} s, {} sounds{})",
        written_file("WAV sound", wav),
        s.sounds.len(),
        if args.proximity {
            ", with the proximity tone"
        } else {
            ""
        }
    ))
}

/// The pictures of `run` (`--out`).
fn pictures(args: &RenderArgs, out: &Path) -> Result<RenderSummary, RenderCmdError> {
    let view = parse_view(&args.view)?;
    let recording = match args.input.extension().and_then(|e| e.to_str()) {
        Some("toml") => false,
        Some("mcap") => true,
        _ => return Err(RenderCmdError::InputKind(args.input.clone())),
    };
    let output = output_for(recording, out)?;
    if args.gif.is_some() && !matches!(output, Output::Frames(_)) {
        return Err(RenderCmdError::OutKind {
            out: out.to_path_buf(),
            problem: "--gif adds an animation to a folder of frames only".into(),
            allowed: if recording {
                RECORDING_OUTPUTS
            } else {
                SCENE_OUTPUTS
            },
        });
    }
    match output {
        Output::Png(png) if !recording => {
            scene_picture(&args.input, &png, view, args.width)?;
            Ok(RenderSummary {
                frames: 1,
                ticks: 0,
                from_recorded_state: false,
                gif_bytes: 0,
                written: vec![written_file("PNG picture (initial state)", &png)],
            })
        }
        Output::Png(png) => {
            let ticks = final_picture_view(&args.input, &png, view, args.width)?;
            Ok(RenderSummary {
                frames: 1,
                ticks,
                from_recorded_state: false,
                gif_bytes: 0,
                written: vec![written_file("PNG picture (last tick)", &png)],
            })
        }
        Output::Frames(dir) => recording_frames(args, view, Some(dir), args.gif.clone(), false),
        Output::Gif(gif) => recording_frames(args, view, None, Some(gif), false),
    }
}

/// `what path (N bytes)`, for the summary.
fn written_file(what: &str, path: &Path) -> String {
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    format!("{what} {} ({bytes} bytes)", path.display())
}

/// Draws a scene file's initial state into a PNG.
fn scene_picture(
    scene_path: &Path,
    out: &Path,
    view: Option<View>,
    width: u32,
) -> Result<(), RenderCmdError> {
    let source = SceneSource::from_path(scene_path)?;
    Ok(media::scene_picture(&source, out, view, width)?)
}

/// Recomputes (or, for the optical tweezers, draws from the recorded state) the frames of the
/// recording `args.input`.
fn recording_frames(
    args: &RenderArgs,
    view: Option<View>,
    frames_dir: Option<PathBuf>,
    gif: Option<PathBuf>,
    resimulate: bool,
) -> Result<RenderSummary, RenderCmdError> {
    let rec = read_recording_file(&args.input, false)?;
    let opts = FramesOptions {
        every: args.every,
        view,
        width: args.width,
        frames_dir,
        gif,
        resimulate,
    };
    let s = media::recording_frames(&rec, &opts)?;
    Ok(RenderSummary {
        frames: s.frames,
        ticks: s.ticks,
        from_recorded_state: s.from_recorded_state,
        gif_bytes: s.gif_bytes,
        written: s.written,
    })
}

/// Recomputes a recording and draws its last tick into a PNG (the `demo` picture of a scene).
pub fn final_picture(rec_path: &Path, out: &Path, width: u32) -> Result<(), RenderCmdError> {
    final_picture_view(rec_path, out, None, width).map(|_| ())
}

/// [`final_picture`] with a camera choice; returns the ticks recomputed.
fn final_picture_view(
    rec_path: &Path,
    out: &Path,
    view: Option<View>,
    width: u32,
) -> Result<u64, RenderCmdError> {
    let rec = read_recording_file(rec_path, false)?;
    let f = media::final_frame(&rec, view, width)?;
    f.frame
        .finish()
        .and_then(|img| img.save_png(out))
        .map_err(|e| RenderCmdError::Media(e.into()))?;
    Ok(f.ticks)
}

/// `nanohaptics render` as the program runs it: prints what was written.
pub fn cmd(args: &RenderArgs) -> Result<u8, String> {
    let s = run(args).map_err(|e| e.to_string())?;
    if s.ticks > 0 {
        println!(
            "{}: {} ticks {}",
            args.input.display(),
            s.ticks,
            if s.from_recorded_state {
                "drawn from the recorded state"
            } else {
                "recomputed"
            }
        );
    }
    for w in &s.written {
        println!("wrote {w}");
    }
    Ok(crate::status::SUCCESS)
}

#[cfg(test)]
mod tests;
