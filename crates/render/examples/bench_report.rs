//! Benchmark report for the renderer: three 60 s sessions at 30 fps (1800 frames each) turned
//! into GIFs, with frames/s, GIF size and the accuracy reached (palette error, geometry), plus
//! the paper's Fig. 9 layout and one still per world.
//!
//! `cargo run --release -p render --example render-report` writes `docs/bench/render.md` and
//! `docs/figures/render-*.png` (GIFs go to `target/render-bench/`, not committed), framed and
//! timed by the shared `bench-harness`.
//! `--quick` renders 180 frames per session instead of 1800 (for a smoke run).

mod scenes;

use bench_harness::chart::{Bar, BarChart, PALETTE, Scale};
use bench_harness::{Align, Report, Span, Table, Verdict, span};
use haptic_types::Rgba;
use render::{Camera, Frame, GifWriter, Image, Palette, Style, View};
use scenes::*;
use std::fmt::Write as _;
use std::path::Path;

type BoxError = Box<dyn std::error::Error>;

const FPS: f64 = 30.0;
const SECONDS: f64 = 60.0;
const W: u32 = 640;
const H: u32 = 480;
const TARGET_S: f64 = 30.0;

struct Run {
    name: &'static str,
    frames: u64,
    primitives: usize,
    /// Wall-clock time of rendering, GIF encoding and the palette, s.
    render: f64,
    encode: f64,
    palette: f64,
    gif_bytes: u64,
    /// Thread-CPU time of the whole session (palette, render, encode, finish), s: on a shared
    /// machine the "one core" time, without the time the thread waited for a core.
    cpu_s: f64,
    stored_frac: f64,
    switches: u64,
    /// Mean time to encode one frame as PNG, s, and its mean size, bytes (sampled frames).
    png_s: f64,
    png_bytes: f64,
    /// The same with the png crate's default (balanced) compression.
    png_default_s: f64,
    png_default_bytes: f64,
    mean_err: f64,
    max_err: u8,
}

impl Run {
    /// Wall time of the session, s.
    fn total(&self) -> f64 {
        self.render + self.encode + self.palette
    }
    fn fps(&self) -> f64 {
        self.frames as f64 / self.total()
    }
    /// Wall time for the full 1800-frame session, s (scaled when fewer frames were run).
    fn session_s(&self) -> f64 {
        self.total() * (SECONDS * FPS) / self.frames as f64
    }
    /// CPU time for the full 1800-frame session, s (scaled when fewer frames were run).
    fn session_cpu_s(&self) -> f64 {
        self.cpu_s * (SECONDS * FPS) / self.frames as f64
    }
}

/// Renders `frames` frames of a scene at 30 fps into a GIF file and measures each stage.
fn run_session(
    name: &'static str,
    cam: Camera,
    frames: u64,
    draw: &dyn Fn(&mut Frame, f64) -> Result<(), render::RenderError>,
    out: &Path,
) -> Result<Run, BoxError> {
    let mut frame = Frame::new(cam, Style::default())?;
    let mut img = Image::new(W, H)?;
    let t_of = |i: u64| i as f64 / FPS;
    // palette from the first, middle and last frames
    let (pal, pal_span) = span(|| -> Result<Palette, BoxError> {
        let mut samples = Vec::new();
        for i in [0, frames / 2, frames - 1] {
            frame.clear();
            draw(&mut frame, t_of(i))?;
            samples.push(frame.finish()?);
        }
        let refs: Vec<&Image> = samples.iter().collect();
        Ok(Palette::from_images(&refs, 255)?)
    });
    let pal = pal?;
    let palette = pal_span.wall_s;
    // the session's thread-CPU time: the timed stages only (the measurements aside, PNG and
    // palette error, are left out)
    let mut cpu_s = pal_span.cpu_s;
    let file = std::io::BufWriter::new(std::fs::File::create(out)?);
    let mut gif = GifWriter::new(file, W, H, FPS, pal.clone())?;
    let (mut render, mut encode) = (0.0, 0.0);
    let mut primitives = 0;
    let (mut err_sum, mut err_n, mut max_err) = (0.0f64, 0u64, 0u8);
    let (mut png_t, mut png_b, mut png_n) = (0.0, 0usize, 0u32);
    let (mut pngd_t, mut pngd_b) = (0.0, 0usize);
    for i in 0..frames {
        let (r, a) = span(|| -> Result<(), BoxError> {
            frame.clear();
            draw(&mut frame, t_of(i))?;
            Ok(frame.draw_into(&mut img)?)
        });
        r?;
        let (r, b): (_, Span) = span(|| gif.add_frame(&img));
        r?;
        render += a.wall_s;
        encode += b.wall_s;
        cpu_s += a.cpu_s + b.cpu_s;
        primitives = primitives.max(frame.primitives().len());
        if i % 100 == 7 {
            // PNG cost (what `render --out DIR` adds per frame), timed apart (wall clock)
            let (bytes, p0) = span(|| img.encode_png());
            png_b += bytes?.len();
            png_t += p0.wall_s;
            png_n += 1;
            let (bytes, p1) = span(|| png_default(&img));
            pngd_b += bytes?.len();
            pngd_t += p1.wall_s;
            // palette error on every 100th frame (not timed)
            for px in img.data().chunks_exact(4) {
                let q = pal.colors()[usize::from(pal.index_of([px[0], px[1], px[2]]))];
                for j in 0..3 {
                    let e = q[j].abs_diff(px[j]);
                    err_sum += f64::from(e);
                    max_err = max_err.max(e);
                }
                err_n += 3;
            }
        }
    }
    let stored = gif.pixels_stored();
    let switches = gif.palette_switches();
    let (r, fin) = span(|| -> Result<(), BoxError> {
        let mut w = gif.finish()?;
        std::io::Write::flush(&mut w)?;
        Ok(())
    });
    r?;
    cpu_s += fin.cpu_s;
    let gif_bytes = std::fs::metadata(out)?.len();
    Ok(Run {
        name,
        frames,
        primitives,
        render,
        encode,
        palette,
        gif_bytes,
        cpu_s,
        switches,
        png_s: png_t / f64::from(png_n.max(1)),
        png_bytes: png_b as f64 / f64::from(png_n.max(1)),
        png_default_s: pngd_t / f64::from(png_n.max(1)),
        png_default_bytes: pngd_b as f64 / f64::from(png_n.max(1)),
        stored_frac: stored as f64 / (frames as f64 * f64::from(W * H)),
        mean_err: err_sum / err_n.max(1) as f64,
        max_err,
    })
}

/// PNG bytes with the png crate's default settings (balanced deflate, adaptive filter), for
/// comparison with `Image::encode_png` (fast deflate).
fn png_default(img: &Image) -> Result<Vec<u8>, BoxError> {
    let data = img.to_rgba8();
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, img.width(), img.height());
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header()?;
    w.write_image_data(&data)?;
    w.finish()?;
    Ok(out)
}

/// Measured radius (px) of a ×100 loop of radius 3 nm at 1e8 px/m (expected 30 px): the mean
/// over 36 rays of the darkest pixel's distance, refined to 1/8 px.
fn loop_radius_check() -> Result<(f64, f64), BoxError> {
    let cam = Camera::new(View::Top, [0.0; 3], 1e8, 200, 200)?;
    let mut f = Frame::new(cam, Style::default())?;
    let pts: Vec<[f64; 3]> = (0..720)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 720.0;
            [3e-9 * a.cos(), 3e-9 * a.sin(), 0.0]
        })
        .collect();
    f.scaled_loop(&pts, [0.0; 3], 100.0, Rgba::from_u8(0, 0, 0))?;
    let img = f.finish()?;
    let mut worst = 0.0f64;
    let mut sum = 0.0;
    for k in 0..36 {
        let a = std::f64::consts::TAU * f64::from(k) / 36.0;
        // intensity-weighted centroid of darkness along the ray
        let (mut wsum, mut rsum) = (0.0, 0.0);
        let mut r = 20.0;
        while r < 40.0 {
            let x = 100.0 + r * a.cos();
            let y = 100.0 - r * a.sin();
            let p = img.pixel(x as u32, y as u32).ok_or("outside")?;
            let dark = 250.0 - f64::from(p[0]);
            if dark > 0.0 {
                wsum += dark;
                rsum += dark * r;
            }
            r += 0.125;
        }
        let rr = rsum / wsum;
        sum += rr;
        worst = worst.max((rr - 30.0).abs());
    }
    Ok((sum / 36.0, worst))
}

fn main() -> Result<(), BoxError> {
    let quick = std::env::args().any(|a| a == "--quick");
    let frames = if quick { 180 } else { (SECONDS * FPS) as u64 };
    let mut md = Report::start("render", "Renderer (crates/render)")?;
    let root = md.root().to_path_buf();
    let figs = root.join("docs/figures");
    let gifs = root.join("target/render-bench");
    std::fs::create_dir_all(&gifs)?;

    eprintln!("[1/4] figures…");
    let fig9 = fig9_state();
    let mut panels = Image::new(1600, 640)?;
    for (k, (state, title)) in [
        (
            fig9a_state(),
            "(a) initial screen: particle in the beam, cursor on the left",
        ),
        (
            fig9.clone(),
            "(b) steered right beyond the working envelope (×100)",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let mut f = Frame::new(tweezers_camera(800, 640)?, Style::default())?;
        draw_tweezers(&mut f, &state, true)?;
        f.scale_bar(Some(1e-6), ink())?;
        f.title(title, ink())?;
        panels.draw_image(&f.finish()?, 800 * k as i32, 0);
    }
    panels.save_png(figs.join("render-fig9.png"))?;
    let mut f = Frame::new(bricks_camera(800, 600)?, Style::default())?;
    draw_bricks(&mut f, 41.0, true)?;
    f.title("Brick world at t = 41 s (oblique view)", ink())?;
    f.finish()?.save_png(figs.join("render-bricks.png"))?;
    let mut f = Frame::new(nano_camera(800, 600)?, Style::default())?;
    draw_nano(&mut f, 41.0, true)?;
    f.scale_bar(None, ink())?;
    f.title("Nano world at t = 41 s (oblique view)", ink())?;
    f.finish()?.save_png(figs.join("render-nano.png"))?;

    eprintln!("[2/4] sessions ({frames} frames each)…");
    let table = envelope_table();
    let tw_cam = tweezers_session_camera(W, H)?;
    let tw = run_session(
        "optical tweezers (top view)",
        tw_cam,
        frames,
        &|f, t| {
            draw_tweezers(f, &tweezers_at(t, &table), false)?;
            f.scale_bar(None, ink())
        },
        &gifs.join("tweezers.gif"),
    )?;
    eprintln!("  tweezers: {:.1} frames/s", tw.fps());
    let br = run_session(
        "brick house (oblique)",
        bricks_camera(W, H)?,
        frames,
        &|f, t| draw_bricks(f, t, true),
        &gifs.join("bricks.gif"),
    )?;
    eprintln!("  bricks: {:.1} frames/s", br.fps());
    let na = run_session(
        "atom house (oblique)",
        nano_camera(W, H)?,
        frames,
        &|f, t| draw_nano(f, t, true),
        &gifs.join("nano.gif"),
    )?;
    eprintln!("  nano: {:.1} frames/s", na.fps());
    let runs = [tw, br, na];

    eprintln!("[3/4] geometry check…");
    let (r_mean, r_worst) = loop_radius_check()?;

    eprintln!("[4/4] report…");
    plot_speed(&runs, &figs.join("render-speed.png"))?;
    report(&mut md, &runs, frames, r_mean, r_worst, &fig9)?;
    md.finish()?;
    Ok(())
}

/// Time per frame of each run (render, GIF, CPU) next to the 30 s / 1800 frames target.
fn plot_speed(runs: &[Run], path: &Path) -> Result<(), BoxError> {
    let target_ms = TARGET_S * 1e3 / (SECONDS * FPS);
    let bar = |group: &str, label: &str, value: f64, color: [u8; 3]| Bar {
        group: group.to_string(),
        label: label.to_string(),
        value,
        color,
    };
    let mut bars = Vec::new();
    for r in runs {
        let per_frame = |s: f64| s * 1e3 / r.frames as f64;
        bars.extend([
            bar(r.name, "render (wall)", per_frame(r.render), PALETTE[0]),
            bar(
                r.name,
                "GIF (wall)",
                per_frame(r.encode + r.palette),
                PALETTE[1],
            ),
            bar(r.name, "CPU, all", per_frame(r.cpu_s), [60, 60, 60]),
        ]);
    }
    bars.push(bar("target", "1800 in 30 s", target_ms, PALETTE[3]));
    let chart = BarChart {
        title: "Time per frame, 640×480, one thread".into(),
        y_label: "ms per frame".into(),
        y_scale: Scale::Linear,
        bars,
    };
    chart.write_png(path, 900, 420)?;
    Ok(())
}

fn report(
    md: &mut Report,
    runs: &[Run],
    frames: u64,
    r_mean: f64,
    r_worst: f64,
    fig9: &Tweezers,
) -> Result<(), BoxError> {
    md.para(&format!(
        "Generated by `cargo run --release -p render --example render-report`. One process, one \
         thread, {W}×{H} px, {FPS} fps, {frames} frames per session ({} s of session). Each \
         session draws its scene afresh every frame from the state at that time (a recording's \
         replay does the same), renders it and appends it to a GIF file.",
        frames as f64 / FPS
    ));
    md.heading("Target: a 60 s recording becomes a 30 fps GIF in under 30 s on one core");
    md.para(
        "The target is judged on the session's thread-CPU time (one thread, so one core; the time \
         the thread waited for a core on this shared machine is left out). Wall-clock time is \
         shown too: see the load average at the top of this section.",
    );
    let mut t = Table::new([
        "session".to_string(),
        "primitives / frame".into(),
        "render ms/frame".into(),
        "GIF ms/frame".into(),
        "frames/s (wall)".into(),
        "1800 frames, wall".into(),
        "1800 frames, CPU".into(),
        format!("target ≤ {TARGET_S} s CPU"),
        "GIF size".into(),
        "pixels stored".into(),
        "palette switches".into(),
        "palette error, mean / max (8-bit)".into(),
    ])
    .align_from(1, Align::Right)
    .align(7, Align::Default);
    for r in runs {
        let n = r.frames as f64;
        let judged = r.session_cpu_s();
        t.row([
            r.name.to_string(),
            r.primitives.to_string(),
            format!("{:.2}", r.render * 1e3 / n),
            format!("{:.2}", (r.encode + r.palette) * 1e3 / n),
            format!("{:.0}", r.fps()),
            format!("{:.1} s", r.session_s()),
            format!("{judged:.1} s"),
            format!(
                "{} ({judged:.1} s)",
                match Verdict::at_most(judged, TARGET_S) {
                    Verdict::Met => "met",
                    Verdict::NotMet => "**not met**",
                }
            ),
            format!("{:.2} MB", r.gif_bytes as f64 / 1e6),
            format!("{:.1} %", 100.0 * r.stored_frac),
            r.switches.to_string(),
            format!("{:.2} / {}", r.mean_err, r.max_err),
        ])?;
    }
    md.table(&t);
    md.para(&format!(
        "*render* and *GIF* columns are wall-clock. *GIF ms/frame* includes the palette (median \
         cut over three sample frames, built once). *Pixels stored*: share of all frame pixels \
         written to the GIF after cropping each frame to the rectangle that changed. *Palette \
         error*: |GIF colour − rendered colour| per channel over every 100th frame (255 colours, \
         15-bit lookup); this measurement and the PNG timing below are left out of the CPU time. *Palette \
         switches*: frames where more than {:.2} % of the pixels were off by more than {} and \
         the writer moved to a palette made from that frame.",
        100.0 * render::BAD_PIXEL_SHARE,
        render::BAD_PIXEL_ERROR
    ));
    md.para(
        "Writing every frame as a PNG as well (`nanohaptics render REC --out DIR`) adds the \
         PNG encoding, measured (wall-clock) on every 100th frame. `Image::encode_png` uses the \
         png crate's fast deflate; its default (balanced deflate, adaptive filter) is shown for \
         comparison, same frames, same run:",
    );
    let mut t = Table::new([
        "session",
        "PNG ms/frame (fast)",
        "size (fast)",
        "PNG ms/frame (default)",
        "size (default)",
        "speed-up",
        "1800 frames with PNGs: CPU above + fast PNG time",
    ])
    .align_from(1, Align::Right);
    for r in runs {
        t.row([
            r.name.to_string(),
            format!("{:.2}", r.png_s * 1e3),
            format!("{:.0} kB", r.png_bytes / 1e3),
            format!("{:.2}", r.png_default_s * 1e3),
            format!("{:.0} kB", r.png_default_bytes / 1e3),
            format!("{:.1}×", r.png_default_s / r.png_s),
            format!("{:.1} s", r.session_cpu_s() + r.png_s * SECONDS * FPS),
        ])?;
    }
    md.table(&t);
    md.image("time per frame", "render-speed.png");
    md.heading("Geometry");
    md.para(&format!(
        "A 3 nm circle drawn ×100 about its centre at 1e8 px/m must be a 30 px circle: measured \
         radius (darkness centroid over 36 rays) {r_mean:.3} px, worst ray off by {r_worst:.3} px."
    ));
    let fmag = (fig9.force_n[0].powi(2) + fig9.force_n[1].powi(2)).sqrt();
    let reach_x = fig9
        .envelope_m
        .iter()
        .map(|p| p[0])
        .fold(f64::NEG_INFINITY, f64::max);
    let reach_y = fig9
        .envelope_m
        .iter()
        .map(|p| p[1])
        .fold(f64::NEG_INFINITY, f64::max);
    md.heading("Paper Fig. 9, reproduced");
    writeln!(
        md,
        "![Fig. 9 layout](../figures/render-fig9.png)\n\n(a) The initial screen: a particle of \
         1 µm on a 2.9 µm grid, the beam as a rod of elliptic cross-section (a = 600 nm, \
         b = 300 nm), the cursor to the left. (b) Steering: the cursor 250 nm ahead, the working envelope for one 0.2 µs cycle at 50 nm/µs (computed here with the \
         paper's one-step RK4 map over trap positions: reach {:.1} nm along +x, {:.1} nm along \
         +y) drawn ×100, and the reaction force {:.1} pN (spring 0.05 pN/nm on the excess) \
         against the steering motion, drawn at 0.1 µm/pN.\n",
        reach_x * 1e9,
        reach_y * 1e9,
        fmag * 1e12
    )?;
    let mut t = Table::new(["brick world", "nano world"]);
    t.row([
        "![bricks](../figures/render-bricks.png)",
        "![nano](../figures/render-nano.png)",
    ])?;
    md.table(&t);
    Ok(())
}
