//! The paper's figures 2, 3, 4, 7 and 8, each with the paper's one-step
//! model (one RK4 step per tick) next to the converged dynamics.
//!
//! Run: `cargo run --release -p ot-envelope --example figures`
//! Writes `docs/figures/ot-envelope-fig{2,3,4,7,8}.png`.

use bench_harness::chart::{Chart, Legend, Raster, Series, Style, write_grid_png};
use nalgebra::Vector2;
use ot_envelope::geometry::first_crossing;
use ot_envelope::inverse::TrapSolver;
use ot_envelope::paper::paper_envelope;
use ot_envelope::{OffsetRegion, working_envelope};
use ot_physics::{Method, Propagator, TrapModel};
use std::time::Instant;

type V2 = Vector2<f64>;
type Res<T> = Result<T, Box<dyn std::error::Error>>;
const NM: f64 = 1e-9;
/// The paper's one-step model.
const ONE: [u8; 3] = [200, 40, 40];
/// The converged dynamics.
const CONV: [u8; 3] = [30, 80, 200];
const BLACK: [u8; 3] = [0, 0, 0];
const WHITE: [u8; 3] = [255, 255, 255];

fn model() -> TrapModel<2> {
    TrapModel::builder(1e-15, [600e-9, 300e-9])
        .mass(1e-15)
        .build()
        .expect("paper constants are valid")
}

fn prop(method: Method, dt: f64) -> Res<Propagator<2>> {
    Ok(Propagator::new(model(), method, dt)?)
}

/// Positions of a particle (relative to the trap at the origin) after each
/// of `k` ticks of `p`, starting at rest at `r0`.
fn trajectory(p: &Propagator<2>, r0: V2, k: usize) -> Res<Vec<V2>> {
    let (mut r, mut v) = (r0, V2::zeros());
    let mut out = vec![r];
    for _ in 0..k {
        let (d, v1, _) = p.flow(&(-r), &v)?;
        r += d;
        v = v1;
        out.push(r);
    }
    Ok(out)
}

/// An empty panel over `x` × `y` (nm) without a legend.
fn panel(title: &str, x: (f64, f64), y: (f64, f64), xl: &str, yl: &str) -> Chart {
    let mut c = Chart::new(title, xl, yl);
    (c.x_range, c.y_range) = (Some([x.0, x.1]), Some([y.0, y.1]));
    c.legend = Legend::None;
    c
}

/// A line `px` wide.
fn pen(px: f32) -> Style {
    Style::Pen {
        line_px: px,
        dot_px: 0.0,
    }
}

/// Dots of radius `px`.
fn dots(px: f32) -> Style {
    Style::Pen {
        line_px: 0.0,
        dot_px: px,
    }
}

/// Points in nm.
fn nm(q: &V2) -> [f64; 2] {
    [q.x / NM, q.y / NM]
}

/// Line segments as one polyline with a gap (a NaN point) after each.
fn segments(segs: &[(V2, V2)]) -> Vec<[f64; 2]> {
    segs.iter()
        .flat_map(|(a, b)| [nm(a), nm(b), [f64::NAN; 2]])
        .collect()
}

/// `c` at `alpha` over white.
fn faded(c: [u8; 3], alpha: f64) -> [u8; 3] {
    c.map(|v| (alpha * f64::from(v) + (1.0 - alpha) * 255.0).round() as u8)
}

fn fig2() -> Res<()> {
    let runs: [(&str, Propagator<2>, usize, [u8; 3]); 3] = [
        (
            "(a) paper: ONE RK4 step of 1 µs",
            prop(Method::PaperRk4, 1e-6)?,
            1,
            ONE,
        ),
        (
            "(b) paper: 10 RK4 steps of 0.1 µs",
            prop(Method::PaperRk4, 1e-7)?,
            10,
            ONE,
        ),
        (
            "(c) converged (DOP853), drawn every 20 ns",
            prop(Method::Adaptive { rtol: 1e-10 }, 2e-8)?,
            50,
            CONV,
        ),
    ];
    let mut charts = Vec::new();
    for (title, p, k, col) in &runs {
        let mut c = panel(title, (-800.0, 800.0), (-800.0, 800.0), "x (nm)", "y (nm)");
        let (mut paths, mut starts) = (Vec::new(), Vec::new());
        for i in -4i32..=4 {
            for j in -4i32..=4 {
                let r0 = V2::new(160e-9 * f64::from(i), 160e-9 * f64::from(j));
                paths.extend(trajectory(p, r0, *k)?.iter().map(nm));
                paths.push([f64::NAN; 2]);
                starts.push(nm(&r0));
            }
        }
        c.series = vec![
            Series::new("", paths, *col, pen(1.0)),
            Series::new("", starts, BLACK, dots(2.5)),
        ];
        charts.push(c);
    }
    write_grid_png(
        "docs/figures/ot-envelope-fig2.png".as_ref(),
        &charts,
        3,
        1500,
        520,
    )?;
    Ok(())
}

fn colour(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let r = (255.0 * (1.5 * t).min(1.0)) as u8;
    let g = (255.0 * (1.5 * t - 0.5).clamp(0.0, 1.0)) as u8;
    let b = (255.0 * (0.6 - t).clamp(0.0, 0.6)) as u8;
    [r, g, b]
}

/// Marching-squares contour segments of `f` (n × n grid over [lo, hi]) at `level`.
fn contour(f: &[f64], n: usize, lo: V2, hi: V2, level: f64) -> Vec<(V2, V2)> {
    let h = (hi - lo) / (n - 1) as f64;
    let mut out = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            let g: Vec<f64> = c.iter().map(|&(a, b)| f[a * n + b] - level).collect();
            let mut pts = Vec::new();
            for k in 0..4 {
                let (a, b) = (g[k], g[(k + 1) % 4]);
                if (a >= 0.0) != (b >= 0.0) {
                    let t = a / (a - b);
                    let (pa, pb) = (c[k], c[(k + 1) % 4]);
                    let p = V2::new(
                        pa.0 as f64 + t * (pb.0 as f64 - pa.0 as f64),
                        pa.1 as f64 + t * (pb.1 as f64 - pa.1 as f64),
                    );
                    pts.push(lo + p.component_mul(&h));
                }
            }
            for pair in pts.chunks(2).filter(|p| p.len() == 2) {
                out.push((pair[0], pair[1]));
            }
        }
    }
    out
}

fn fig3() -> Res<()> {
    let n = 161;
    let (lo, hi) = (V2::new(-1500e-9, -1000e-9), V2::new(1500e-9, 1000e-9));
    let mut charts = Vec::new();
    for (title, p) in [
        (
            "(a) paper one-step model: |Δ| vs particle position, iso-contours every 100 nm",
            prop(Method::PaperRk4, 1e-6)?,
        ),
        (
            "(b) converged: |Δ| vs particle position, iso-contours every 100 nm",
            prop(Method::Rk4 { substeps: 16 }, 1e-6)?,
        ),
    ] {
        let mut f = vec![0.0; n * n];
        let mut fmax: f64 = 0.0;
        let mut arg = V2::zeros();
        for i in 0..n {
            for j in 0..n {
                let r = lo + (hi - lo).component_mul(&V2::new(i as f64, j as f64)) / (n - 1) as f64;
                let d = p.flow(&(-r), &V2::zeros())?.0.norm();
                f[i * n + j] = d;
                if d > fmax {
                    fmax = d;
                    arg = r;
                }
            }
        }
        let mut c = panel(
            title,
            (lo.x / NM, hi.x / NM),
            (lo.y / NM, hi.y / NM),
            "particle x − trap x (nm)",
            "particle y − trap y (nm)",
        );
        // cells centred on the grid points, colour = |Δ| / 1200 nm
        let h = (hi - lo) / (n - 1) as f64 / 2.0;
        let scale = 1200e-9;
        c.raster = Some(Raster {
            x_range: [(lo.x - h.x) / NM, (hi.x + h.x) / NM],
            y_range: [(lo.y - h.y) / NM, (hi.y + h.y) / NM],
            columns: n,
            cells: (0..n)
                .flat_map(|j| (0..n).map(move |i| (i, j)))
                .map(|(i, j)| colour(f[i * n + j] / scale))
                .collect(),
        });
        let mut iso = Vec::new();
        for level in (1..12).map(|k| k as f64 * 100e-9) {
            iso.extend(contour(&f, n, lo, hi, level));
        }
        let max = format!(
            "max |Δ| = {:.0} nm at ({:.0}, {:.0}) nm",
            fmax / NM,
            arg.x / NM,
            arg.y / NM
        );
        c.series = vec![
            Series::new("", segments(&iso), BLACK, pen(1.0)),
            Series::new("", vec![nm(&arg), nm(&-arg)], WHITE, dots(6.0)),
            Series::new(
                &max,
                vec![nm(&arg), nm(&-arg)],
                BLACK,
                Style::Rings { radius_px: 8.0 },
            ),
        ];
        c.legend = Legend::UpperRight;
        charts.push(c);
    }
    write_grid_png(
        "docs/figures/ot-envelope-fig3.png".as_ref(),
        &charts,
        2,
        1300,
        620,
    )?;
    Ok(())
}

/// Largest radial extent of the envelope polygon along `θ` from the origin.
fn radial(poly: &[V2], theta: f64) -> Option<V2> {
    let far = V2::new(theta.cos(), theta.sin()) * 1e-4;
    let n = poly.len();
    let mut best: Option<f64> = None;
    for i in 0..n {
        if let Some(t) = first_crossing(&[poly[i], poly[(i + 1) % n], poly[i]], &V2::zeros(), &far)
        {
            best = Some(best.map_or(t, |b: f64| b.max(t)));
        }
    }
    best.map(|t| far * t)
}

fn fig4() -> Res<()> {
    let one = prop(Method::PaperRk4, 1e-6)?;
    let conv = prop(Method::Rk4 { substeps: 8 }, 1e-6)?;
    let mut charts = Vec::new();
    for v0 in [V2::zeros(), V2::new(0.1, 0.1)] {
        let title = format!(
            "locus of maximal displacement, 3.6° steps, v0 = ({:.0}, {:.0}) nm/µs",
            v0.x * 1e3,
            v0.y * 1e3
        );
        let mut c = panel(
            &title,
            (-1500.0, 1500.0),
            (-1500.0, 1500.0),
            "Δx (nm)",
            "Δy (nm)",
        );
        for (p, col, label) in [
            (&one, ONE, "paper one-step model"),
            (&conv, CONV, "converged (RK4 × 8)"),
        ] {
            let we = working_envelope(p, &v0, None)?;
            let mut poly: Vec<[f64; 2]> = we.polygon.iter().map(nm).collect();
            poly.push(poly[0]);
            let pts: Vec<[f64; 2]> = (0..100)
                .filter_map(|k| radial(&we.polygon, f64::from(k) * 3.6f64.to_radians()))
                .map(|q| nm(&q))
                .collect();
            c.series
                .push(Series::new("", poly, faded(col, 0.4), pen(1.0)));
            c.series.push(Series::new(label, pts, col, dots(3.0)));
        }
        c.legend = Legend::UpperLeft;
        charts.push(c);
    }
    write_grid_png(
        "docs/figures/ot-envelope-fig4.png".as_ref(),
        &charts,
        2,
        1300,
        640,
    )?;
    Ok(())
}

fn fig7() -> Res<()> {
    let v0 = V2::new(0.1, 0.1);
    let target = V2::new(-160e-9, -800e-9);
    let n = 241;
    let (lo, hi) = (V2::new(-1200e-9, -900e-9), V2::new(1200e-9, 900e-9));
    let mut charts = Vec::new();
    for (title, p) in [
        (
            "(a) paper one-step model, Δt = 1.3 µs",
            prop(Method::PaperRk4, 1.3e-6)?,
        ),
        (
            "(b) converged (RK4 × 12), Δt = 1.3 µs",
            prop(Method::Rk4 { substeps: 12 }, 1.3e-6)?,
        ),
    ] {
        let mut fx = vec![0.0; n * n];
        let mut fy = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let o = lo + (hi - lo).component_mul(&V2::new(i as f64, j as f64)) / (n - 1) as f64;
                let d = p.flow(&o, &v0)?.0;
                fx[i * n + j] = d.x;
                fy[i * n + j] = d.y;
            }
        }
        let region = OffsetRegion::new(lo, hi)?;
        let solver = TrapSolver::new(&p, &v0, Some(region), Some(0.1))?;
        let sols = solver.solve(&target)?.0;
        let full = format!("{title}: {} solutions", sols.offsets().len());
        let mut c = panel(
            &full,
            (lo.x / NM, hi.x / NM),
            (lo.y / NM, hi.y / NM),
            "trap offset x (nm)",
            "trap offset y (nm)",
        );
        let x_iso = contour(&fx, n, lo, hi, target.x);
        let y_iso = contour(&fy, n, lo, hi, target.y);
        c.series = vec![
            Series::new("Δx = −160 nm", segments(&x_iso), ONE, pen(2.0)),
            Series::new("Δy = −800 nm", segments(&y_iso), CONV, pen(2.0)),
            Series::new(
                "solutions (both at once)",
                sols.offsets().iter().map(nm).collect(),
                BLACK,
                Style::Rings { radius_px: 7.0 },
            ),
        ];
        c.legend = Legend::LowerLeft;
        charts.push(c);
    }
    write_grid_png(
        "docs/figures/ot-envelope-fig7.png".as_ref(),
        &charts,
        2,
        1300,
        640,
    )?;
    Ok(())
}

fn fig8() -> Res<()> {
    let v0 = V2::new(0.1, 0.1);
    let conv = prop(Method::Rk4 { substeps: 8 }, 1e-6)?;
    let one = prop(Method::PaperRk4, 1e-6)?;
    let s = Instant::now();
    let ours = working_envelope(&conv, &v0, None)?;
    let t_ours = s.elapsed().as_secs_f64();
    let s = Instant::now();
    let ours1 = working_envelope(&one, &v0, None)?;
    let t_ours1 = s.elapsed().as_secs_f64();
    let (t_lo, t_hi) = (V2::new(-520e-9, -740e-9), V2::new(700e-9, 840e-9));
    let closed = |label: &str, poly: &[V2], col: [u8; 3]| {
        let mut pts: Vec<[f64; 2]> = poly.iter().map(nm).collect();
        pts.push(pts[0]);
        Series::new(label, pts, col, pen(2.0))
    };
    let mut charts = Vec::new();
    for spacing in [80e-9, 40e-9, 20e-9] {
        let s = Instant::now();
        let b = paper_envelope(&conv, &v0, &ours.region, 0.3, t_lo, t_hi, spacing)?;
        let t = s.elapsed().as_secs_f64();
        let title = format!(
            "paper method, targets every {:.0} nm: {:.1} ms (red); ours (blue)",
            spacing / NM,
            t * 1e3
        );
        // room on top for the legend, clear of the targets
        let mut c = panel(
            &title,
            (-650.0, 800.0),
            (-850.0, 1250.0),
            "Δx (nm)",
            "Δy (nm)",
        );
        let [nx, ny] = b.shape;
        let (mut solved, mut unsolved) = (Vec::new(), Vec::new());
        for a in 0..nx {
            for bb in 0..ny {
                let q = nm(&(t_lo + V2::new(a as f64, bb as f64) * spacing));
                if b.solved[a * ny + bb] {
                    solved.push(q);
                } else {
                    unsolved.push(q);
                }
            }
        }
        c.series = vec![
            Series::new("target solved", solved, BLACK, dots(3.0)),
            Series::new("target not solved", unsolved, BLACK, dots(1.0)),
            closed("paper method's envelope", &b.polygon, ONE),
            closed("ours", &ours.polygon, CONV),
        ];
        c.legend = Legend::UpperLeft;
        charts.push(c);
    }
    let title = format!(
        "ours: converged {:.2} ms (blue), one-step model {:.2} ms (red)",
        t_ours * 1e3,
        t_ours1 * 1e3
    );
    let mut c = panel(
        &title,
        (-650.0, 800.0),
        (-850.0, 950.0),
        "Δx (nm)",
        "Δy (nm)",
    );
    c.series = vec![
        closed("converged (RK4 × 8)", &ours.polygon, CONV),
        closed("paper one-step model", &ours1.polygon, ONE),
    ];
    c.legend = Legend::UpperLeft;
    charts.push(c);
    write_grid_png(
        "docs/figures/ot-envelope-fig8.png".as_ref(),
        &charts,
        2,
        1600,
        1100,
    )?;
    Ok(())
}

fn main() -> Res<()> {
    std::fs::create_dir_all("docs/figures")?;
    fig2()?;
    fig3()?;
    fig4()?;
    fig7()?;
    fig8()?;
    println!("wrote docs/figures/ot-envelope-fig{{2,3,4,7,8}}.png");
    Ok(())
}
