//! The optical-tweezers steering scene (Lee, Lyons & LeBrun, §2.4 and §3.3): a 1 µm particle
//! in an elliptic Gaussian trap, a cursor sphere on the stylus, grab by touching the particle
//! and pressing the button, steering through `ot-envelope`'s controller, release on button up.
//!
//! Each haptic tick advances the particle by `dt_us` of particle time (the paper's control
//! cycle). While grabbed, the controller computes this tick's working envelope from the
//! particle's current velocity, clips the command (cursor − particle) to it, places the trap so
//! that the particle makes the allowed displacement, and returns the spring force `−k·excess`
//! felt on the stylus (when `feedback` is on). The particle is then moved by the trap's flow
//! map (not by the command), so what the recording shows is the physics, not the wish. Not
//! grabbed, the particle evolves in the last trap. The paper's viscous simplification (the
//! velocity kept to a fraction each cycle) is `velocity_retain` (1: none).
//!
//! The tick map is chosen from an error budget (`tick_map_tol_nm`, default 0.01 nm from
//! converged dynamics, see `ot_physics::budget`) unless `rk4_substeps` fixes it; the choice and
//! its measured error are reported by an `ot.tick_map` event on the first tick. The envelope's
//! offset region and grid spacing are sized from `envelope_tol_nm` and the tick
//! (`ot_envelope::grid::choose_grid`) unless `envelope_margin_waists` / `envelope_cell_waists` fix
//! them, reported by an `ot.envelope_grid` event on the first tick. The controller is
//! `ot_envelope::TickController`: warm-started from the last full envelope build (translated by
//! the change of free drift, checked at fold points), allocation-free in a steady-state tick.

use super::check::{SceneError, check_positive, check_range, out_of_range};
use super::{Event, Primitive, Rgba, Scene, SceneInput, SceneOutput, WorldKind, world_table};
use crate::vec3::Vec3;
use nalgebra::Vector2;
use ot_envelope::ClipMode;
use ot_envelope::grid::choose_grid;
use ot_envelope::steer::{ParticleState, SteerParams};
use ot_envelope::tick::{TickController, TickParams};
use ot_physics::budget::{choose_tick_map, measure};
use ot_physics::{Method, Propagator, TrapModel};
use serde::Deserialize;

type V2 = Vector2<f64>;

/// The optical tweezers in the scene registry: `kind = "optical_tweezers"`, table
/// `[optical_tweezers]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "optical_tweezers",
    check: |text| super::table::pick::<OtParams>(text, "optical_tweezers").map(drop),
    build: |text, config| {
        let p: OtParams = world_table(text, "optical_tweezers")?;
        Ok(Box::new(OpticalScene::new(
            p,
            config.world_stiffness_cap_n_per_m(),
        )?))
    },
};

/// `[optical_tweezers]`: what a human types, with units in the names.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct OtParams {
    /// Well depth P0, nJ (paper: 1e-6).
    pub depth_nj: f64,
    /// Beam waist a along x, nm (paper: 600).
    pub waist_x_nm: f64,
    /// Beam waist b along y, nm (paper: 300).
    pub waist_y_nm: f64,
    /// Particle mass, g (paper: 1e-12).
    pub mass_g: f64,
    /// Particle time per haptic tick, µs (paper: 1).
    pub dt_us: f64,
    /// RK4 substeps of the tick map, fixed by hand (1–1000); absent: the tick map is chosen
    /// from `tick_map_tol_nm`.
    #[serde(default)]
    pub rk4_substeps: Option<u32>,
    /// Error budget of the tick map, nm from converged dynamics (default 0.01); the cheapest
    /// RK4/RK8 map within it is chosen (`ot_physics::budget::choose_tick_map`).
    #[serde(default)]
    pub tick_map_tol_nm: Option<f64>,
    /// Largest particle speed the tick map's budget is checked for, m/s (default 0.1, the
    /// paper's 100 nm/µs).
    #[serde(default)]
    pub tick_map_speed_m_per_s: Option<f64>,
    /// Warm-start the working envelope from the last full build (default true; false rebuilds
    /// it every tick).
    #[serde(default = "yes")]
    pub warm_start: bool,
    /// Particle diameter, µm (paper: 1).
    pub particle_diameter_um: f64,
    /// Cursor sphere radius, nm.
    pub cursor_radius_nm: f64,
    /// Spring stiffness on the excess, world frame, N/m.
    pub stiffness_n_per_m: f64,
    /// Force feedback on the stylus (the paper's experiment switches it off).
    #[serde(default = "yes")]
    pub feedback: bool,
    /// Clipping rule: "radial" (the paper's) or "nearest".
    #[serde(default)]
    pub clip: ClipMode,
    /// Fraction of the velocity kept after each tick (paper §3.3: 0.1; 1: no damping).
    #[serde(default = "one")]
    pub velocity_retain: f64,
    /// Drawing scale of the working envelope around the particle (paper: 100).
    #[serde(default = "hundred")]
    pub envelope_draw_scale: f64,
    /// Particle (and trap) start, µm.
    #[serde(default)]
    pub start_um: [f64; 2],
    /// Geometric tolerance of the working envelope, nm (default: `ot_envelope::DEFAULT_TOL`).
    #[serde(default)]
    pub envelope_tol_nm: Option<f64>,
    /// Grid spacing of a full envelope build, waists per cell, fixed by hand (0.01–2); absent:
    /// chosen from `envelope_tol_nm` and the tick (`ot_envelope::grid::choose_grid`).
    #[serde(default)]
    pub envelope_cell_waists: Option<f64>,
    /// Half-width of the envelope's offset region beyond the drift path, waists, fixed by hand
    /// (1–10); absent: chosen from `envelope_tol_nm` and the tick.
    #[serde(default)]
    pub envelope_margin_waists: Option<f64>,
}

fn yes() -> bool {
    true
}
fn one() -> f64 {
    1.0
}
fn hundred() -> f64 {
    100.0
}

/// The optical-tweezers scene.
pub struct OpticalScene {
    p: OtParams,
    prop: Propagator<2>,
    controller: TickController,
    /// The tick map's report, sent as an `ot.tick_map` event on the first tick.
    tick_map_report: Option<String>,
    /// The envelope grid's report, sent as an `ot.envelope_grid` event on the first tick.
    grid_report: Option<String>,
    particle_r_m: f64,
    cursor_r_m: f64,
    position: V2,
    velocity: V2,
    trap: V2,
    cursor: V2,
    grabbed: bool,
    button_was: bool,
    excess: V2,
    force: V2,
    envelope: Vec<V2>,
    clipping: bool,
}

impl OpticalScene {
    /// Builds the scene; `cap_n_per_m` is the world stiffness cap.
    pub fn new(p: OtParams, cap_n_per_m: f64) -> Result<Self, SceneError> {
        check_positive("optical_tweezers.depth_nj", p.depth_nj, 1e3)?;
        check_positive("optical_tweezers.waist_x_nm", p.waist_x_nm, 1e6)?;
        check_positive("optical_tweezers.waist_y_nm", p.waist_y_nm, 1e6)?;
        check_positive("optical_tweezers.mass_g", p.mass_g, 1.0)?;
        check_positive("optical_tweezers.dt_us", p.dt_us, 1e6)?;
        if let Some(n) = p.rk4_substeps {
            check_range("optical_tweezers.rk4_substeps", f64::from(n), 1.0, 1000.0)?;
        }
        let map_tol_m = match p.tick_map_tol_nm {
            Some(t) => {
                check_range("optical_tweezers.tick_map_tol_nm", t, 1e-4, 100.0)?;
                t * 1e-9
            }
            None => ot_physics::DEFAULT_TOL_M,
        };
        let map_speed = match p.tick_map_speed_m_per_s {
            Some(v) => {
                check_range("optical_tweezers.tick_map_speed_m_per_s", v, 0.0, 1e3)?;
                v
            }
            None => 0.1,
        };
        check_positive(
            "optical_tweezers.particle_diameter_um",
            p.particle_diameter_um,
            1e3,
        )?;
        check_positive("optical_tweezers.cursor_radius_nm", p.cursor_radius_nm, 1e6)?;
        check_positive(
            "optical_tweezers.stiffness_n_per_m",
            p.stiffness_n_per_m,
            cap_n_per_m,
        )
        .map_err(|_| {
            out_of_range(
                "optical_tweezers.stiffness_n_per_m",
                p.stiffness_n_per_m,
                format!(
                    "0 < stiffness ≤ {cap_n_per_m} N/m, the device's limit mapped to the world"
                ),
            )
        })?;
        check_range(
            "optical_tweezers.velocity_retain",
            p.velocity_retain,
            0.0,
            1.0,
        )?;
        check_positive(
            "optical_tweezers.envelope_draw_scale",
            p.envelope_draw_scale,
            1e6,
        )?;
        let tol = match p.envelope_tol_nm {
            Some(t) => {
                check_positive("optical_tweezers.envelope_tol_nm", t, 1e3)?;
                t * 1e-9
            }
            None => ot_envelope::DEFAULT_TOL,
        };
        for (k, c) in p.start_um.iter().enumerate() {
            check_range(&format!("optical_tweezers.start_um[{k}]"), *c, -1e6, 1e6)?;
        }
        let waists_m = [p.waist_x_nm * 1e-9, p.waist_y_nm * 1e-9];
        let model = TrapModel::builder(p.depth_nj * 1e-9, waists_m)
            .mass(p.mass_g * 1e-3)
            .build()
            .map_err(ot_error)?;
        let dt_s = p.dt_us * 1e-6;
        // A haptic tick must be cheap: its envelope's cost grows with how many small
        // oscillations of the trapped particle one tick holds (their folds multiply the
        // envelope's boundary). At paper constants the period is 0.94 µs: 1 µs ticks cost
        // ~2 ms at p99, 5 µs ticks up to 0.5 s; a 1000× lighter particle at 0.2 µs never
        // finished building the scene. Refuse beyond two periods instead of hanging.
        let max_dt_us = 2.0 * small_oscillation_period_s(&p) * 1e6;
        if !max_dt_us.is_finite() || p.dt_us > max_dt_us {
            return Err(out_of_range(
                "optical_tweezers.dt_us",
                p.dt_us,
                format!(
                    "0 < dt_us ≤ {} µs, two periods of the particle's small oscillation in \
                     this trap (period 2π·√(mass·waist²/(4·depth)), narrower waist); a longer \
                     tick makes the envelope too costly for a haptic loop",
                    three_digits_down(max_dt_us)
                ),
            ));
        }
        let physics = ot_error::<ot_physics::PhysicsError>;
        let (prop, report) = match p.rk4_substeps {
            Some(n) => {
                let method = Method::Rk4 { substeps: n };
                let m = measure(model, method, dt_s, map_speed).map_err(physics)?;
                let prop = Propagator::new(model, method, dt_s).map_err(physics)?;
                (prop, format!("fixed by rk4_substeps: {m}"))
            }
            None => {
                let (prop, c) =
                    choose_tick_map(model, dt_s, map_tol_m, map_speed).map_err(physics)?;
                (prop, format!("chosen from tick_map_tol_nm: {c}"))
            }
        };
        if let Some(c) = p.envelope_cell_waists {
            check_range("optical_tweezers.envelope_cell_waists", c, 0.01, 2.0)?;
        }
        if let Some(m) = p.envelope_margin_waists {
            check_range("optical_tweezers.envelope_margin_waists", m, 1.0, 10.0)?;
        }
        let envelope = ot_error::<ot_envelope::EnvelopeError>;
        let (margin, cell, grid_report) = match (p.envelope_margin_waists, p.envelope_cell_waists) {
            (Some(m), Some(c)) => (
                m,
                c,
                format!(
                    "fixed by envelope_margin_waists and envelope_cell_waists: region {m} waists beyond the drift path, cell {c} waists"
                ),
            ),
            (m, c) => {
                let g = choose_grid(&prop, tol, map_speed).map_err(envelope)?;
                (
                    m.unwrap_or(g.margin_waists),
                    c.unwrap_or(g.cell_waists),
                    format!("chosen from envelope_tol_nm: {g}"),
                )
            }
        };
        let mut tick = TickParams::new(SteerParams {
            stiffness: p.stiffness_n_per_m,
            mode: p.clip,
            tol,
            margin_waists: margin,
        });
        tick.warm_start = p.warm_start;
        tick.cell_waists = Some(cell);
        let controller = TickController::new(tick).map_err(ot_error)?;
        let start = V2::new(p.start_um[0] * 1e-6, p.start_um[1] * 1e-6);
        Ok(OpticalScene {
            particle_r_m: 0.5 * p.particle_diameter_um * 1e-6,
            cursor_r_m: p.cursor_radius_nm * 1e-9,
            p,
            prop,
            controller,
            tick_map_report: Some(report),
            grid_report: Some(grid_report),
            position: start,
            velocity: V2::zeros(),
            trap: start,
            cursor: start,
            grabbed: false,
            button_was: false,
            excess: V2::zeros(),
            force: V2::zeros(),
            envelope: Vec::new(),
            clipping: false,
        })
    }

    /// Advances the particle in the trap at `self.trap` for one tick.
    fn advance(&mut self) -> Result<(), String> {
        let offset = self.trap - self.position;
        let (d, v, _) = self
            .prop
            .flow(&offset, &self.velocity)
            .map_err(|e| e.to_string())?;
        self.position += d;
        self.velocity = v * self.p.velocity_retain;
        Ok(())
    }
}

impl OpticalScene {
    /// The steering counters so far (rebuilds, warm ticks, solves).
    pub fn tick_stats(&self) -> ot_envelope::TickStats {
        self.controller.stats()
    }

    /// The tick map in use.
    pub fn tick_map(&self) -> &Propagator<2> {
        &self.prop
    }
}

impl Scene for OpticalScene {
    fn kind(&self) -> &'static str {
        "optical_tweezers"
    }

    fn state_fields(&self) -> Vec<String> {
        STATE_FIELDS.iter().map(|s| s.to_string()).collect()
    }

    fn step(&mut self, input: &SceneInput, out: &mut SceneOutput) {
        if let Some(r) = self.tick_map_report.take() {
            out.events.push(Event::new("ot.tick_map", r));
        }
        if let Some(r) = self.grid_report.take() {
            out.events.push(Event::new("ot.envelope_grid", r));
        }
        self.cursor = V2::new(input.cursor_m[0], input.cursor_m[1]);
        let button = input.buttons.pressed(0);
        if button && !self.button_was && !self.grabbed {
            let gap = (self.cursor - self.position).norm();
            if gap <= self.particle_r_m + self.cursor_r_m {
                self.grabbed = true;
                self.controller.reset();
                out.events.push(Event::new(
                    "ot.grab",
                    format!("cursor {gap:e} m from the particle centre"),
                ));
            } else {
                out.events.push(Event::new(
                    "ot.grab_missed",
                    format!("cursor {gap:e} m from the particle centre"),
                ));
            }
        }
        if !button && self.grabbed {
            self.grabbed = false;
            out.events.push(Event::new("ot.release", ""));
        }
        self.button_was = button;
        self.excess = V2::zeros();
        self.force = V2::zeros();
        if self.grabbed {
            let state = ParticleState {
                position: self.position,
                velocity: self.velocity,
            };
            match self.controller.step(&self.prop, &state, &self.cursor) {
                Ok(s) => {
                    self.trap = s.trap;
                    self.excess = s.excess;
                    if self.p.feedback {
                        self.force = s.force;
                    }
                    // reuse the buffer: no allocation once it has grown
                    self.envelope.clear();
                    self.envelope.extend_from_slice(self.controller.envelope());
                }
                Err(e) => {
                    out.events
                        .push(Event::new("ot.controller_error", e.to_string()));
                }
            }
        } else {
            self.envelope.clear();
        }
        let clipping = self.excess.norm() > 0.0;
        if clipping && !self.clipping {
            out.events.push(Event::new(
                "ot.clipped",
                "command outside the working envelope",
            ));
        }
        self.clipping = clipping;
        if let Err(e) = self.advance() {
            out.events.push(Event::new("ot.physics_error", e));
        }
        out.force_n = [self.force.x, self.force.y, 0.0];
        out.stiffness_n_per_m = if self.grabbed && self.p.feedback {
            self.p.stiffness_n_per_m
        } else {
            0.0
        };
    }

    fn state(&self, out: &mut Vec<f64>) {
        out.extend_from_slice(&[
            self.position.x,
            self.position.y,
            self.velocity.x,
            self.velocity.y,
            self.trap.x,
            self.trap.y,
            f64::from(u8::from(self.grabbed)),
            self.excess.norm(),
            (self.cursor - self.position).norm(),
            self.envelope.len() as f64,
        ]);
    }

    fn draw(&self, out: &mut Vec<Primitive>) {
        let p = self.position;
        let s = self.p.envelope_draw_scale;
        let envelope: Vec<Vec3> = self
            .envelope
            .iter()
            .map(|q| [p.x + s * q.x, p.y + s * q.y, 0.0])
            .collect();
        Look::of(&self.p).draw(
            &Shown {
                position: self.position,
                trap: self.trap,
                cursor: self.cursor,
                grabbed: self.grabbed,
                force: self.force,
            },
            envelope,
            out,
        );
    }
}

/// The parts of the picture that never change during a session: sizes, the envelope's drawing
/// scale, the label.
struct Look {
    waists_m: [f64; 2],
    particle_r_m: f64,
    cursor_r_m: f64,
    draw_scale: f64,
    feedback: bool,
}

/// What one tick's picture shows (world frame, m; force N).
struct Shown {
    position: V2,
    trap: V2,
    cursor: V2,
    grabbed: bool,
    force: V2,
}

impl Look {
    fn of(p: &OtParams) -> Self {
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
    fn draw(&self, t: &Shown, envelope: Vec<Vec3>, out: &mut Vec<Primitive>) {
        let p = [t.position.x, t.position.y, 0.0];
        out.push(Primitive::Ellipse {
            center_m: [t.trap.x, t.trap.y, -self.particle_r_m],
            semi_axes_m: self.waists_m,
            color: Rgba([0.3, 0.8, 0.3, 0.4]),
        });
        out.push(Primitive::Sphere {
            center_m: p,
            radius_m: self.particle_r_m,
            color: if t.grabbed {
                Rgba([0.95, 0.6, 0.2, 1.0])
            } else {
                Rgba([0.8, 0.8, 0.85, 1.0])
            },
        });
        out.push(Primitive::Sphere {
            center_m: [t.cursor.x, t.cursor.y, 0.0],
            radius_m: self.cursor_r_m,
            color: Rgba([0.2, 0.5, 0.95, 1.0]),
        });
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

/// `x` (> 0) rounded down to three significant digits, as text (a bound stated inside itself).
fn three_digits_down(x: f64) -> String {
    let e = x.log10().floor() as i32;
    let unit = 10f64.powi(e - 2);
    let decimals = usize::try_from(2 - e).unwrap_or(0);
    format!("{:.*}", decimals, (x / unit).floor() * unit)
}

/// The period (s) of the particle's small oscillation about the centre of the well, along the
/// narrower waist: ω² = 4·depth / (mass · waist²) for the well −depth·e^{−2x²/w²}.
fn small_oscillation_period_s(p: &OtParams) -> f64 {
    let depth_j = p.depth_nj * 1e-9;
    let mass_kg = p.mass_g * 1e-3;
    let w_m = p.waist_x_nm.min(p.waist_y_nm) * 1e-9;
    let omega = (4.0 * depth_j / (mass_kg * w_m * w_m)).sqrt();
    2.0 * std::f64::consts::PI / omega
}

/// An optical-tweezers model or steering error as a scene error (located at the
/// `[optical_tweezers]` table: the model's field names are not the scene's).
fn ot_error<E: std::fmt::Display>(e: E) -> SceneError {
    SceneError::World {
        section: "optical_tweezers".into(),
        field: None,
        message: e.to_string(),
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

/// The state fields of the scene, in the order [`Scene::state`] writes them.
const STATE_FIELDS: [&str; 10] = [
    "particle_x_m",
    "particle_y_m",
    "particle_vx_m_per_s",
    "particle_vy_m_per_s",
    "trap_x_m",
    "trap_y_m",
    "grabbed",
    "excess_m",
    "lag_m",
    "envelope_vertices",
];

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::scene::SceneFile;

    fn params(extra: &str) -> OtParams {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/optical_tweezers.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let text = text.replace("tick_map_tol_nm = 0.01", extra);
        SceneFile::parse(&text)
            .unwrap()
            .world::<OtParams>()
            .unwrap()
            .expect("optical scene")
    }

    fn first_events(p: OtParams) -> Vec<Event> {
        let mut s = OpticalScene::new(p, 3.0).unwrap();
        let mut out = SceneOutput::default();
        let input = SceneInput {
            tick: 0,
            dt_s: 1e-3,
            cursor_m: [0.0; 3],
            buttons: crate::device::Buttons(0),
            input_valid: true,
        };
        s.step(&input, &mut out);
        out.events
    }

    #[test]
    fn the_tick_map_choice_is_reported_once() {
        let ev = first_events(params("tick_map_tol_nm = 0.01"));
        assert_eq!(ev.len(), 2);
        assert_eq!(ev[0].name, "ot.tick_map");
        assert_eq!(ev[1].name, "ot.envelope_grid");
        assert!(
            ev[1]
                .detail
                .starts_with("chosen from envelope_tol_nm: envelope grid: region "),
            "{}",
            ev[1].detail
        );
        assert!(
            ev[0]
                .detail
                .starts_with("chosen from tick_map_tol_nm: tick map rk4×2: "),
            "{}",
            ev[0].detail
        );
        let fixed = first_events(params("rk4_substeps = 8"));
        assert!(
            fixed[0]
                .detail
                .starts_with("fixed by rk4_substeps: tick map rk4×8: "),
            "{}",
            fixed[0].detail
        );
    }

    #[test]
    fn the_10_khz_scene_loads_with_an_exact_period() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/optical_tweezers_10khz.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let loaded = crate::scene::load_scene(&text, None).unwrap();
        assert_eq!(loaded.config.rate_hz, 10_000);
        assert_eq!(loaded.config.period_ns(), 100_000);
        assert_eq!(loaded.scene.kind(), "optical_tweezers");
    }

    #[test]
    fn budget_fields_are_validated_with_their_range() {
        let err = |extra: &str| match OpticalScene::new(params(extra), 3.0) {
            Ok(_) => panic!("accepted {extra}"),
            Err(e) => e.to_string(),
        };
        assert_eq!(
            err("tick_map_tol_nm = 0.0"),
            "scene: `optical_tweezers.tick_map_tol_nm` = 0 is out of range (allowed: 1e-4 ≤ \
             optical_tweezers.tick_map_tol_nm ≤ 100)"
        );
        assert_eq!(
            err("tick_map_speed_m_per_s = -1.0"),
            "scene: `optical_tweezers.tick_map_speed_m_per_s` = -1 is out of range (allowed: 0 ≤ \
             optical_tweezers.tick_map_speed_m_per_s ≤ 1000)"
        );
        assert_eq!(
            err("rk4_substeps = 0"),
            "scene: `optical_tweezers.rk4_substeps` = 0 is out of range (allowed: 1 ≤ \
             optical_tweezers.rk4_substeps ≤ 1000)"
        );
    }

    #[test]
    fn a_tick_longer_than_two_small_oscillations_is_refused() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/optical_tweezers.toml"
        );
        let text = std::fs::read_to_string(path).unwrap();
        let with = |from: &str, to: &str| {
            let t = text.replace(from, to);
            let p = SceneFile::parse(&t)
                .unwrap()
                .world::<OtParams>()
                .unwrap()
                .unwrap();
            OpticalScene::new(p, 3.0).err().map(|e| e.to_string())
        };
        // Paper constants: period 2π·√(1e-15 kg · (300 nm)² / (4e-15 J)) = 0.942 µs.
        assert_eq!(
            with("dt_us = 0.2", "dt_us = 5.0").as_deref(),
            Some(
                "scene: `optical_tweezers.dt_us` = 5 is out of range (allowed: 0 < dt_us ≤ 1.88 \
                 µs, two periods of the particle's small oscillation in this trap (period \
                 2π·√(mass·waist²/(4·depth)), narrower waist); a longer tick makes the envelope \
                 too costly for a haptic loop)"
            )
        );
        // The fuzz finding: a particle 1000× lighter at the default 0.2 µs tick.
        let light = with("mass_g = 1.0e-12", "mass_g = 1e-15").unwrap_or_default();
        assert!(light.contains("≤ 0.0596 µs"), "{light}");
        assert_eq!(with("dt_us = 0.2", "dt_us = 1.0"), None);
        assert_eq!(three_digits_down(1.8849), "1.88");
        assert_eq!(three_digits_down(0.059605), "0.0596");
        assert_eq!(three_digits_down(123456.0), "123000");
    }
}
