//! A rendered RGBA image and its PNG encoding: `picture`'s [`picture::Image`] (the pixels, the
//! PNG, one image drawn onto another), with the renderer's errors.

use std::path::Path;

use tiny_skia::Pixmap;

use crate::error::RenderError;

/// An RGBA image, 8 bits per channel, sRGB, top-left origin (`picture`'s image, whose
/// errors are [`RenderError`]s).
#[derive(Clone, Debug, PartialEq)]
pub struct Image(picture::Image);

impl Image {
    /// A blank (transparent) image of `width_px` × `height_px` (each side in
    /// 1..=[`crate::MAX_SIDE_PX`]).
    pub fn new(width_px: u32, height_px: u32) -> Result<Image, RenderError> {
        Ok(Image(picture::Image::new(width_px, height_px)?))
    }

    /// Width, px.
    pub fn width(&self) -> u32 {
        self.0.width()
    }

    /// Height, px.
    pub fn height(&self) -> u32 {
        self.0.height()
    }

    /// The straight (not premultiplied) RGBA of the pixel at column `x`, row `y`, or `None`
    /// outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        self.0.pixel(x, y)
    }

    /// All pixels as straight RGBA bytes, row by row.
    pub fn to_rgba8(&self) -> Vec<u8> {
        self.0.to_rgba8()
    }

    /// Premultiplied RGBA bytes as stored, row by row (equal to straight RGBA where the image
    /// is opaque).
    pub fn data(&self) -> &[u8] {
        self.0.data()
    }

    /// Draws `other` over this image with its top-left corner at column `x`, row `y` (px; parts
    /// outside are clipped), blending by its alpha. Used to put panels side by side.
    pub fn draw_image(&mut self, other: &Image, x: i32, y: i32) {
        self.0.draw_image(&other.0, x, y);
    }

    /// The image as PNG bytes (8-bit RGBA, the png crate's fast deflate).
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        Ok(self.0.encode_png()?)
    }

    /// Writes the image as a PNG file.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), RenderError> {
        Ok(self.0.save_png(path)?)
    }

    /// The pixels, for drawing.
    pub(crate) fn pixmap_mut(&mut self) -> &mut Pixmap {
        self.0.pixmap_mut()
    }
}

impl From<picture::PictureError> for RenderError {
    fn from(e: picture::PictureError) -> Self {
        match e {
            picture::PictureError::ImageSize {
                width_px,
                height_px,
                max,
            } => RenderError::ImageSize {
                width_px,
                height_px,
                max,
            },
            picture::PictureError::Font => RenderError::Font,
            picture::PictureError::Png(m) => RenderError::Png(m),
        }
    }
}
