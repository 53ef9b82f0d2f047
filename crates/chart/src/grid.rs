//! Several charts in one image: a row (`columns` = the number of charts) or a grid.

use std::path::Path;

use crate::{Chart, ChartError};
use picture::Image;

/// Draws `charts` into one `width_px` × `height_px` image, `columns` per row (left to right,
/// then top to bottom), each panel `width_px / columns` wide and `height_px / rows` high
/// (each within [`crate::SIDE_RANGE_PX`]); pixels a whole number of panels leaves over stay
/// white.
pub fn render_grid(
    charts: &[Chart],
    columns: usize,
    width_px: u32,
    height_px: u32,
) -> Result<Image, ChartError> {
    if charts.is_empty() || columns == 0 || columns > charts.len() {
        return Err(ChartError::Grid {
            charts: charts.len(),
            columns,
        });
    }
    let rows = charts.len().div_ceil(columns);
    let (pw, ph) = (width_px / columns as u32, height_px / rows as u32);
    let mut out = Image::new(width_px, height_px)?;
    out.pixmap_mut().fill(tiny_skia::Color::WHITE);
    for (k, c) in charts.iter().enumerate() {
        let panel = c.render(pw, ph)?;
        let (i, j) = ((k % columns) as u32, (k / columns) as u32);
        out.draw_image(&panel, (i * pw) as i32, (j * ph) as i32);
    }
    Ok(out)
}

/// [`render_grid`] into a PNG file.
pub fn write_grid_png(
    path: &Path,
    charts: &[Chart],
    columns: usize,
    width_px: u32,
    height_px: u32,
) -> Result<(), ChartError> {
    Ok(render_grid(charts, columns, width_px, height_px)?.save_png(path)?)
}
