//! The one chart engine of nanohaptics: small 2D charts for reports and figures (the lesson's,
//! every benchmark report's through `bench_harness::chart`, the ot-envelope paper figures).
//!
//! **What it is for.**
//!
//! * [`Chart`]: line, dot, ring, step and filled series on linear or log axes, with vertical
//!   event markers, horizontal reference lines ([`Level`]), translucent bands, a colour
//!   raster under the data (a heat map) and a legend in any corner;
//! * [`BarChart`]: grouped bars on a linear or log scale, each with its value printed;
//! * [`render_grid`] / [`write_grid_png`]: several charts side by side (a row) or in a grid,
//!   in one image.
//!
//! Charts are drawn with tiny-skia into `picture`'s [`Image`] with its embedded font, so they
//! need nothing from the system (no fontconfig) and give the same PNG bytes everywhere. Bad
//! input is a typed [`ChartError`] naming the field. The user guide is `docs/chart.md`.
//!
//! ```no_run
//! use chart::{Chart, Series, Style};
//! let mut c = Chart::new("force over time", "time (s)", "force (N)");
//! c.series.push(Series {
//!     label: "Fz".into(),
//!     points: (0..100).map(|i| [i as f64 * 0.01, (i as f64 * 0.1).sin()]).collect(),
//!     color: [31, 119, 180],
//!     style: Style::Line,
//! });
//! c.write_png("force.png".as_ref(), 1000, 500)?;
//! # Ok::<(), chart::ChartError>(())
//! ```
//!
//! **What it is not.** Not the renderer of worlds (`render` draws world primitives through a
//! camera) and it knows no world, recording or measurement: callers hand it numbers. No
//! interactive plots, no colour bar, contour filling or 3D (use matplotlib on a recording's
//! arrays for those).

mod bar;
mod canvas;
mod grid;
mod line;
mod ticks;

use std::path::Path;

use picture::PictureError;

pub use canvas::plot_area;
pub use grid::{render_grid, write_grid_png};
pub use picture::Image;
pub use ticks::{Axis, log_ticks, nice_ticks, sci_label, tick_label, value_label};

/// Smallest and largest chart side, px.
pub const SIDE_RANGE_PX: (u32, u32) = (200, 4000);

/// Ten distinct colours (matplotlib's "tab10"), for series that have no colour of their own.
pub const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// An axis scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear.
    Linear,
    /// Base-10 logarithmic (positive values only).
    Log10,
}

/// How a series is drawn. [`Style::Line`] and [`Style::Dots`] scale with the chart (a line
/// about 2 px wide and dots of radius 4 px on a 900 px chart); [`Style::Pen`] and
/// [`Style::Rings`] are sized in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Style {
    /// A polyline through the points (a gap at non-finite points).
    Line,
    /// A dot at each point.
    Dots,
    /// A staircase: each value held until the next point.
    Steps,
    /// A polyline `line_px` wide (0: none) with a dot of radius `dot_px` at each point (0:
    /// none).
    Pen {
        /// Line width, px.
        line_px: f32,
        /// Dot radius, px.
        dot_px: f32,
    },
    /// A hollow circle of radius `radius_px` at each point (outline 2 px).
    Rings {
        /// Radius, px.
        radius_px: f32,
    },
    /// The points as a closed polygon, filled (a gap at a non-finite point starts the next
    /// polygon).
    Fill,
}

/// A data series. A series with an empty label stays out of the legend.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend text (empty: not in the legend).
    pub label: String,
    /// (x, y) points in data units; non-finite points are skipped.
    pub points: Vec<[f64; 2]>,
    /// RGB colour.
    pub color: [u8; 3],
    /// How it is drawn.
    pub style: Style,
}

impl Series {
    /// A series of `points` drawn as `style`.
    pub fn new(label: &str, points: Vec<[f64; 2]>, color: [u8; 3], style: Style) -> Self {
        Series {
            label: label.to_string(),
            points,
            color,
            style,
        }
    }
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

/// A horizontal solid line across the plot at `y` (a target, a reference); in the legend
/// unless its label is empty.
#[derive(Clone, Debug, PartialEq)]
pub struct Level {
    /// Position, data units.
    pub y: f64,
    /// Legend text (empty: not in the legend).
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

/// A grid of coloured cells under the data (a heat map), drawn without anti-aliasing so the
/// cells meet without seams.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// Left and right edges of the grid, data units.
    pub x_range: [f64; 2],
    /// Bottom and top edges of the grid, data units.
    pub y_range: [f64; 2],
    /// Cells along x.
    pub columns: usize,
    /// Colours, `columns` per row, the bottom row first, each row from the left; its length
    /// is a whole number of rows.
    pub cells: Vec<[u8; 3]>,
}

/// Where the legend sits in the plot area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Legend {
    /// Top right corner (under the marker labels when there are markers).
    UpperRight,
    /// Top left corner.
    UpperLeft,
    /// Bottom right corner.
    LowerRight,
    /// Bottom left corner.
    LowerLeft,
    /// No legend.
    None,
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
    /// x tick labels in scientific notation (`1e-3`); otherwise only far from 1 (see
    /// [`tick_label`]).
    pub x_sci: bool,
    /// y tick labels in scientific notation.
    pub y_sci: bool,
    /// x range; `None`: from the data and the markers.
    pub x_range: Option<[f64; 2]>,
    /// y range; `None`: from the data, the levels and the bands (a linear axis includes 0
    /// when the data touch or straddle it).
    pub y_range: Option<[f64; 2]>,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// Vertical event markers.
    pub markers: Vec<Marker>,
    /// Horizontal reference lines.
    pub levels: Vec<Level>,
    /// Horizontal bands.
    pub bands: Vec<Band>,
    /// A heat map under everything else.
    pub raster: Option<Raster>,
    /// Where the legend goes.
    pub legend: Legend,
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
        /// `x_range`, `y_range`, `raster.x_range` or `raster.y_range`.
        field: &'static str,
        /// Lower end given.
        lo: f64,
        /// Upper end given.
        hi: f64,
    },
    /// A raster whose cells do not fill whole rows.
    #[error(
        "raster: {cells} cells in rows of {columns}: allowed columns ≥ 1 and a whole number of rows"
    )]
    Raster {
        /// Cells given.
        cells: usize,
        /// Columns given.
        columns: usize,
    },
    /// A chart size outside [`SIDE_RANGE_PX`].
    #[error("chart size {width_px}x{height_px} px is out of range: allowed 200..=4000 px per side")]
    Size {
        /// Width asked for.
        width_px: u32,
        /// Height asked for.
        height_px: u32,
    },
    /// A grid without charts or with a column count outside 1..=charts.
    #[error(
        "a grid of {charts} charts in {columns} columns: allowed 1..={charts} columns and at least one chart"
    )]
    Grid {
        /// Charts given.
        charts: usize,
        /// Columns asked for.
        columns: usize,
    },
    /// Drawing or writing failed (the font, the image or the PNG file).
    #[error(transparent)]
    Picture(#[from] PictureError),
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

/// The user guide's examples (`docs/chart.md`), compiled as doc-tests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/chart.md")]
pub struct UserGuide;
