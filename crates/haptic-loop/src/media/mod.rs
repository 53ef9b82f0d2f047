//! Pictures and animations of scenes and recordings: the library half of `nanohaptics render`
//! and of `demo`'s pictures, drawn by the `render` crate.
//!
//! - [`frames`]: a recording's frames (PNG files and/or an animated GIF), recomputed through
//!   the one re-simulation path ([`Resimulation`](crate::replay::Resimulation)) or, for the
//!   optical tweezers, drawn from the recorded state;
//! - [`picture`]: one picture of a scene's initial state or of a recording's last tick, framed
//!   on its bodies.
//!
//! What it is not: no command-line parsing (the program maps its flags to these options), no
//! sound (that is [`sound`](crate::sound)).

pub mod frames;
pub mod picture;

use crate::error::SessionError;
use haptic_types::value::ValueError;
use haptic_types::{Primitive, Rgba};
use recording::RecordingError;
use render::{Camera, Frame, RenderError, Style, View};
use std::ops::RangeInclusive;
use std::path::PathBuf;

pub use frames::{FramesOptions, FramesSummary, recording_frames};
pub use picture::{FinalPicture, final_frame, scene_picture};

/// Widths a picture may have, px (its height is 3/4 of it).
pub const WIDTH_PX: RangeInclusive<u32> = 64..=4096;

/// Why a picture or an animation could not be made.
#[derive(Debug, thiserror::Error)]
pub enum MediaError {
    /// An option out of its range (`width`, `every`), named as the option; the one wording
    /// of [`ValueError`] (the program renames the field to its flag).
    #[error(transparent)]
    Range(ValueError),
    /// Reading or writing a file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// The recording.
    #[error(transparent)]
    Recording(#[from] RecordingError),
    /// Rebuilding or re-running the session (the scene, its file, the replay).
    #[error(transparent)]
    Session(#[from] SessionError),
    /// Drawing.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A recorded state that cannot be drawn.
    #[error("{0}")]
    Picture(String),
}

/// Checks a picture width against [`WIDTH_PX`].
pub fn check_width(width: u32) -> Result<(), MediaError> {
    if !WIDTH_PX.contains(&width) {
        return Err(MediaError::Range(ValueError::out_of_range(
            "width",
            f64::from(width),
            format!("{}–{} px", WIDTH_PX.start(), WIDTH_PX.end()),
        )));
    }
    Ok(())
}

/// Text and scale bar colour, light on the dark background the scenes' colours are chosen for
/// (they are shared with the Foxglove channels).
const INK: Rgba = Rgba([0.9, 0.9, 0.9, 1.0]);

/// The picture style: the scenes' dark background.
fn style() -> Style {
    Style {
        background: Rgba([0.12, 0.13, 0.15, 1.0]),
        ..Style::default()
    }
}

/// Top view for a flat box (height under 5 % of its width), oblique otherwise, unless `view`
/// says.
fn view_for(lo: [f64; 3], hi: [f64; 3], view: Option<View>) -> View {
    let flat = (hi[2] - lo[2]) < 0.05 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    view.unwrap_or(if flat {
        View::Top
    } else {
        View::oblique_default()
    })
}

/// A camera that frames the action: the scene's bodies (not its backdrops — the ground, a wall
/// plate, a substrate: `render::is_backdrop`) and every `extra` point (the cursor's world
/// positions over a recording, so the cursor never leaves the image); the whole picture when
/// only backdrops are drawn. Top view for a flat world unless `view` says otherwise.
fn camera_for(
    prims: &[Primitive],
    extra: &[[f64; 3]],
    view: Option<View>,
    width: u32,
) -> Result<Camera, RenderError> {
    let (mut lo, mut hi) = render::action_bounds(prims)
        .or_else(|| (!extra.is_empty()).then(|| (extra[0], extra[0])))
        .or_else(|| render::bounds(prims))
        .unwrap_or(([0.0; 3], [0.0; 3]));
    for p in extra {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    // room around the cursor path for what the cursor carries (a particle, a brick)
    if !extra.is_empty() {
        let pad = 0.08 * (0..3).map(|i| hi[i] - lo[i]).fold(0.0, f64::max);
        for i in 0..3 {
            lo[i] -= pad;
            hi[i] += pad;
        }
    }
    Camera::fit(view_for(lo, hi, view), lo, hi, width, width * 3 / 4, 0.04)
}

/// Draws `prims`, the scale bar and `title` into a cleared `frame`.
fn draw_prims(frame: &mut Frame, prims: &[Primitive], title: &str) -> Result<(), RenderError> {
    frame.clear();
    for p in prims {
        frame.push(p.clone())?;
    }
    frame.scale_bar(None, INK)?;
    frame.title(title, INK)
}
