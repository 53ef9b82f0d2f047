//! Drawing each kind of primitive onto a pixmap: shading, outlines, arrow heads, dashes, text
//! and the scale bar. The order of drawing is decided in `frame` and `order`.

use tiny_skia::{
    FillRule, GradientStop, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Point, RadialGradient,
    SpreadMode, Stroke, StrokeDash, Transform,
};

use crate::ToSkia;
use crate::error::RenderError;
use crate::frame::{Frame, ScaleBar, format_length};
use haptic_types::Rgba;
use haptic_types::vec3::{Vec3, add, box_corners, dot, normalize, scale};
use haptic_types::{Ball, OrientedBox, Primitive};
use picture::text;

impl Frame {
    /// Light direction (unit, world frame): from the viewer's upper left.
    pub(crate) fn light(&self) -> Vec3 {
        let c = &self.camera;
        normalize(add(
            add(scale(c.forward(), -0.55), scale(c.up(), 0.7)),
            scale(c.right(), -0.45),
        ))
    }

    pub(crate) fn draw_solid(&self, pm: &mut Pixmap, p: &Primitive) {
        match p {
            Primitive::Sphere(ball) => self.draw_sphere(pm, ball, false),
            Primitive::Cursor(ball) => self.draw_sphere(pm, ball, true),
            Primitive::Box(block) => self.draw_box(pm, block),
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                color,
            } => self.draw_ellipse(pm, *center_m, *semi_axes_m, *color),
            _ => {}
        }
    }

    /// A shaded ball; with `cursor`, see-through with an opaque outline and cross-hair.
    pub(crate) fn draw_sphere(&self, pm: &mut Pixmap, ball: &Ball, cursor: bool) {
        let Ball {
            center_m,
            radius_m,
            color,
        } = *ball;
        let q = self.camera.project(center_m);
        let r = (radius_m * self.camera.pixels_per_m()) as f32;
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

    /// The image points (px) of the 8 corners of a box with centre `c` (m), unit axes `ax` and
    /// half extents `half` (m), in [`box_corners`]' order.
    fn corner_pixels(&self, c: Vec3, ax: [Vec3; 3], half: Vec3) -> [(f32, f32); 8] {
        box_corners(c, ax, half).map(|p| {
            let q = self.camera.project(p);
            (q.x_px as f32, q.y_px as f32)
        })
    }

    /// A shaded box: its faces toward the camera, lit, with their edges.
    pub(crate) fn draw_box(&self, pm: &mut Pixmap, block: &OrientedBox) {
        let color = block.color;
        let ax = block.axes();
        let pts = self.corner_pixels(block.center_m, ax, block.half_extents_m);
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

    pub(crate) fn ellipse_path(&self, c: Vec3, semi: [f64; 2]) -> Option<tiny_skia::Path> {
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

    pub(crate) fn draw_ellipse(&self, pm: &mut Pixmap, c: Vec3, semi: [f64; 2], color: Rgba) {
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

    pub(crate) fn draw_polyline(&self, pm: &mut Pixmap, pts: &[Vec3], closed: bool, color: Rgba) {
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

    pub(crate) fn draw_arrow(&self, pm: &mut Pixmap, from: Vec3, to: Vec3, color: Rgba) {
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

    /// A blueprint slot: the box's twelve edges, dashed.
    pub(crate) fn draw_slot(&self, pm: &mut Pixmap, slot: &OrientedBox) {
        let ax = slot.axes();
        let pts = self.corner_pixels(slot.center_m, ax, slot.half_extents_m);
        let mut pb = PathBuilder::new();
        for a in 0..8usize {
            for bit in [1usize, 2, 4] {
                if a & bit == 0 {
                    pb.move_to(pts[a].0, pts[a].1);
                    pb.line_to(pts[a | bit].0, pts[a | bit].1);
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
        let paint = solid(slot.color);
        pm.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }

    pub(crate) fn draw_text(
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

    pub(crate) fn draw_scale_bar(&self, pm: &mut Pixmap, sb: ScaleBar) -> Result<(), RenderError> {
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

pub(crate) fn solid(c: Rgba) -> Paint<'static> {
    let mut p = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    p.set_color(c.skia());
    p
}
