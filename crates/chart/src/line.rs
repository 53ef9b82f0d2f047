//! [`Chart`]: its axes from the data, and its drawing (bands, raster, markers, levels,
//! series, legend).

use std::path::Path;

use crate::canvas::{Canvas, Entry, Swatch, frame, plot_area};
use crate::ticks::{Axis, auto_range, check_range};
use crate::{Chart, ChartError, Legend, Raster, Scale, Series, Style};
use picture::Image;

/// Pixel sizes of the standard styles relative to the base font: line width, dot radius.
const LINE: f32 = 0.16;
const DOT: f32 = 0.3;

impl Chart {
    /// An empty chart with linear axes, automatic ranges and the legend upper right.
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Chart {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            x_sci: false,
            y_sci: false,
            x_range: None,
            y_range: None,
            series: Vec::new(),
            markers: Vec::new(),
            levels: Vec::new(),
            bands: Vec::new(),
            raster: None,
            legend: Legend::UpperRight,
        }
    }

    /// The chart's axes at this size: the data ranges and their pixels.
    pub fn axes(&self, width_px: u32, height_px: u32) -> Result<(Axis, Axis), ChartError> {
        let pts = || self.series.iter().flat_map(|s| s.points.iter());
        if !pts().any(|p| p[0].is_finite() && p[1].is_finite()) {
            return Err(ChartError::NoData { field: "series" });
        }
        // an axis without a fixed range spans its data: the points whose other coordinate is
        // finite, and the markers (x) or the levels and bands (y)
        let xs = pts()
            .filter(|p| p[1].is_finite())
            .map(|p| p[0])
            .chain(self.markers.iter().map(|m| m.x));
        let xr = self
            .x_range
            .map_or_else(|| auto_range(xs, self.x_scale, false, "x"), Ok)?;
        let ys = pts()
            .filter(|p| p[0].is_finite())
            .map(|p| p[1])
            .chain(self.levels.iter().map(|l| l.y))
            .chain(self.bands.iter().flat_map(|b| [b.y_min, b.y_max]));
        let yr = self
            .y_range
            .map_or_else(|| auto_range(ys, self.y_scale, true, "y"), Ok)?;
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

    /// Draws the chart, in this order: grid, raster, bands, frame and labels, markers,
    /// series, levels, legend.
    pub fn render(&self, width_px: u32, height_px: u32) -> Result<Image, ChartError> {
        let mut cv = Canvas::new(width_px, height_px)?;
        let (x, y) = self.axes(width_px, height_px)?;
        let f = cv.font;
        let area = frame(&x, &y);
        let (l, t, r, b) = area;
        cv.grid(&x, &y);
        if let Some(raster) = &self.raster {
            draw_raster(&mut cv, raster, (&x, &y))?;
        }
        for band in &self.bands {
            let (Some(a), Some(c)) = (y.px(band.y_min), y.px(band.y_max)) else {
                continue;
            };
            let (a, c) = ((a as f32).clamp(t, b), (c as f32).clamp(t, b));
            cv.rect(l, a, r, c, band.color, 40);
        }
        cv.axes(
            (&x, &y),
            [self.x_sci, self.y_sci],
            &self.title,
            &self.x_label,
            &self.y_label,
        )?;
        self.draw_markers(&mut cv, &x, area)?;
        for s in &self.series {
            draw_series(&mut cv, s, (&x, &y));
        }
        for lv in &self.levels {
            if let Some(py) = y.px(lv.y).map(|v| v as f32).filter(|v| (t..=b).contains(v)) {
                cv.line(&[(l, py), (r, py)], lv.color, 1.5, false, 255);
            }
        }
        let mut items: Vec<Entry> = self
            .series
            .iter()
            .map(|s| (s.label.clone(), s.color, swatch(s.style, f)))
            .collect();
        items.extend(
            self.levels
                .iter()
                .map(|v| (v.label.clone(), v.color, Swatch::Line(1.5))),
        );
        items.extend(
            self.bands
                .iter()
                .map(|b| (b.label.clone(), b.color, Swatch::Block)),
        );
        items.retain(|e| !e.0.is_empty());
        let top_gap = if self.markers.is_empty() {
            0.0
        } else {
            4.2 * f
        };
        cv.legend(&items, self.legend, area, top_gap)?;
        Ok(cv.image())
    }

    /// Markers: dashed lines, labels staggered over four rows so neighbours stay readable.
    fn draw_markers(
        &self,
        cv: &mut Canvas,
        x: &Axis,
        (l, t, r, b): (f32, f32, f32, f32),
    ) -> Result<(), ChartError> {
        let f = cv.font;
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
        Ok(())
    }

    /// Draws the chart into a PNG file.
    pub fn write_png(&self, path: &Path, width_px: u32, height_px: u32) -> Result<(), ChartError> {
        Ok(self.render(width_px, height_px)?.save_png(path)?)
    }
}

/// The legend swatch of a style at base font `f`.
fn swatch(style: Style, f: f32) -> Swatch {
    match style {
        Style::Line | Style::Steps => Swatch::Line(LINE * f),
        Style::Dots => Swatch::Dot(DOT * f),
        Style::Pen { line_px, .. } if line_px > 0.0 => Swatch::Line(line_px),
        Style::Pen { dot_px, .. } => Swatch::Dot(dot_px),
        Style::Rings { radius_px } => Swatch::Ring(radius_px),
        Style::Fill => Swatch::Block,
    }
}

/// The raster's cells, clipped to the plot area.
fn draw_raster(cv: &mut Canvas, g: &Raster, (x, y): (&Axis, &Axis)) -> Result<(), ChartError> {
    if g.columns == 0 || g.cells.len() % g.columns != 0 {
        return Err(ChartError::Raster {
            cells: g.cells.len(),
            columns: g.columns,
        });
    }
    check_range(g.x_range, x.scale, "raster.x_range")?;
    check_range(g.y_range, y.scale, "raster.y_range")?;
    let rows = g.cells.len() / g.columns;
    let (l, t, r, b) = frame(x, y);
    let edge = |a: &Axis, range: [f64; 2], k: usize, n: usize| -> f32 {
        let v = range[0] + (range[1] - range[0]) * k as f64 / n as f64;
        a.px(v).map_or(f32::NAN, |p| p as f32)
    };
    let xs: Vec<f32> = (0..=g.columns)
        .map(|i| edge(x, g.x_range, i, g.columns).clamp(l, r))
        .collect();
    let ys: Vec<f32> = (0..=rows)
        .map(|j| edge(y, g.y_range, j, rows).clamp(t, b))
        .collect();
    for (j, row) in g.cells.chunks(g.columns).enumerate() {
        for (i, c) in row.iter().enumerate() {
            if xs[i] < xs[i + 1] && ys[j + 1] < ys[j] {
                cv.cell(xs[i], ys[j + 1], xs[i + 1], ys[j], *c);
            }
        }
    }
    Ok(())
}

/// One series, clipped to the plot area.
fn draw_series(cv: &mut Canvas, s: &Series, (x, y): (&Axis, &Axis)) {
    let f = cv.font;
    let (l, t, r, b) = frame(x, y);
    let (line_px, dot_px) = match s.style {
        Style::Line | Style::Steps | Style::Fill => (LINE * f, 0.0),
        Style::Dots => (0.0, DOT * f),
        Style::Pen { line_px, dot_px } => (line_px, dot_px),
        Style::Rings { .. } => (0.0, 0.0),
    };
    let inside = |p: (f32, f32)| p.0 >= l - 1.0 && p.0 <= r + 1.0;
    let mut run: Vec<(f32, f32)> = Vec::new();
    let end_run = |cv: &mut Canvas, run: &mut Vec<(f32, f32)>| {
        match s.style {
            Style::Fill => cv.polygon(run, s.color),
            _ => cv.line(run, s.color, line_px, false, 255),
        }
        run.clear();
    };
    for p in &s.points {
        let q = match (x.px(p[0]), y.px(p[1])) {
            (Some(a), Some(c)) => Some((a as f32, (c as f32).clamp(t, b))),
            _ => None,
        };
        let Some(q) = q.filter(|q| inside(*q)) else {
            end_run(cv, &mut run);
            continue;
        };
        if dot_px > 0.0 {
            cv.dot(q.0, q.1, dot_px, s.color);
        }
        match s.style {
            Style::Rings { radius_px } => cv.ring(q.0, q.1, radius_px, 2.0, s.color),
            Style::Steps => {
                if let Some(pv) = run.last().copied() {
                    run.push((q.0, pv.1));
                }
                run.push(q);
            }
            _ => run.push(q),
        }
    }
    end_run(cv, &mut run);
}
