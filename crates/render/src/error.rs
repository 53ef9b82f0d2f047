//! The renderer's error type.

use thiserror::Error;

/// Why a camera, a primitive, an image or a GIF could not be made.
///
/// Every variant names the offending field and, where there is one, the allowed range.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RenderError {
    /// A number that is NaN, infinite or outside its allowed range.
    #[error(transparent)]
    Value(#[from] haptic_types::ValueError),
    /// A name that is not one of the allowed ones.
    #[error("{field} = {got:?} is not known: allowed {allowed}")]
    UnknownName {
        /// Name of the field, e.g. `view`.
        field: String,
        /// The name given.
        got: String,
        /// The allowed names.
        allowed: &'static str,
    },
    /// An image size the renderer cannot make.
    #[error("{}", haptic_types::value::out_of_range(
        "image size",
        format_args!("{width_px}x{height_px} px"),
        &format!("1..={max} px per side"),
    ))]
    ImageSize {
        /// Width asked for, px.
        width_px: u32,
        /// Height asked for, px.
        height_px: u32,
        /// Largest side allowed, px.
        max: u32,
    },
    /// An image does not have the size expected (the GIF's, or the camera's).
    #[error("image is {got_width}x{got_height} px, expected {width}x{height} px")]
    FrameSize {
        /// Expected width, px.
        width: u32,
        /// Expected height, px.
        height: u32,
        /// Width given, px.
        got_width: u32,
        /// Height given, px.
        got_height: u32,
    },
    /// A palette was asked for from no pixels.
    #[error("palette needs at least one image with at least one pixel")]
    EmptyPalette,
    /// The embedded font could not be parsed (a build problem, not an input problem).
    #[error("embedded font could not be parsed")]
    Font,
    /// PNG encoding or file writing failed.
    #[error("PNG: {0}")]
    Png(String),
    /// GIF encoding or writing failed.
    #[error("GIF: {0}")]
    Gif(String),
    /// Writing a sound file failed.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        message: String,
    },
}

/// Checks that `value` is finite.
pub(crate) fn finite(field: impl FnOnce() -> String, value: f64) -> Result<f64, RenderError> {
    Ok(haptic_types::value::finite(field, value)?)
}

/// Checks that every component of a point is finite.
pub(crate) fn finite3(field: &str, p: [f64; 3]) -> Result<(), RenderError> {
    Ok(haptic_types::value::finite3(field, p)?)
}

/// The error of a number outside its allowed range, naming the field and the range.
pub(crate) fn out_of_range(
    field: impl Into<std::borrow::Cow<'static, str>>,
    value: f64,
    allowed: impl Into<std::borrow::Cow<'static, str>>,
) -> RenderError {
    RenderError::Value(haptic_types::ValueError::out_of_range(
        field, value, allowed,
    ))
}
