//! Orthographic cameras: a fixed top or side view, or an oblique 3D view, and the world → pixel
//! map.
//!
//! World frame: x right, y away, z up (m). Pixel frame: x right, y down, origin at the top-left
//! corner of the image, pixel centres at half-integers. Every view is orthographic, so one
//! metre in any plane facing the camera is `pixels_per_m` pixels everywhere on the image and a
//! scale bar is exact.

use crate::error::{RenderError, finite, finite3, out_of_range};
use haptic_types::vec3::{Vec3, add, box_corners, cross, dot, normalize, sub};
use haptic_types::{OrientedBox, Primitive};

/// Largest image side the renderer makes, px (`picture`'s).
pub use picture::MAX_SIDE_PX;

/// Where the camera looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// From above, looking down −z: +x right, +y up on the image (the optical-tweezers plane).
    Top,
    /// From −y, looking along +y: +x right, +z up on the image.
    Side,
    /// From a direction at `azimuth_rad` about +z (0 = from +x, −π/2 = from −y) and
    /// `elevation_rad` above the xy-plane, world +z kept upright on the image.
    Oblique {
        /// Azimuth of the eye direction about +z, rad, any finite value.
        azimuth_rad: f64,
        /// Elevation of the eye above the xy-plane, rad, in (−π/2, π/2).
        elevation_rad: f64,
    },
}

impl View {
    /// The default oblique view: from the front-left, 30° up (azimuth −60°).
    pub fn oblique_default() -> View {
        View::Oblique {
            azimuth_rad: -60f64.to_radians(),
            elevation_rad: 30f64.to_radians(),
        }
    }

    /// Unit vectors (right, up, forward) of the image in the world frame; `forward` points
    /// away from the viewer (depth grows along it).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        match *self {
            View::Top => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]),
            View::Side => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
            View::Oblique {
                azimuth_rad,
                elevation_rad,
            } => {
                let (se, ce) = elevation_rad.sin_cos();
                let (sa, ca) = azimuth_rad.sin_cos();
                let eye = [ce * ca, ce * sa, se];
                let right = normalize(cross([0.0, 0.0, 1.0], eye));
                let up = cross(eye, right);
                (right, up, [-eye[0], -eye[1], -eye[2]])
            }
        }
    }

    fn validate(&self) -> Result<(), RenderError> {
        if let View::Oblique {
            azimuth_rad,
            elevation_rad,
        } = *self
        {
            finite(|| "view.azimuth_rad".into(), azimuth_rad)?;
            finite(|| "view.elevation_rad".into(), elevation_rad)?;
            let lim = std::f64::consts::FRAC_PI_2;
            if elevation_rad.abs() >= lim {
                return Err(out_of_range(
                    "view.elevation_rad",
                    elevation_rad,
                    "(-pi/2, pi/2) rad; use View::Top for straight down",
                ));
            }
        }
        Ok(())
    }
}

impl std::str::FromStr for View {
    type Err = RenderError;

    /// `top`, `side` or `oblique` (the default oblique view), as typed on a command line.
    fn from_str(s: &str) -> Result<View, RenderError> {
        match s {
            "top" => Ok(View::Top),
            "side" => Ok(View::Side),
            "oblique" => Ok(View::oblique_default()),
            other => Err(RenderError::UnknownName {
                field: "view".into(),
                got: other.into(),
                allowed: "top, side, oblique",
            }),
        }
    }
}

/// The axis-aligned box (m) holding every primitive's extent: spheres and cursors with their
/// radius, boxes and slots with their rotated corners, ellipses with their semi-axes,
/// polylines and arrows with their points; labels count by their anchor only (text has no
/// size in metres). `None` when there is nothing with a position.
pub fn bounds(prims: &[Primitive]) -> Option<(Vec3, Vec3)> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut grow = |p: Vec3| {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    };
    for p in prims {
        match p {
            Primitive::Sphere(ball) | Primitive::Cursor(ball) => {
                grow(sub(ball.center_m, [ball.radius_m; 3]));
                grow(add(ball.center_m, [ball.radius_m; 3]));
            }
            Primitive::Box(block) | Primitive::Slot(block) => {
                for c in box_corners(block.center_m, block.axes(), block.half_extents_m) {
                    grow(c);
                }
            }
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                ..
            } => {
                let e = [semi_axes_m[0], semi_axes_m[1], 0.0];
                grow(sub(*center_m, e));
                grow(add(*center_m, e));
            }
            Primitive::Polyline { points_m, .. } => points_m.iter().for_each(|q| grow(*q)),
            Primitive::Arrow { from_m, to_m, .. } => {
                grow(*from_m);
                grow(*to_m);
            }
            Primitive::Label { position_m, .. } => grow(*position_m),
        }
    }
    (lo[0] <= hi[0]).then_some((lo, hi))
}

/// True for a backdrop: a box that is a slab (its smallest half extent under a tenth of its
/// largest) — the ground, a wall plate, a substrate. Backdrops are drawn but do not choose the
/// framing of a picture, and labels may lie over them.
pub fn is_backdrop(p: &Primitive) -> bool {
    match p {
        Primitive::Box(OrientedBox { half_extents_m, .. }) => {
            let lo = half_extents_m.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = half_extents_m.iter().copied().fold(0.0, f64::max);
            lo < 0.1 * hi
        }
        _ => false,
    }
}

/// The box (m) of the action: [`bounds`] of every primitive but the backdrops
/// ([`is_backdrop`]) and the labels; `None` when only those are drawn.
pub fn action_bounds(prims: &[Primitive]) -> Option<(Vec3, Vec3)> {
    let action: Vec<Primitive> = prims
        .iter()
        .filter(|p| !is_backdrop(p) && !matches!(p, Primitive::Label { .. }))
        .cloned()
        .collect();
    bounds(&action)
}

/// A point after projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    /// Image x, px (right).
    pub x_px: f64,
    /// Image y, px (down).
    pub y_px: f64,
    /// Distance along the viewing direction from the camera's centre plane, m (larger is
    /// farther from the viewer).
    pub depth_m: f64,
}

/// An orthographic camera: a view, the world point at the image centre, a scale and an image
/// size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    view: View,
    center_m: Vec3,
    pixels_per_m: f64,
    width_px: u32,
    height_px: u32,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
}

impl Camera {
    /// A camera looking from `view` at `center_m` (m, drawn at the image centre), with
    /// `pixels_per_m` pixels per metre (> 0) and an image of `width_px` × `height_px`
    /// (1..=[`MAX_SIDE_PX`] each).
    pub fn new(
        view: View,
        center_m: Vec3,
        pixels_per_m: f64,
        width_px: u32,
        height_px: u32,
    ) -> Result<Camera, RenderError> {
        view.validate()?;
        finite3("camera.center_m", center_m)?;
        finite(|| "camera.pixels_per_m".into(), pixels_per_m)?;
        if pixels_per_m <= 0.0 {
            return Err(out_of_range(
                "camera.pixels_per_m",
                pixels_per_m,
                "(0, inf) px/m",
            ));
        }
        check_size(width_px, height_px)?;
        let (right, up, forward) = view.basis();
        Ok(Camera {
            view,
            center_m,
            pixels_per_m,
            width_px,
            height_px,
            right,
            up,
            forward,
        })
    }

    /// A camera from `view` that fits the axis-aligned box `min_m`..`max_m` (m) into the image,
    /// leaving `margin` (fraction of each side, in [0, 0.45]) free around it.
    pub fn fit(
        view: View,
        min_m: Vec3,
        max_m: Vec3,
        width_px: u32,
        height_px: u32,
        margin: f64,
    ) -> Result<Camera, RenderError> {
        view.validate()?;
        finite3("fit.min_m", min_m)?;
        finite3("fit.max_m", max_m)?;
        finite(|| "fit.margin".into(), margin)?;
        if !(0.0..=0.45).contains(&margin) {
            return Err(out_of_range(
                "fit.margin",
                margin,
                "[0, 0.45] (fraction of each side)",
            ));
        }
        for i in 0..3 {
            if max_m[i] < min_m[i] {
                return Err(out_of_range(
                    format!("fit.max_m[{i}]"),
                    max_m[i],
                    "[fit.min_m, inf) m",
                ));
            }
        }
        check_size(width_px, height_px)?;
        let center = [
            0.5 * (min_m[0] + max_m[0]),
            0.5 * (min_m[1] + max_m[1]),
            0.5 * (min_m[2] + max_m[2]),
        ];
        let (right, up, _) = view.basis();
        let (mut ex, mut ey) = (0.0f64, 0.0f64);
        for k in 0..8 {
            let c = [
                if k & 1 == 0 { min_m[0] } else { max_m[0] },
                if k & 2 == 0 { min_m[1] } else { max_m[1] },
                if k & 4 == 0 { min_m[2] } else { max_m[2] },
            ];
            let d = sub(c, center);
            ex = ex.max(dot(d, right).abs());
            ey = ey.max(dot(d, up).abs());
        }
        let usable_w = f64::from(width_px) * (1.0 - 2.0 * margin);
        let usable_h = f64::from(height_px) * (1.0 - 2.0 * margin);
        let sx = if ex > 0.0 {
            usable_w / (2.0 * ex)
        } else {
            f64::INFINITY
        };
        let sy = if ey > 0.0 {
            usable_h / (2.0 * ey)
        } else {
            f64::INFINITY
        };
        let s = sx.min(sy);
        if !s.is_finite() {
            return Err(out_of_range(
                "fit.max_m - fit.min_m",
                0.0,
                "a box with non-zero extent on the image plane",
            ));
        }
        Camera::new(view, center, s, width_px, height_px)
    }

    /// A camera from `view` that fits every primitive ([`bounds`]) into the image with
    /// `margin` (fraction of each side, in [0, 0.45]) free around them. A single point (or
    /// nothing) has no extent to fit and gives an error.
    pub fn fit_primitives(
        view: View,
        prims: &[Primitive],
        width_px: u32,
        height_px: u32,
        margin: f64,
    ) -> Result<Camera, RenderError> {
        let (lo, hi) = bounds(prims).ok_or(out_of_range(
            "fit.primitives",
            0.0,
            "at least one primitive with a position",
        ))?;
        Camera::fit(view, lo, hi, width_px, height_px, margin)
    }

    /// Projects a world point (m).
    pub fn project(&self, p_m: Vec3) -> Projected {
        let d = sub(p_m, self.center_m);
        Projected {
            x_px: 0.5 * f64::from(self.width_px) + self.pixels_per_m * dot(d, self.right),
            y_px: 0.5 * f64::from(self.height_px) - self.pixels_per_m * dot(d, self.up),
            depth_m: dot(d, self.forward),
        }
    }

    /// The view.
    pub fn view(&self) -> View {
        self.view
    }

    /// The world point drawn at the image centre, m.
    pub fn center_m(&self) -> Vec3 {
        self.center_m
    }

    /// Scale, px per m.
    pub fn pixels_per_m(&self) -> f64 {
        self.pixels_per_m
    }

    /// Image width, px.
    pub fn width_px(&self) -> u32 {
        self.width_px
    }

    /// Image height, px.
    pub fn height_px(&self) -> u32 {
        self.height_px
    }

    /// Unit vector pointing right on the image, world frame.
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// Unit vector pointing up on the image, world frame.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// Unit vector pointing away from the viewer, world frame.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }
}

fn check_size(width_px: u32, height_px: u32) -> Result<(), RenderError> {
    Ok(picture::image::check_size(width_px, height_px)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::Ball;

    #[test]
    fn oblique_basis_is_orthonormal_and_right_handed() {
        for az in [-2.0, -1.0, 0.0, 0.7, 3.0] {
            for el in [-1.2, 0.0, 0.5, 1.5] {
                let v = View::Oblique {
                    azimuth_rad: az,
                    elevation_rad: el,
                };
                let (r, u, f) = v.basis();
                assert!((dot(r, r) - 1.0).abs() < 1e-12);
                assert!((dot(u, u) - 1.0).abs() < 1e-12);
                assert!(dot(r, u).abs() < 1e-12 && dot(r, f).abs() < 1e-12);
                // right × up points toward the viewer (−forward).
                let c = cross(r, u);
                assert!((dot(c, f) + 1.0).abs() < 1e-12);
                // world up never points down on the image
                assert!(u[2] >= 0.0);
            }
        }
    }

    #[test]
    fn oblique_from_minus_y_at_zero_elevation_is_the_side_view() {
        let v = View::Oblique {
            azimuth_rad: -std::f64::consts::FRAC_PI_2,
            elevation_rad: 0.0,
        };
        let (r, u, f) = v.basis();
        let (r2, u2, f2) = View::Side.basis();
        for i in 0..3 {
            assert!((r[i] - r2[i]).abs() < 1e-12);
            assert!((u[i] - u2[i]).abs() < 1e-12);
            assert!((f[i] - f2[i]).abs() < 1e-12);
        }
    }

    #[test]
    fn top_view_maps_plus_y_up_the_image() {
        let c = Camera::new(View::Top, [0.0; 3], 1e6, 200, 100).expect("camera");
        let p = c.project([1e-5, 2e-5, 0.0]);
        assert_eq!((p.x_px, p.y_px), (110.0, 30.0));
    }

    #[test]
    fn fit_puts_the_box_inside_the_margin() {
        let c = Camera::fit(View::Top, [-1.0, -2.0, 0.0], [1.0, 2.0, 0.0], 400, 400, 0.1)
            .expect("camera");
        // height limits: 4 m over 320 px
        assert!((c.pixels_per_m() - 80.0).abs() < 1e-12);
        let p = c.project([1.0, 2.0, 0.0]);
        assert!((p.y_px - 40.0).abs() < 1e-9 && (p.x_px - 280.0).abs() < 1e-9);
    }

    #[test]
    fn fitted_primitives_land_inside_the_margin() {
        use haptic_types::Rgba;
        let c = Rgba([1.0, 0.0, 0.0, 1.0]);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let prims = vec![
            Primitive::Sphere(Ball {
                center_m: [1.0, 2.0, 0.5],
                radius_m: 0.5,
                color: c,
            }),
            Primitive::Box(OrientedBox {
                center_m: [-1.0, 0.0, 0.0],
                half_extents_m: [1.0, 0.1, 0.1],
                rotation: [0.0, 0.0, h, h], // long axis turned onto y
                color: c,
            }),
        ];
        let (lo, hi) = bounds(&prims).expect("bounds");
        assert!((lo[0] + 1.1).abs() < 1e-12 && (hi[0] - 1.5).abs() < 1e-12);
        assert!((lo[1] + 1.0).abs() < 1e-12 && (hi[1] - 2.5).abs() < 1e-12);
        for view in [View::Top, View::Side, View::oblique_default()] {
            let cam = Camera::fit_primitives(view, &prims, 300, 200, 0.1).expect("camera");
            for k in 0..8 {
                let p = [
                    if k & 1 == 0 { lo[0] } else { hi[0] },
                    if k & 2 == 0 { lo[1] } else { hi[1] },
                    if k & 4 == 0 { lo[2] } else { hi[2] },
                ];
                let q = cam.project(p);
                assert!(
                    (30.0 - 1e-9..=270.0 + 1e-9).contains(&q.x_px),
                    "{view:?} {q:?}"
                );
                assert!(
                    (20.0 - 1e-9..=180.0 + 1e-9).contains(&q.y_px),
                    "{view:?} {q:?}"
                );
            }
        }
        assert!(Camera::fit_primitives(View::Top, &[], 10, 10, 0.1).is_err());
    }

    #[test]
    fn views_parse_from_their_names() {
        assert_eq!("top".parse::<View>(), Ok(View::Top));
        assert_eq!("oblique".parse::<View>(), Ok(View::oblique_default()));
        assert_eq!(
            "front".parse::<View>().unwrap_err().to_string(),
            "view = \"front\" is not known: allowed top, side, oblique"
        );
    }

    #[test]
    fn bad_cameras_name_the_field() {
        let e = Camera::new(View::Top, [0.0; 3], -1.0, 10, 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "camera.pixels_per_m = -1 is out of range: allowed (0, inf) px/m"
        );
        let e = Camera::new(View::Top, [0.0, f64::NAN, 0.0], 1.0, 10, 10).unwrap_err();
        assert_eq!(e.to_string(), "camera.center_m[1] must be finite, got NaN");
        let e = Camera::new(View::Top, [0.0; 3], 1.0, 0, 10).unwrap_err();
        assert_eq!(
            e.to_string(),
            "image size = 0x10 px is out of range: allowed 1..=8192 px per side"
        );
        let v = View::Oblique {
            azimuth_rad: 0.0,
            elevation_rad: 2.0,
        };
        let e = Camera::new(v, [0.0; 3], 1.0, 10, 10).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("view.elevation_rad = 2 is out of range")
        );
    }

    /// docs/render.md: "`View::oblique_default()` is azimuth −60°, elevation 30°".
    #[test]
    fn the_default_oblique_view_is_azimuth_minus_60_elevation_30() {
        let View::Oblique {
            azimuth_rad,
            elevation_rad,
        } = View::oblique_default()
        else {
            panic!("not oblique")
        };
        assert!(
            (azimuth_rad.to_degrees() + 60.0).abs() < 1e-9,
            "{azimuth_rad}"
        );
        assert!(
            (elevation_rad.to_degrees() - 30.0).abs() < 1e-9,
            "{elevation_rad}"
        );
    }

    /// docs/render.md: a backdrop is "a slab whose thinnest side is under a tenth of its
    /// widest" (both sides of the tenth).
    #[test]
    fn a_backdrop_is_a_slab_thinner_than_a_tenth_of_its_width() {
        let slab = |h: [f64; 3]| {
            Primitive::Box(OrientedBox {
                center_m: [0.0; 3],
                half_extents_m: h,
                rotation: [0.0, 0.0, 0.0, 1.0],
                color: haptic_types::Rgba([0.5, 0.5, 0.5, 1.0]),
            })
        };
        assert!(is_backdrop(&slab([1.0, 0.5, 0.099_999])));
        assert!(!is_backdrop(&slab([1.0, 0.5, 0.1])));
        assert!(is_backdrop(&slab([0.999, 10.0, 5.0])));
        assert!(!is_backdrop(&slab([1.0, 10.0, 5.0])));
        assert!(!is_backdrop(&Primitive::Sphere(Ball {
            center_m: [0.0; 3],
            radius_m: 1.0,
            color: haptic_types::Rgba([0.5, 0.5, 0.5, 1.0]),
        })));
    }
}
