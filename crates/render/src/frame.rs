//! A frame: primitives added in world coordinates, drawn back to front with shading into an
//! [`Image`].

use crate::ToSkia;
use crate::camera::Camera;
use crate::error::{RenderError, finite, finite3, out_of_range};
use crate::image::Image;
use crate::order::{Item, Shape, back_to_front};
use haptic_types::Primitive;
use haptic_types::Rgba;
use haptic_types::vec3::{Vec3, add, box_corners, scale, sub};
use picture::text;
use world_form::numbers::{SiStyle, fmt_si};

/// How a frame looks apart from its primitives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Background colour.
    pub background: Rgba,
    /// Width of polylines, arrow shafts and outlines, px.
    pub line_width_px: f32,
    /// Label text size, px per em.
    pub font_size_px: f32,
    /// Length of an arrow head, px (shortened to 40 % of a short arrow).
    pub arrow_head_px: f32,
    /// Share of a lit face's brightness that does not depend on the light direction, 0–1.
    pub ambient: f64,
}

impl Default for Style {
    fn default() -> Style {
        Style {
            background: Rgba::from_u8(250, 250, 247),
            line_width_px: 2.0,
            font_size_px: 14.0,
            arrow_head_px: 12.0,
            ambient: 0.45,
        }
    }
}

impl Style {
    fn validate(&self) -> Result<(), RenderError> {
        self.background.validate("style.background")?;
        let pos = |field: &str, v: f32, max: f32| -> Result<(), RenderError> {
            finite(|| field.to_string(), f64::from(v))?;
            if !(v > 0.0 && v <= max) {
                return Err(out_of_range(field.to_string(), f64::from(v), "(0, 200] px"));
            }
            Ok(())
        };
        pos("style.line_width_px", self.line_width_px, 200.0)?;
        pos("style.font_size_px", self.font_size_px, 200.0)?;
        pos("style.arrow_head_px", self.arrow_head_px, 200.0)?;
        finite(|| "style.ambient".into(), self.ambient)?;
        if !(0.0..=1.0).contains(&self.ambient) {
            return Err(out_of_range("style.ambient", self.ambient, "[0, 1]"));
        }
        Ok(())
    }
}

/// A scale bar in the bottom-left corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ScaleBar {
    pub(crate) length_m: f64,
    pub(crate) color: Rgba,
}

/// One picture being composed: a camera, a style and the primitives added so far.
///
/// Solids (spheres, cursors, boxes, ellipses) are drawn back to front in an exact order for
/// disjoint convex bodies (see the `order` module); polylines, arrows and slots are drawn over
/// them in the order added; labels, the title and the scale bar go on top.
#[derive(Clone, Debug)]
pub struct Frame {
    pub(crate) camera: Camera,
    pub(crate) style: Style,
    items: Vec<Primitive>,
    scale_bar: Option<ScaleBar>,
    title: Option<(String, Rgba)>,
}

/// Picks a length of 1, 2 or 5 × 10^k m whose bar is at most `max_px` long.
pub fn nice_length_m(pixels_per_m: f64, max_px: f64) -> f64 {
    let target = max_px / pixels_per_m;
    let p = 10f64.powf(target.log10().floor());
    for m in [5.0, 2.0, 1.0] {
        if m * p <= target {
            return m * p;
        }
    }
    p
}

/// Writes a length in metres with an SI prefix, e.g. `2 µm`, `100 nm`, `5 cm`
/// ([`fmt_si`] in the [`SiStyle::LENGTH`] style).
pub fn format_length(length_m: f64) -> String {
    fmt_si(length_m, "m", SiStyle::LENGTH)
}

impl Frame {
    /// An empty frame.
    pub fn new(camera: Camera, style: Style) -> Result<Frame, RenderError> {
        style.validate()?;
        Ok(Frame {
            camera,
            style,
            items: Vec::new(),
            scale_bar: None,
            title: None,
        })
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The style.
    pub fn style(&self) -> &Style {
        &self.style
    }

    /// The primitives added so far.
    pub fn primitives(&self) -> &[Primitive] {
        &self.items
    }

    /// Removes every primitive, the title and the scale bar (keeps camera and style).
    pub fn clear(&mut self) {
        self.items.clear();
        self.scale_bar = None;
        self.title = None;
    }

    /// Adds a primitive after checking its numbers ([`Primitive::validate`]).
    pub fn push(&mut self, p: Primitive) -> Result<(), RenderError> {
        p.validate()?;
        self.items.push(p);
        Ok(())
    }

    /// Adds a closed loop through `points_m` drawn `factor` times larger about `about_m` (m):
    /// point p is drawn at `about + factor · (p − about)`. This is how the working envelope,
    /// a region a few nm across around a µm particle, is drawn ×100 as in the optical-tweezers
    /// paper. `factor` must be finite and > 0.
    pub fn scaled_loop(
        &mut self,
        points_m: &[Vec3],
        about_m: Vec3,
        factor: f64,
        color: Rgba,
    ) -> Result<(), RenderError> {
        finite3("scaled_loop.about_m", about_m)?;
        finite(|| "scaled_loop.factor".into(), factor)?;
        if factor <= 0.0 {
            return Err(out_of_range("scaled_loop.factor", factor, "(0, inf)"));
        }
        let points_m = points_m
            .iter()
            .map(|p| add(about_m, scale(sub(*p, about_m), factor)))
            .collect();
        self.push(Primitive::Polyline {
            points_m,
            closed: true,
            color,
        })
    }

    /// Shows a scale bar in the bottom-left corner, `length_m` long (m, > 0), or when `None` the
    /// longest 1-2-5 length that fits a fifth of the image width. In an oblique view the bar
    /// measures lengths in planes facing the camera.
    pub fn scale_bar(&mut self, length_m: Option<f64>, color: Rgba) -> Result<(), RenderError> {
        color.validate("scale_bar.color")?;
        let length_m = match length_m {
            Some(l) => {
                finite(|| "scale_bar.length_m".into(), l)?;
                if l <= 0.0 {
                    return Err(out_of_range("scale_bar.length_m", l, "(0, inf) m"));
                }
                l
            }
            None => nice_length_m(
                self.camera.pixels_per_m(),
                f64::from(self.camera.width_px()) / 5.0,
            ),
        };
        self.scale_bar = Some(ScaleBar { length_m, color });
        Ok(())
    }

    /// The scale bar's length, m, if one is shown.
    pub fn scale_bar_length_m(&self) -> Option<f64> {
        self.scale_bar.map(|s| s.length_m)
    }

    /// Shows `text` in the top-left corner.
    pub fn title(&mut self, text: impl Into<String>, color: Rgba) -> Result<(), RenderError> {
        color.validate("title.color")?;
        self.title = Some((text.into(), color));
        Ok(())
    }

    /// Draws the frame into a new image.
    pub fn finish(&self) -> Result<Image, RenderError> {
        let mut img = Image::new(self.camera.width_px(), self.camera.height_px())?;
        self.draw_into(&mut img)?;
        Ok(img)
    }

    /// Draws the frame into `img` (which must have the camera's size), overwriting it.
    pub fn draw_into(&self, img: &mut Image) -> Result<(), RenderError> {
        let (w, h) = (self.camera.width_px(), self.camera.height_px());
        if img.width() != w || img.height() != h {
            return Err(RenderError::FrameSize {
                width: w,
                height: h,
                got_width: img.width(),
                got_height: img.height(),
            });
        }
        let pm = img.pixmap_mut();
        pm.fill(self.style.background.skia());
        let mut solids = Vec::new();
        let mut solid_idx = Vec::new();
        for (i, p) in self.items.iter().enumerate() {
            if let Some(it) = self.solid_item(p) {
                solids.push(it);
                solid_idx.push(i);
            }
        }
        for k in back_to_front(&solids, self.camera.forward()) {
            self.draw_solid(pm, &self.items[solid_idx[k]]);
        }
        for p in &self.items {
            match p {
                Primitive::Polyline {
                    points_m,
                    closed,
                    color,
                } => self.draw_polyline(pm, points_m, *closed, *color),
                Primitive::Arrow {
                    from_m,
                    to_m,
                    color,
                } => self.draw_arrow(pm, *from_m, *to_m, *color),
                Primitive::Slot(slot) => self.draw_slot(pm, slot),
                _ => {}
            }
        }
        for (text, x, y, color) in self.placed_labels()? {
            self.draw_text(pm, &text, x as f32, y as f32, color, 0.0)?;
        }
        if let Some((t, c)) = &self.title {
            let size = self.style.font_size_px;
            self.draw_text(pm, t, 10.0, 10.0 + size, *c, 0.0)?;
        }
        if let Some(sb) = self.scale_bar {
            self.draw_scale_bar(pm, sb)?;
        }
        Ok(())
    }

    /// Screen rectangles (x0, y0, x1, y1 px) of the bodies labels must not cover: every solid
    /// but the backdrops ([`crate::camera::is_backdrop`]).
    pub fn body_rects(&self) -> Vec<[f64; 4]> {
        self.items
            .iter()
            .filter(|p| !crate::camera::is_backdrop(p))
            .filter_map(|p| self.solid_item(p))
            .filter(|it| !it.flat)
            .map(|it| it.rect)
            .collect()
    }

    /// Screen rectangles (x0, y0, x1, y1 px) of the labels as drawn.
    pub fn label_rects(&self) -> Result<Vec<[f64; 4]>, RenderError> {
        let size = f64::from(self.style.font_size_px);
        Ok(self
            .placed_labels()?
            .into_iter()
            .map(|(t, x, y, _)| {
                let w = f64::from(
                    text::layout(&t, 0.0, 0.0, self.style.font_size_px)
                        .map(|l| l.width_px)
                        .unwrap_or(0.0),
                );
                [x, y - 0.8 * size, x + w, y + 0.25 * size]
            })
            .collect())
    }

    /// Where each label goes: its baseline start (px). The first of eight places around its
    /// anchor (right above, right below, left above, left below, then twice as far) where its
    /// text stays in the picture and covers no body and no label placed before it; the first
    /// place when none is free.
    fn placed_labels(&self) -> Result<Vec<(String, f64, f64, Rgba)>, RenderError> {
        let bodies = self.body_rects();
        let size = f64::from(self.style.font_size_px);
        let (fw, fh) = (
            f64::from(self.camera.width_px()),
            f64::from(self.camera.height_px()),
        );
        let mut placed: Vec<[f64; 4]> = Vec::new();
        let mut out = Vec::new();
        let hits =
            |r: &[f64; 4], o: &[f64; 4]| r[0] < o[2] && o[0] < r[2] && r[1] < o[3] && o[1] < r[3];
        for p in &self.items {
            let Primitive::Label {
                position_m,
                text: t,
                color,
            } = p
            else {
                continue;
            };
            let q = self.camera.project(*position_m);
            let w = f64::from(text::layout(t, 0.0, 0.0, self.style.font_size_px)?.width_px);
            // The bodies at the anchor push the label out past their own rectangle.
            let reach = bodies
                .iter()
                .filter(|b| b[0] <= q.x_px && q.x_px <= b[2] && b[1] <= q.y_px && q.y_px <= b[3])
                .map(|b| (b[2] - b[0]).max(b[3] - b[1]) / 2.0)
                .fold(0.0, f64::max);
            let mut best = None;
            for k in 0..8 {
                let d =
                    4.0 + reach * if k < 4 { 1.0 } else { 2.0 } + if k < 4 { 0.0 } else { size };
                let (sx, sy) = [(1.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (-1.0, 1.0)][k % 4];
                let x = if sx > 0.0 { q.x_px + d } else { q.x_px - d - w };
                let y = if sy < 0.0 {
                    q.y_px - d
                } else {
                    q.y_px + d + 0.8 * size
                };
                let r = [x, y - 0.8 * size, x + w, y + 0.25 * size];
                if best.is_none() {
                    best = Some((x, y, r));
                }
                let inside = r[0] >= 0.0 && r[1] >= 0.0 && r[2] <= fw && r[3] <= fh;
                if inside && !bodies.iter().chain(&placed).any(|b| hits(&r, b)) {
                    best = Some((x, y, r));
                    break;
                }
            }
            if let Some((x, y, r)) = best {
                placed.push(r);
                out.push((t.clone(), x, y, *color));
            }
        }
        Ok(out)
    }

    fn solid_item(&self, p: &Primitive) -> Option<Item> {
        let cam = &self.camera;
        let s = cam.pixels_per_m();
        match p {
            Primitive::Sphere(ball) | Primitive::Cursor(ball) => {
                let q = cam.project(ball.center_m);
                let r = ball.radius_m * s;
                Some(Item {
                    shape: Shape::Sphere {
                        c: ball.center_m,
                        r: ball.radius_m,
                    },
                    depth: q.depth_m,
                    flat: false,
                    rect: [q.x_px - r, q.y_px - r, q.x_px + r, q.y_px + r],
                })
            }
            Primitive::Box(block) => Some(obb_item(
                cam,
                block.center_m,
                block.axes(),
                block.half_extents_m,
                false,
            )),
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                ..
            } => {
                let ax = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let half = [semi_axes_m[0], semi_axes_m[1], 0.0];
                Some(obb_item(cam, *center_m, ax, half, true))
            }
            _ => None,
        }
    }
}

/// The item of an oriented box centred at `c` (m) with unit axes `ax` and half extents `half`
/// (m): its depth that of its centre, its screen rectangle that of its eight corners.
fn obb_item(cam: &Camera, c: Vec3, ax: [Vec3; 3], half: Vec3, flat: bool) -> Item {
    let rect = rect_of(box_corners(c, ax, half).iter().map(|p| cam.project(*p)));
    Item {
        shape: Shape::Obb { c, axes: ax, half },
        depth: cam.project(c).depth_m,
        flat,
        rect,
    }
}

fn rect_of(it: impl Iterator<Item = crate::camera::Projected>) -> [f64; 4] {
    let mut r = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for q in it {
        r[0] = r[0].min(q.x_px);
        r[1] = r[1].min(q.y_px);
        r[2] = r[2].max(q.x_px);
        r[3] = r[3].max(q.y_px);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_lengths_and_their_labels() {
        // 1e6 px/m, at most 130 px: 100 µm fits (100 px), 200 µm does not
        assert!((nice_length_m(1e6, 130.0) - 1e-4).abs() < 1e-18);
        assert!((nice_length_m(1e8, 130.0) - 1e-6).abs() < 1e-18);
        assert!((nice_length_m(1e8, 250.0) - 2e-6).abs() < 1e-18);
        assert!((nice_length_m(1e8, 600.0) - 5e-6).abs() < 1e-18);
        assert_eq!(format_length(2e-6), "2 µm");
        assert_eq!(format_length(1e-7), "100 nm");
        assert_eq!(format_length(0.05), "5 cm");
        assert_eq!(format_length(3.0), "3 m");
        assert_eq!(format_length(1.5e-6), "1.500 µm");
    }
}
