//! Text as filled glyph outlines, from the embedded DejaVu Sans font (Bitstream Vera licence,
//! `assets/fonts/LICENSE-DejaVu.txt`).

use std::sync::OnceLock;

use tiny_skia::{Path, PathBuilder};
use ttf_parser::{Face, GlyphId, OutlineBuilder};

use crate::PictureError;

static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn face() -> Result<&'static Face<'static>, PictureError> {
    static FACE: OnceLock<Option<Face<'static>>> = OnceLock::new();
    FACE.get_or_init(|| Face::parse(FONT, 0).ok())
        .as_ref()
        .ok_or(PictureError::Font)
}

struct Sink<'a> {
    pb: &'a mut PathBuilder,
    k: f32,
    x0: f32,
    y0: f32,
}

impl Sink<'_> {
    fn p(&self, x: f32, y: f32) -> (f32, f32) {
        (self.x0 + x * self.k, self.y0 - y * self.k)
    }
}

impl OutlineBuilder for Sink<'_> {
    fn move_to(&mut self, x: f32, y: f32) {
        let (x, y) = self.p(x, y);
        self.pb.move_to(x, y);
    }
    fn line_to(&mut self, x: f32, y: f32) {
        let (x, y) = self.p(x, y);
        self.pb.line_to(x, y);
    }
    fn quad_to(&mut self, x1: f32, y1: f32, x: f32, y: f32) {
        let (x1, y1) = self.p(x1, y1);
        let (x, y) = self.p(x, y);
        self.pb.quad_to(x1, y1, x, y);
    }
    fn curve_to(&mut self, x1: f32, y1: f32, x2: f32, y2: f32, x: f32, y: f32) {
        let (x1, y1) = self.p(x1, y1);
        let (x2, y2) = self.p(x2, y2);
        let (x, y) = self.p(x, y);
        self.pb.cubic_to(x1, y1, x2, y2, x, y);
    }
    fn close(&mut self) {
        self.pb.close();
    }
}

/// Laid-out text: its outline path (pixel coordinates) and its advance width, px.
pub struct TextPath {
    /// Glyph outlines; `None` for text with no visible glyph (e.g. spaces only).
    pub path: Option<Path>,
    /// Width of the text, px.
    pub width_px: f32,
}

/// Lays out one line of `text` with its baseline starting at (`x`, `y`) px, `size_px` pixels
/// per em. Characters missing from the font draw as the font's missing-glyph box; control
/// characters (e.g. a newline) are skipped.
pub fn layout(text: &str, x: f32, y: f32, size_px: f32) -> Result<TextPath, PictureError> {
    let face = face()?;
    let k = size_px / f32::from(face.units_per_em());
    let mut pb = PathBuilder::new();
    let mut pen = x;
    for ch in text.chars().filter(|c| !c.is_control()) {
        let g = face.glyph_index(ch).unwrap_or(GlyphId(0));
        let mut sink = Sink {
            pb: &mut pb,
            k,
            x0: pen,
            y0: y,
        };
        face.outline_glyph(g, &mut sink);
        pen += f32::from(face.glyph_hor_advance(g).unwrap_or(0)) * k;
    }
    Ok(TextPath {
        path: pb.finish(),
        width_px: pen - x,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_grows_with_text_and_size() {
        let a = layout("1 um", 0.0, 0.0, 10.0).expect("font");
        let b = layout("1 um", 0.0, 0.0, 20.0).expect("font");
        assert!(a.width_px > 10.0);
        assert!((b.width_px - 2.0 * a.width_px).abs() < 1e-3);
        let bounds = a.path.expect("glyphs").bounds();
        // glyphs sit above the baseline (y grows downward) and within the advance
        assert!(bounds.top() < -5.0 && bounds.bottom() <= 3.0);
        assert!(bounds.right() <= a.width_px + 1.0);
        // control characters take no room
        let c = layout("1 \num\n", 0.0, 0.0, 10.0).expect("font");
        assert_eq!(c.width_px, a.width_px);
    }
}
