//! The paper's figures 2, 3, 4, 7 and 8, each with the paper's one-step
//! model (one RK4 step per tick) next to the converged dynamics.
//!
//! Run: `cargo run --release -p ot-envelope --example figures`
//! Writes `docs/figures/ot-envelope-fig{2,3,4,7,8}.png`.

use nalgebra::Vector2;
use ot_envelope::geometry::first_crossing;
use ot_envelope::inverse::TrapSolver;
use ot_envelope::paper::paper_envelope;
use ot_envelope::{OffsetRegion, working_envelope};
use ot_physics::{Method, Propagator, TrapModel};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::time::Instant;

type V2 = Vector2<f64>;
type Res<T> = Result<T, Box<dyn std::error::Error>>;
const NM: f64 = 1e-9;
const ONE: RGBColor = RGBColor(200, 40, 40);
const CONV: RGBColor = RGBColor(30, 80, 200);

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

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

fn panel<'a, 'b>(
    area: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    xl: &str,
    yl: &str,
) -> Res<Chart<'a, 'b>> {
    let mut c = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    c.configure_mesh()
        .x_desc(xl)
        .y_desc(yl)
        .light_line_style(WHITE)
        .draw()?;
    Ok(c)
}

fn fig2() -> Res<()> {
    let root =
        BitMapBackend::new("docs/figures/ot-envelope-fig2.png", (1500, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, 3));
    let runs: [(&str, Propagator<2>, usize, RGBColor); 3] = [
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
    for (area, (title, p, k, col)) in areas.iter().zip(runs.iter()) {
        let mut c = panel(
            area,
            title,
            (-800.0, 800.0),
            (-800.0, 800.0),
            "x (nm)",
            "y (nm)",
        )?;
        for i in -4i32..=4 {
            for j in -4i32..=4 {
                let r0 = V2::new(160e-9 * f64::from(i), 160e-9 * f64::from(j));
                let tr = trajectory(p, r0, *k)?;
                c.draw_series(LineSeries::new(
                    tr.iter().map(|q| (q.x / NM, q.y / NM)),
                    col,
                ))?;
                c.draw_series(std::iter::once(Circle::new(
                    (r0.x / NM, r0.y / NM),
                    2,
                    BLACK.filled(),
                )))?;
            }
        }
    }
    root.present()?;
    Ok(())
}

fn colour(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let r = (255.0 * (1.5 * t).min(1.0)) as u8;
    let g = (255.0 * (1.5 * t - 0.5).clamp(0.0, 1.0)) as u8;
    let b = (255.0 * (0.6 - t).clamp(0.0, 0.6)) as u8;
    RGBColor(r, g, b)
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
    let root =
        BitMapBackend::new("docs/figures/ot-envelope-fig3.png", (1300, 620)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, 2));
    let n = 161;
    let (lo, hi) = (V2::new(-1500e-9, -1000e-9), V2::new(1500e-9, 1000e-9));
    for (area, (title, p)) in areas.iter().zip([
        (
            "(a) paper one-step model: |Δ| vs particle position, iso-contours every 100 nm",
            prop(Method::PaperRk4, 1e-6)?,
        ),
        (
            "(b) converged: |Δ| vs particle position, iso-contours every 100 nm",
            prop(Method::Rk4 { substeps: 16 }, 1e-6)?,
        ),
    ]) {
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
            area,
            title,
            (lo.x / NM, hi.x / NM),
            (lo.y / NM, hi.y / NM),
            "particle x − trap x (nm)",
            "particle y − trap y (nm)",
        )?;
        let h = (hi - lo) / (n - 1) as f64 / NM;
        let scale = 1200e-9;
        c.draw_series(
            (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let x = lo.x / NM + h.x * i as f64;
                    let y = lo.y / NM + h.y * j as f64;
                    Rectangle::new(
                        [
                            (x - h.x / 2.0, y - h.y / 2.0),
                            (x + h.x / 2.0, y + h.y / 2.0),
                        ],
                        colour(f[i * n + j] / scale).filled(),
                    )
                }),
        )?;
        for level in (1..12).map(|k| k as f64 * 100e-9) {
            for (a, b) in contour(&f, n, lo, hi, level) {
                c.draw_series(LineSeries::new(
                    [(a.x / NM, a.y / NM), (b.x / NM, b.y / NM)],
                    BLACK,
                ))?;
            }
        }
        c.draw_series(
            [arg, -arg]
                .iter()
                .map(|q| Cross::new((q.x / NM, q.y / NM), 8, WHITE.stroke_width(3))),
        )?;
        c.draw_series(std::iter::once(Text::new(
            format!(
                "max |Δ| = {:.0} nm at ({:.0}, {:.0}) nm",
                fmax / NM,
                arg.x / NM,
                arg.y / NM
            ),
            (lo.x / NM + 40.0, hi.y / NM - 80.0),
            ("sans-serif", 15).into_font().color(&WHITE),
        )))?;
    }
    root.present()?;
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
    let root =
        BitMapBackend::new("docs/figures/ot-envelope-fig4.png", (1300, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, 2));
    let one = prop(Method::PaperRk4, 1e-6)?;
    let conv = prop(Method::Rk4 { substeps: 8 }, 1e-6)?;
    for (area, v0) in areas.iter().zip([V2::zeros(), V2::new(0.1, 0.1)]) {
        let title = format!(
            "locus of maximal displacement, 3.6° steps, v0 = ({:.0}, {:.0}) nm/µs",
            v0.x * 1e3,
            v0.y * 1e3
        );
        let mut c = panel(
            area,
            &title,
            (-1500.0, 1500.0),
            (-1500.0, 1500.0),
            "Δx (nm)",
            "Δy (nm)",
        )?;
        for (p, col, label) in [
            (&one, ONE, "paper one-step model"),
            (&conv, CONV, "converged (RK4 × 8)"),
        ] {
            let we = working_envelope(p, &v0, None)?;
            let mut poly: Vec<(f64, f64)> =
                we.polygon.iter().map(|q| (q.x / NM, q.y / NM)).collect();
            poly.push(poly[0]);
            c.draw_series(LineSeries::new(poly, col.mix(0.4)))?;
            let pts: Vec<V2> = (0..100)
                .filter_map(|k| radial(&we.polygon, f64::from(k) * 3.6f64.to_radians()))
                .collect();
            c.draw_series(
                pts.iter()
                    .map(|q| Circle::new((q.x / NM, q.y / NM), 3, col.filled())),
            )?
            .label(label)
            .legend(move |(x, y)| Circle::new((x + 8, y), 4, col.filled()));
        }
        c.configure_series_labels()
            .border_style(BLACK)
            .background_style(WHITE)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

fn fig7() -> Res<()> {
    let root =
        BitMapBackend::new("docs/figures/ot-envelope-fig7.png", (1300, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, 2));
    let v0 = V2::new(0.1, 0.1);
    let target = V2::new(-160e-9, -800e-9);
    let n = 241;
    let (lo, hi) = (V2::new(-1200e-9, -900e-9), V2::new(1200e-9, 900e-9));
    for (area, (title, p)) in areas.iter().zip([
        (
            "(a) paper one-step model, Δt = 1.3 µs",
            prop(Method::PaperRk4, 1.3e-6)?,
        ),
        (
            "(b) converged (RK4 × 12), Δt = 1.3 µs",
            prop(Method::Rk4 { substeps: 12 }, 1.3e-6)?,
        ),
    ]) {
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
        let full = format!(
            "{title}: Δx = −160 nm (red), Δy = −800 nm (blue); {} solutions",
            sols.offsets().len()
        );
        let mut c = panel(
            area,
            &full,
            (lo.x / NM, hi.x / NM),
            (lo.y / NM, hi.y / NM),
            "trap offset x (nm)",
            "trap offset y (nm)",
        )?;
        for (a, b) in contour(&fx, n, lo, hi, target.x) {
            c.draw_series(LineSeries::new(
                [(a.x / NM, a.y / NM), (b.x / NM, b.y / NM)],
                ONE.stroke_width(2),
            ))?;
        }
        for (a, b) in contour(&fy, n, lo, hi, target.y) {
            c.draw_series(LineSeries::new(
                [(a.x / NM, a.y / NM), (b.x / NM, b.y / NM)],
                CONV.stroke_width(2),
            ))?;
        }
        c.draw_series(
            sols.offsets()
                .iter()
                .map(|o| Circle::new((o.x / NM, o.y / NM), 7, BLACK.stroke_width(2))),
        )?;
    }
    root.present()?;
    Ok(())
}

fn fig8() -> Res<()> {
    let root =
        BitMapBackend::new("docs/figures/ot-envelope-fig8.png", (1600, 1100)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((2, 2));
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
    let draw_poly = |c: &mut Chart<'_, '_>, poly: &[V2], col: RGBColor| -> Res<()> {
        let mut pts: Vec<(f64, f64)> = poly.iter().map(|q| (q.x / NM, q.y / NM)).collect();
        pts.push(pts[0]);
        c.draw_series(LineSeries::new(pts, col.stroke_width(2)))?;
        Ok(())
    };
    for (k, spacing) in [80e-9, 40e-9, 20e-9].into_iter().enumerate() {
        let s = Instant::now();
        let b = paper_envelope(&conv, &v0, &ours.region, 0.3, t_lo, t_hi, spacing)?;
        let t = s.elapsed().as_secs_f64();
        let title = format!(
            "paper method, targets every {:.0} nm: {:.1} ms (red); ours (blue)",
            spacing / NM,
            t * 1e3
        );
        let mut c = panel(
            &areas[k],
            &title,
            (-650.0, 800.0),
            (-850.0, 950.0),
            "Δx (nm)",
            "Δy (nm)",
        )?;
        let [nx, ny] = b.shape;
        let pts: Vec<(V2, bool)> = (0..nx)
            .flat_map(|a| (0..ny).map(move |bb| (a, bb)))
            .map(|(a, bb)| {
                (
                    t_lo + V2::new(a as f64, bb as f64) * spacing,
                    b.solved[a * ny + bb],
                )
            })
            .collect();
        c.draw_series(pts.iter().map(|(q, ok)| {
            let r = if *ok { 3 } else { 1 };
            Circle::new((q.x / NM, q.y / NM), r, BLACK.filled())
        }))?;
        draw_poly(&mut c, &b.polygon, ONE)?;
        draw_poly(&mut c, &ours.polygon, CONV)?;
    }
    let title = format!(
        "ours: converged {:.2} ms (blue), one-step model {:.2} ms (red)",
        t_ours * 1e3,
        t_ours1 * 1e3
    );
    let mut c = panel(
        &areas[3],
        &title,
        (-650.0, 800.0),
        (-850.0, 950.0),
        "Δx (nm)",
        "Δy (nm)",
    )?;
    draw_poly(&mut c, &ours.polygon, CONV)?;
    draw_poly(&mut c, &ours1.polygon, ONE)?;
    root.present()?;
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
