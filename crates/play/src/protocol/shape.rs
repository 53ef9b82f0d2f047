//! The shapes a `frame` carries: a scene's primitives as the page draws them.

use serde::{Deserialize, Serialize};

/// A shape as the page draws it: world frame, metres, tagged by `k`, with short keys (a
/// frame carries dozens of them 60 times a second). Made from a scene's
/// [`haptic_types::primitive::Primitive`] by [`Shape::from`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "k", rename_all = "snake_case")]
pub enum Shape {
    /// A shaded sphere.
    Sphere {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Radius, m.
        #[serde(rename = "r")]
        radius_m: f64,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// The haptic cursor: a see-through sphere with an outline.
    Cursor {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Radius, m.
        #[serde(rename = "r")]
        radius_m: f64,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A shaded box (drawn dashed and see-through when its alpha is below 0.5).
    Box {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Half extents along the box axes, m.
        #[serde(rename = "h")]
        half_extents_m: [f64; 3],
        /// Orientation, unit quaternion `[x, y, z, w]`.
        #[serde(rename = "q")]
        rotation: [f64; 4],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A blueprint slot: the dashed edges of a box where a brick should go.
    Slot {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Half extents along the box axes, m.
        #[serde(rename = "h")]
        half_extents_m: [f64; 3],
        /// Orientation, unit quaternion `[x, y, z, w]`.
        #[serde(rename = "q")]
        rotation: [f64; 4],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// An ellipse in a plane of constant z (the page draws it as a disc of radius `ax[0]`).
    Ellipse {
        /// Centre, m.
        #[serde(rename = "c")]
        center_m: [f64; 3],
        /// Semi-axes along x and y, m.
        #[serde(rename = "ax")]
        semi_axes_m: [f64; 2],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A polyline, dashed, over the ground.
    #[serde(rename = "line")]
    Line {
        /// Vertices, m.
        #[serde(rename = "p")]
        points_m: Vec<[f64; 3]>,
        /// Join the last vertex to the first.
        closed: bool,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// An arrow (a force drawn at the scene's m/N scale), drawn over the solids.
    Arrow {
        /// Tail, m.
        #[serde(rename = "a")]
        from_m: [f64; 3],
        /// Head, m.
        #[serde(rename = "b")]
        to_m: [f64; 3],
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
    /// A text label (the first one is also the page's task line).
    Label {
        /// Anchor, m.
        #[serde(rename = "c")]
        position_m: [f64; 3],
        /// Text.
        text: String,
        /// Colour, RGBA each 0–1.
        #[serde(rename = "col")]
        color: [f64; 4],
    },
}

impl From<&haptic_types::primitive::Primitive> for Shape {
    fn from(p: &haptic_types::primitive::Primitive) -> Self {
        use haptic_types::primitive::Primitive as P;
        match p {
            P::Sphere {
                center_m,
                radius_m,
                color,
            } => Shape::Sphere {
                center_m: *center_m,
                radius_m: *radius_m,
                color: color.0,
            },
            P::Cursor {
                center_m,
                radius_m,
                color,
            } => Shape::Cursor {
                center_m: *center_m,
                radius_m: *radius_m,
                color: color.0,
            },
            P::Box {
                center_m,
                half_extents_m,
                rotation,
                color,
            } => Shape::Box {
                center_m: *center_m,
                half_extents_m: *half_extents_m,
                rotation: *rotation,
                color: color.0,
            },
            P::Slot {
                center_m,
                half_extents_m,
                rotation,
                color,
            } => Shape::Slot {
                center_m: *center_m,
                half_extents_m: *half_extents_m,
                rotation: *rotation,
                color: color.0,
            },
            P::Ellipse {
                center_m,
                semi_axes_m,
                color,
            } => Shape::Ellipse {
                center_m: *center_m,
                semi_axes_m: *semi_axes_m,
                color: color.0,
            },
            P::Polyline {
                points_m,
                closed,
                color,
            } => Shape::Line {
                points_m: points_m.clone(),
                closed: *closed,
                color: color.0,
            },
            P::Arrow {
                from_m,
                to_m,
                color,
            } => Shape::Arrow {
                from_m: *from_m,
                to_m: *to_m,
                color: color.0,
            },
            P::Label {
                position_m,
                text,
                color,
            } => Shape::Label {
                position_m: *position_m,
                text: text.clone(),
                color: color.0,
            },
        }
    }
}
