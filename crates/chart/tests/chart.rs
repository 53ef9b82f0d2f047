//! Charts: data land on the pixels the axes give, each style draws what it says at the size
//! it says, the legend goes where it is asked, and bad input is a named error.

use chart::{
    Chart, Image, Legend, Level, Marker, Raster, Scale, Series, Style, plot_area, render_grid,
};

const RED: [u8; 3] = [255, 0, 0];
const BLUE: [u8; 3] = [0, 0, 255];
const WHITE: [u8; 4] = [255, 255, 255, 255];

fn px(img: &Image, x: f64, y: f64) -> [u8; 4] {
    img.pixel(x.floor() as u32, y.floor() as u32)
        .expect("pixel inside the image")
}

fn opaque(c: [u8; 3]) -> [u8; 4] {
    [c[0], c[1], c[2], 255]
}

/// A chart over x, y ∈ [0, 10] with one series.
fn chart(points: Vec<[f64; 2]>, color: [u8; 3], style: Style) -> Chart {
    let mut c = Chart::new("t", "x", "y");
    c.x_range = Some([0.0, 10.0]);
    c.y_range = Some([0.0, 10.0]);
    c.series.push(Series::new("s", points, color, style));
    c
}

/// Base font of an 800 × 400 chart, px.
const FONT: f64 = 800.0 / 70.0;

#[test]
fn data_land_on_their_pixels() {
    let mut c = chart(
        vec![[0.0, 0.0], [10.0, 5.0], [f64::NAN, 1.0]],
        RED,
        Style::Dots,
    );
    c.y_range = Some([0.0, 5.0]);
    let img = c.render(800, 400).unwrap();
    let (l, t, r, b) = plot_area(800, 400);
    for (x, y) in [(l, b), (r, t)] {
        let p = px(&img, x.round(), y.round());
        assert!(p[0] > 200 && p[1] < 80 && p[2] < 80, "{p:?} at {x},{y}");
    }
    let (x, y) = c.axes(800, 400).unwrap();
    assert!((x.px(5.0).unwrap() - (l + r) / 2.0).abs() < 1e-9);
    assert!((y.px(5.0).unwrap() - t).abs() < 1e-9);
}

#[test]
fn bad_input_is_named() {
    let c = chart(vec![[f64::NAN, 1.0]], RED, Style::Dots);
    assert_eq!(
        c.render(800, 400).unwrap_err().to_string(),
        "series: no finite value to draw"
    );
    let mut c = chart(vec![[1.0, -1.0], [2.0, 0.0]], RED, Style::Dots);
    c.y_range = None;
    c.y_scale = Scale::Log10;
    assert_eq!(
        c.render(800, 400).unwrap_err().to_string(),
        "y axis is logarithmic but no value on it is positive"
    );
    let c = chart(vec![[1.0, 1.0]], RED, Style::Dots);
    assert_eq!(
        c.render(100, 400).unwrap_err().to_string(),
        "chart size 100x400 px is out of range: allowed 200..=4000 px per side"
    );
    let mut c = chart(vec![[1.0, 1.0]], RED, Style::Dots);
    c.x_range = Some([2.0, 1.0]);
    assert_eq!(
        c.render(800, 400).unwrap_err().to_string(),
        "x_range = [2, 1] is not a usable range: allowed two finite numbers lo < hi (both > 0 on a log axis)"
    );
    let mut c = chart(vec![[1.0, 1.0]], RED, Style::Dots);
    c.raster = Some(Raster {
        x_range: [0.0, 10.0],
        y_range: [0.0, 10.0],
        columns: 2,
        cells: vec![RED; 3],
    });
    assert_eq!(
        c.render(800, 400).unwrap_err().to_string(),
        "raster: 3 cells in rows of 2: allowed columns ≥ 1 and a whole number of rows"
    );
    // One point and automatic ranges: a range around it, drawn.
    let mut c = chart(vec![[1.0, 1.0]], RED, Style::Dots);
    (c.x_range, c.y_range) = (None, None);
    assert!(c.render(800, 400).is_ok());
}

#[test]
fn the_same_chart_gives_the_same_bytes() {
    let pts = (0..200).map(|i| [i as f64 / 20.0, 5.0 + 4.0 * (i as f64).sin()]);
    let mut c = chart(pts.collect(), RED, Style::Line);
    c.markers.push(Marker {
        x: 5.0,
        label: "event".into(),
        color: BLUE,
    });
    let a = c.render(900, 450).unwrap().encode_png().unwrap();
    let b = c.render(900, 450).unwrap().encode_png().unwrap();
    assert_eq!(a, b);
}

#[test]
fn pen_lines_and_dots_have_the_asked_size() {
    // An 8 px line along y = 5 from x = 0 to 5, and 10 px dots at its ends.
    let style = Style::Pen {
        line_px: 8.0,
        dot_px: 10.0,
    };
    let mut c = chart(vec![[0.0, 5.0], [5.0, 5.0]], RED, style);
    c.legend = Legend::None;
    let img = c.render(800, 400).unwrap();
    let (x, y) = c.axes(800, 400).unwrap();
    let (x2, y5) = (x.px(2.5).unwrap(), y.px(5.0).unwrap());
    for d in [-3.0, 0.0, 3.0] {
        assert_eq!(px(&img, x2, y5 + d), opaque(RED), "{d} px off the line");
    }
    for d in [-6.0, 6.0] {
        assert_eq!(px(&img, x2, y5 + d), WHITE, "{d} px off the line");
    }
    // the end dot: red 8 px right of the end, white 13 px right of it
    let x5 = x.px(5.0).unwrap();
    assert_eq!(px(&img, x5 + 8.0, y5), opaque(RED));
    assert_eq!(px(&img, x5 + 13.0, y5), WHITE);
}

#[test]
fn rings_are_hollow_and_fills_are_full() {
    let mut c = chart(vec![[5.0, 5.0]], BLUE, Style::Rings { radius_px: 20.0 });
    c.series.push(Series::new(
        "square",
        vec![[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]],
        RED,
        Style::Fill,
    ));
    c.legend = Legend::None;
    let img = c.render(800, 400).unwrap();
    let (x, y) = c.axes(800, 400).unwrap();
    let (cx, cy) = (x.px(5.0).unwrap(), y.px(5.0).unwrap());
    let ring = px(&img, cx + 20.0, cy);
    assert!(ring[2] > 150 && ring[0] < 100, "{ring:?} on the ring");
    // off the grid lines through the centre: white inside and outside
    assert_eq!(px(&img, cx + 7.0, cy + 7.0), WHITE, "inside the ring");
    assert_eq!(px(&img, cx + 21.0, cy + 21.0), WHITE, "outside the ring");
    // the square is red inside, white outside
    let (sx, sy) = (x.px(1.5).unwrap(), y.px(1.5).unwrap());
    assert_eq!(px(&img, sx, sy), opaque(RED));
    assert_eq!(px(&img, x.px(3.5).unwrap(), sy), WHITE);
}

#[test]
fn levels_cross_the_plot_and_widen_the_auto_range() {
    let mut c = chart(vec![[0.0, 0.0], [10.0, 1.0]], RED, Style::Line);
    c.y_range = None;
    c.legend = Legend::None;
    c.levels.push(Level {
        y: 5.0,
        label: String::new(),
        color: BLUE,
    });
    let (x, y) = c.axes(800, 400).unwrap();
    assert!(y.hi >= 5.0 && y.lo <= 0.0, "{} … {}", y.lo, y.hi);
    let img = c.render(800, 400).unwrap();
    let py = y.px(5.0).unwrap();
    for v in [0.5, 5.0, 9.5] {
        let p = px(&img, x.px(v).unwrap(), py);
        assert!(p[2] > 240 && p[0] < 130 && p[0] == p[1], "{p:?} at x = {v}");
    }
}

/// Whether row `sy` of the first legend entry in `corner` of an 800 × 400 chart without
/// markers has a `c` pixel within 10 fonts of that corner's side of the plot area.
fn swatch_in(img: &Image, corner: Legend, c: [u8; 3]) -> bool {
    let (l, t, r, b) = plot_area(800, 400);
    let f = 0.9 * FONT;
    let h = 1.35 * f + 0.6 * f;
    let xs = match corner {
        Legend::UpperLeft | Legend::LowerLeft => l..l + 10.0 * f,
        _ => r - 10.0 * f..r,
    };
    let y0 = match corner {
        Legend::LowerLeft | Legend::LowerRight => b - 0.5 * f - h,
        _ => t + 0.5 * f,
    };
    let sy = y0 + 0.3 * f + 1.35 * f - 0.35 * f;
    (xs.start as u32..xs.end as u32).any(|x| px(img, x as f64, sy) == opaque(c))
}

#[test]
fn the_legend_goes_to_the_asked_corner_and_skips_unlabelled_series() {
    // A dot far from every corner; its legend swatch is a dot of the same colour.
    let base = chart(vec![[5.0, 5.0]], RED, Style::Dots);
    let corners = [
        Legend::UpperLeft,
        Legend::UpperRight,
        Legend::LowerLeft,
        Legend::LowerRight,
    ];
    for at in corners {
        let mut c = base.clone();
        c.legend = at;
        let img = c.render(800, 400).unwrap();
        for other in corners {
            assert_eq!(
                swatch_in(&img, other, RED),
                other == at,
                "{at:?}: {other:?}"
            );
        }
    }
    let mut c = base.clone();
    c.series[0].label.clear();
    let img = c.render(800, 400).unwrap();
    assert!(!swatch_in(&img, Legend::UpperRight, RED));
    c.legend = Legend::None;
    c.series[0].label = "s".into();
    let img = c.render(800, 400).unwrap();
    assert!(corners.iter().all(|at| !swatch_in(&img, *at, RED)));
}

#[test]
fn raster_cells_fill_their_rectangles_exactly() {
    let mut c = chart(vec![[5.0, 5.0]], [0, 0, 0], Style::Dots);
    c.legend = Legend::None;
    let (g, k) = ([0, 200, 0], [250, 250, 0]);
    // bottom row: red, blue; top row: green, yellow; over x ∈ [0, 8], y ∈ [0, 8]
    c.raster = Some(Raster {
        x_range: [0.0, 8.0],
        y_range: [0.0, 8.0],
        columns: 2,
        cells: vec![RED, BLUE, g, k],
    });
    let img = c.render(800, 400).unwrap();
    let (x, y) = c.axes(800, 400).unwrap();
    let at = |a: f64, b: f64| px(&img, x.px(a).unwrap(), y.px(b).unwrap());
    assert_eq!(at(1.3, 1.3), opaque(RED));
    assert_eq!(at(6.7, 1.3), opaque(BLUE));
    assert_eq!(at(1.3, 6.7), opaque(g));
    assert_eq!(at(6.7, 6.7), opaque(k));
    assert_eq!(at(9.0, 1.3), WHITE, "right of the raster");
}

#[test]
fn a_grid_puts_each_chart_in_its_panel() {
    let a = chart(vec![[1.0, 1.0], [9.0, 9.0]], RED, Style::Line);
    let b = chart(vec![[1.0, 9.0], [9.0, 1.0]], BLUE, Style::Dots);
    let row = render_grid(&[a.clone(), b.clone(), a.clone()], 3, 1200, 400).unwrap();
    let grid = render_grid(&[a.clone(), b.clone(), a.clone()], 2, 800, 800).unwrap();
    let (ia, ib) = (a.render(400, 400).unwrap(), b.render(400, 400).unwrap());
    for (img, panels) in [
        (&row, [(0, 0, &ia), (400, 0, &ib), (800, 0, &ia)]),
        (&grid, [(0, 0, &ia), (400, 0, &ib), (0, 400, &ia)]),
    ] {
        for (ox, oy, p) in panels {
            for (x, y) in [(200, 200), (57, 333), (390, 20), (123, 77)] {
                assert_eq!(
                    img.pixel(ox + x, oy + y),
                    p.pixel(x, y),
                    "{ox}+{x}, {oy}+{y}"
                );
            }
        }
    }
    // the fourth cell of the 2 × 2 grid is empty
    assert_eq!(grid.pixel(600, 600), Some(WHITE));
    assert_eq!(
        render_grid(std::slice::from_ref(&a), 2, 800, 400)
            .unwrap_err()
            .to_string(),
        "a grid of 1 charts in 2 columns: allowed 1..=1 columns and at least one chart"
    );
}
