//! Small 2D charts for reports (line, dot and step series with event markers and bands; bar
//! charts on linear or log scales), drawn with tiny-skia and the embedded font, so they need
//! nothing from the system (no fontconfig) and give the same bytes everywhere.
//!
//! ```no_run
//! use render::chart::{Chart, Series, Style};
//! let mut c = Chart::new("force over time", "time (s)", "force (N)");
//! c.series.push(Series {
//!     label: "Fz".into(),
//!     points: (0..100).map(|i| [i as f64 * 0.01, (i as f64 * 0.1).sin()]).collect(),
//!     color: [31, 119, 180],
//!     style: Style::Line,
//! });
//! c.write_png("force.png".as_ref(), 1000, 500).unwrap();
//! ```
//!
//! Not for: interactive plots, dense scientific figures with many panels (use matplotlib on
//! the recording's arrays for those).

use std::path::Path;

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

use crate::error::RenderError;
use crate::image::Image;
use crate::text::layout;

/// Smallest and largest chart side, px.
pub const SIDE_RANGE_PX: (u32, u32) = (200, 4000);

/// An axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic (positive values only).
    Log10,
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    /// A polyline through the points (a gap at non-finite points).
    Line,
    /// A dot at each point.
    Dots,
    /// A staircase: each value held until the next point.
    Steps,
}

/// A data series.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points in data units; non-finite points are skipped.
    pub points: Vec<[f64; 2]>,
    /// RGB colour.
    pub color: [u8; 3],
    /// How it is drawn.
    pub style: Style,
}

/// A vertical dashed line at `x` with its label near the top (an event).
#[derive(Clone, Debug, PartialEq)]
pub struct Marker {
    /// Position, data units.
    pub x: f64,
    /// Label.
    pub label: String,
    /// RGB colour.
    pub color: [u8; 3],
}

/// A translucent horizontal band between two y values (a limit, a region).
#[derive(Clone, Debug, PartialEq)]
pub struct Band {
    /// Lower edge, data units.
    pub y_min: f64,
    /// Upper edge, data units.
    pub y_max: f64,
    /// Legend text.
    pub label: String,
    /// RGB colour.
    pub color: [u8; 3],
}

/// A chart of series against two axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    /// Title, on top.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// x scale.
    pub x_scale: Scale,
    /// y scale.
    pub y_scale: Scale,
    /// x range; `None`: from the data and the markers.
    pub x_range: Option<[f64; 2]>,
    /// y range; `None`: from the data and the bands (a linear axis includes 0 when the data
    /// touch or straddle it).
    pub y_range: Option<[f64; 2]>,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Vertical event markers.
    pub markers: Vec<Marker>,
    /// Horizontal bands.
    pub bands: Vec<Band>,
}

/// One bar.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    /// Group: bars of a group stand side by side, groups apart.
    pub group: String,
    /// Label under the bar.
    pub label: String,
    /// Height, data units (> 0 on a log scale).
    pub value: f64,
    /// RGB colour.
    pub color: [u8; 3],
}

/// A bar chart; each bar's value is printed above it.
#[derive(Clone, Debug, PartialEq)]
pub struct BarChart {
    /// Title.
    pub title: String,
    /// y-axis label.
    pub y_label: String,
    /// y scale.
    pub y_scale: Scale,
    /// The bars, in order (groups in order of first appearance).
    pub bars: Vec<Bar>,
}

/// Why a chart cannot be drawn.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ChartError {
    /// Nothing finite to draw.
    #[error("{field}: no finite value to draw")]
    NoData {
        /// `series` or `bars`.
        field: &'static str,
    },
    /// A log axis with no positive value.
    #[error("{axis} axis is logarithmic but no value on it is positive")]
    LogAxis {
        /// `x` or `y`.
        axis: &'static str,
    },
    /// A range that is not two finite increasing numbers (positive on a log axis).
    #[error(
        "{field} = [{lo}, {hi}] is not a usable range: allowed two finite numbers lo < hi (both > 0 on a log axis)"
    )]
    Range {
        /// `x_range` or `y_range`.
        field: &'static str,
        /// Lower end given.
        lo: f64,
        /// Upper end given.
        hi: f64,
    },
    /// A chart size outside [`SIDE_RANGE_PX`].
    #[error("chart size {width_px}x{height_px} px is out of range: allowed 200..=4000 px per side")]
    Size {
        /// Width asked for.
        width_px: u32,
        /// Height asked for.
        height_px: u32,
    },
    /// Drawing or writing failed.
    #[error(transparent)]
    Render(#[from] RenderError),
}

fn color(c: [u8; 3], alpha: u8) -> Color {
    Color::from_rgba8(c[0], c[1], c[2], alpha)
}

fn paint(c: [u8; 3], alpha: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(color(c, alpha));
    p.anti_alias = true;
    p
}

/// "Nice" tick positions (1-2-5 steps) covering `[lo, hi]`, about `n` of them.
pub fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo || n == 0 {
        return Vec::new();
    }
    let raw = (hi - lo) / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| (hi - lo) / s <= n as f64 + 0.5)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            if v.abs() < step * 1e-9 { 0.0 } else { v }
        })
        .collect()
}

/// Decades `10^k` within `[lo, hi]` (both > 0).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return Vec::new();
    }
    let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
    let every = (((b - a) as f64 / 8.0).ceil() as i32).max(1);
    (a..=b)
        .filter(|k| (k - a) % every == 0)
        .map(|k| 10f64.powi(k))
        .collect()
}

/// A tick label: compact decimal, or `e` notation for very small or large values.
pub fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".to_string();
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let t = format!("{v:.1e}");
        return t.replace(".0e", "e");
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A bar's value: three significant digits (`57.3`, `4.91`, `3e-9`, `9.81e-25`).
pub fn value_label(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let t = format!("{v:.2e}");
        let (m, e) = t.split_once('e').unwrap_or((&t, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let digits = (2 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Maps data to pixels along one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    /// Data range (for a log axis, the range of the values themselves).
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// Scale.
    pub scale: Scale,
    /// Pixel of `lo`.
    pub px_lo: f64,
    /// Pixel of `hi`.
    pub px_hi: f64,
}

impl Axis {
    fn t(&self, v: f64) -> f64 {
        match self.scale {
            Scale::Linear => v,
            Scale::Log10 => v.log10(),
        }
    }

    /// Pixel of data value `v` (`None` when it cannot be shown: non-finite, or ≤ 0 on a log
    /// axis).
    pub fn px(&self, v: f64) -> Option<f64> {
        if !v.is_finite() || (self.scale == Scale::Log10 && v <= 0.0) {
            return None;
        }
        let (a, b) = (self.t(self.lo), self.t(self.hi));
        Some(self.px_lo + (self.t(v) - a) / (b - a) * (self.px_hi - self.px_lo))
    }

    fn ticks(&self) -> Vec<f64> {
        match self.scale {
            Scale::Linear => nice_ticks(self.lo, self.hi, 6),
            Scale::Log10 => log_ticks(self.lo, self.hi),
        }
    }
}

/// The range of `values` on a `scale` axis (with a margin), or an error naming `axis`.
fn auto_range(
    values: impl Iterator<Item = f64>,
    scale: Scale,
    include_zero: bool,
    axis: &'static str,
) -> Result<[f64; 2], ChartError> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut any = false;
    for v in values.filter(|v| v.is_finite()) {
        any = true;
        if scale == Scale::Log10 && v <= 0.0 {
            continue;
        }
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !any {
        return Err(ChartError::NoData { field: "series" });
    }
    if lo > hi {
        return Err(ChartError::LogAxis { axis });
    }
    Ok(match scale {
        Scale::Log10 => {
            let (a, b) = (lo.log10().floor(), hi.log10().ceil());
            let b = if b <= a { a + 1.0 } else { b };
            [10f64.powf(a), 10f64.powf(b)]
        }
        Scale::Linear => {
            if include_zero && lo <= 0.0 && hi >= 0.0 {
                // keep 0 inside
            } else if include_zero && lo > 0.0 && lo < 0.25 * hi {
                lo = 0.0;
            } else if include_zero && hi < 0.0 && hi > 0.25 * lo {
                hi = 0.0;
            }
            if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
                let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
                [lo - d, hi + d]
            } else {
                let m = 0.04 * (hi - lo);
                [lo - m, hi + m]
            }
        }
    })
}

fn check_range(r: [f64; 2], scale: Scale, field: &'static str) -> Result<(), ChartError> {
    let ok = r[0].is_finite() && r[1].is_finite() && r[0] < r[1];
    if !ok || (scale == Scale::Log10 && r[0] <= 0.0) {
        return Err(ChartError::Range {
            field,
            lo: r[0],
            hi: r[1],
        });
    }
    Ok(())
}

fn check_size(w: u32, h: u32) -> Result<(), ChartError> {
    let (lo, hi) = SIDE_RANGE_PX;
    if w < lo || w > hi || h < lo || h > hi {
        return Err(ChartError::Size {
            width_px: w,
            height_px: h,
        });
    }
    Ok(())
}

/// A drawing surface with the chart's fonts and sizes.
struct Canvas {
    pm: Pixmap,
    /// Base font size, px.
    font: f32,
}

impl Canvas {
    fn new(w: u32, h: u32) -> Result<Canvas, ChartError> {
        check_size(w, h)?;
        let mut pm = Pixmap::new(w, h).ok_or(ChartError::Size {
            width_px: w,
            height_px: h,
        })?;
        pm.fill(Color::WHITE);
        let font = (w.min(2 * h) as f32 / 70.0).clamp(9.0, 40.0);
        Ok(Canvas { pm, font })
    }

    fn text_width(&self, s: &str, size: f32) -> Result<f32, ChartError> {
        Ok(layout(s, 0.0, 0.0, size)?.width_px)
    }

    /// Text with its baseline at `y`, anchored at `x` (`(x, y)`) (`align`: 0 left, 0.5 centre, 1 right),
    /// rotated by `rot_deg` about the anchor.
    fn text(
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

    fn line(&mut self, pts: &[(f32, f32)], c: [u8; 3], width: f32, dash: bool, alpha: u8) {
        if pts.len() < 2 {
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

    fn rect(&mut self, x0: f32, y0: f32, x1: f32, y1: f32, c: [u8; 3], alpha: u8) {
        let (l, r) = (x0.min(x1), x0.max(x1));
        let (t, b) = (y0.min(y1), y0.max(y1));
        if let Some(rc) = Rect::from_ltrb(l, t, r.max(l + 0.5), b.max(t + 0.5)) {
            self.pm
                .fill_rect(rc, &paint(c, alpha), Transform::identity(), None);
        }
    }

    fn dot(&mut self, x: f32, y: f32, r: f32, c: [u8; 3]) {
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

    fn image(self) -> Image {
        Image { pixmap: self.pm }
    }
}

/// The plot area of a chart of this size: (left, top, right, bottom), px.
pub fn plot_area(width_px: u32, height_px: u32) -> (f64, f64, f64, f64) {
    let font = (width_px.min(2 * height_px) as f64 / 70.0).clamp(9.0, 40.0);
    (
        6.5 * font,
        3.2 * font,
        width_px as f64 - 1.5 * font,
        height_px as f64 - 4.2 * font,
    )
}

/// The plot area's edges in pixels: (left, top, right, bottom).
fn frame(x: &Axis, y: &Axis) -> (f32, f32, f32, f32) {
    (
        x.px_lo as f32,
        y.px_hi as f32,
        x.px_hi as f32,
        y.px_lo as f32,
    )
}

const GRID: [u8; 3] = [225, 225, 225];
const INK: [u8; 3] = [40, 40, 40];

/// Draws the frame, grid, ticks and labels of a plot area; returns nothing.
fn axes(
    cv: &mut Canvas,
    x: &Axis,
    y: &Axis,
    title: &str,
    x_label: &str,
    y_label: &str,
) -> Result<(), ChartError> {
    let f = cv.font;
    let (l, t, r, b) = frame(x, y);
    for v in y.ticks() {
        if let Some(py) = y.px(v) {
            let py = py as f32;
            cv.line(&[(l, py), (r, py)], GRID, 1.0, false, 255);
            cv.text(
                &tick_label(v),
                (l - 0.4 * f, py + 0.35 * f),
                0.9 * f,
                1.0,
                0.0,
                INK,
            )?;
        }
    }
    for v in x.ticks() {
        if let Some(px) = x.px(v) {
            let px = px as f32;
            cv.line(&[(px, t), (px, b)], GRID, 1.0, false, 255);
            cv.text(&tick_label(v), (px, b + 1.3 * f), 0.9 * f, 0.5, 0.0, INK)?;
        }
    }
    cv.line(
        &[(l, t), (r, t), (r, b), (l, b), (l, t)],
        INK,
        1.2,
        false,
        255,
    );
    let w = cv.pm.width() as f32;
    cv.text(title, (w / 2.0, 1.9 * f), 1.2 * f, 0.5, 0.0, INK)?;
    cv.text(x_label, ((l + r) / 2.0, b + 2.9 * f), f, 0.5, 0.0, INK)?;
    cv.text(y_label, (1.4 * f, (t + b) / 2.0), f, 0.5, -90.0, INK)?;
    Ok(())
}

fn legend(cv: &mut Canvas, items: &[(String, [u8; 3])], r: f32, t: f32) -> Result<(), ChartError> {
    if items.is_empty() {
        return Ok(());
    }
    let f = 0.9 * cv.font;
    let mut wmax: f32 = 0.0;
    for (s, _) in items {
        wmax = wmax.max(cv.text_width(s, f)?);
    }
    let (x0, y0) = (r - wmax - 3.2 * f, t + 0.5 * f);
    let h = items.len() as f32 * 1.35 * f + 0.6 * f;
    cv.rect(x0, y0, r - 0.5 * f, y0 + h, [255, 255, 255], 220);
    cv.line(
        &[
            (x0, y0),
            (r - 0.5 * f, y0),
            (r - 0.5 * f, y0 + h),
            (x0, y0 + h),
            (x0, y0),
        ],
        [180, 180, 180],
        1.0,
        false,
        255,
    );
    for (i, (s, c)) in items.iter().enumerate() {
        let yy = y0 + 0.3 * f + (i as f32 + 1.0) * 1.35 * f;
        cv.rect(
            x0 + 0.5 * f,
            yy - 0.75 * f,
            x0 + 1.7 * f,
            yy + 0.05 * f,
            *c,
            255,
        );
        cv.text(s, (x0 + 2.2 * f, yy), f, 0.0, 0.0, INK)?;
    }
    Ok(())
}

/// Anything that draws itself into a PNG file (a [`Chart`] or a [`BarChart`]).
pub trait Figure {
    /// Draws into a PNG file of `width_px` × `height_px`.
    fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError>;
}

impl Figure for Chart {
    fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError> {
        Chart::write_png(self, path, width_px, height_px)
    }
}

impl Figure for BarChart {
    fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError> {
        BarChart::write_png(self, path, width_px, height_px)
    }
}

impl Chart {
    /// An empty chart with linear axes.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Chart {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            series: Vec::new(),
            markers: Vec::new(),
            bands: Vec::new(),
        }
    }

    /// The chart's axes at this size: the data ranges and their pixels.
    pub fn axes(&self, width_px: u32, height_px: u32) -> Result<(Axis, Axis), ChartError> {
        let pts = || self.series.iter().flat_map(|s| s.points.iter());
        if !pts().any(|p| p[0].is_finite() && p[1].is_finite()) {
            return Err(ChartError::NoData { field: "series" });
        }
        let xr = match self.x_range {
            Some(r) => r,
            None => auto_range(
                pts()
                    .filter(|p| p[1].is_finite())
                    .map(|p| p[0])
                    .chain(self.markers.iter().map(|m| m.x)),
                self.x_scale,
                false,
                "x",
            )?,
        };
        let yr = match self.y_range {
            Some(r) => r,
            None => auto_range(
                pts()
                    .filter(|p| p[0].is_finite())
                    .map(|p| p[1])
                    .chain(self.bands.iter().flat_map(|b| [b.y_min, b.y_max])),
                self.y_scale,
                true,
                "y",
            )?,
        };
        check_range(xr, self.x_scale, "x_range")?;
        check_range(yr, self.y_scale, "y_range")?;
        let (l, t, r, b) = plot_area(width_px, height_px);
        Ok((
            Axis {
                lo: xr[0],
                hi: xr[1],
                scale: self.x_scale,
                px_lo: l,
                px_hi: r,
            },
            Axis {
                lo: yr[0],
                hi: yr[1],
                scale: self.y_scale,
                px_lo: b,
                px_hi: t,
            },
        ))
    }

    /// Draws the chart.
    pub fn render(&self, width_px: u32, height_px: u32) -> Result<Image, ChartError> {
        let mut cv = Canvas::new(width_px, height_px)?;
        let (x, y) = self.axes(width_px, height_px)?;
        let f = cv.font;
        let (l, t, r, b) = frame(&x, &y);
        let clampy = |v: f64| (v as f32).clamp(t, b);
        for band in &self.bands {
            let (Some(a), Some(c)) = (y.px(band.y_min), y.px(band.y_max)) else {
                continue;
            };
            cv.rect(l, clampy(a), r, clampy(c), band.color, 40);
        }
        axes(&mut cv, &x, &y, &self.title, &self.x_label, &self.y_label)?;
        // Markers: dashed lines, labels staggered over four rows so neighbours stay readable.
        let mut last_px = [f32::NEG_INFINITY; 4];
        for m in &self.markers {
            let Some(px) = x.px(m.x) else { continue };
            let px = px as f32;
            if px < l || px > r {
                continue;
            }
            cv.line(&[(px, t), (px, b)], m.color, 1.0, true, 200);
            let w = cv.text_width(&m.label, 0.75 * f)?;
            let row = (0..4).find(|k| px - last_px[*k] > w + 0.4 * f).unwrap_or(0);
            last_px[row] = px;
            let ty = t + (1.0 + row as f32) * 0.95 * f;
            cv.text(&m.label, (px + 0.2 * f, ty), 0.75 * f, 0.0, 0.0, m.color)?;
        }
        // Series, clipped to the plot area.
        let inside = |p: (f32, f32)| p.0 >= l - 1.0 && p.0 <= r + 1.0;
        for s in &self.series {
            let mut run: Vec<(f32, f32)> = Vec::new();
            let mut prev: Option<(f32, f32)> = None;
            for p in &s.points {
                let q = match (x.px(p[0]), y.px(p[1])) {
                    (Some(a), Some(c)) => Some((a as f32, clampy(c))),
                    _ => None,
                };
                match (s.style, q) {
                    (Style::Dots, Some(q)) if inside(q) => cv.dot(q.0, q.1, 0.3 * f, s.color),
                    (Style::Line, Some(q)) if inside(q) => run.push(q),
                    (Style::Steps, Some(q)) if inside(q) => {
                        if let Some(pv) = prev {
                            run.push((q.0, pv.1));
                        }
                        run.push(q);
                        prev = Some(q);
                    }
                    (Style::Dots, _) => {}
                    _ => {
                        cv.line(&run, s.color, 0.16 * f, false, 255);
                        run.clear();
                        prev = None;
                    }
                }
            }
            cv.line(&run, s.color, 0.16 * f, false, 255);
        }
        let mut items: Vec<(String, [u8; 3])> = self
            .series
            .iter()
            .map(|s| (s.label.clone(), s.color))
            .collect();
        items.extend(self.bands.iter().map(|b| (b.label.clone(), b.color)));
        legend(&mut cv, &items, r, t + 4.2 * f)?;
        Ok(cv.image())
    }

    /// Draws the chart into a PNG file.
    pub fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError> {
        Ok(self.render(width_px, height_px)?.save_png(path)?)
    }
}

impl BarChart {
    /// The value axis at this size.
    pub fn axis(&self, width_px: u32, height_px: u32) -> Result<Axis, ChartError> {
        if !self.bars.iter().any(|b| b.value.is_finite()) {
            return Err(ChartError::NoData { field: "bars" });
        }
        let r = auto_range(self.bars.iter().map(|b| b.value), self.y_scale, true, "y")?;
        let (_, t, _, b) = plot_area(width_px, height_px);
        // Room under the plot for two rows of bar labels.
        let font = (width_px.min(2 * height_px) as f64 / 70.0).clamp(9.0, 40.0);
        let r = if self.y_scale == Scale::Linear {
            [r[0].min(0.0), r[1] * 1.08]
        } else {
            r
        };
        Ok(Axis {
            lo: r[0],
            hi: r[1],
            scale: self.y_scale,
            px_lo: b - 1.4 * font,
            px_hi: t + 1.2 * font,
        })
    }

    /// Draws the bar chart.
    pub fn render(&self, width_px: u32, height_px: u32) -> Result<Image, ChartError> {
        let mut cv = Canvas::new(width_px, height_px)?;
        let y = self.axis(width_px, height_px)?;
        let f = cv.font;
        let (l, _, r, _) = plot_area(width_px, height_px);
        let mut groups: Vec<&str> = Vec::new();
        for b in &self.bars {
            if !groups.contains(&b.group.as_str()) {
                groups.push(&b.group);
            }
        }
        // Slots: one per bar plus one gap between groups.
        let slots = self.bars.len() + groups.len().saturating_sub(1);
        let slot_w = (r - l) / slots.max(1) as f64;
        let x = Axis {
            lo: 0.0,
            hi: 1.0,
            scale: Scale::Linear,
            px_lo: l,
            px_hi: r,
        };
        let (t, b) = (y.px_hi as f32, y.px_lo as f32);
        for v in y.ticks() {
            if let Some(py) = y.px(v) {
                let py = py as f32;
                cv.line(&[(l as f32, py), (r as f32, py)], GRID, 1.0, false, 255);
                cv.text(
                    &tick_label(v),
                    (l as f32 - 0.4 * f, py + 0.35 * f),
                    0.9 * f,
                    1.0,
                    0.0,
                    INK,
                )?;
            }
        }
        let base = match self.y_scale {
            Scale::Linear => y.px(0.0).unwrap_or(y.px_lo),
            Scale::Log10 => y.px_lo,
        } as f32;
        let mut slot = 0usize;
        for (gi, g) in groups.iter().enumerate() {
            let first = slot;
            for (k, bar) in self.bars.iter().filter(|b| b.group == *g).enumerate() {
                let x0 = (x.px_lo + slot as f64 * slot_w) as f32;
                let x1 = x0 + slot_w as f32;
                let pad = 0.15 * slot_w as f32;
                if let Some(py) = y.px(bar.value) {
                    let py = (py as f32).clamp(t, b);
                    cv.rect(x0 + pad, py, x1 - pad, base, bar.color, 255);
                    let label = value_label(bar.value);
                    cv.text(
                        &label,
                        ((x0 + x1) / 2.0, py - 0.3 * f),
                        0.8 * f,
                        0.5,
                        0.0,
                        INK,
                    )?;
                }
                let ly = b + (1.0 + (k % 2) as f32) * 0.95 * f;
                cv.text(&bar.label, ((x0 + x1) / 2.0, ly), 0.72 * f, 0.5, 0.0, INK)?;
                slot += 1;
            }
            let gx = (x.px_lo + (first as f64 + (slot - first) as f64 / 2.0) * slot_w) as f32;
            cv.text(g, (gx, b + 3.3 * f), f, 0.5, 0.0, INK)?;
            if gi + 1 < groups.len() {
                slot += 1;
            }
        }
        cv.line(
            &[
                (l as f32, t),
                (r as f32, t),
                (r as f32, b),
                (l as f32, b),
                (l as f32, t),
            ],
            INK,
            1.2,
            false,
            255,
        );
        let w = cv.pm.width() as f32;
        cv.text(&self.title, (w / 2.0, 1.9 * f), 1.2 * f, 0.5, 0.0, INK)?;
        cv.text(&self.y_label, (1.4 * f, (t + b) / 2.0), f, 0.5, -90.0, INK)?;
        Ok(cv.image())
    }

    /// Draws the bar chart into a PNG file.
    pub fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError> {
        Ok(self.render(width_px, height_px)?.save_png(path)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_ticks_are_1_2_5_steps() {
        assert_eq!(nice_ticks(0.0, 7.3, 6), vec![0.0, 2.0, 4.0, 6.0]);
        assert_eq!(nice_ticks(-1.0, 1.0, 4), vec![-1.0, -0.5, 0.0, 0.5, 1.0]);
        assert_eq!(log_ticks(1e-12, 1e-8).len(), 5);
        assert_eq!(tick_label(0.25), "0.25");
        assert_eq!(tick_label(1.5e-9), "1.5e-9");
        assert_eq!(tick_label(1e-9), "1e-9");
        assert_eq!(tick_label(-4.0), "-4");
        assert_eq!(value_label(57.2964), "57.3");
        assert_eq!(value_label(4.905), "4.91");
        assert_eq!(value_label(3e-9), "3e-9");
        assert_eq!(value_label(9.81e-25), "9.81e-25");
        assert_eq!(value_label(1603.7), "1604");
    }

    fn red_dots(points: Vec<[f64; 2]>) -> Chart {
        let mut c = Chart::new("t", "x", "y");
        c.series.push(Series {
            label: "s".into(),
            points,
            color: [255, 0, 0],
            style: Style::Dots,
        });
        c
    }

    #[test]
    fn data_land_on_their_pixels() {
        let mut c = red_dots(vec![[0.0, 0.0], [10.0, 5.0], [f64::NAN, 1.0]]);
        c.x_range = Some([0.0, 10.0]);
        c.y_range = Some([0.0, 5.0]);
        let img = c.render(800, 400).unwrap();
        let (l, t, r, b) = plot_area(800, 400);
        for (px, py) in [(l, b), (r, t)] {
            let p = img.pixel(px.round() as u32, py.round() as u32).unwrap();
            assert!(p[0] > 200 && p[1] < 80 && p[2] < 80, "{p:?} at {px},{py}");
        }
        let (x, y) = c.axes(800, 400).unwrap();
        assert!((x.px(5.0).unwrap() - (l + r) / 2.0).abs() < 1e-9);
        assert!((y.px(5.0).unwrap() - t).abs() < 1e-9);
    }

    #[test]
    fn bad_input_is_named() {
        let c = red_dots(vec![[f64::NAN, 1.0]]);
        assert_eq!(
            c.render(800, 400).unwrap_err().to_string(),
            "series: no finite value to draw"
        );
        let mut c = red_dots(vec![[1.0, -1.0], [2.0, 0.0]]);
        c.y_scale = Scale::Log10;
        assert_eq!(
            c.render(800, 400).unwrap_err().to_string(),
            "y axis is logarithmic but no value on it is positive"
        );
        let c = red_dots(vec![[1.0, 1.0]]);
        assert_eq!(
            c.render(100, 400).unwrap_err().to_string(),
            "chart size 100x400 px is out of range: allowed 200..=4000 px per side"
        );
        let mut c = red_dots(vec![[1.0, 1.0]]);
        c.x_range = Some([2.0, 1.0]);
        assert_eq!(
            c.render(800, 400).unwrap_err().to_string(),
            "x_range = [2, 1] is not a usable range: allowed two finite numbers lo < hi (both > 0 on a log axis)"
        );
        // One point: a range around it, drawn.
        assert!(red_dots(vec![[1.0, 1.0]]).render(800, 400).is_ok());
    }

    #[test]
    fn the_same_chart_gives_the_same_bytes() {
        let mut c = red_dots((0..200).map(|i| [i as f64, (i as f64).sin()]).collect());
        c.series[0].style = Style::Line;
        c.markers.push(Marker {
            x: 50.0,
            label: "event".into(),
            color: [0, 0, 255],
        });
        let a = c.render(900, 450).unwrap().encode_png().unwrap();
        let b = c.render(900, 450).unwrap().encode_png().unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn log_bars_are_proportional_to_their_decades() {
        let bars = BarChart {
            title: "t".into(),
            y_label: "v".into(),
            y_scale: Scale::Log10,
            bars: vec![
                Bar {
                    group: "a".into(),
                    label: "1e-9".into(),
                    value: 1e-9,
                    color: [255, 0, 0],
                },
                Bar {
                    group: "b".into(),
                    label: "1".into(),
                    value: 1.0,
                    color: [255, 0, 0],
                },
            ],
        };
        let y = bars.axis(800, 400).unwrap();
        assert_eq!((y.lo, y.hi), (1e-9, 1.0));
        let (p9, p0) = (y.px(1e-9).unwrap(), y.px(1.0).unwrap());
        let mid = y.px(10f64.powf(-4.5)).unwrap();
        assert!((mid - (p9 + p0) / 2.0).abs() < 1e-9);
        assert!(bars.render(800, 400).is_ok());
    }
}
