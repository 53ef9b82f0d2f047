//! What every picture of nanohaptics is drawn on: an RGBA [`Image`] (a tiny-skia pixmap) with
//! its PNG encoding, and one line of text laid out as filled glyph outlines from the embedded
//! DejaVu Sans font ([`text::layout`]).
//!
//! **What it is for.** The bottom both drawing crates share, so neither copies it: `render`
//! (world primitives through a camera, GIFs; its `Image` wraps this one with the renderer's
//! errors) and `chart` (2D charts) draw into an [`Image`] and write their text with
//! [`text::layout`]. The font is compiled in: no system fonts, no fontconfig, the same pixels
//! and PNG bytes on every machine.
//!
//! **What it is not.** No drawing of its own beyond copying one image onto another: shapes,
//! shading, axes and labels are the callers'. No other image format than 8-bit RGBA PNG, no
//! text shaping beyond one left-to-right line (no kerning, no ligatures, no line breaking).
//!
//! ```
//! use picture::{Image, text};
//! let mut img = Image::new(120, 40)?;
//! img.pixmap_mut().fill(tiny_skia::Color::WHITE);
//! let t = text::layout("1 um", 4.0, 30.0, 20.0)?;
//! assert!(t.width_px > 20.0 && t.path.is_some());
//! assert_eq!(img.pixel(0, 0), Some([255, 255, 255, 255]));
//! assert!(img.encode_png()?.starts_with(b"\x89PNG"));
//! # Ok::<(), picture::PictureError>(())
//! ```

pub mod image;
pub mod text;

pub use image::{Image, MAX_SIDE_PX};

/// Why an image could not be made, encoded or written, or text not laid out.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum PictureError {
    /// An image size outside 1..=[`MAX_SIDE_PX`] per side.
    #[error("image size {width_px}x{height_px} px is out of range: allowed 1..={max} px per side")]
    ImageSize {
        /// Width asked for, px.
        width_px: u32,
        /// Height asked for, px.
        height_px: u32,
        /// Largest side allowed, px.
        max: u32,
    },
    /// The embedded font could not be parsed (a build problem, not an input problem).
    #[error("embedded font could not be parsed")]
    Font,
    /// PNG encoding or file writing failed.
    #[error("PNG: {0}")]
    Png(String),
}
