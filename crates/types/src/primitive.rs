//! What can be drawn: the primitives, world frame, metres.
//!
//! Every scene draws with these (`[f64; 3]` points, `[x, y, z, w]` quaternions, RGBA in 0–1);
//! the renderer, the recording's Foxglove scene messages and the live views take them as they
//! are. [`Primitive::Cursor`] and [`Primitive::Slot`] are the haptic cursor and blueprint slots,
//! drawn from the same [`Ball`] and [`OrientedBox`] as a sphere and a box.
//!
//! A primitive serialises (serde) in the compact form a page's frame carries
//! (`docs/play.md`): an object tagged by `k` (`sphere`, `cursor`, `box`, `slot`, `ellipse`,
//! `line`, `arrow`, `label`) with short keys (`c`, `r`, `h`, `q`, `ax`, `p`, `a`, `b`, `col`),
//! a colour as its four channels.

use crate::value::{ValueError, finite, finite3};
use crate::vec3::{self, Vec3};

/// An RGBA colour, each channel in 0–1 (straight, not premultiplied alpha).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct Rgba(pub [f64; 4]);

impl Rgba {
    /// An opaque colour from 8-bit sRGB channels.
    pub fn from_u8(r: u8, g: u8, b: u8) -> Rgba {
        Rgba([
            f64::from(r) / 255.0,
            f64::from(g) / 255.0,
            f64::from(b) / 255.0,
            1.0,
        ])
    }

    /// The same colour with alpha `a` (0–1).
    pub fn with_alpha(self, a: f64) -> Rgba {
        let [r, g, b, _] = self.0;
        Rgba([r, g, b, a])
    }

    /// The colour as 8-bit straight RGBA (each channel rounded).
    pub fn to_u8(self) -> [u8; 4] {
        self.0.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)
    }

    /// Multiplies the RGB channels by `k` (≥ 0, results capped at 1); alpha unchanged.
    pub fn times(self, k: f64) -> Rgba {
        let [r, g, b, a] = self.0;
        Rgba([(r * k).min(1.0), (g * k).min(1.0), (b * k).min(1.0), a])
    }

    /// Mixes the RGB channels toward white by `t` (0 = unchanged, 1 = white).
    pub fn toward_white(self, t: f64) -> Rgba {
        let [r, g, b, a] = self.0;
        Rgba([r + (1.0 - r) * t, g + (1.0 - g) * t, b + (1.0 - b) * t, a])
    }

    /// Checks every channel is finite and in 0–1 (`field` names the colour in the error).
    pub fn validate(self, field: &str) -> Result<(), ValueError> {
        for (i, c) in self.0.iter().enumerate() {
            finite(|| format!("{field}[{i}]"), *c)?;
            if !(0.0..=1.0).contains(c) {
                return Err(ValueError::out_of_range(
                    format!("{field}[{i}]"),
                    *c,
                    "[0, 1]",
                ));
            }
        }
        Ok(())
    }
}

/// A ball, world frame, metres: what a [`Primitive::Sphere`] and the [`Primitive::Cursor`] are
/// drawn from.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ball {
    /// Centre, m.
    #[serde(rename = "c")]
    pub center_m: Vec3,
    /// Radius, m (> 0).
    #[serde(rename = "r")]
    pub radius_m: f64,
    /// Colour.
    #[serde(rename = "col")]
    pub color: Rgba,
}

impl Ball {
    /// Checks a finite centre, a positive radius and a colour in 0–1 (`kind` names the
    /// primitive in the error: `sphere.radius_m`, …).
    fn validate(&self, kind: &str) -> Result<(), ValueError> {
        finite3(&format!("{kind}.center_m"), self.center_m)?;
        positive(&format!("{kind}.radius_m"), self.radius_m, false)?;
        self.color.validate(&format!("{kind}.color"))
    }
}

/// A box rotated by a unit quaternion `[x, y, z, w]`, world frame, metres: what a
/// [`Primitive::Box`] and a blueprint [`Primitive::Slot`] are drawn from.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrientedBox {
    /// Centre, m.
    #[serde(rename = "c")]
    pub center_m: Vec3,
    /// Half extents along the box axes, m (each ≥ 0).
    #[serde(rename = "h")]
    pub half_extents_m: Vec3,
    /// Orientation as a unit quaternion `[x, y, z, w]` (normalised when drawn).
    #[serde(rename = "q")]
    pub rotation: [f64; 4],
    /// Colour.
    #[serde(rename = "col")]
    pub color: Rgba,
}

impl OrientedBox {
    /// The box's unit axes in the world frame (its rotation normalised first).
    pub fn axes(&self) -> [Vec3; 3] {
        vec3::axes(vec3::normq(self.rotation))
    }

    /// Checks a finite centre, half extents ≥ 0, a quaternion near unit length and a colour
    /// in 0–1 (`kind` names the primitive in the error: `box.rotation`, …).
    fn validate(&self, kind: &str) -> Result<(), ValueError> {
        finite3(&format!("{kind}.center_m"), self.center_m)?;
        for (i, h) in self.half_extents_m.iter().enumerate() {
            positive(&format!("{kind}.half_extents_m[{i}]"), *h, true)?;
        }
        quaternion(&format!("{kind}.rotation"), self.rotation)?;
        self.color.validate(&format!("{kind}.color"))
    }
}

/// A drawable primitive, world frame, metres.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "k", rename_all = "snake_case")]
pub enum Primitive {
    /// A shaded sphere.
    Sphere(Ball),
    /// A shaded box.
    Box(OrientedBox),
    /// A filled, outlined ellipse in a plane of constant z (e.g. the beam's cross-section).
    Ellipse {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: Vec3,
        /// Semi-axes along x and y, m (each ≥ 0).
        #[serde(rename = "ax")]
        semi_axes_m: [f64; 2],
        /// Colour (the fill uses a third of its alpha, the outline all of it).
        #[serde(rename = "col")]
        color: Rgba,
    },
    /// A polyline, closed into a loop when `closed`; drawn over the solids.
    #[serde(rename = "line")]
    Polyline {
        /// Vertices, m.
        #[serde(rename = "p")]
        points_m: Vec<Vec3>,
        /// Join the last vertex to the first.
        closed: bool,
        /// Colour.
        #[serde(rename = "col")]
        color: Rgba,
    },
    /// An arrow from `from_m` to `to_m` (e.g. a force drawn at some m/N scale); drawn over the
    /// solids.
    Arrow {
        /// Tail, m.
        #[serde(rename = "a")]
        from_m: Vec3,
        /// Head, m.
        #[serde(rename = "b")]
        to_m: Vec3,
        /// Colour.
        #[serde(rename = "col")]
        color: Rgba,
    },
    /// A text label whose baseline starts a few pixels right of and above its anchor; drawn
    /// last.
    Label {
        /// Anchor, m.
        #[serde(rename = "c")]
        position_m: Vec3,
        /// Text.
        text: String,
        /// Colour.
        #[serde(rename = "col")]
        color: Rgba,
    },
    /// The haptic cursor: a see-through sphere with an outline and a cross-hair at its centre
    /// (the body uses the colour's alpha, the outline and cross-hair are opaque).
    Cursor(Ball),
    /// A blueprint slot: the dashed edges of a box where a brick should go; drawn over the
    /// solids.
    Slot(OrientedBox),
}

fn positive(field: &str, v: f64, allow_zero: bool) -> Result<(), ValueError> {
    finite(|| field.to_string(), v)?;
    if v < 0.0 || (!allow_zero && v == 0.0) {
        return Err(ValueError::out_of_range(
            field.to_string(),
            v,
            if allow_zero {
                "[0, inf) m"
            } else {
                "(0, inf) m"
            },
        ));
    }
    Ok(())
}

fn quaternion(field: &str, q: [f64; 4]) -> Result<(), ValueError> {
    for (i, v) in q.iter().enumerate() {
        finite(|| format!("{field}[{i}]"), *v)?;
    }
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(0.5..=2.0).contains(&n) {
        return Err(ValueError::out_of_range(
            format!("{field} (norm)"),
            n,
            "[0.5, 2] (a unit quaternion [x, y, z, w], normalised when drawn)",
        ));
    }
    Ok(())
}

impl Primitive {
    /// One primitive of each kind, in the order the page's protocol documents them (for
    /// docs and tests of the serialised form).
    pub fn examples() -> Vec<Primitive> {
        let color = Rgba([0.5, 0.25, 1.0, 1.0]);
        let c = [0.25, -0.5, 1.0];
        let ball = Ball {
            center_m: c,
            radius_m: 0.5,
            color,
        };
        let block = OrientedBox {
            center_m: c,
            half_extents_m: [1.0, 2.0, 3.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            color,
        };
        vec![
            Primitive::Sphere(ball),
            Primitive::Cursor(ball),
            Primitive::Box(block),
            Primitive::Slot(block),
            Primitive::Ellipse {
                center_m: c,
                semi_axes_m: [0.5, 0.25],
                color,
            },
            Primitive::Polyline {
                points_m: vec![c, [0.0; 3]],
                closed: true,
                color,
            },
            Primitive::Arrow {
                from_m: c,
                to_m: [0.0; 3],
                color,
            },
            Primitive::Label {
                position_m: c,
                text: "blueprint 1/4".into(),
                color,
            },
        ]
    }

    /// Short name of the variant, used in error field names (`sphere`, `box`, …).
    pub fn kind(&self) -> &'static str {
        match self {
            Primitive::Sphere(_) => "sphere",
            Primitive::Box(_) => "box",
            Primitive::Ellipse { .. } => "ellipse",
            Primitive::Polyline { .. } => "polyline",
            Primitive::Arrow { .. } => "arrow",
            Primitive::Label { .. } => "label",
            Primitive::Cursor(_) => "cursor",
            Primitive::Slot(_) => "slot",
        }
    }

    /// Checks every number: finite points, positive sizes, colours in 0–1, quaternions near
    /// unit length.
    pub fn validate(&self) -> Result<(), ValueError> {
        let k = self.kind();
        let f = |name: &str| format!("{k}.{name}");
        match self {
            Primitive::Sphere(ball) | Primitive::Cursor(ball) => ball.validate(k),
            Primitive::Box(block) | Primitive::Slot(block) => block.validate(k),
            Primitive::Ellipse {
                center_m,
                semi_axes_m,
                color,
            } => {
                finite3(&f("center_m"), *center_m)?;
                for (i, h) in semi_axes_m.iter().enumerate() {
                    positive(&format!("{k}.semi_axes_m[{i}]"), *h, true)?;
                }
                color.validate(&f("color"))
            }
            Primitive::Polyline {
                points_m, color, ..
            } => {
                for (i, p) in points_m.iter().enumerate() {
                    finite3(&format!("{k}.points_m[{i}]"), *p)?;
                }
                color.validate(&f("color"))
            }
            Primitive::Arrow {
                from_m,
                to_m,
                color,
            } => {
                finite3(&f("from_m"), *from_m)?;
                finite3(&f("to_m"), *to_m)?;
                color.validate(&f("color"))
            }
            Primitive::Label {
                position_m, color, ..
            } => {
                finite3(&f("position_m"), *position_m)?;
                color.validate(&f("color"))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_primitive_serialises_with_its_short_keys_and_reads_back() {
        let want = [
            r#"{"k":"sphere","c":[0.25,-0.5,1.0],"r":0.5,"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"cursor","c":[0.25,-0.5,1.0],"r":0.5,"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"box","c":[0.25,-0.5,1.0],"h":[1.0,2.0,3.0],"q":[0.0,0.0,0.0,1.0],"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"slot","c":[0.25,-0.5,1.0],"h":[1.0,2.0,3.0],"q":[0.0,0.0,0.0,1.0],"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"ellipse","c":[0.25,-0.5,1.0],"ax":[0.5,0.25],"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"line","p":[[0.25,-0.5,1.0],[0.0,0.0,0.0]],"closed":true,"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"arrow","a":[0.25,-0.5,1.0],"b":[0.0,0.0,0.0],"col":[0.5,0.25,1.0,1.0]}"#,
            r#"{"k":"label","c":[0.25,-0.5,1.0],"text":"blueprint 1/4","col":[0.5,0.25,1.0,1.0]}"#,
        ];
        let examples = Primitive::examples();
        assert_eq!(examples.len(), want.len());
        for (p, want) in examples.iter().zip(want) {
            assert_eq!(serde_json::to_string(p).unwrap(), want);
            assert_eq!(&serde_json::from_str::<Primitive>(want).unwrap(), p);
        }
    }

    #[test]
    fn validation_names_field_and_range() {
        let p = Primitive::Sphere(Ball {
            center_m: [0.0, 0.0, 0.0],
            radius_m: 0.0,
            color: Rgba([1.0, 0.0, 0.0, 1.0]),
        });
        assert_eq!(
            p.validate().unwrap_err().to_string(),
            "sphere.radius_m = 0 is out of range: allowed (0, inf) m"
        );
        let p = Primitive::Arrow {
            from_m: [0.0; 3],
            to_m: [0.0, f64::INFINITY, 0.0],
            color: Rgba([1.0, 0.0, 0.0, 1.0]),
        };
        assert_eq!(
            p.validate().unwrap_err().to_string(),
            "arrow.to_m[1] must be finite, got inf"
        );
        let block = OrientedBox {
            center_m: [0.0; 3],
            half_extents_m: [1.0; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
            color: Rgba([1.5, 0.0, 0.0, 1.0]),
        };
        assert_eq!(
            Primitive::Box(block).validate().unwrap_err().to_string(),
            "box.color[0] = 1.5 is out of range: allowed [0, 1]"
        );
        let p = Primitive::Slot(OrientedBox {
            rotation: [0.0; 4],
            color: Rgba([1.0, 0.0, 0.0, 1.0]),
            ..block
        });
        assert!(
            p.validate()
                .unwrap_err()
                .to_string()
                .starts_with("slot.rotation (norm) = 0 is out of range")
        );
    }
}
