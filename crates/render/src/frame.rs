//! A frame: primitives added in world coordinates, drawn back to front with shading into an
//! [`Image`].

use tiny_skia::{
    FillRule, GradientStop, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Point, RadialGradient,
    SpreadMode, Stroke, StrokeDash, Transform,
};

use crate::camera::Camera;
use crate::error::{RenderError, finite, finite3};
use crate::image::Image;
use crate::math::{Vec3, add, axes, dot, normalize, scale, sub};
use crate::order::{Item, Shape, back_to_front};
use crate::primitive::{Primitive, Rgba};
use crate::text;

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
                return Err(RenderError::OutOfRange {
                    field: field.to_string(),
                    value: f64::from(v),
                    allowed: "(0, 200] px",
                });
            }
            Ok(())
        };
        pos("style.line_width_px", self.line_width_px, 200.0)?;
        pos("style.font_size_px", self.font_size_px, 200.0)?;
        pos("style.arrow_head_px", self.arrow_head_px, 200.0)?;
        finite(|| "style.ambient".into(), self.ambient)?;
        if !(0.0..=1.0).contains(&self.ambient) {
            return Err(RenderError::OutOfRange {
                field: "style.ambient".into(),
                value: self.ambient,
                allowed: "[0, 1]",
            });
        }
        Ok(())
    }
}

/// A scale bar in the bottom-left corner.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ScaleBar {
    length_m: f64,
    color: Rgba,
}

/// One picture being composed: a camera, a style and the primitives added so far.
///
/// Solids (spheres, cursors, boxes, ellipses) are drawn back to front in an exact order for
/// disjoint convex bodies (see the `order` module); polylines, arrows and slots are drawn over
/// them in the order added; labels, the title and the scale bar go on top.
#[derive(Clone, Debug)]
pub struct Frame {
    camera: Camera,
    style: Style,
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

/// Writes a length in metres with an SI prefix, e.g. `2 µm`, `100 nm`, `5 cm`.
pub fn format_length(length_m: f64) -> String {
    let units = [
        (1.0, "m"),
        (1e-2, "cm"),
        (1e-3, "mm"),
        (1e-6, "µm"),
        (1e-9, "nm"),
        (1e-12, "pm"),
    ];
    let a = length_m.abs();
    let (k, u) = units
        .iter()
        .find(|(k, _)| a >= *k * 0.999_999)
        .copied()
        .unwrap_or((1e-12, "pm"));
    let v = length_m / k;
    if (v - v.round()).abs() < 1e-6 * v.abs().max(1.0) {
        format!("{} {u}", v.round())
    } else {
        format!("{v:.3} {u}")
    }
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
            return Err(RenderError::OutOfRange {
                field: "scaled_loop.factor".into(),
                value: factor,
                allowed: "(0, inf)",
            });
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
                    return Err(RenderError::OutOfRange {
                        field: "scale_bar.length_m".into(),
                        value: l,
                        allowed: "(0, inf) m",
                    });
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
        let pm = &mut img.pixmap;
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
                Primitive::Slot {
                    center_m,
                    half_extents_m,
                    rotation,
                    color,
                } => self.draw_slot(pm, *center_m, *half_extents_m, *rotation, *color),
                _ => {}
            }
        }
        for p in &self.items {
            if let Primitive::Label {
                position_m,
                text,
                color,
            } = p
            {
                let q = self.camera.project(*position_m);
                self.draw_text(
                    pm,
                    text,
                    q.x_px as f32 + 4.0,
                    q.y_px as f32 - 4.0,
                    *color,
                    0.0,
                )?;
            }
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

    fn solid_item(&self, p: &Primitive) -> Option<Item> {
        let cam = &self.camera;
        let s = cam.pixels_per_m();
        match p {
            Primitive::Sphere {
                center_m, radius_m, ..
            }
            | Primitive::Cursor {
                center_m, radius_m, ..
            } => {
                let q = cam.project(*center_m);
                let r = radius_m * s;
                Some(Item {
                    shape: Shape::Sphere {
                        c: *center_m,
                        r: *radius_m,
                    },
                    depth: q.depth_m,
                    flat: false,
                    rect: [q.x_px - r, q.y_px - r, q.x_px + r, q.y_px + r],
                })
            }
            Primitive::Box {
                center_m,
                half_extents_m,
                rotation,
                ..
            } => {
                let ax = axes(normq(*rotation));
                let rect = rect_of(
                    box_corners(*center_m, ax, *half_extents_m)
                        .iter()
                        .map(|c| cam.project(*c)),
                );
                Some(Item {
                    shape: Shape::Obb {
                        c: *center_m,
                        axes: ax,
                        half: *half_extents_m,
                    },
                    depth: cam.project(*center_m).depth_m,
                    flat: false,
                    rect,
                })
            }
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                ..
            } => {
                let ax = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                let half = [semi_axes_m[0], semi_axes_m[1], 0.0];
                let rect = rect_of(
                    box_corners(*center_m, ax, half)
                        .iter()
                        .map(|c| cam.project(*c)),
                );
                Some(Item {
                    shape: Shape::Obb {
                        c: *center_m,
                        axes: ax,
                        half,
                    },
                    depth: cam.project(*center_m).depth_m,
                    flat: true,
                    rect,
                })
            }
            _ => None,
        }
    }

    /// Light direction (unit, world frame): from the viewer's upper left.
    fn light(&self) -> Vec3 {
        let c = &self.camera;
        normalize(add(
            add(scale(c.forward(), -0.55), scale(c.up(), 0.7)),
            scale(c.right(), -0.45),
        ))
    }

    fn draw_solid(&self, pm: &mut Pixmap, p: &Primitive) {
        match p {
            Primitive::Sphere {
                center_m,
                radius_m,
                color,
            } => self.draw_sphere(pm, *center_m, *radius_m, *color, false),
            Primitive::Cursor {
                center_m,
                radius_m,
                color,
            } => self.draw_sphere(pm, *center_m, *radius_m, *color, true),
            Primitive::Box {
                center_m,
                half_extents_m,
                rotation,
                color,
            } => self.draw_box(pm, *center_m, *half_extents_m, *rotation, *color),
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                color,
            } => self.draw_ellipse(pm, *center_m, *semi_axes_m, *color),
            _ => {}
        }
    }

    fn draw_sphere(&self, pm: &mut Pixmap, c: Vec3, r_m: f64, color: Rgba, cursor: bool) {
        let q = self.camera.project(c);
        let r = (r_m * self.camera.pixels_per_m()) as f32;
        let (cx, cy) = (q.x_px as f32, q.y_px as f32);
        let Some(circle) = PathBuilder::from_circle(cx, cy, r.max(0.5)) else {
            return;
        };
        // highlight toward the light, projected on the image
        let l = self.light();
        let (lx, ly) = (
            dot(l, self.camera.right()) as f32,
            -dot(l, self.camera.up()) as f32,
        );
        let hx = cx + 0.45 * r * lx;
        let hy = cy + 0.45 * r * ly;
        let amb = self.style.ambient;
        let stops = vec![
            GradientStop::new(0.0, color.toward_white(0.55).skia()),
            GradientStop::new(0.35, color.skia()),
            GradientStop::new(1.0, color.times(amb + 0.1).skia()),
        ];
        let mut paint = Paint {
            anti_alias: true,
            ..Paint::default()
        };
        paint.shader = RadialGradient::new(
            Point::from_xy(hx, hy),
            0.0,
            Point::from_xy(cx, cy),
            r,
            stops,
            SpreadMode::Pad,
            Transform::identity(),
        )
        .unwrap_or(tiny_skia::Shader::SolidColor(color.skia()));
        pm.fill_path(
            &circle,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        if cursor {
            let edge = color.with_alpha(1.0).times(0.6);
            let stroke = Stroke {
                width: self.style.line_width_px,
                ..Stroke::default()
            };
            let paint = solid(edge);
            pm.stroke_path(&circle, &paint, &stroke, Transform::identity(), None);
            let arm = (0.35 * r).max(3.0);
            let mut pb = PathBuilder::new();
            pb.move_to(cx - arm, cy);
            pb.line_to(cx + arm, cy);
            pb.move_to(cx, cy - arm);
            pb.line_to(cx, cy + arm);
            if let Some(cross) = pb.finish() {
                let thin = Stroke {
                    width: (0.6 * self.style.line_width_px).max(1.0),
                    ..Stroke::default()
                };
                pm.stroke_path(&cross, &paint, &thin, Transform::identity(), None);
            }
        }
    }

    fn draw_box(&self, pm: &mut Pixmap, c: Vec3, half: Vec3, rot: [f64; 4], color: Rgba) {
        let ax = axes(normq(rot));
        let corners = box_corners(c, ax, half);
        let pts: Vec<(f32, f32)> = corners
            .iter()
            .map(|p| {
                let q = self.camera.project(*p);
                (q.x_px as f32, q.y_px as f32)
            })
            .collect();
        let fwd = self.camera.forward();
        let light = self.light();
        let amb = self.style.ambient;
        // faces as corner indices (bit 0: x, bit 1: y, bit 2: z), with outward normals
        let faces: [([usize; 4], usize, f64); 6] = [
            ([1, 3, 7, 5], 0, 1.0),
            ([0, 4, 6, 2], 0, -1.0),
            ([2, 6, 7, 3], 1, 1.0),
            ([0, 1, 5, 4], 1, -1.0),
            ([4, 5, 7, 6], 2, 1.0),
            ([0, 2, 3, 1], 2, -1.0),
        ];
        let edge_stroke = Stroke {
            width: (0.5 * self.style.line_width_px).max(0.75),
            line_join: LineJoin::Round,
            ..Stroke::default()
        };
        for (idx, axis, sign) in faces {
            let n = scale(ax[axis], sign);
            let facing = -dot(n, fwd);
            if facing <= 1e-9 {
                continue;
            }
            let mut pb = PathBuilder::new();
            pb.move_to(pts[idx[0]].0, pts[idx[0]].1);
            for &k in &idx[1..] {
                pb.line_to(pts[k].0, pts[k].1);
            }
            pb.close();
            let Some(path) = pb.finish() else { continue };
            let lit = amb + (1.0 - amb) * dot(n, light).max(0.0);
            let face = color.times(lit);
            // the face interior without anti-aliasing (4× cheaper); its anti-aliased hairline
            // edge below covers the staircase
            let mut fill = solid(face);
            fill.anti_alias = false;
            pm.fill_path(&path, &fill, FillRule::Winding, Transform::identity(), None);
            pm.stroke_path(
                &path,
                &solid(face.times(0.7)),
                &edge_stroke,
                Transform::identity(),
                None,
            );
        }
    }

    fn ellipse_path(&self, c: Vec3, semi: [f64; 2]) -> Option<tiny_skia::Path> {
        const N: usize = 96;
        let mut pb = PathBuilder::new();
        for k in 0..N {
            let t = std::f64::consts::TAU * k as f64 / N as f64;
            let p = [c[0] + semi[0] * t.cos(), c[1] + semi[1] * t.sin(), c[2]];
            let q = self.camera.project(p);
            if k == 0 {
                pb.move_to(q.x_px as f32, q.y_px as f32);
            } else {
                pb.line_to(q.x_px as f32, q.y_px as f32);
            }
        }
        pb.close();
        pb.finish()
    }

    fn draw_ellipse(&self, pm: &mut Pixmap, c: Vec3, semi: [f64; 2], color: Rgba) {
        let Some(path) = self.ellipse_path(c, semi) else {
            return;
        };
        let [r, g, b, a] = color.0;
        pm.fill_path(
            &path,
            &solid(Rgba([r, g, b, a / 3.0])),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
        let stroke = Stroke {
            width: self.style.line_width_px,
            ..Stroke::default()
        };
        pm.stroke_path(&path, &solid(color), &stroke, Transform::identity(), None);
    }

    fn draw_polyline(&self, pm: &mut Pixmap, pts: &[Vec3], closed: bool, color: Rgba) {
        let mut pb = PathBuilder::new();
        for (k, p) in pts.iter().enumerate() {
            let q = self.camera.project(*p);
            if k == 0 {
                pb.move_to(q.x_px as f32, q.y_px as f32);
            } else {
                pb.line_to(q.x_px as f32, q.y_px as f32);
            }
        }
        if closed {
            pb.close();
        }
        let Some(path) = pb.finish() else { return };
        let stroke = Stroke {
            width: self.style.line_width_px,
            line_join: LineJoin::Round,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        pm.stroke_path(&path, &solid(color), &stroke, Transform::identity(), None);
    }

    fn draw_arrow(&self, pm: &mut Pixmap, from: Vec3, to: Vec3, color: Rgba) {
        let a = self.camera.project(from);
        let b = self.camera.project(to);
        let (dx, dy) = ((b.x_px - a.x_px) as f32, (b.y_px - a.y_px) as f32);
        let len = (dx * dx + dy * dy).sqrt();
        if len < 0.5 {
            return;
        }
        let (ux, uy) = (dx / len, dy / len);
        let head = self.style.arrow_head_px.min(0.4 * len);
        let half_w = 0.45 * head;
        let (bx, by) = (b.x_px as f32, b.y_px as f32);
        let (base_x, base_y) = (bx - ux * head, by - uy * head);
        let paint = solid(color);
        let mut pb = PathBuilder::new();
        pb.move_to(a.x_px as f32, a.y_px as f32);
        pb.line_to(base_x + 0.5 * ux, base_y + 0.5 * uy);
        if let Some(shaft) = pb.finish() {
            let stroke = Stroke {
                width: 1.5 * self.style.line_width_px,
                line_cap: LineCap::Butt,
                ..Stroke::default()
            };
            pm.stroke_path(&shaft, &paint, &stroke, Transform::identity(), None);
        }
        let mut pb = PathBuilder::new();
        pb.move_to(bx, by);
        pb.line_to(base_x - uy * half_w, base_y + ux * half_w);
        pb.line_to(base_x + uy * half_w, base_y - ux * half_w);
        pb.close();
        if let Some(tri) = pb.finish() {
            pm.fill_path(&tri, &paint, FillRule::Winding, Transform::identity(), None);
        }
    }

    fn draw_slot(&self, pm: &mut Pixmap, c: Vec3, half: Vec3, rot: [f64; 4], color: Rgba) {
        let corners = box_corners(c, axes(normq(rot)), half);
        let mut pb = PathBuilder::new();
        for a in 0..8usize {
            for bit in [1usize, 2, 4] {
                if a & bit == 0 {
                    let p = self.camera.project(corners[a]);
                    let q = self.camera.project(corners[a | bit]);
                    pb.move_to(p.x_px as f32, p.y_px as f32);
                    pb.line_to(q.x_px as f32, q.y_px as f32);
                }
            }
        }
        let Some(path) = pb.finish() else { return };
        // a 1 px (hairline) dashed stroke: dashes of a wider stroke would each be filled
        let w = self.style.line_width_px;
        let stroke = Stroke {
            width: 1.0,
            dash: StrokeDash::new(vec![3.0 * w, 2.0 * w], 0.0),
            ..Stroke::default()
        };
        pm.stroke_path(&path, &solid(color), &stroke, Transform::identity(), None);
    }

    fn draw_text(
        &self,
        pm: &mut Pixmap,
        s: &str,
        x: f32,
        y: f32,
        color: Rgba,
        align: f32,
    ) -> Result<(), RenderError> {
        let mut t = text::layout(s, x, y, self.style.font_size_px)?;
        if align != 0.0 {
            t = text::layout(s, x - align * t.width_px, y, self.style.font_size_px)?;
        }
        if let Some(path) = t.path {
            let halo = Stroke {
                width: 3.0,
                line_join: LineJoin::Round,
                ..Stroke::default()
            };
            let bg = self.style.background.with_alpha(0.85);
            pm.stroke_path(&path, &solid(bg), &halo, Transform::identity(), None);
            pm.fill_path(
                &path,
                &solid(color),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
        Ok(())
    }

    fn draw_scale_bar(&self, pm: &mut Pixmap, sb: ScaleBar) -> Result<(), RenderError> {
        let len = (sb.length_m * self.camera.pixels_per_m()) as f32;
        let x0 = 16.0f32;
        let y0 = self.camera.height_px() as f32 - 16.0;
        let tick = 5.0f32;
        let mut pb = PathBuilder::new();
        pb.move_to(x0, y0);
        pb.line_to(x0 + len, y0);
        pb.move_to(x0, y0 - tick);
        pb.line_to(x0, y0 + tick);
        pb.move_to(x0 + len, y0 - tick);
        pb.line_to(x0 + len, y0 + tick);
        if let Some(path) = pb.finish() {
            let stroke = Stroke {
                width: self.style.line_width_px,
                line_cap: LineCap::Butt,
                ..Stroke::default()
            };
            pm.stroke_path(
                &path,
                &solid(sb.color),
                &stroke,
                Transform::identity(),
                None,
            );
        }
        let label = format_length(sb.length_m);
        self.draw_text(pm, &label, x0 + 0.5 * len, y0 - tick - 4.0, sb.color, 0.5)
    }
}

fn solid(c: Rgba) -> Paint<'static> {
    let mut p = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    p.set_color(c.skia());
    p
}

fn normq(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

fn box_corners(c: Vec3, ax: [Vec3; 3], h: Vec3) -> [Vec3; 8] {
    let mut out = [[0.0; 3]; 8];
    for (k, o) in out.iter_mut().enumerate() {
        let sx = if k & 1 == 0 { -h[0] } else { h[0] };
        let sy = if k & 2 == 0 { -h[1] } else { h[1] };
        let sz = if k & 4 == 0 { -h[2] } else { h[2] };
        *o = add(
            add(add(c, scale(ax[0], sx)), scale(ax[1], sy)),
            scale(ax[2], sz),
        );
    }
    out
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
