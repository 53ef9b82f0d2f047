//! Animated GIF output: frame count, size, timing, and what a decoder composites.

use render::{Camera, Frame, GifWriter, Image, Palette, Style, View, frame_delays_cs};

use haptic_types::{Ball, Primitive};

use haptic_types::Rgba;

const W: u32 = 160;
const H: u32 = 120;

/// A particle moving right by 4 px per frame.
fn frame(i: u32) -> Image {
    let cam = Camera::new(View::Top, [0.0; 3], 1e8, W, H).expect("camera");
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    f.push(Primitive::Sphere(Ball {
        center_m: [(-50.0 + 4.0 * f64::from(i)) * 1e-8, 0.0, 0.0],
        radius_m: 1e-7,
        color: Rgba([0.85, 0.15, 0.1, 1.0]),
    }))
    .expect("sphere");
    f.finish().expect("image")
}

struct Decoded {
    width: u16,
    height: u16,
    frames: usize,
    delays_cs: Vec<u16>,
    /// RGB of the composited canvas after each frame.
    canvases: Vec<Vec<[u8; 3]>>,
}

fn decode(bytes: &[u8]) -> Decoded {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(bytes).expect("gif header");
    let (width, height) = (dec.width(), dec.height());
    let pal: Vec<[u8; 3]> = dec
        .global_palette()
        .expect("global palette")
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let mut canvas = vec![[0u8; 3]; usize::from(width) * usize::from(height)];
    let mut delays_cs = Vec::new();
    let mut canvases = Vec::new();
    while let Some(fr) = dec.read_next_frame().expect("frame") {
        delays_cs.push(fr.delay);
        for y in 0..usize::from(fr.height) {
            for x in 0..usize::from(fr.width) {
                let idx = fr.buffer[y * usize::from(fr.width) + x];
                if Some(idx) == fr.transparent {
                    continue;
                }
                let cx = usize::from(fr.left) + x;
                let cy = usize::from(fr.top) + y;
                canvas[cy * usize::from(width) + cx] = pal[usize::from(idx)];
            }
        }
        canvases.push(canvas.clone());
    }
    Decoded {
        width,
        height,
        frames: delays_cs.len(),
        delays_cs,
        canvases,
    }
}

fn encode(n: u32, fps: f64) -> (Vec<u8>, Vec<Image>, Palette) {
    let images: Vec<Image> = (0..n).map(frame).collect();
    let sample: Vec<&Image> = [0, n / 2, n - 1]
        .iter()
        .map(|&i| &images[i as usize])
        .collect();
    let pal = Palette::from_images(&sample, 255).expect("palette");
    let mut g = GifWriter::new(Vec::new(), W, H, fps, pal.clone()).expect("writer");
    for img in &images {
        g.add_frame(img).expect("frame");
    }
    assert_eq!(g.frame_count(), u64::from(n));
    (g.finish().expect("finish"), images, pal)
}

#[test]
fn gif_has_every_frame_at_the_right_size_and_time() {
    let (bytes, _, _) = encode(30, 30.0);
    let d = decode(&bytes);
    assert_eq!((d.width, d.height), (W as u16, H as u16));
    assert_eq!(d.frames, 30);
    // 30 frames at 30 fps last exactly one second
    assert_eq!(d.delays_cs.iter().map(|&c| u32::from(c)).sum::<u32>(), 100);
    let expect: Vec<u16> = frame_delays_cs(30, 30.0).collect();
    assert_eq!(d.delays_cs, expect);
}

#[test]
fn decoded_frames_show_the_particle_moving() {
    let (bytes, images, pal) = encode(20, 25.0);
    let d = decode(&bytes);
    for (i, canvas) in d.canvases.iter().enumerate() {
        // every composited pixel is the palette colour of the rendered pixel
        for (k, px) in images[i].to_rgba8().chunks_exact(4).enumerate() {
            let want = pal.colors()[usize::from(pal.index_of([px[0], px[1], px[2]]))];
            assert_eq!(canvas[k], want, "frame {i} pixel {k}");
        }
        // and the particle centre is red at x = 30 + 4 i px
        let x = 30 + 4 * i;
        let c = canvas[60 * W as usize + x];
        assert!(c[0] > 150 && c[2] < 100, "frame {i}: {c:?}");
    }
}

#[test]
fn palette_reproduces_few_colours_exactly() {
    let img = frame(0);
    let pal = Palette::from_images(&[&img], 255).expect("palette");
    // the background is represented exactly
    let bg = Style::default().background.to_u8();
    let i = pal.index_of([bg[0], bg[1], bg[2]]);
    assert_eq!(pal.colors()[usize::from(i)], [bg[0], bg[1], bg[2]]);
    // mean palette error over the image is small
    let rgba = img.to_rgba8();
    let mut err = 0.0;
    for px in rgba.chunks_exact(4) {
        let c = pal.colors()[usize::from(pal.index_of([px[0], px[1], px[2]]))];
        err += (0..3)
            .map(|j| (f64::from(c[j]) - f64::from(px[j])).abs())
            .sum::<f64>();
    }
    let mean = err / (rgba.len() / 4) as f64 / 3.0;
    assert!(mean < 1.0, "mean abs error {mean} per channel");
}

#[test]
fn same_frames_same_gif_bytes() {
    assert_eq!(encode(8, 30.0).0, encode(8, 30.0).0);
}

#[test]
fn unchanged_frames_cost_almost_nothing() {
    let img = frame(3);
    let pal = Palette::from_images(&[&img], 64).expect("palette");
    let mut g = GifWriter::new(Vec::new(), W, H, 30.0, pal).expect("writer");
    g.add_frame(&img).expect("first");
    let first = g.pixels_stored();
    for _ in 0..9 {
        g.add_frame(&img).expect("again");
    }
    assert_eq!(first, u64::from(W * H));
    assert_eq!(g.pixels_stored(), first + 9);
    assert_eq!(decode(&g.finish().expect("gif")).frames, 10);
}

#[test]
fn bad_gif_settings_are_refused() {
    let img = frame(0);
    let pal = Palette::from_images(&[&img], 16).expect("palette");
    let e = GifWriter::new(Vec::new(), W, H, 60.0, pal.clone())
        .err()
        .expect("60 fps refused");
    assert_eq!(
        e.to_string(),
        "gif.fps = 60 is out of range: allowed (0, 50] frames/s"
    );
    let mut g = GifWriter::new(Vec::new(), W + 1, H, 30.0, pal).expect("writer");
    let e = g.add_frame(&img).unwrap_err();
    assert_eq!(e.to_string(), "image is 160x120 px, expected 161x120 px");
    let e = Palette::from_images(&[&img], 0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "palette.max_colors = 0 is out of range: allowed 1..=255"
    );
    assert_eq!(
        Palette::from_images(&[], 8).unwrap_err().to_string(),
        "palette needs at least one image with at least one pixel"
    );
}

#[test]
fn a_colour_missing_from_the_palette_switches_to_a_frame_palette() {
    // palette from a frame with only the red particle; later a green particle appears
    let cam = Camera::new(View::Top, [0.0; 3], 1e8, W, H).expect("camera");
    let draw = |green: bool| {
        let mut f = Frame::new(cam, Style::default()).expect("frame");
        f.push(Primitive::Sphere(Ball {
            center_m: [-3e-7, 0.0, 0.0],
            radius_m: 1e-7,
            color: Rgba([0.85, 0.15, 0.1, 1.0]),
        }))
        .expect("red");
        if green {
            f.push(Primitive::Sphere(Ball {
                center_m: [3e-7, 0.0, 0.0],
                radius_m: 2e-7,
                color: Rgba([0.1, 0.8, 0.2, 1.0]),
            }))
            .expect("green");
        }
        f.finish().expect("image")
    };
    let (red_only, both) = (draw(false), draw(true));
    let pal = Palette::from_images(&[&red_only], 255).expect("palette");
    let mut g = GifWriter::new(Vec::new(), W, H, 30.0, pal).expect("writer");
    g.add_frame(&red_only).expect("frame 0");
    g.add_frame(&both).expect("frame 1");
    g.add_frame(&both).expect("frame 2");
    g.add_frame(&red_only).expect("frame 3");
    assert_eq!(g.palette_switches(), 1);
    let d = decode_local(&g.finish().expect("gif"));
    assert_eq!(d.len(), 4);
    // the green particle's centre (110, 60) decodes green in frames 1 and 2
    let want = both.pixel(110, 60).expect("pixel");
    for (i, canvas) in d.iter().enumerate().skip(1).take(2) {
        let c = canvas[60 * W as usize + 110];
        for k in 0..3 {
            assert!(c[k].abs_diff(want[k]) <= 8, "frame {i}: {c:?} vs {want:?}");
        }
    }
    // and is background again in frame 3
    let bg = Style::default().background.to_u8();
    let c = d[3][60 * W as usize + 110];
    for k in 0..3 {
        assert!(c[k].abs_diff(bg[k]) <= 4, "frame 3: {c:?}");
    }
}

/// Composited RGB canvases, honouring per-frame (local) palettes.
fn decode_local(bytes: &[u8]) -> Vec<Vec<[u8; 3]>> {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::Indexed);
    let mut dec = opts.read_info(bytes).expect("gif header");
    let (w, h) = (usize::from(dec.width()), usize::from(dec.height()));
    let global: Vec<u8> = dec.global_palette().expect("global").to_vec();
    let mut canvas = vec![[0u8; 3]; w * h];
    let mut out = Vec::new();
    while let Some(fr) = dec.read_next_frame().expect("frame") {
        let pal = fr.palette.clone().unwrap_or_else(|| global.clone());
        for y in 0..usize::from(fr.height) {
            for x in 0..usize::from(fr.width) {
                let idx = fr.buffer[y * usize::from(fr.width) + x];
                if Some(idx) == fr.transparent {
                    continue;
                }
                let k = 3 * usize::from(idx);
                canvas[(usize::from(fr.top) + y) * w + usize::from(fr.left) + x] =
                    [pal[k], pal[k + 1], pal[k + 2]];
            }
        }
        out.push(canvas.clone());
    }
    out
}

/// docs/render.md: a frame switches the palette when "more than `BAD_PIXEL_SHARE` = 0.05 % of
/// its pixels [lie] in 15-bit cells farther than `BAD_PIXEL_ERROR` = 40 from their palette
/// colour".
#[test]
fn the_palette_switch_thresholds_are_the_documented_ones() {
    assert_eq!(render::BAD_PIXEL_SHARE, 0.0005);
    assert_eq!(render::BAD_PIXEL_ERROR, 40);
}
