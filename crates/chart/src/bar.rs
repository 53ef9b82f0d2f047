//! [`BarChart`]: grouped bars with their values printed above them.

use std::path::Path;

use crate::canvas::{Canvas, INK, font_px, plot_area};
use crate::ticks::{Axis, auto_range, value_label};
use crate::{BarChart, ChartError, Scale};
use picture::Image;

impl BarChart {
    /// The value axis at this size.
    pub fn axis(&self, width_px: u32, height_px: u32) -> Result<Axis, ChartError> {
        if !self.bars.iter().any(|b| b.value.is_finite()) {
            return Err(ChartError::NoData { field: "bars" });
        }
        let r = auto_range(self.bars.iter().map(|b| b.value), self.y_scale, true, "y")?;
        let (_, t, _, b) = plot_area(width_px, height_px);
        // Room under the plot for two rows of bar labels.
        let font = font_px(width_px, height_px);
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
        let (t, b) = (y.px_hi as f32, y.px_lo as f32);
        cv.y_grid(&y, (l as f32, r as f32));
        cv.y_labels(&y, l as f32, false)?;
        let base = match self.y_scale {
            Scale::Linear => y.px(0.0).unwrap_or(y.px_lo),
            Scale::Log10 => y.px_lo,
        } as f32;
        let mut slot = 0usize;
        for (gi, g) in groups.iter().enumerate() {
            let first = slot;
            for (k, bar) in self.bars.iter().filter(|b| b.group == *g).enumerate() {
                let x0 = (l + slot as f64 * slot_w) as f32;
                let x1 = x0 + slot_w as f32;
                let pad = 0.15 * slot_w as f32;
                if let Some(py) = y.px(bar.value) {
                    let py = (py as f32).clamp(t, b);
                    cv.rect(x0 + pad, py, x1 - pad, base, bar.color, 255);
                    let label = value_label(bar.value);
                    let at = ((x0 + x1) / 2.0, py - 0.3 * f);
                    cv.text(&label, at, 0.8 * f, 0.5, 0.0, INK)?;
                }
                let ly = b + (1.0 + (k % 2) as f32) * 0.95 * f;
                cv.text(&bar.label, ((x0 + x1) / 2.0, ly), 0.72 * f, 0.5, 0.0, INK)?;
                slot += 1;
            }
            let gx = (l + (first as f64 + (slot - first) as f64 / 2.0) * slot_w) as f32;
            cv.text(g, (gx, b + 3.3 * f), f, 0.5, 0.0, INK)?;
            if gi + 1 < groups.len() {
                slot += 1;
            }
        }
        cv.frame_box((l as f32, t, r as f32, b), INK, 1.2);
        cv.title_and_y_label(&self.title, &self.y_label, (t, b))?;
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
    use crate::Bar;

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
        // the 1 bar is red from its top down to the axis, in the middle of its slot
        let img = bars.render(800, 400).unwrap();
        let (l, _, r, _) = plot_area(800, 400);
        let slot = (r - l) / 3.0;
        let cx = (l + 2.5 * slot) as u32;
        for py in [p0 + 3.0, (p0 + y.px_lo) / 2.0, y.px_lo - 3.0] {
            let p = img.pixel(cx, py as u32).unwrap();
            assert_eq!(p, [255, 0, 0, 255], "at {cx},{py}");
        }
        // the gap slot between the two groups is white at mid height
        let p = img.pixel((l + 1.5 * slot) as u32, ((p0 + y.px_lo) / 2.0) as u32);
        assert_eq!(p.unwrap(), [255, 255, 255, 255]);
    }
}
