//! Conversion of the scene's primitives, the cursor and the events to Foxglove schemas
//! (`foxglove.SceneUpdate`, `foxglove.FrameTransform`, `foxglove.Log`), protobuf-encoded.
//!
//! Positions are multiplied by the scene's display scale (e.g. 1e6: one micrometre shows as
//! one metre), so nanoscale worlds are visible in Foxglove's 3D panel. Timestamps are the tick
//! time from the session start, never the wall clock.

use foxglove::Encode;
use foxglove::schemas::{
    ArrowPrimitive, Color, CubePrimitive, CylinderPrimitive, FrameTransform, LinePrimitive, Log,
    Point3, Pose, Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, TextPrimitive, Timestamp,
    Vector3, line_primitive, log,
};
use haptic_types::vec3::{self, Vec3};
use haptic_types::{Event, Primitive, Rgba};

/// Frame of the world in the Foxglove channels.
pub const WORLD_FRAME: &str = "world";
/// Frame of the cursor (child of `world`).
pub const CURSOR_FRAME: &str = "cursor";

/// Tick time as a Foxglove timestamp.
pub fn timestamp(time_ns: u64) -> Timestamp {
    Timestamp::new(
        (time_ns / 1_000_000_000) as u32,
        (time_ns % 1_000_000_000) as u32,
    )
}

fn v3(p: Vec3, s: f64) -> Vector3 {
    Vector3 {
        x: p[0] * s,
        y: p[1] * s,
        z: p[2] * s,
    }
}

fn color(c: Rgba) -> Color {
    Color {
        r: c.0[0],
        g: c.0[1],
        b: c.0[2],
        a: c.0[3],
    }
}

fn identity() -> Quaternion {
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    }
}

fn pose(p: Vec3, s: f64, q: Quaternion) -> Option<Pose> {
    Some(Pose {
        position: Some(v3(p, s)),
        orientation: Some(q),
    })
}

/// Quaternion rotating +x onto the unit vector `d` (Foxglove arrows point along +x).
fn quat_x_to(d: Vec3) -> Quaternion {
    let w = 1.0 + d[0];
    if w < 1e-12 {
        return Quaternion {
            x: 0.0,
            y: 0.0,
            z: 1.0,
            w: 0.0,
        };
    }
    // (x × d, 1 + x·d) normalised; x × d = (0, −d_z, d_y).
    let (qy, qz) = (-d[2], d[1]);
    let n = (qy * qy + qz * qz + w * w).sqrt();
    Quaternion {
        x: 0.0,
        y: qy / n,
        z: qz / n,
        w: w / n,
    }
}

/// Entity id of a primitive: its kind and its index among the primitives of that kind in
/// drawing order (`sphere_0`, `box_3`, `cursor_0`, `polyline_0`), stable while the scene draws
/// the same bodies in the same order.
fn entity_id(p: &Primitive, counts: &mut [u32; 8]) -> String {
    let (k, name) = match p {
        Primitive::Sphere(_) => (0, "sphere"),
        Primitive::Cursor(_) => (1, "cursor"),
        Primitive::Box(_) => (2, "box"),
        Primitive::Slot(_) => (3, "slot"),
        Primitive::Ellipse { .. } => (4, "ellipse"),
        Primitive::Polyline { .. } => (5, "polyline"),
        Primitive::Arrow { .. } => (6, "arrow"),
        Primitive::Label { .. } => (7, "label"),
    };
    let n = counts[k];
    counts[k] += 1;
    format!("{name}_{n}")
}

/// Builds a `foxglove.SceneUpdate` with one entity per primitive (each body can be selected and
/// hidden in Foxglove's 3D panel).
pub fn scene_update(prims: &[Primitive], scale: f64, time_ns: u64) -> SceneUpdate {
    let mut entities = Vec::with_capacity(prims.len());
    let mut counts = [0u32; 8];
    for p in prims {
        let mut e = SceneEntity {
            timestamp: Some(timestamp(time_ns)),
            frame_id: WORLD_FRAME.to_string(),
            id: entity_id(p, &mut counts),
            ..Default::default()
        };
        add_primitive(&mut e, p, scale);
        entities.push(e);
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// Adds `p` to entity `e` as Foxglove's primitive of its kind (positions × `scale`).
fn add_primitive(e: &mut SceneEntity, p: &Primitive, scale: f64) {
    match p {
        // Foxglove has no cursor or dashed-slot primitive: a cursor is
        // drawn as its sphere, a blueprint slot as its box.
        Primitive::Sphere(ball) | Primitive::Cursor(ball) => e.spheres.push(SpherePrimitive {
            pose: pose(ball.center_m, scale, identity()),
            size: Some(v3([2.0 * ball.radius_m; 3], scale)),
            color: Some(color(ball.color)),
        }),
        Primitive::Box(block) | Primitive::Slot(block) => {
            let [x, y, z, w] = block.rotation;
            e.cubes.push(CubePrimitive {
                pose: pose(block.center_m, scale, Quaternion { x, y, z, w }),
                size: Some(v3(vec3::scale(block.half_extents_m, 2.0), scale)),
                color: Some(color(block.color)),
            })
        }
        Primitive::Ellipse {
            center_m,
            semi_axes_m,
            color: c,
        } => e.cylinders.push(CylinderPrimitive {
            // A flat elliptic disc: a cylinder of height 1 % of the larger axis.
            pose: pose(*center_m, scale, identity()),
            size: Some(v3(
                [
                    2.0 * semi_axes_m[0],
                    2.0 * semi_axes_m[1],
                    0.01 * semi_axes_m[0].max(semi_axes_m[1]),
                ],
                scale,
            )),
            bottom_scale: 1.0,
            top_scale: 1.0,
            color: Some(color(*c)),
        }),
        Primitive::Polyline {
            points_m,
            closed,
            color: c,
        } => e.lines.push(line(points_m, *closed, *c, scale)),
        Primitive::Arrow {
            from_m,
            to_m,
            color: c,
        } => e.arrows.extend(arrow(*from_m, *to_m, *c, scale)),
        Primitive::Label {
            position_m,
            text,
            color: c,
        } => e.texts.push(TextPrimitive {
            pose: pose(*position_m, scale, identity()),
            billboard: true,
            font_size: 14.0,
            scale_invariant: true,
            color: Some(color(*c)),
            text: text.clone(),
        }),
    }
}

/// A polyline (a loop when `closed`) of width 2 px on screen.
fn line(points_m: &[Vec3], closed: bool, c: Rgba, scale: f64) -> LinePrimitive {
    LinePrimitive {
        r#type: if closed {
            line_primitive::Type::LineLoop as i32
        } else {
            line_primitive::Type::LineStrip as i32
        },
        pose: pose([0.0; 3], scale, identity()),
        thickness: 2.0,
        scale_invariant: true,
        points: points_m
            .iter()
            .map(|q| Point3 {
                x: q[0] * scale,
                y: q[1] * scale,
                z: q[2] * scale,
            })
            .collect(),
        color: Some(color(c)),
        colors: Vec::new(),
        indices: Vec::new(),
    }
}

/// An arrow from `from_m` to `to_m` (none when of zero or non-finite length).
fn arrow(from_m: Vec3, to_m: Vec3, c: Rgba, scale: f64) -> Option<ArrowPrimitive> {
    let d = vec3::sub(to_m, from_m);
    let len = vec3::norm(d) * scale;
    (len > 0.0 && len.is_finite()).then(|| ArrowPrimitive {
        pose: pose(from_m, scale, quat_x_to(vec3::scale(d, scale / len))),
        shaft_length: 0.75 * len,
        shaft_diameter: 0.05 * len,
        head_length: 0.25 * len,
        head_diameter: 0.12 * len,
        color: Some(color(c)),
    })
}

/// The cursor frame relative to the world frame.
pub fn cursor_transform(cursor_m: Vec3, scale: f64, time_ns: u64) -> FrameTransform {
    FrameTransform {
        timestamp: Some(timestamp(time_ns)),
        parent_frame_id: WORLD_FRAME.to_string(),
        child_frame_id: CURSOR_FRAME.to_string(),
        translation: Some(v3(cursor_m, scale)),
        rotation: Some(identity()),
    }
}

/// A log line for an event; loop warnings (invalid input, clamp, missed deadline) are warnings.
pub fn event_log(ev: &Event, time_ns: u64) -> Log {
    let warn = matches!(
        ev.name.as_str(),
        "input.invalid"
            | "force.clamped"
            | "force.invalid"
            | "deadline.missed"
            | "scene.stiffness_over_cap"
            | "device.sample_late"
            | "device.lost"
    );
    Log {
        timestamp: Some(timestamp(time_ns)),
        level: if warn {
            log::Level::Warning as i32
        } else {
            log::Level::Info as i32
        },
        message: if ev.detail.is_empty() {
            ev.name.clone()
        } else {
            format!("{}: {}", ev.name, ev.detail)
        },
        name: "nanohaptics".to_string(),
        file: String::new(),
        line: 0,
    }
}

/// Protobuf bytes of a Foxglove message.
pub fn encode<T: Encode>(msg: &T) -> Vec<u8> {
    let mut buf = Vec::with_capacity(msg.encoded_len().unwrap_or(256));
    // Encoding into a growable Vec cannot run out of space.
    match msg.encode(&mut buf) {
        Ok(()) => buf,
        Err(_) => Vec::new(),
    }
}

/// Name, encoding and data of the schema of a Foxglove message type.
pub fn schema<T: Encode>() -> (String, String, Vec<u8>) {
    match T::get_schema() {
        Some(s) => (s.name, s.encoding, s.data.into_owned()),
        None => (String::new(), String::new(), Vec::new()),
    }
}

/// The points of the polylines of entity `id` in an encoded `foxglove.SceneUpdate` (display
/// units, as written), in order; empty when the update has no such entity.
pub fn polyline_points(data: &[u8], id: &str) -> Result<Vec<[f64; 3]>, String> {
    use foxglove::Decode;
    let u = SceneUpdate::decode(data).map_err(|e| e.to_string())?;
    Ok(u.entities
        .iter()
        .filter(|e| e.id == id)
        .flat_map(|e| e.lines.iter())
        .flat_map(|l| l.points.iter())
        .map(|q| [q.x, q.y, q.z])
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::Ball;

    #[test]
    fn arrow_orientation_points_along_the_force() {
        for d in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
            [-1.0, 0.0, 0.0],
        ] {
            let q = quat_x_to(d);
            // Rotated x axis = first column of the rotation matrix.
            let (x, y, z, w) = (q.x, q.y, q.z, q.w);
            let col = [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ];
            for k in 0..3 {
                assert!((col[k] - d[k]).abs() < 1e-12, "{d:?} -> {col:?}");
            }
        }
    }

    #[test]
    fn schemas_are_the_foxglove_protobuf_ones() {
        let (name, enc, data) = schema::<SceneUpdate>();
        assert_eq!(
            (name.as_str(), enc.as_str()),
            ("foxglove.SceneUpdate", "protobuf")
        );
        assert!(data.len() > 100);
        assert_eq!(schema::<FrameTransform>().0, "foxglove.FrameTransform");
        assert_eq!(schema::<Log>().0, "foxglove.Log");
        let u = scene_update(
            &[Primitive::Sphere(Ball {
                center_m: [1e-6, 0.0, 0.0],
                radius_m: 5e-7,
                color: Rgba([1.0, 0.0, 0.0, 1.0]),
            })],
            1e6,
            1_500_000_000,
        );
        let s = &u.entities[0].spheres[0];
        assert_eq!(s.size.map(|v| v.x), Some(1.0));
        assert_eq!(
            u.entities[0].timestamp,
            Some(Timestamp::new(1, 500_000_000))
        );
        // Decodes back to the same message.
        let bytes = encode(&u);
        let back = <SceneUpdate as foxglove::Decode>::decode(bytes.as_slice());
        assert_eq!(back.ok(), Some(u));
    }
}
