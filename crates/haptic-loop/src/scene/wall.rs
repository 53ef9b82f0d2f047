//! The stiff virtual wall: the classic haptic-rendering calibration scene.
//!
//! A plane through `point_m` with unit normal `n`; the free side is `n·(x − p) > 0`. Inside
//! the wall the cursor feels `F = max(0, k·d − b·v_n)·n` with penetration depth `d` (m) and
//! normal velocity `v_n` (m/s, backward difference of the cursor over one tick). The force
//! never pulls the cursor into the wall. `k` is capped at the device's stiffness limit mapped to
//! the world; the cap is reported by a `wall.stiffness_capped` event on the first tick.
//!
//! It checks the loop's stiffness cap and force clamp: pressed `d` deep, a wall of stiffness
//! `k` gives `k·d` until the device maximum, then exactly the maximum, in the same direction.

use super::{WorldKind, world_table};
use haptic_engine::check::{SceneError, check_positive, check_range, out_of_range_text};
use haptic_engine::scene::Scene;
use haptic_engine::scene::SceneInput;
use haptic_engine::scene::SceneOutput;
use haptic_types::Event;
use haptic_types::Rgba;
use haptic_types::vec3::{self, Vec3};
use haptic_types::{Ball, OrientedBox, Primitive};
use serde::{Deserialize, Serialize};
use world_form::Limits;
use world_form::fmt_num;

/// The wall in the scene registry: `kind = "wall"`, table `[wall]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "wall",
    check: |text| super::table::pick::<WallParams>(text, "wall").map(drop),
    build: |text, config| {
        let p: WallParams = world_table(text, "wall")?;
        let scene = WallScene::new(&p, &config.world_limits(), config.dt_s())?;
        Ok(Box::new(scene))
    },
};

/// Parameters of the wall (`[wall]` table), SI.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct WallParams {
    /// Outward normal of the wall (normalised on load; must be non-zero).
    #[serde(deserialize_with = "world_form::exact::array")]
    pub normal: Vec3,
    /// A point on the wall surface, world frame, m.
    #[serde(default)]
    #[serde(deserialize_with = "world_form::exact::array")]
    pub point_m: Vec3,
    /// Wall stiffness, world frame, N/m. Allowed: 0 < k ≤ 1e12 (capped at the device limit).
    pub stiffness_n_per_m: f64,
    /// Damping while in contact, N·s/m. Allowed: 0–1e9.
    #[serde(default)]
    pub damping_n_s_per_m: f64,
    /// Half side of the drawn wall slab, m.
    #[serde(default = "default_half_size")]
    pub draw_half_size_m: f64,
    /// Radius of the drawn cursor sphere, m.
    #[serde(default = "default_cursor_radius")]
    pub cursor_radius_m: f64,
}

fn default_half_size() -> f64 {
    0.04
}
fn default_cursor_radius() -> f64 {
    0.002
}

/// The wall scene's state.
#[derive(Clone, Debug)]
pub struct WallScene {
    normal: Vec3,
    point_m: Vec3,
    stiffness: f64,
    requested_stiffness: f64,
    damping: f64,
    dt_s: f64,
    half_size: f64,
    cursor_radius: f64,
    cursor_m: Vec3,
    prev_cursor_m: Option<Vec3>,
    penetration_m: f64,
    in_contact: bool,
    force_n: Vec3,
    started: bool,
}

impl WallScene {
    /// A wall from `params`, rendered within the device's `limits` in the world (its stiffness
    /// is capped at `limits.max_stiffness_n_per_m`), stepped every `dt_s` (s).
    pub fn new(params: &WallParams, limits: &Limits, dt_s: f64) -> Result<Self, SceneError> {
        let cap_n_per_m = limits.max_stiffness_n_per_m;
        let len = vec3::norm(params.normal);
        if !(len.is_finite() && len > 0.0) {
            return Err(out_of_range_text(
                "wall.normal",
                format!(
                    "[{}, {}, {}]",
                    fmt_num(params.normal[0]),
                    fmt_num(params.normal[1]),
                    fmt_num(params.normal[2])
                ),
                "a non-zero finite vector",
            ));
        }
        for (k, c) in params.point_m.iter().enumerate() {
            check_range(&format!("wall.point_m[{k}]"), *c, -1e3, 1e3)?;
        }
        check_positive("wall.stiffness_n_per_m", params.stiffness_n_per_m, 1e12)?;
        check_range("wall.damping_n_s_per_m", params.damping_n_s_per_m, 0.0, 1e9)?;
        check_positive("wall.draw_half_size_m", params.draw_half_size_m, 1e3)?;
        check_positive("wall.cursor_radius_m", params.cursor_radius_m, 1e3)?;
        Ok(WallScene {
            normal: vec3::scale(params.normal, 1.0 / len),
            point_m: params.point_m,
            stiffness: params.stiffness_n_per_m.min(cap_n_per_m),
            requested_stiffness: params.stiffness_n_per_m,
            damping: params.damping_n_s_per_m,
            dt_s,
            half_size: params.draw_half_size_m,
            cursor_radius: params.cursor_radius_m,
            cursor_m: params.point_m,
            prev_cursor_m: None,
            penetration_m: 0.0,
            in_contact: false,
            force_n: [0.0; 3],
            started: false,
        })
    }

    /// The stiffness in use, N/m (world frame).
    pub fn stiffness_n_per_m(&self) -> f64 {
        self.stiffness
    }
}

/// What happens at the wall. Serialized with a `type` tag and named fields, the detail of the
/// loop's `wall.<type>` event.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum WallEvent {
    /// The wall asked for more stiffness than the device renders (first tick only).
    StiffnessCapped {
        /// The stiffness asked for, N/m.
        requested_n_per_m: f64,
        /// The stiffness rendered: the device's limit in the world, N/m.
        rendered_n_per_m: f64,
    },
    /// The cursor entered the wall.
    ContactBegin {
        /// Depth of the cursor in the wall at the first tick of contact, m.
        penetration_m: f64,
    },
    /// The cursor left the wall.
    ContactEnd,
}

impl WallEvent {
    /// The event's short name (its `type` tag).
    pub fn name(&self) -> &'static str {
        match self {
            WallEvent::StiffnessCapped { .. } => "stiffness_capped",
            WallEvent::ContactBegin { .. } => "contact_begin",
            WallEvent::ContactEnd => "contact_end",
        }
    }
}

/// Adds a wall event to the tick's output: name `wall.<type>`, detail its JSON form.
fn push(out: &mut SceneOutput, e: &WallEvent) {
    out.events.push(Event::new(
        format!("wall.{}", e.name()),
        serde_json::to_string(e).unwrap_or_default(),
    ));
}

/// Unit quaternion `[x, y, z, w]` rotating +z onto the unit vector `n`.
pub fn quat_z_to(n: Vec3) -> [f64; 4] {
    let w = 1.0 + n[2];
    if w < 1e-12 {
        return [1.0, 0.0, 0.0, 0.0]; // n = −z: half turn about x
    }
    // q = (z × n, 1 + z·n) normalised.
    let q = [-n[1], n[0], 0.0, w];
    let len = (q[0] * q[0] + q[1] * q[1] + q[3] * q[3]).sqrt();
    [q[0] / len, q[1] / len, 0.0, q[3] / len]
}

impl Scene for WallScene {
    fn kind(&self) -> &'static str {
        "wall"
    }

    fn state_fields(&self) -> Vec<String> {
        ["penetration_m", "in_contact", "stiffness_n_per_m"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    fn local_primitives(&self, out: &mut haptic_types::local::WorldPrimitives) {
        // The wall's face as a plane (its damper stays with the simulator).
        out.planes.push(haptic_types::local::Plane {
            normal: self.normal,
            offset_m: vec3::dot(self.point_m, self.normal),
            stiffness_n_per_m: self.stiffness,
        });
    }

    fn step(&mut self, input: &SceneInput, out: &mut SceneOutput) {
        if !self.started {
            self.started = true;
            if self.stiffness < self.requested_stiffness {
                push(
                    out,
                    &WallEvent::StiffnessCapped {
                        requested_n_per_m: self.requested_stiffness,
                        rendered_n_per_m: self.stiffness,
                    },
                );
            }
        }
        self.cursor_m = input.cursor_m;
        let v_n = match self.prev_cursor_m {
            Some(prev) => vec3::dot(vec3::sub(input.cursor_m, prev), self.normal) / self.dt_s,
            None => 0.0,
        };
        self.prev_cursor_m = Some(input.cursor_m);
        let d = -vec3::dot(vec3::sub(input.cursor_m, self.point_m), self.normal);
        let contact = d > 0.0;
        self.penetration_m = d.max(0.0);
        if contact != self.in_contact {
            let e = if contact {
                WallEvent::ContactBegin {
                    penetration_m: self.penetration_m,
                }
            } else {
                WallEvent::ContactEnd
            };
            push(out, &e);
        }
        self.in_contact = contact;
        if contact {
            let mag = (self.stiffness * d - self.damping * v_n).max(0.0);
            self.force_n = vec3::scale(self.normal, mag);
            out.stiffness_n_per_m = self.stiffness;
            out.stiffness_axis = Some(self.normal);
        } else {
            self.force_n = [0.0; 3];
        }
        out.force_n = self.force_n;
    }

    fn state(&self, out: &mut Vec<f64>) {
        out.push(self.penetration_m);
        out.push(if self.in_contact { 1.0 } else { 0.0 });
        out.push(self.stiffness);
    }

    fn draw(&self, out: &mut Vec<Primitive>) {
        let thickness = self.half_size * 0.05;
        out.push(Primitive::Box(OrientedBox {
            center_m: vec3::sub(self.point_m, vec3::scale(self.normal, thickness)),
            half_extents_m: [self.half_size, self.half_size, thickness],
            rotation: quat_z_to(self.normal),
            color: Rgba([0.55, 0.6, 0.7, 0.8]),
        }));
        let color = if self.in_contact {
            Rgba([0.9, 0.3, 0.2, 1.0])
        } else {
            Rgba([0.2, 0.6, 0.9, 1.0])
        };
        out.push(Primitive::Sphere(Ball {
            center_m: self.cursor_m,
            radius_m: self.cursor_radius,
            color,
        }));
        if vec3::norm(self.force_n) > 0.0 {
            // Arrow length: 1 cm per newton of world force (drawing only).
            let tip = vec3::add(self.cursor_m, vec3::scale(self.force_n, 0.01));
            out.push(Primitive::Arrow {
                from_m: self.cursor_m,
                to_m: tip,
                color: Rgba([1.0, 0.8, 0.1, 1.0]),
            });
        }
        out.push(Primitive::Label {
            position_m: vec3::add(self.point_m, vec3::scale(self.normal, self.half_size * 0.5)),
            text: format!("wall k = {} N/m", self.stiffness),
            color: Rgba([1.0, 1.0, 1.0, 1.0]),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall(k: f64, cap: f64, b: f64) -> WallScene {
        WallScene::new(
            &WallParams {
                normal: [0.0, 0.0, 2.0],
                point_m: [0.0, 0.0, 0.01],
                stiffness_n_per_m: k,
                damping_n_s_per_m: b,
                draw_half_size_m: 0.04,
                cursor_radius_m: 0.002,
            },
            &Limits {
                max_force_n: 8.0,
                max_stiffness_n_per_m: cap,
            },
            1e-3,
        )
        .unwrap()
    }

    fn step(w: &mut WallScene, tick: u64, z: f64) -> SceneOutput {
        let mut out = SceneOutput::default();
        w.step(
            &SceneInput {
                tick,
                dt_s: 1e-3,
                cursor_m: [0.003, -0.002, z],
                buttons: Default::default(),
                input_valid: true,
            },
            &mut out,
        );
        out
    }

    #[test]
    fn hooke_force_and_capped_stiffness() {
        let mut w = wall(5000.0, 3000.0, 0.0);
        let out = step(&mut w, 0, 0.008);
        assert_eq!(out.events[0].name, "wall.stiffness_capped");
        assert_eq!(
            out.events[0].detail,
            r#"{"type":"stiffness_capped","requested_n_per_m":5000.0,"rendered_n_per_m":3000.0}"#
        );
        assert_eq!(out.events[1].name, "wall.contact_begin");
        assert_eq!(
            out.events[1].detail,
            r#"{"type":"contact_begin","penetration_m":0.002}"#
        );
        // 2 mm deep at the capped 3000 N/m: 6 N along +z (normal normalised).
        assert!((out.force_n[2] - 6.0).abs() < 1e-12 && out.force_n[0] == 0.0);
        assert_eq!(out.stiffness_n_per_m, 3000.0);
        let out = step(&mut w, 1, 0.02);
        assert_eq!(out.force_n, [0.0; 3]);
        assert_eq!(out.events[0].name, "wall.contact_end");
        assert_eq!(out.events[0].detail, r#"{"type":"contact_end"}"#);
    }

    #[test]
    fn damping_never_pulls_into_the_wall() {
        let mut w = wall(1000.0, 3000.0, 50.0);
        step(&mut w, 0, 0.0095);
        // Leaving fast (v_n = +0.4 m/s): k d − b v_n < 0, so no force rather than a pull.
        let out = step(&mut w, 1, 0.0099 + 0.0);
        assert!(out.force_n[2] >= 0.0);
        assert_eq!(out.force_n[2], 0.0);
    }

    #[test]
    fn quaternion_rotates_z_onto_normal() {
        for n in [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [0.0, 0.6, 0.8],
            [0.0, 0.0, -1.0],
        ] {
            let q = quat_z_to(n);
            // Rotated z axis = third column of the rotation matrix.
            let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
            let col = [
                2.0 * (x * z + w * y),
                2.0 * (y * z - w * x),
                1.0 - 2.0 * (x * x + y * y),
            ];
            for k in 0..3 {
                assert!((col[k] - n[k]).abs() < 1e-12, "{n:?} -> {col:?}");
            }
        }
    }
}
