//! Headless CPU renderer for nanohaptics: pictures, animations and the sound of a world's
//! session, without a GPU, a window, a browser or a sound card.
//!
//! **What it is for.**
//!
//! * Pictures of worlds: `haptic-types`' drawable [`Primitive`]s (spheres, boxes, the beam
//!   ellipse, the haptic cursor, force arrows, polylines and loops such as the working
//!   envelope, blueprint slots, text labels) given in world coordinates (metres, z up), seen
//!   through an orthographic [`Camera`] (top, side or oblique 3D view; [`bounds`] and
//!   [`action_bounds`] frame a scene), drawn by a [`Frame`] with anti-aliasing (tiny-skia),
//!   light shading so solids read as solid, an exact back-to-front order for disjoint convex
//!   bodies and a scale bar, into an [`Image`] (RGBA, PNG: `picture`'s image and font).
//! * Animations: a [`GifWriter`] turns a sequence of images into an animated GIF at a given
//!   frame rate (one median-cut palette, frames cropped to what changed).
//! * Sound: [`audio`] synthesises a session's impacts, contact clicks and proximity tone
//!   sample by sample, for a whole recording ([`audio::synthesize`], a WAV file) or live
//!   ([`audio::StreamSynth`], the browser game).
//!
//! **What it is not.** It knows nothing of worlds, scenes, recordings or the command line:
//! every scene draws with `haptic-types`' primitives and hands over its sound events;
//! `haptic-loop` reads recordings and owns the frames and sound of a session, and the
//! `nanohaptics render` command is the CLI's. No charts (the `chart` crate draws those, on the
//! same image and font), no perspective, no lighting model beyond one directional light with
//! ambient, no interpenetrating solids (they are ordered by centre depth).
//!
//! ```
//! use haptic_types::{Ball, Primitive, Rgba};
//! use render::{Camera, Frame, Style, View};
//! let cam = Camera::new(View::Top, [0.0; 3], 1e8, 320, 240)?; // 1 px = 10 nm
//! let mut f = Frame::new(cam, Style::default())?;
//! f.push(Primitive::Sphere(Ball {
//!     center_m: [0.0; 3],
//!     radius_m: 0.5e-6,
//!     color: Rgba::from_u8(200, 60, 40),
//! }))?;
//! f.scale_bar(None, Rgba::from_u8(0, 0, 0))?;
//! let img = f.finish()?;
//! let [r, g, b, _] = img.pixel(160, 120).expect("inside");
//! assert!(r > g && r > b); // the particle is where it should be
//! # Ok::<(), render::RenderError>(())
//! ```

pub mod audio;
pub mod camera;
mod draw;
pub mod error;
pub mod frame;
pub mod gif;
pub mod image;
mod order;

pub use camera::{Camera, MAX_SIDE_PX, Projected, View, action_bounds, bounds, is_backdrop};
pub use error::RenderError;
pub use frame::{Frame, Style, format_length, nice_length_m};
pub use gif::{BAD_PIXEL_ERROR, BAD_PIXEL_SHARE, GifWriter, Palette, frame_delays_cs};
pub use image::Image;

/// An [`Rgba`](haptic_types::Rgba) as tiny-skia's colour (channels clamped to 0–1).
pub(crate) trait ToSkia {
    /// The colour for tiny-skia.
    fn skia(self) -> tiny_skia::Color;
}

impl ToSkia for haptic_types::Rgba {
    fn skia(self) -> tiny_skia::Color {
        let [r, g, b, a] = self.0.map(|c| c.clamp(0.0, 1.0) as f32);
        tiny_skia::Color::from_rgba(r, g, b, a).unwrap_or(tiny_skia::Color::BLACK)
    }
}

/// The user guide's examples (`docs/render.md`), compiled and run as doc-tests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/render.md")]
pub struct UserGuide;
