//! A rendered RGBA image and its PNG encoding.

use std::path::Path;

use tiny_skia::Pixmap;

use crate::PictureError;

/// Largest image side, px.
pub const MAX_SIDE_PX: u32 = 8192;

/// Checks an image size: each side in 1..=[`MAX_SIDE_PX`].
pub fn check_size(width_px: u32, height_px: u32) -> Result<(), PictureError> {
    if width_px == 0 || height_px == 0 || width_px > MAX_SIDE_PX || height_px > MAX_SIDE_PX {
        return Err(PictureError::ImageSize {
            width_px,
            height_px,
            max: MAX_SIDE_PX,
        });
    }
    Ok(())
}

/// An RGBA image, 8 bits per channel, sRGB, top-left origin.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pixmap: Pixmap,
}

impl Image {
    /// A blank (transparent) image of `width_px` × `height_px`.
    pub fn new(width_px: u32, height_px: u32) -> Result<Image, PictureError> {
        check_size(width_px, height_px)?;
        let pixmap = Pixmap::new(width_px, height_px).ok_or(PictureError::ImageSize {
            width_px,
            height_px,
            max: MAX_SIDE_PX,
        })?;
        Ok(Image { pixmap })
    }

    /// The image of a pixmap drawn elsewhere (any size tiny-skia made).
    pub fn from_pixmap(pixmap: Pixmap) -> Image {
        Image { pixmap }
    }

    /// The pixels to draw on with tiny-skia.
    pub fn pixmap_mut(&mut self) -> &mut Pixmap {
        &mut self.pixmap
    }

    /// Width, px.
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// Height, px.
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The straight (not premultiplied) RGBA of the pixel at column `x`, row `y`, or `None`
    /// outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 4]> {
        let p = self.pixmap.pixel(x, y)?.demultiply();
        Some([p.red(), p.green(), p.blue(), p.alpha()])
    }

    /// All pixels as straight RGBA bytes, row by row.
    pub fn to_rgba8(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixmap.data().len());
        for p in self.pixmap.pixels() {
            let c = p.demultiply();
            out.extend_from_slice(&[c.red(), c.green(), c.blue(), c.alpha()]);
        }
        out
    }

    /// Premultiplied RGBA bytes as stored, row by row (equal to straight RGBA where the image
    /// is opaque).
    pub fn data(&self) -> &[u8] {
        self.pixmap.data()
    }

    /// Draws `other` over this image with its top-left corner at column `x`, row `y` (px; parts
    /// outside are clipped), blending by its alpha. Used to put panels side by side.
    pub fn draw_image(&mut self, other: &Image, x: i32, y: i32) {
        self.pixmap.draw_pixmap(
            x,
            y,
            other.pixmap.as_ref(),
            &tiny_skia::PixmapPaint::default(),
            tiny_skia::Transform::identity(),
            None,
        );
    }

    /// The image as PNG bytes (8-bit RGBA, the png crate's fast deflate: encoding costs a few
    /// times less than its default at a slightly larger file).
    pub fn encode_png(&self) -> Result<Vec<u8>, PictureError> {
        let err = |e: png::EncodingError| PictureError::Png(e.to_string());
        let data = self.to_rgba8();
        let mut out = Vec::with_capacity(data.len() / 8);
        let mut enc = png::Encoder::new(&mut out, self.width(), self.height());
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let mut w = enc.write_header().map_err(err)?;
        w.write_image_data(&data).map_err(err)?;
        w.finish().map_err(err)?;
        Ok(out)
    }

    /// Writes the image as a PNG file.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), PictureError> {
        let bytes = self.encode_png()?;
        std::fs::write(path.as_ref(), bytes)
            .map_err(|e| PictureError::Png(format!("{}: {e}", path.as_ref().display())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panels_land_where_asked_and_clip() {
        let mut big = Image::new(20, 10).expect("image");
        big.pixmap.fill(tiny_skia::Color::WHITE);
        let mut small = Image::new(4, 4).expect("image");
        small
            .pixmap
            .fill(tiny_skia::Color::from_rgba8(200, 0, 0, 255));
        big.draw_image(&small, 18, 3); // half outside on the right
        assert_eq!(big.pixel(18, 3), Some([200, 0, 0, 255]));
        assert_eq!(big.pixel(19, 6), Some([200, 0, 0, 255]));
        assert_eq!(big.pixel(17, 3), Some([255, 255, 255, 255]));
        assert_eq!(big.pixel(18, 7), Some([255, 255, 255, 255]));
    }

    #[test]
    fn png_round_trip_keeps_the_pixels() {
        let mut img = Image::new(3, 2).expect("image");
        img.pixmap
            .fill(tiny_skia::Color::from_rgba8(10, 20, 30, 255));
        let png = img.encode_png().expect("png");
        let back = tiny_skia::Pixmap::decode_png(&png).expect("decode");
        assert_eq!(back.data(), img.data());
    }
}
