//! Criterion micro-benchmarks: drawing one optical-tweezers frame and one brick-house frame,
//! and adding one frame to a GIF.

use criterion::{Criterion, criterion_group, criterion_main};
use haptic_types::Rgba;
use haptic_types::{Ball, OrientedBox, Primitive};
use render::{Camera, Frame, GifWriter, Palette, Style, View};
use std::hint::black_box;

fn tweezers(t: f64) -> Frame {
    let cam = Camera::new(View::Top, [0.0; 3], 1.2e8, 640, 480).expect("camera");
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    let p = [0.3e-6 * t.cos(), 0.3e-6 * t.sin(), 0.0];
    f.push(Primitive::Ellipse {
        center_m: [p[0] + 50e-9, p[1], 0.0],
        semi_axes_m: [600e-9, 300e-9],
        color: Rgba([0.2, 0.6, 0.2, 0.8]),
    })
    .expect("beam");
    f.push(Primitive::Sphere(Ball {
        center_m: p,
        radius_m: 0.5e-6,
        color: Rgba::from_u8(200, 80, 40),
    }))
    .expect("particle");
    let loop_m: Vec<[f64; 3]> = (0..200)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 200.0;
            [p[0] + 3e-9 * a.cos(), p[1] + 2e-9 * a.sin(), 0.0]
        })
        .collect();
    f.scaled_loop(&loop_m, p, 100.0, Rgba::from_u8(20, 20, 160))
        .expect("loop");
    f.push(Primitive::Cursor(Ball {
        center_m: [p[0] + 0.4e-6, p[1], 0.0],
        radius_m: 0.15e-6,
        color: Rgba([0.1, 0.3, 0.9, 0.4]),
    }))
    .expect("cursor");
    f.push(Primitive::Arrow {
        from_m: p,
        to_m: [p[0] + 0.8e-6, p[1] + 0.2e-6, 0.0],
        color: Rgba::from_u8(200, 0, 0),
    })
    .expect("arrow");
    f.scale_bar(None, Rgba::from_u8(0, 0, 0)).expect("bar");
    f
}

fn house() -> Frame {
    let cam = Camera::fit(
        View::oblique_default(),
        [-0.3, -0.3, 0.0],
        [0.3, 0.3, 0.3],
        640,
        480,
        0.05,
    )
    .expect("camera");
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    for i in 0..10 {
        for j in 0..4 {
            for k in 0..6 {
                f.push(Primitive::Box(OrientedBox {
                    center_m: [
                        -0.2 + 0.045 * i as f64,
                        -0.1 + 0.06 * j as f64,
                        0.012 + 0.025 * k as f64,
                    ],
                    half_extents_m: [0.02, 0.01, 0.012],
                    rotation: [0.0, 0.0, 0.0, 1.0],
                    color: Rgba::from_u8(180, 70, 50),
                }))
                .expect("brick");
            }
        }
    }
    f
}

fn bench(c: &mut Criterion) {
    let fr = tweezers(0.3);
    c.bench_function("tweezers_frame_640x480", |b| {
        b.iter(|| black_box(fr.finish().expect("image")))
    });
    let hs = house();
    c.bench_function("house_240_bricks_640x480", |b| {
        b.iter(|| black_box(hs.finish().expect("image")))
    });
    let imgs: Vec<_> = (0..16)
        .map(|i| tweezers(0.1 * i as f64).finish().expect("image"))
        .collect();
    let refs: Vec<_> = imgs.iter().collect();
    let pal = Palette::from_images(&refs, 255).expect("palette");
    c.bench_function("gif_add_frame_640x480", |b| {
        let mut g = GifWriter::new(Vec::new(), 640, 480, 30.0, pal.clone()).expect("gif");
        let mut i = 0;
        b.iter(|| {
            g.add_frame(&imgs[i % imgs.len()]).expect("frame");
            i += 1;
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
