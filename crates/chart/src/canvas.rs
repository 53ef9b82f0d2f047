//! The drawing surface of a chart: text, lines, rectangles, dots and rings in pixels, the
//! frame with its grid, ticks and labels, and the legend box.

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

use crate::ticks::{Axis, sci_label, tick_label};
use crate::{ChartError, Legend, SIDE_RANGE_PX};
use picture::Image;
use picture::text::layout;

/// Grid lines.
pub(super) const GRID: [u8; 3] = [225, 225, 225];
/// Frame, ticks and text.
pub(super) const INK: [u8; 3] = [40, 40, 40];

fn paint(c: [u8; 3], alpha: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(c[0], c[1], c[2], alpha));
    p.anti_alias = true;
    p
}

/// The base font size of a chart of this size, px.
pub(super) fn font_px(width_px: u32, height_px: u32) -> f64 {
    (width_px.min(2 * height_px) as f64 / 70.0).clamp(9.0, 40.0)
}

/// The plot area of a chart of this size: (left, top, right, bottom), px.
pub fn plot_area(width_px: u32, height_px: u32) -> (f64, f64, f64, f64) {
    let font = font_px(width_px, height_px);
    (
        6.5 * font,
        3.2 * font,
        width_px as f64 - 1.5 * font,
        height_px as f64 - 4.2 * font,
    )
}

/// The plot area's edges in pixels: (left, top, right, bottom).
pub(super) fn frame(x: &Axis, y: &Axis) -> (f32, f32, f32, f32) {
    (
        x.px_lo as f32,
        y.px_hi as f32,
        x.px_hi as f32,
        y.px_lo as f32,
    )
}

/// How a legend entry shows its series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Swatch {
    /// A short line `width` px wide.
    Line(f32),
    /// A dot of this radius, px.
    Dot(f32),
    /// A ring of this radius, px.
    Ring(f32),
    /// A filled square.
    Block,
}

/// One legend entry: text, colour, swatch.
pub(super) type Entry = (String, [u8; 3], Swatch);

/// A drawing surface with the chart's fonts and sizes.
pub(super) struct Canvas {
    pub(super) pm: Pixmap,
    /// Base font size, px.
    pub(super) font: f32,
}

impl Canvas {
    pub(super) fn new(w: u32, h: u32) -> Result<Canvas, ChartError> {
        let (lo, hi) = SIDE_RANGE_PX;
        let size = ChartError::Size {
            width_px: w,
            height_px: h,
        };
        if w < lo || w > hi || h < lo || h > hi {
            return Err(size);
        }
        let mut pm = Pixmap::new(w, h).ok_or(size)?;
        pm.fill(Color::WHITE);
        let font = font_px(w, h) as f32;
        Ok(Canvas { pm, font })
    }

    pub(super) fn text_width(&self, s: &str, size: f32) -> Result<f32, ChartError> {
        Ok(layout(s, 0.0, 0.0, size)?.width_px)
    }

    /// Text with its baseline at `y`, anchored at `x` (`align`: 0 left, 0.5 centre, 1
    /// right), rotated by `rot_deg` about the anchor.
    pub(super) fn text(
        &mut self,
        s: &str,
        (x, y): (f32, f32),
        size: f32,
        align: f32,
        rot_deg: f32,
        c: [u8; 3],
    ) -> Result<(), ChartError> {
        let w = self.text_width(s, size)?;
        let t = layout(s, x - align * w, y, size)?;
        if let Some(p) = t.path {
            let tr = Transform::from_rotate_at(rot_deg, x, y);
            self.pm
                .fill_path(&p, &paint(c, 255), FillRule::Winding, tr, None);
        }
        Ok(())
    }

    /// A polyline through `pts`, `width` px wide (dashed if `dash`).
    pub(super) fn line(
        &mut self,
        pts: &[(f32, f32)],
        c: [u8; 3],
        width: f32,
        dash: bool,
        alpha: u8,
    ) {
        if pts.len() < 2 || width <= 0.0 {
            return;
        }
        let mut pb = PathBuilder::new();
        pb.move_to(pts[0].0, pts[0].1);
        for p in &pts[1..] {
            pb.line_to(p.0, p.1);
        }
        if let Some(path) = pb.finish() {
            let mut st = Stroke {
                width,
                ..Stroke::default()
            };
            if dash {
                st.dash = StrokeDash::new(vec![6.0, 4.0], 0.0);
            }
            self.pm
                .stroke_path(&path, &paint(c, alpha), &st, Transform::identity(), None);
        }
    }

    /// The closed polygon through `pts`, filled.
    pub(super) fn polygon(&mut self, pts: &[(f32, f32)], c: [u8; 3]) {
        if pts.len() < 3 {
            return;
        }
        let mut pb = PathBuilder::new();
        pb.move_to(pts[0].0, pts[0].1);
        for p in &pts[1..] {
            pb.line_to(p.0, p.1);
        }
        pb.close();
        if let Some(path) = pb.finish() {
            self.pm.fill_path(
                &path,
                &paint(c, 255),
                FillRule::EvenOdd,
                Transform::identity(),
                None,
            );
        }
    }

    /// A filled rectangle between two corners (at least half a pixel each way).
    pub(super) fn rect(&mut self, x0: f32, y0: f32, x1: f32, y1: f32, c: [u8; 3], alpha: u8) {
        let (l, r) = (x0.min(x1), x0.max(x1));
        let (t, b) = (y0.min(y1), y0.max(y1));
        if let Some(rc) = Rect::from_ltrb(l, t, r.max(l + 0.5), b.max(t + 0.5)) {
            self.pm
                .fill_rect(rc, &paint(c, alpha), Transform::identity(), None);
        }
    }

    /// A filled rectangle on whole pixels, without anti-aliasing (cells of a raster meet
    /// without seams).
    pub(super) fn cell(&mut self, x0: f32, y0: f32, x1: f32, y1: f32, c: [u8; 3]) {
        let (l, r) = (x0.min(x1).round(), x0.max(x1).round());
        let (t, b) = (y0.min(y1).round(), y0.max(y1).round());
        let mut p = paint(c, 255);
        p.anti_alias = false;
        if let Some(rc) = Rect::from_ltrb(l, t, r.max(l + 1.0), b.max(t + 1.0)) {
            self.pm.fill_rect(rc, &p, Transform::identity(), None);
        }
    }

    /// A filled dot of radius `r` px.
    pub(super) fn dot(&mut self, x: f32, y: f32, r: f32, c: [u8; 3]) {
        if let Some(p) = PathBuilder::from_circle(x, y, r) {
            self.pm.fill_path(
                &p,
                &paint(c, 255),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    /// A circle of radius `r` px, outlined `width` px wide.
    pub(super) fn ring(&mut self, x: f32, y: f32, r: f32, width: f32, c: [u8; 3]) {
        if let Some(p) = PathBuilder::from_circle(x, y, r) {
            let st = Stroke {
                width,
                ..Stroke::default()
            };
            self.pm
                .stroke_path(&p, &paint(c, 255), &st, Transform::identity(), None);
        }
    }

    /// The outline of the rectangle (l, t, r, b).
    pub(super) fn frame_box(&mut self, (l, t, r, b): (f32, f32, f32, f32), c: [u8; 3], width: f32) {
        self.line(
            &[(l, t), (r, t), (r, b), (l, b), (l, t)],
            c,
            width,
            false,
            255,
        );
    }

    /// Horizontal grid lines at the ticks of `y`, from `l` to `r`.
    pub(super) fn y_grid(&mut self, y: &Axis, (l, r): (f32, f32)) {
        for py in y.ticks().into_iter().filter_map(|v| y.px(v)) {
            let py = py as f32;
            self.line(&[(l, py), (r, py)], GRID, 1.0, false, 255);
        }
    }

    /// The tick labels of `y`, left of `l`.
    pub(super) fn y_labels(&mut self, y: &Axis, l: f32, sci: bool) -> Result<(), ChartError> {
        let f = self.font;
        for v in y.ticks() {
            if let Some(py) = y.px(v) {
                let s = if sci { sci_label(v) } else { tick_label(v) };
                let at = (l - 0.4 * f, py as f32 + 0.35 * f);
                self.text(&s, at, 0.9 * f, 1.0, 0.0, INK)?;
            }
        }
        Ok(())
    }

    /// The grid lines of the plot area of `x` and `y`.
    pub(super) fn grid(&mut self, x: &Axis, y: &Axis) {
        let (l, t, r, b) = frame(x, y);
        self.y_grid(y, (l, r));
        for px in x.ticks().into_iter().filter_map(|v| x.px(v)) {
            let px = px as f32;
            self.line(&[(px, t), (px, b)], GRID, 1.0, false, 255);
        }
    }

    /// Tick labels, frame, title and axis labels of the plot area of `x` and `y`.
    pub(super) fn axes(
        &mut self,
        (x, y): (&Axis, &Axis),
        sci: [bool; 2],
        title: &str,
        x_label: &str,
        y_label: &str,
    ) -> Result<(), ChartError> {
        let f = self.font;
        let (l, t, r, b) = frame(x, y);
        self.y_labels(y, l, sci[1])?;
        for v in x.ticks() {
            if let Some(px) = x.px(v) {
                let s = if sci[0] { sci_label(v) } else { tick_label(v) };
                self.text(&s, (px as f32, b + 1.3 * f), 0.9 * f, 0.5, 0.0, INK)?;
            }
        }
        self.frame_box((l, t, r, b), INK, 1.2);
        self.title_and_y_label(title, y_label, (t, b))?;
        self.text(x_label, ((l + r) / 2.0, b + 2.9 * f), f, 0.5, 0.0, INK)
    }

    /// The title on top and the y label along the left edge, centred on `t..b`.
    pub(super) fn title_and_y_label(
        &mut self,
        title: &str,
        y_label: &str,
        (t, b): (f32, f32),
    ) -> Result<(), ChartError> {
        let f = self.font;
        let w = self.pm.width() as f32;
        self.text(title, (w / 2.0, 1.9 * f), 1.2 * f, 0.5, 0.0, INK)?;
        self.text(y_label, (1.4 * f, (t + b) / 2.0), f, 0.5, -90.0, INK)
    }

    /// The legend box in corner `at` of the plot area `(l, t, r, b)`, its top edge at least
    /// `top_gap` px under `t` when it sits on top.
    pub(super) fn legend(
        &mut self,
        items: &[Entry],
        at: Legend,
        (l, t, r, b): (f32, f32, f32, f32),
        top_gap: f32,
    ) -> Result<(), ChartError> {
        if items.is_empty() || at == Legend::None {
            return Ok(());
        }
        let f = 0.9 * self.font;
        let mut wmax: f32 = 0.0;
        for (s, _, _) in items {
            wmax = wmax.max(self.text_width(s, f)?);
        }
        let (w, h) = (wmax + 2.7 * f, items.len() as f32 * 1.35 * f + 0.6 * f);
        let x0 = match at {
            Legend::UpperLeft | Legend::LowerLeft => l + 0.5 * f,
            _ => r - 0.5 * f - w,
        };
        let y0 = match at {
            Legend::LowerLeft | Legend::LowerRight => b - 0.5 * f - h,
            _ => t + top_gap + 0.5 * f,
        };
        self.rect(x0, y0, x0 + w, y0 + h, [255, 255, 255], 220);
        self.frame_box((x0, y0, x0 + w, y0 + h), [180, 180, 180], 1.0);
        for (i, (s, c, sw)) in items.iter().enumerate() {
            let yy = y0 + 0.3 * f + (i as f32 + 1.0) * 1.35 * f;
            let (sx0, sx1, sy) = (x0 + 0.5 * f, x0 + 1.7 * f, yy - 0.35 * f);
            match *sw {
                Swatch::Line(wd) => self.line(&[(sx0, sy), (sx1, sy)], *c, wd, false, 255),
                Swatch::Dot(rd) => self.dot((sx0 + sx1) / 2.0, sy, rd.min(0.5 * f), *c),
                Swatch::Ring(rd) => self.ring((sx0 + sx1) / 2.0, sy, rd.min(0.5 * f), 1.5, *c),
                Swatch::Block => self.rect(sx0, yy - 0.75 * f, sx1, yy + 0.05 * f, *c, 255),
            }
            self.text(s, (x0 + 2.2 * f, yy), f, 0.0, 0.0, INK)?;
        }
        Ok(())
    }

    pub(super) fn image(self) -> Image {
        Image::from_pixmap(self.pm)
    }
}
