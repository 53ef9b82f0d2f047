//! How the optical tweezers are drawn: live from the world, or from a recording's state
//! without the physics.

use super::{OtParams, STATE_FIELDS, V2};
use haptic_types::Rgba;
use haptic_types::vec3::Vec3;
use haptic_types::{Ball, Primitive};

/// The parts of the picture that never change during a session: sizes, the envelope's drawing
/// scale, the label.
pub(super) struct Look {
    waists_m: [f64; 2],
    particle_r_m: f64,
    cursor_r_m: f64,
    pub(super) draw_scale: f64,
    feedback: bool,
}

/// What one tick's picture shows (world frame, m; force N).
pub(super) struct Shown {
    pub(super) position: V2,
    pub(super) trap: V2,
    pub(super) cursor: V2,
    pub(super) grabbed: bool,
    pub(super) force: V2,
}

impl Look {
    pub(super) fn of(p: &OtParams) -> Self {
        Look {
            waists_m: [p.waist_x_nm * 1e-9, p.waist_y_nm * 1e-9],
            particle_r_m: 0.5 * p.particle_diameter_um * 1e-6,
            cursor_r_m: p.cursor_radius_nm * 1e-9,
            draw_scale: p.envelope_draw_scale,
            feedback: p.feedback,
        }
    }

    /// The scene's primitives: trap, particle, cursor, the envelope (already placed around the
    /// particle and scaled for drawing; none when empty), the force arrow, the label.
    pub(super) fn draw(&self, t: &Shown, envelope: Vec<Vec3>, out: &mut Vec<Primitive>) {
        let p = [t.position.x, t.position.y, 0.0];
        out.push(Primitive::Ellipse {
            center_m: [t.trap.x, t.trap.y, -self.particle_r_m],
            semi_axes_m: self.waists_m,
            color: Rgba([0.3, 0.8, 0.3, 0.4]),
        });
        out.push(Primitive::Sphere(Ball {
            center_m: p,
            radius_m: self.particle_r_m,
            color: if t.grabbed {
                Rgba([0.95, 0.6, 0.2, 1.0])
            } else {
                Rgba([0.8, 0.8, 0.85, 1.0])
            },
        }));
        out.push(Primitive::Sphere(Ball {
            center_m: [t.cursor.x, t.cursor.y, 0.0],
            radius_m: self.cursor_r_m,
            color: Rgba([0.2, 0.5, 0.95, 1.0]),
        }));
        if !envelope.is_empty() {
            out.push(Primitive::Polyline {
                points_m: envelope,
                closed: true,
                color: Rgba([0.9, 0.2, 0.2, 1.0]),
            });
        }
        if t.force.norm() > 0.0 {
            // Arrow: 1 µm per µN of world force (drawing only).
            let tip: Vec3 = [p[0] + t.force.x, p[1] + t.force.y, 0.0];
            out.push(Primitive::Arrow {
                from_m: [t.cursor.x, t.cursor.y, 0.0],
                to_m: [
                    t.cursor.x + (tip[0] - p[0]),
                    t.cursor.y + (tip[1] - p[1]),
                    0.0,
                ],
                color: Rgba([1.0, 0.9, 0.1, 1.0]),
            });
        }
        out.push(Primitive::Label {
            position_m: [p[0], p[1] - 2.0 * self.particle_r_m, 0.0],
            text: format!(
                "WE ×{} · feedback {}",
                self.draw_scale,
                if self.feedback { "on" } else { "off" }
            ),
            color: Rgba([1.0, 1.0, 1.0, 1.0]),
        });
    }
}

/// Draws optical-tweezers ticks from a recording's state, without the physics (`nanohaptics
/// render`): the `/world/state` fields, the cursor, the scene force of `/haptic/force` and the
/// envelope polyline that `/foxglove/scene` holds at display rate are all the picture needs.
/// At a display tick the primitives are those [`Scene::draw`] gives after that tick, to the
/// rounding of the envelope's display scale.
pub struct RecordedPicture {
    look: Look,
    fields: Vec<String>,
}

impl RecordedPicture {
    /// The picture of a scene with parameters `p` (as recorded in the description's scene file).
    pub fn new(p: &OtParams) -> Self {
        RecordedPicture {
            look: Look::of(p),
            fields: STATE_FIELDS.iter().map(|s| s.to_string()).collect(),
        }
    }

    /// Whether a recording's `state_fields` are the ones this build draws from.
    pub fn reads(&self, state_fields: &[String]) -> bool {
        self.fields == state_fields
    }

    /// Appends the primitives of one recorded tick to `out`: `fields` its `/world/state`
    /// values, `cursor_m` its cursor (world, m), `world_force_n` the scene force (N),
    /// `envelope_m` the envelope polyline of `/foxglove/scene` divided by the display scale
    /// (world, m; empty when none was drawn). A state of the wrong length is an error naming
    /// the field count.
    pub fn draw(
        &self,
        fields: &[f64],
        cursor_m: Vec3,
        world_force_n: Vec3,
        envelope_m: Vec<Vec3>,
        out: &mut Vec<Primitive>,
    ) -> Result<(), String> {
        if fields.len() != self.fields.len() {
            return Err(format!(
                "optical_tweezers state has {} fields, expected {}",
                fields.len(),
                self.fields.len()
            ));
        }
        let shown = Shown {
            position: V2::new(fields[0], fields[1]),
            trap: V2::new(fields[4], fields[5]),
            cursor: V2::new(cursor_m[0], cursor_m[1]),
            grabbed: fields[6] != 0.0,
            force: V2::new(world_force_n[0], world_force_n[1]),
        };
        self.look.draw(&shown, envelope_m, out);
        Ok(())
    }
}
