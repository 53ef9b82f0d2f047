//! Pixel checks at known positions: things are drawn where the camera says, in the right
//! colour, pointing the right way, in the right depth order, at the right size.

use haptic_types::Rgba;
use haptic_types::{Ball, OrientedBox, Primitive};
use proptest::prelude::*;
use render::{Camera, Frame, Image, Style, View};

const RED: Rgba = Rgba([0.85, 0.15, 0.1, 1.0]);
const BLUE: Rgba = Rgba([0.1, 0.2, 0.85, 1.0]);
const INK: Rgba = Rgba([0.05, 0.05, 0.05, 1.0]);

fn bg() -> [u8; 4] {
    Style::default().background.to_u8()
}

fn px(img: &Image, x: f64, y: f64) -> [u8; 4] {
    img.pixel(x.floor() as u32, y.floor() as u32)
        .expect("pixel inside the image")
}

fn reddish(p: [u8; 4]) -> bool {
    i32::from(p[0]) > i32::from(p[2]) + 60 && i32::from(p[0]) > i32::from(p[1]) + 40
}

fn bluish(p: [u8; 4]) -> bool {
    i32::from(p[2]) > i32::from(p[0]) + 60 && i32::from(p[2]) > i32::from(p[1]) + 40
}

fn top(scale: f64) -> Camera {
    Camera::new(View::Top, [0.0; 3], scale, 400, 300).expect("camera")
}

#[test]
fn particle_where_it_is_background_elsewhere() {
    // 1 µm particle at (+1 µm, −0.5 µm), 1e8 px/m: centre at pixel (300, 200), radius 50 px.
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Sphere(Ball {
        center_m: [1e-6, -0.5e-6, 0.0],
        radius_m: 0.5e-6,
        color: RED,
    }))
    .expect("sphere");
    let img = f.finish().expect("image");
    assert!(reddish(px(&img, 300.0, 200.0)));
    // inside near the rim (45 px from the centre, any direction) still the particle
    for k in 0..8 {
        let a = std::f64::consts::TAU * k as f64 / 8.0;
        assert!(
            reddish(px(&img, 300.0 + 45.0 * a.cos(), 200.0 + 45.0 * a.sin())),
            "k={k}"
        );
        // just outside (55 px): background, exactly
        assert_eq!(
            px(&img, 300.0 + 55.0 * a.cos(), 200.0 + 55.0 * a.sin()),
            bg(),
            "k={k}"
        );
    }
    // the mirror position is empty
    assert_eq!(px(&img, 100.0, 100.0), bg());
    // shading: the lit side (upper left) is brighter than the shadow side
    let lit = px(&img, 280.0, 180.0);
    let dark = px(&img, 320.0, 220.0);
    let sum = |p: [u8; 4]| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    assert!(sum(lit) > sum(dark) + 60, "lit {lit:?} dark {dark:?}");
}

fn arrow_img(from: [f64; 3], to: [f64; 3]) -> Image {
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Arrow {
        from_m: from,
        to_m: to,
        color: INK,
    })
    .expect("arrow");
    f.finish().expect("image")
}

/// Dark pixels across the line perpendicular to the arrow at `(x, y)`, direction (dx, dy).
fn width_at(img: &Image, x: f64, y: f64, dx: f64, dy: f64) -> usize {
    (-12..=12)
        .filter(|&k| {
            let p = px(img, x - dy * f64::from(k), y + dx * f64::from(k));
            p[0] < 128
        })
        .count()
}

#[test]
fn arrow_points_the_right_way() {
    // from pixel (100, 150) to (300, 150): head (12 px, 10.8 px wide) at the right end
    let right = arrow_img([-1e-6, 0.0, 0.0], [1e-6, 0.0, 0.0]);
    let left = arrow_img([1e-6, 0.0, 0.0], [-1e-6, 0.0, 0.0]);
    let near_right_end = width_at(&right, 291.5, 150.5, 1.0, 0.0);
    let near_left_end = width_at(&right, 108.5, 150.5, 1.0, 0.0);
    assert!(near_right_end >= 5, "head width {near_right_end}");
    assert!(near_left_end <= 4, "shaft width {near_left_end}");
    assert!(near_right_end > near_left_end + 1);
    // reversed arrow: the head moves to the left end
    assert!(width_at(&left, 108.5, 150.5, 1.0, 0.0) >= 5);
    assert!(width_at(&left, 291.5, 150.5, 1.0, 0.0) <= 4);
    // nothing past the tip
    assert_eq!(px(&right, 304.0, 150.5), bg());
    // a diagonal arrow toward +x +y (up-right on the image) has its head up-right
    let diag = arrow_img([0.0, 0.0, 0.0], [1e-6, 1e-6, 0.0]);
    let (hx, hy) = (200.0 + 100.0, 150.0 - 100.0);
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let head = width_at(&diag, hx - 8.5 * s + 0.5, hy + 8.5 * s + 0.5, s, -s);
    let tail = width_at(&diag, 200.0 + 8.5 * s + 0.5, 150.0 - 8.5 * s + 0.5, s, -s);
    assert!(head > tail + 1, "head {head} tail {tail}");
}

#[test]
fn nearer_sphere_wins_where_two_overlap() {
    // top view: the sphere with larger z is nearer the viewer
    for order in [false, true] {
        let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
        let low = Primitive::Sphere(Ball {
            center_m: [-0.3e-6, 0.0, 0.0],
            radius_m: 0.5e-6,
            color: RED,
        });
        let high = Primitive::Sphere(Ball {
            center_m: [0.3e-6, 0.0, 1.2e-6],
            radius_m: 0.5e-6,
            color: BLUE,
        });
        let (a, b) = if order { (low, high) } else { (high, low) };
        f.push(a).expect("a");
        f.push(b).expect("b");
        let img = f.finish().expect("image");
        // overlap of the two discs: x in (−20, 20) px about the image centre
        assert!(bluish(px(&img, 200.5, 150.5)), "order {order}");
        assert!(bluish(px(&img, 190.5, 150.5)), "order {order}");
        // outside the blue disc but inside the red one
        assert!(reddish(px(&img, 140.5, 150.5)), "order {order}");
    }
}

#[test]
fn brick_on_a_long_slab_is_in_front_from_an_oblique_view() {
    // The cube's centre is farther from the viewer than the slab's, but it stands on the slab.
    let view = View::Oblique {
        azimuth_rad: std::f64::consts::PI,
        elevation_rad: 0.5,
    };
    let cam =
        Camera::fit(view, [-5.0, -1.0, -0.2], [5.0, 1.0, 1.2], 500, 300, 0.05).expect("camera");
    let slab = Primitive::Box(OrientedBox {
        center_m: [0.0, 0.0, 0.0],
        half_extents_m: [5.0, 0.5, 0.1],
        rotation: [0.0, 0.0, 0.0, 1.0],
        color: RED,
    });
    let cube = Primitive::Box(OrientedBox {
        center_m: [4.5, 0.0, 0.6],
        half_extents_m: [0.5, 0.5, 0.5],
        rotation: [0.0, 0.0, 0.0, 1.0],
        color: BLUE,
    });
    for order in [false, true] {
        let mut f = Frame::new(cam, Style::default()).expect("frame");
        let (a, b) = if order {
            (slab.clone(), cube.clone())
        } else {
            (cube.clone(), slab.clone())
        };
        f.push(a).expect("a");
        f.push(b).expect("b");
        let img = f.finish().expect("image");
        // the cube's bottom front edge midpoint, nudged up into the cube's front face,
        // lies over the slab's top face on the image
        let q = cam.project([4.0, 0.0, 0.15]);
        assert!(bluish(px(&img, q.x_px, q.y_px)), "order {order}");
        let s = cam.project([-4.0, 0.0, 0.1]);
        assert!(reddish(px(&img, s.x_px, s.y_px)), "order {order}");
    }
}

#[test]
fn envelope_times_100_is_drawn_at_the_right_radius() {
    // a 3 nm circle about the particle drawn ×100 is a 300 nm circle: 30 px at 1e8 px/m
    let about = [0.2e-6, 0.1e-6, 0.0];
    let pts: Vec<[f64; 3]> = (0..360)
        .map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / 360.0;
            [about[0] + 3e-9 * a.cos(), about[1] + 3e-9 * a.sin(), 0.0]
        })
        .collect();
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Sphere(Ball {
        center_m: about,
        radius_m: 0.1e-6,
        color: RED,
    }))
    .expect("sphere");
    f.scaled_loop(&pts, about, 100.0, INK).expect("loop");
    let img = f.finish().expect("image");
    let (cx, cy) = (220.0, 140.0);
    for k in 0..12 {
        let a = std::f64::consts::TAU * f64::from(k) / 12.0;
        // darkest pixel along the ray from the centre
        let mut best = (0.0, 255u8);
        let mut r = 15.0;
        while r < 45.0 {
            let p = px(&img, cx + r * a.cos(), cy - r * a.sin());
            if p[0] < best.1 {
                best = (r, p[0]);
            }
            r += 0.25;
        }
        assert!(best.1 < 100, "ray {k}: no loop found");
        assert!(
            (best.0 - 30.0).abs() <= 1.0,
            "ray {k}: loop at {} px",
            best.0
        );
    }
}

#[test]
fn scale_bar_has_its_stated_length() {
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.scale_bar(None, INK).expect("bar");
    // a fifth of 400 px is 80 px = 800 nm at 1e8 px/m: the longest 1-2-5 length is 500 nm
    assert_eq!(f.scale_bar_length_m(), Some(5e-7));
    let img = f.finish().expect("image");
    let y = 300 - 16;
    let dark: Vec<u32> = (0..400)
        .filter(|&x| img.pixel(x, y).expect("pixel")[0] < 128)
        .collect();
    let (first, last) = (dark[0], dark[dark.len() - 1]);
    // bar from x = 16 to 66 px, with end ticks 2 px wide centred on them
    assert_eq!(first, 15);
    assert_eq!(last, 66);
}

#[test]
fn label_text_appears_right_of_its_anchor() {
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Label {
        position_m: [0.0, 0.0, 0.0],
        text: "particle".into(),
        color: INK,
    })
    .expect("label");
    let img = f.finish().expect("image");
    let ink = |x0: u32, x1: u32, y0: u32, y1: u32| {
        (x0..x1)
            .flat_map(|x| (y0..y1).map(move |y| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y).expect("pixel")[0] < 100)
            .count()
    };
    // baseline 4 px above the anchor (200, 150), text starting 4 px right of it
    assert!(ink(204, 270, 130, 147) > 60);
    assert_eq!(ink(0, 200, 0, 300), 0);
    assert_eq!(ink(200, 400, 151, 300), 0);
}

#[test]
fn same_frame_same_bytes() {
    let build = || {
        let cam = Camera::new(View::oblique_default(), [0.0; 3], 200.0, 320, 240).expect("cam");
        let mut f = Frame::new(cam, Style::default()).expect("frame");
        for i in 0..20 {
            let x = f64::from(i) * 0.05 - 0.5;
            f.push(Primitive::Box(OrientedBox {
                center_m: [x, 0.0, 0.02 * f64::from(i % 3)],
                half_extents_m: [0.02, 0.03, 0.01],
                rotation: [0.0, 0.0, 0.38268343236508984, 0.9238795325112867],
                color: RED,
            }))
            .expect("box");
        }
        f.finish().expect("image")
    };
    assert_eq!(build().data(), build().data());
}

#[test]
fn bad_input_is_refused_with_the_field_named() {
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    let e = f
        .push(Primitive::Polyline {
            points_m: vec![[0.0; 3], [0.0, f64::NAN, 0.0]],
            closed: false,
            color: INK,
        })
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "polyline.points_m[1][1] must be finite, got NaN"
    );
    let e = f.scaled_loop(&[[0.0; 3]], [0.0; 3], -2.0, INK).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scaled_loop.factor = -2 is out of range: allowed (0, inf)"
    );
    assert!(f.primitives().is_empty());
    let style = Style {
        line_width_px: 0.0,
        ..Style::default()
    };
    let e = Frame::new(top(1e8), style).unwrap_err();
    assert_eq!(
        e.to_string(),
        "style.line_width_px = 0 is out of range: allowed (0, 200] px"
    );
    let mut small = Image::new(10, 10).expect("image");
    let e = f.draw_into(&mut small).unwrap_err();
    assert_eq!(e.to_string(), "image is 10x10 px, expected 400x300 px");
}

/// Depth of the first hit of the ray through pixel (x, y) on a sphere, if any.
fn ray_hit(cam: &Camera, x: f64, y: f64, c: [f64; 3], r: f64) -> Option<f64> {
    let q = cam.project(c);
    let dx = (x - q.x_px) / cam.pixels_per_m();
    let dy = (y - q.y_px) / cam.pixels_per_m();
    let rho2 = dx * dx + dy * dy;
    (rho2 < r * r).then(|| q.depth_m - (r * r - rho2).sqrt())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Two disjoint spheres seen from a random oblique direction: wherever both cover a pixel
    /// (away from the rims), the pixel has the colour of the one the viewing ray hits first.
    #[test]
    fn overlapping_spheres_show_the_first_hit(
        az in -3.1f64..3.1, el in -1.4f64..1.4,
        ax in -0.3f64..0.3, ay in -0.3f64..0.3, az_ in -0.3f64..0.3,
        ra in 0.15f64..0.4, rb in 0.15f64..0.4,
        phi in 0.0f64..std::f64::consts::TAU, u in 0.0f64..1.0, behind in any::<bool>(),
        gap in 0.001f64..0.3, red_first in any::<bool>(),
    ) {
        // b lies at distance ra + rb + gap from a, mostly along the viewing direction (in
        // front of or behind it), with a sideways offset small enough that the images overlap
        let view = View::Oblique { azimuth_rad: az, elevation_rad: el };
        let (right, up, fwd) = view.basis();
        let d = ra + rb + gap;
        let side = u * 0.7 * (ra + rb);
        let along = (d * d - side * side).sqrt() * if behind { 1.0 } else { -1.0 };
        let a = [ax, ay, az_];
        let b: [f64; 3] = std::array::from_fn(|i| {
            a[i] + along * fwd[i] + side * (phi.cos() * right[i] + phi.sin() * up[i])
        });
        let cam = Camera::new(view, [0.0; 3], 200.0, 400, 400).expect("camera");
        let sa = Primitive::Sphere(Ball { center_m: a, radius_m: ra, color: RED });
        let sb = Primitive::Sphere(Ball { center_m: b, radius_m: rb, color: BLUE });
        let mut f = Frame::new(cam, Style::default()).expect("frame");
        if red_first { f.push(sa).expect("a"); f.push(sb).expect("b"); }
        else { f.push(sb).expect("b"); f.push(sa).expect("a"); }
        let img = f.finish().expect("image");
        let (qa, qb) = (cam.project(a), cam.project(b));
        let mut checked = 0;
        for k in 1..20 {
            let t = f64::from(k) / 20.0;
            let x = (qa.x_px + t * (qb.x_px - qa.x_px)).floor() + 0.5;
            let y = (qa.y_px + t * (qb.y_px - qa.y_px)).floor() + 0.5;
            // keep 3 px away from either rim
            let inner = |c: [f64; 3], r: f64| ray_hit(&cam, x, y, c, r - 3.0 / 200.0);
            if let (Some(_), Some(_)) = (inner(a, ra), inner(b, rb)) {
                let da = ray_hit(&cam, x, y, a, ra).expect("hit a");
                let db = ray_hit(&cam, x, y, b, rb).expect("hit b");
                let p = px(&img, x, y);
                if da < db { prop_assert!(reddish(p), "expected red at ({x},{y}): {p:?}"); }
                else { prop_assert!(bluish(p), "expected blue at ({x},{y}): {p:?}"); }
                checked += 1;
            }
        }
        // the images overlap by at least 0.3 (ra + rb): some sample must fall in the overlap
        prop_assert!(checked >= 1);
    }

    /// A sphere anywhere in the image shows its colour at its projected centre.
    #[test]
    fn sphere_centre_pixel_has_its_colour(x in -1.8e-6f64..1.8e-6, y in -1.3e-6f64..1.3e-6,
                                          r in 0.05e-6f64..0.5e-6) {
        let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
        f.push(Primitive::Sphere(Ball { center_m: [x, y, 0.0], radius_m: r, color: BLUE })).expect("s");
        let img = f.finish().expect("image");
        let q = f.camera().project([x, y, 0.0]);
        prop_assert!(bluish(px(&img, q.x_px, q.y_px)));
    }
}

/// Entry distance of the viewing ray through pixel (x, y) into an oriented box, measured from a
/// plane 100 m in front of the camera centre, if the ray hits it (slab method).
fn ray_box(cam: &Camera, x: f64, y: f64, c: [f64; 3], half: [f64; 3], q: [f64; 4]) -> Option<f64> {
    let (r, u, f) = (cam.right(), cam.up(), cam.forward());
    let s = cam.pixels_per_m();
    let (dx, dy) = (
        (x - 0.5 * f64::from(cam.width_px())) / s,
        (0.5 * f64::from(cam.height_px()) - y) / s,
    );
    let o: [f64; 3] =
        std::array::from_fn(|i| cam.center_m()[i] + dx * r[i] + dy * u[i] - 100.0 * f[i]);
    // box axes from the unit quaternion
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let [qx, qy, qz, qw] = q.map(|v| v / n);
    let axes = [
        [
            1.0 - 2.0 * (qy * qy + qz * qz),
            2.0 * (qx * qy + qz * qw),
            2.0 * (qx * qz - qy * qw),
        ],
        [
            2.0 * (qx * qy - qz * qw),
            1.0 - 2.0 * (qx * qx + qz * qz),
            2.0 * (qy * qz + qx * qw),
        ],
        [
            2.0 * (qx * qz + qy * qw),
            2.0 * (qy * qz - qx * qw),
            1.0 - 2.0 * (qx * qx + qy * qy),
        ],
    ];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let rel = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..3 {
        let (p, d) = (dot(rel, axes[k]), dot(f, axes[k]));
        if d.abs() < 1e-12 {
            if p.abs() > half[k] {
                return None;
            }
        } else {
            let (a, b) = ((-half[k] - p) / d, (half[k] - p) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some(t0)
}

/// Two disjoint boxes of random size and orientation seen from an oblique direction: wherever
/// the viewing rays through a pixel and its neighbours 2 px away hit both boxes, the pixel must
/// have the colour of the box the rays enter first. Returns how many pixels were checked.
#[allow(clippy::too_many_arguments)]
fn check_boxes(
    az: f64,
    el: f64,
    ha: [f64; 3],
    hb: [f64; 3],
    qa: [f64; 4],
    qb: [f64; 4],
    phi: f64,
    u: f64,
    behind: bool,
    gap: f64,
    red_first: bool,
) -> Result<usize, String> {
    let norm = |q: [f64; 4]| q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let qa = qa.map(|v| v / norm(qa));
    let qb = qb.map(|v| v / norm(qb));
    let view = View::Oblique {
        azimuth_rad: az,
        elevation_rad: el,
    };
    let (right, up, fwd) = view.basis();
    // bounding spheres apart, so the boxes are disjoint
    let len = |h: [f64; 3]| (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let d = len(ha) + len(hb) + gap;
    let side = u * (len(ha) + len(hb));
    let along = (d * d - side * side).sqrt() * if behind { 1.0 } else { -1.0 };
    let a = [0.05, -0.02, 0.03];
    let b: [f64; 3] = std::array::from_fn(|i| {
        a[i] + along * fwd[i] + side * (phi.cos() * right[i] + phi.sin() * up[i])
    });
    let cam = Camera::new(view, [0.0; 3], 150.0, 400, 400).expect("camera");
    let ba = Primitive::Box(OrientedBox {
        center_m: a,
        half_extents_m: ha,
        rotation: qa,
        color: RED,
    });
    let bb = Primitive::Box(OrientedBox {
        center_m: b,
        half_extents_m: hb,
        rotation: qb,
        color: BLUE,
    });
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    if red_first {
        f.push(ba).expect("a");
        f.push(bb).expect("b");
    } else {
        f.push(bb).expect("b");
        f.push(ba).expect("a");
    }
    let img = f.finish().expect("image");
    let nearer = |x: f64, y: f64| -> Option<bool> {
        let ta = ray_box(&cam, x, y, a, ha, qa)?;
        let tb = ray_box(&cam, x, y, b, hb, qb)?;
        Some(ta < tb)
    };
    let mut checked = 0;
    for i in (0..400).step_by(5) {
        for j in (0..400).step_by(5) {
            let (x, y) = (f64::from(i) + 0.5, f64::from(j) + 0.5);
            let Some(red_near) = nearer(x, y) else {
                continue;
            };
            let around = [(2.0, 0.0), (-2.0, 0.0), (0.0, 2.0), (0.0, -2.0)];
            if around
                .iter()
                .any(|(ox, oy)| nearer(x + ox, y + oy) != Some(red_near))
            {
                continue;
            }
            let p = px(&img, x, y);
            let ok = if red_near {
                reddish_dim(p)
            } else {
                bluish_dim(p)
            };
            if !ok {
                return Err(format!(
                    "expected {} at ({x},{y}): {p:?}",
                    if red_near { "red" } else { "blue" }
                ));
            }
            checked += 1;
        }
    }
    Ok(checked)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn overlapping_boxes_show_the_first_hit(
        az in -3.1f64..3.1, el in -1.4f64..1.4,
        ha in prop::array::uniform3(0.02f64..0.8), hb in prop::array::uniform3(0.02f64..0.8),
        qa in prop::array::uniform4(-1.0f64..1.0), qb in prop::array::uniform4(-1.0f64..1.0),
        phi in 0.0f64..std::f64::consts::TAU, u in 0.0f64..0.5, behind in any::<bool>(),
        gap in 0.001f64..0.2, red_first in any::<bool>(),
    ) {
        let norm = |q: [f64; 4]| q.iter().map(|v| v * v).sum::<f64>().sqrt();
        prop_assume!(norm(qa) > 0.3 && norm(qb) > 0.3);
        let r = check_boxes(az, el, ha, hb, qa, qb, phi, u, behind, gap, red_first);
        prop_assert!(r.is_ok(), "{:?}", r);
    }
}

/// The same check on 60 seeded configurations, counting how many actually overlap on the
/// image, so that the property above is known not to pass vacuously.
#[test]
fn box_order_check_is_not_vacuous() {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut overlapping = 0;
    let mut pixels = 0;
    for _ in 0..60 {
        let mut g = |lo: f64, hi: f64| lo + (hi - lo) * next();
        let ha = [g(0.02, 0.8), g(0.02, 0.8), g(0.02, 0.8)];
        let hb = [g(0.02, 0.8), g(0.02, 0.8), g(0.02, 0.8)];
        let qa = [g(-1.0, 1.0), g(-1.0, 1.0), g(-1.0, 1.0), 1.0];
        let qb = [g(-1.0, 1.0), g(-1.0, 1.0), g(-1.0, 1.0), 1.0];
        let (az, el, phi, u, gap) = (
            g(-3.1, 3.1),
            g(-1.4, 1.4),
            g(0.0, std::f64::consts::TAU),
            g(0.0, 0.5),
            g(0.001, 0.2),
        );
        let (behind, red_first) = (g(0.0, 1.0) < 0.5, g(0.0, 1.0) < 0.5);
        let n = check_boxes(az, el, ha, hb, qa, qb, phi, u, behind, gap, red_first)
            .expect("nearer box shown");
        if n > 0 {
            overlapping += 1;
            pixels += n;
        }
    }
    assert!(
        overlapping >= 30,
        "only {overlapping} of 60 configurations overlapped"
    );
    assert!(pixels >= 1000, "only {pixels} pixels checked");
}

/// Hue tests that also accept faces in shadow (ambient 0.45 of the colour).
fn reddish_dim(p: [u8; 4]) -> bool {
    i32::from(p[0]) > 2 * i32::from(p[2]) && i32::from(p[0]) > 2 * i32::from(p[1])
}

fn bluish_dim(p: [u8; 4]) -> bool {
    i32::from(p[2]) > 2 * i32::from(p[0]) && i32::from(p[2]) > i32::from(p[1]) + 10
}

#[test]
fn beam_ellipse_fill_outline_and_side_view() {
    // top view, 1e8 px/m: a = 600 nm → 60 px, b = 300 nm → 30 px about (200, 150)
    let beam = Primitive::Ellipse {
        center_m: [0.0; 3],
        semi_axes_m: [600e-9, 300e-9],
        color: RED,
    };
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(beam.clone()).expect("beam");
    let img = f.finish().expect("image");
    let b = bg();
    // inside: a third of the colour's alpha over the background
    let inside = px(&img, 200.5, 150.5);
    let want = |c: f64, bgc: u8| (c * 255.0 / 3.0 + f64::from(bgc) * (2.0 / 3.0)).round();
    for k in 0..3 {
        assert!(
            (f64::from(inside[k]) - want(RED.0[k], b[k])).abs() <= 2.0,
            "{inside:?}"
        );
    }
    // the outline on the axes, at 60 px along x and 30 px along y
    assert!(reddish(px(&img, 260.0, 150.5)));
    assert!(reddish(px(&img, 140.0, 150.5)));
    assert!(reddish(px(&img, 200.5, 120.0)));
    // outside the ellipse, in its bounding box corner: background
    assert_eq!(px(&img, 250.5, 128.5), b);
    // side view: the ellipse is edge-on, a horizontal line through the image centre 120 px long
    let cam = Camera::new(View::Side, [0.0; 3], 1e8, 400, 300).expect("camera");
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    f.push(beam).expect("beam");
    let img = f.finish().expect("image");
    assert!(reddish(px(&img, 200.5, 150.0)));
    assert!(reddish(px(&img, 255.5, 150.0)));
    assert_eq!(px(&img, 265.5, 150.0), b);
    assert_eq!(px(&img, 200.5, 140.5), b);
}

#[test]
fn side_view_puts_plus_z_up() {
    let cam = Camera::new(View::Side, [0.0; 3], 1e8, 400, 300).expect("camera");
    let mut f = Frame::new(cam, Style::default()).expect("frame");
    f.push(Primitive::Sphere(Ball {
        center_m: [0.0, 0.0, 1e-6],
        radius_m: 0.2e-6,
        color: BLUE,
    }))
    .expect("sphere");
    let img = f.finish().expect("image");
    assert!(bluish(px(&img, 200.5, 50.5)));
    assert_eq!(px(&img, 200.5, 250.5), bg());
}

#[test]
fn slot_is_dashed_and_cursor_shows_what_is_behind() {
    // a 2 µm × 1 µm slot seen from above: its top edge y = 100 px from x = 100 to 300
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Slot(OrientedBox {
        center_m: [0.0; 3],
        half_extents_m: [1e-6, 0.5e-6, 0.2e-6],
        rotation: [0.0, 0.0, 0.0, 1.0],
        color: INK,
    }))
    .expect("slot");
    let img = f.finish().expect("image");
    let ink: Vec<bool> = (110..290)
        .map(|x| img.pixel(x, 100).expect("pixel")[0] < 128)
        .collect();
    let on = ink.iter().filter(|&&d| d).count();
    // dashes of 6 px and gaps of 4 px (line width 2): about 60 % ink, never solid
    assert!((90..=125).contains(&on), "{on} of 180 px inked");
    let switches = ink.windows(2).filter(|w| w[0] != w[1]).count();
    assert!(switches >= 30, "{switches} dash ends");
    // a see-through cursor over a red particle: the particle still shows through it
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    f.push(Primitive::Sphere(Ball {
        center_m: [0.0; 3],
        radius_m: 0.5e-6,
        color: RED,
    }))
    .expect("particle");
    f.push(Primitive::Cursor(Ball {
        center_m: [0.2e-6, 0.0, 0.0],
        radius_m: 0.2e-6,
        color: Rgba([0.1, 0.2, 0.85, 0.4]),
    }))
    .expect("cursor");
    let img = f.finish().expect("image");
    let p = px(&img, 228.5, 158.5); // inside the cursor, off its cross-hair
    assert!(p[0] > 60 && p[2] > 60, "blend of both: {p:?}");
}

#[test]
fn things_far_outside_the_image_leave_it_blank() {
    let mut f = Frame::new(top(1e8), Style::default()).expect("frame");
    for far in [1e-3, 1e6, 1e30] {
        f.push(Primitive::Sphere(Ball {
            center_m: [far, 0.0, 0.0],
            radius_m: 1e-6,
            color: RED,
        }))
        .expect("sphere");
        f.push(Primitive::Polyline {
            points_m: vec![[far, far, 0.0], [2.0 * far, far, 0.0]],
            closed: false,
            color: RED,
        })
        .expect("line");
        f.push(Primitive::Box(OrientedBox {
            center_m: [-far, 0.0, 0.0],
            half_extents_m: [1e-6; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            color: RED,
        }))
        .expect("box");
        f.push(Primitive::Arrow {
            from_m: [0.0, far, 0.0],
            to_m: [0.0, 2.0 * far, 0.0],
            color: RED,
        })
        .expect("arrow");
        f.push(Primitive::Label {
            position_m: [far, -far, 0.0],
            text: "far".into(),
            color: RED,
        })
        .expect("label");
    }
    let img = f.finish().expect("image");
    let b = bg();
    assert!(img.to_rgba8().chunks_exact(4).all(|p| p == b));
}
