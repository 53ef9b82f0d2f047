//! Line and scatter charts over plotters, for the figures the reports share: series of points
//! on linear or log axes, with a legend and axis labels that carry their units.
//!
//! Charts a report draws only once (a bar chart, a floor plan) use plotters directly, through
//! the re-exported [`crate::plotters`].

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;

/// A figure that could not be drawn.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlotError {
    /// An axis range that cannot be drawn.
    #[error("{axis} axis \"{label}\": range {lo}..{hi} {why}")]
    Axis {
        /// "x" or "y".
        axis: &'static str,
        /// The axis label.
        label: String,
        /// Lower end, in the axis unit.
        lo: f64,
        /// Upper end, in the axis unit.
        hi: f64,
        /// What is wrong with it.
        why: &'static str,
    },
    /// plotters or the PNG encoder failed (message as plotters gives it).
    #[error("drawing failed: {0}")]
    Draw(String),
}

fn draw_err(e: impl std::fmt::Display) -> PlotError {
    PlotError::Draw(e.to_string())
}

/// One axis: its label (with the unit, e.g. "time per tick (µs)"), range and scale.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Label, with the unit in parentheses.
    pub label: String,
    /// Lower end of the range, in the axis unit.
    pub lo: f64,
    /// Upper end of the range, in the axis unit.
    pub hi: f64,
    /// Logarithmic scale (then `lo` must be > 0).
    pub log: bool,
    /// Tick labels in scientific notation (`1e-3`).
    pub sci: bool,
}

impl Axis {
    /// A linear axis over `lo..hi`.
    pub fn linear(label: &str, lo: f64, hi: f64) -> Self {
        Self {
            label: label.to_string(),
            lo,
            hi,
            log: false,
            sci: false,
        }
    }

    /// A logarithmic axis over `lo..hi` (lo > 0).
    pub fn log(label: &str, lo: f64, hi: f64) -> Self {
        Self {
            log: true,
            ..Self::linear(label, lo, hi)
        }
    }

    /// Tick labels in scientific notation.
    pub fn sci(mut self) -> Self {
        self.sci = true;
        self
    }

    fn check(&self, axis: &'static str) -> Result<(), PlotError> {
        let why = if !(self.lo.is_finite() && self.hi.is_finite()) {
            Some("is not finite")
        } else if self.lo >= self.hi {
            Some("is empty (lo ≥ hi)")
        } else if self.log && self.lo <= 0.0 {
            Some("must be above 0 on a log axis")
        } else {
            None
        };
        match why {
            Some(why) => Err(PlotError::Axis {
                axis,
                label: self.label.clone(),
                lo: self.lo,
                hi: self.hi,
                why,
            }),
            None => Ok(()),
        }
    }
}

/// Points joined by a line and/or marked by dots, with an optional legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry (`None`: not in the legend).
    pub name: Option<String>,
    /// (x, y) in the axes' units.
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBAColor,
    /// Line width, px (0: no line).
    pub width: u32,
    /// Dot radius, px (0: no dots).
    pub marker: u32,
}

impl Series {
    /// A 2 px line through `points`, in the legend as `name`.
    pub fn line(name: &str, points: Vec<(f64, f64)>, color: impl Color) -> Self {
        Self {
            name: Some(name.to_string()),
            points,
            color: color.to_rgba(),
            width: 2,
            marker: 0,
        }
    }

    /// Dots of radius `radius` px at `points`, in the legend as `name`.
    pub fn dots(name: &str, points: Vec<(f64, f64)>, color: impl Color, radius: u32) -> Self {
        Self {
            marker: radius,
            width: 0,
            ..Self::line(name, points, color)
        }
    }

    /// The same series with a line of `px` pixels (0: none).
    pub fn width(mut self, px: u32) -> Self {
        self.width = px;
        self
    }

    /// The same series with dots of radius `px` pixels (0: none).
    pub fn markers(mut self, px: u32) -> Self {
        self.marker = px;
        self
    }

    /// The same series left out of the legend.
    pub fn unlabelled(mut self) -> Self {
        self.name = None;
        self
    }
}

/// A chart: title, two axes, series, a legend.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Caption above the plot.
    pub title: String,
    /// Caption font size, px.
    pub title_px: u32,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Series, drawn in order.
    pub series: Vec<Series>,
    /// Where the legend goes (`None`: no legend).
    pub legend: Option<SeriesLabelPosition>,
}

impl Chart {
    /// A chart with a 20 px title and the legend upper right.
    pub fn new(title: &str, x: Axis, y: Axis) -> Self {
        Self {
            title: title.to_string(),
            title_px: 20,
            x,
            y,
            series: Vec::new(),
            legend: Some(SeriesLabelPosition::UpperRight),
        }
    }

    /// Adds a series.
    pub fn with(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a horizontal line at `y` across the x range, 1 px (a target, a reference).
    pub fn hline(self, name: Option<&str>, y: f64, color: impl Color) -> Self {
        let mut s = Series::line("", vec![(self.x.lo, y), (self.x.hi, y)], color).width(1);
        s.name = name.map(str::to_string);
        self.with(s)
    }

    /// Moves the legend (`None`: no legend).
    pub fn legend(mut self, at: Option<SeriesLabelPosition>) -> Self {
        self.legend = at;
        self
    }

    /// Draws the chart on a plotters drawing area (a whole image or a panel of one).
    pub fn draw_on<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        self.x.check("x")?;
        self.y.check("y")?;
        let (xr, yr) = (self.x.lo..self.x.hi, self.y.lo..self.y.hi);
        match (self.x.log, self.y.log) {
            (false, false) => self.draw_in(area, xr, yr),
            (true, false) => self.draw_in(area, xr.log_scale(), yr),
            (false, true) => self.draw_in(area, xr, yr.log_scale()),
            (true, true) => self.draw_in(area, xr.log_scale(), yr.log_scale()),
        }
    }

    fn draw_in<DB, X, Y>(&self, area: &DrawingArea<DB, Shift>, x: X, y: Y) -> Result<(), PlotError>
    where
        DB: DrawingBackend,
        X: AsRangedCoord<Value = f64>,
        Y: AsRangedCoord<Value = f64>,
        X::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let mut chart = ChartBuilder::on(area)
            .caption(&self.title, ("sans-serif", self.title_px))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x, y)
            .map_err(draw_err)?;
        let sci = |v: &f64| format!("{v:.0e}");
        let mut mesh = chart.configure_mesh();
        mesh.x_desc(self.x.label.as_str())
            .y_desc(self.y.label.as_str());
        if self.x.sci {
            mesh.x_label_formatter(&sci);
        }
        if self.y.sci {
            mesh.y_label_formatter(&sci);
        }
        mesh.draw().map_err(draw_err)?;
        let mut labelled = false;
        for s in &self.series {
            let (c, w, r) = (s.color, s.width, s.marker);
            if w > 0 {
                let a = chart
                    .draw_series(LineSeries::new(s.points.clone(), c.stroke_width(w)))
                    .map_err(draw_err)?;
                if let Some(n) = &s.name {
                    a.label(n.as_str()).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(w))
                    });
                    labelled = true;
                }
            }
            if r > 0 {
                let a = chart
                    .draw_series(s.points.iter().map(|p| Circle::new(*p, r, c.filled())))
                    .map_err(draw_err)?;
                if let (Some(n), 0) = (&s.name, w) {
                    a.label(n.as_str())
                        .legend(move |(x, y)| Circle::new((x + 10, y), r, c.filled()));
                    labelled = true;
                }
            }
        }
        if let (Some(at), true) = (&self.legend, labelled) {
            chart
                .configure_series_labels()
                .position(at.clone())
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(draw_err)?;
        }
        Ok(())
    }

    /// Draws the chart alone into a PNG of `size` (width, height) px at `path`.
    pub fn save(&self, path: &Path, size: (u32, u32)) -> Result<(), PlotError> {
        save_row(path, size, std::slice::from_ref(self))
    }
}

/// Draws `charts` side by side (equal widths) into one PNG of `size` (width, height) px.
pub fn save_row(path: &Path, size: (u32, u32), charts: &[Chart]) -> Result<(), PlotError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(draw_err)?;
    }
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(draw_err)?;
    let panels = root.split_evenly((1, charts.len().max(1)));
    for (c, area) in charts.iter().zip(&panels) {
        c.draw_on(area)?;
    }
    root.present().map_err(draw_err)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// Width and height from a PNG file's IHDR chunk.
    fn png_size(path: &Path) -> (u32, u32) {
        let b = std::fs::read(path).unwrap();
        assert_eq!(&b[1..4], b"PNG");
        let w = u32::from_be_bytes([b[16], b[17], b[18], b[19]]);
        let h = u32::from_be_bytes([b[20], b[21], b[22], b[23]]);
        (w, h)
    }

    #[test]
    fn draws_log_and_linear_charts_to_png() {
        let dir = std::env::temp_dir().join(format!("bench-harness-plot-{}", std::process::id()));
        let a = Chart::new(
            "log–log",
            Axis::log("time (ns)", 1.0, 1e4),
            Axis::log("error (nm)", 1e-6, 10.0).sci(),
        )
        .with(Series::line("rk4", vec![(10.0, 1.0), (100.0, 1e-3)], RED).markers(3))
        .with(Series::dots("peer", vec![(50.0, 1e-2)], BLUE, 4))
        .hline(None, 0.01, BLACK.mix(0.4));
        let b = Chart::new(
            "linear",
            Axis::linear("time (s)", 0.0, 2.5),
            Axis::linear("distance (µm)", 0.0, 3.0),
        )
        .with(Series::line("lag", vec![(0.0, 0.0), (1.0, 2.0)], GREEN).unlabelled())
        .legend(None);
        a.save(&dir.join("a.png"), (400, 300)).unwrap();
        save_row(&dir.join("ab.png"), (800, 300), &[a.clone(), b]).unwrap();
        assert_eq!(png_size(&dir.join("a.png")), (400, 300));
        assert_eq!(png_size(&dir.join("ab.png")), (800, 300));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_axes_are_named() {
        let c = Chart::new(
            "t",
            Axis::log("substrate atoms", 0.0, 10.0),
            Axis::linear("µs", 0.0, 1.0),
        );
        let e = c.save(&std::env::temp_dir().join("never.png"), (10, 10));
        assert_eq!(
            e.unwrap_err().to_string(),
            "x axis \"substrate atoms\": range 0..10 must be above 0 on a log axis"
        );
        let c = Chart::new(
            "t",
            Axis::linear("a", 0.0, 1.0),
            Axis::linear("force (N)", 2.0, 2.0),
        );
        let mut pixels = vec![0u8; 10 * 10 * 3];
        let area = BitMapBackend::with_buffer(&mut pixels, (10, 10)).into_drawing_area();
        assert_eq!(
            c.draw_on(&area).unwrap_err(),
            PlotError::Axis {
                axis: "y",
                label: "force (N)".into(),
                lo: 2.0,
                hi: 2.0,
                why: "is empty (lo ≥ hi)"
            }
        );
        let nan = Axis::linear("z", f64::NAN, 1.0).check("x").unwrap_err();
        assert_eq!(nan.to_string(), "x axis \"z\": range NaN..1 is not finite");
    }
}
