//! The optical-tweezers scene: the adapter of `ot_envelope::world` (Lee, Lyons & LeBrun, §2.4 and
//! §3.3) to the haptic loop. The world — particle, trap, grab / steer / release, the tick map
//! and the working envelope — is `ot_envelope::world::World`; this file maps the scene file's
//! `[optical_tweezers]` table (human units: nm, µs, nJ, g) to the world's SI
//! `ot_envelope::world::Params`, the loop's cursor and first button to its `Input`, its report
//! to the loop's force and events, and draws it.
//!
//! The tick map is model data chosen in the scene file: `tick_map = "budget"` (the default: the
//! cheapest RK4/RK8 map within `tick_map_tol_nm`, default 0.01 nm, of converged dynamics) or a
//! method by name (`tick_map = "rk4"`, `"rk8"`, `"dopri5"`, `"adaptive"`, …) with
//! `tick_map_substeps` or `tick_map_rtol`. The older `rk4_substeps = n` still loads and means
//! `tick_map = "rk4"`, `tick_map_substeps = n`. The choice and its measured error are reported
//! by an `ot.tick_map` event on the first tick, the envelope grid by `ot.envelope_grid`; every
//! event's detail is its JSON form (`{"type":"grab","gap_m":1e-7}`).

use super::check::{SceneError, check_positive, check_range, out_of_range};
use super::{Event, Primitive, Rgba, Scene, SceneInput, SceneOutput, WorldKind, world_table};
use haptic_types::vec3::Vec3;
use nalgebra::Vector2;
use ot_envelope::ClipMode;
use ot_envelope::world::{Input, Params, TickMap, World, WorldError};
use ot_physics::Propagator;
use serde::Deserialize;
use world_form::Limits;

type V2 = Vector2<f64>;

/// The optical tweezers in the scene registry: `kind = "optical_tweezers"`, table
/// `[optical_tweezers]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "optical_tweezers",
    check: |text| super::table::pick::<OtParams>(text, "optical_tweezers").map(drop),
    build: |text, config| {
        let p: OtParams = world_table(text, "optical_tweezers")?;
        Ok(Box::new(OpticalScene::new(p, &config.world_limits())?))
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
    /// Integrator of the tick map: `"budget"` (default: the cheapest RK4/RK8 within
    /// `tick_map_tol_nm`) or an `ot_physics` method name (`"rk4"`, `"rk8"`, `"dopri5"`,
    /// `"adaptive"`, `"paper-rk4"`, `"symplectic"`, `"yoshida4"`, `"yoshida6"`).
    #[serde(default)]
    pub tick_map: Option<String>,
    /// Substeps of a named fixed-step tick map (1–1000; default: the method's own).
    #[serde(default)]
    pub tick_map_substeps: Option<u32>,
    /// Relative tolerance of a named adaptive tick map (1e-14–1e-2; default: the method's own).
    #[serde(default)]
    pub tick_map_rtol: Option<f64>,
    /// The older form of `tick_map = "rk4"` with `tick_map_substeps` (1–1000); still accepted.
    #[serde(default)]
    pub rk4_substeps: Option<u32>,
    /// Error budget of the `"budget"` tick map, nm from converged dynamics (default 0.01).
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
    /// Spread each envelope rebuild over ticks, serving the last envelope translated meanwhile
    /// (default true; false: a rebuild runs whole in the tick that needs it).
    #[serde(default = "yes")]
    pub spread_build: bool,
    /// Force evaluations of a spread rebuild per tick (1–1e6; default
    /// `ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK`, 256).
    #[serde(default)]
    pub envelope_build_evals_per_tick: Option<u64>,
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

impl OtParams {
    /// Checks the table in its own units (errors name the scene file's fields and ranges) and
    /// converts it to the world's SI parameters; `limits` are the device's, in the world.
    pub fn world_params(&self, limits: &Limits) -> Result<Params, SceneError> {
        let p = self;
        check_positive("optical_tweezers.depth_nj", p.depth_nj, 1e3)?;
        check_positive("optical_tweezers.waist_x_nm", p.waist_x_nm, 1e6)?;
        check_positive("optical_tweezers.waist_y_nm", p.waist_y_nm, 1e6)?;
        check_positive("optical_tweezers.mass_g", p.mass_g, 1.0)?;
        check_positive("optical_tweezers.dt_us", p.dt_us, 1e6)?;
        let tick_map = self.tick_map_choice()?;
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
        let cap = limits.max_stiffness_n_per_m;
        check_positive(
            "optical_tweezers.stiffness_n_per_m",
            p.stiffness_n_per_m,
            cap,
        )
        .map_err(|_| {
            out_of_range(
                "optical_tweezers.stiffness_n_per_m",
                p.stiffness_n_per_m,
                format!("0 < stiffness ≤ {cap} N/m, the device's limit mapped to the world"),
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
        if let Some(c) = p.envelope_cell_waists {
            check_range("optical_tweezers.envelope_cell_waists", c, 0.01, 2.0)?;
        }
        if let Some(m) = p.envelope_margin_waists {
            check_range("optical_tweezers.envelope_margin_waists", m, 1.0, 10.0)?;
        }
        if let Some(b) = p.envelope_build_evals_per_tick {
            check_range(
                "optical_tweezers.envelope_build_evals_per_tick",
                b as f64,
                1.0,
                1e6,
            )?;
        }
        let build_evals = match (p.spread_build, p.envelope_build_evals_per_tick) {
            (true, b) => Some(b.unwrap_or(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK)),
            (false, None) => None,
            (false, Some(_)) => {
                return Err(SceneError::World {
                    section: "optical_tweezers".into(),
                    field: Some("envelope_build_evals_per_tick".into()),
                    message: "`envelope_build_evals_per_tick` sets the spread rebuild that \
                              `spread_build = false` switches off: give one of them, not both"
                        .into(),
                });
            }
        };
        let params = Params {
            depth_j: p.depth_nj * 1e-9,
            waists_m: [p.waist_x_nm * 1e-9, p.waist_y_nm * 1e-9],
            mass_kg: p.mass_g * 1e-3,
            dt_s: p.dt_us * 1e-6,
            tick_map,
            map_speed_m_per_s: map_speed,
            warm_start: p.warm_start,
            particle_radius_m: 0.5 * p.particle_diameter_um * 1e-6,
            cursor_radius_m: p.cursor_radius_nm * 1e-9,
            stiffness_n_per_m: p.stiffness_n_per_m,
            feedback: p.feedback,
            clip: p.clip,
            velocity_retain: p.velocity_retain,
            start_m: [p.start_um[0] * 1e-6, p.start_um[1] * 1e-6],
            envelope_tol_m: tol,
            envelope_cell_waists: p.envelope_cell_waists,
            envelope_margin_waists: p.envelope_margin_waists,
            envelope_build_evals_per_tick: build_evals,
        };
        // A haptic tick must be cheap: refuse a tick longer than two small oscillations, in
        // the scene's unit (the world's own check would speak in seconds).
        let max_dt_us = params.max_dt_s() * 1e6;
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
        Ok(params)
    }

    /// The tick map the table asks for: by name (`tick_map`, or the older `rk4_substeps`), or
    /// from the error budget.
    fn tick_map_choice(&self) -> Result<TickMap, SceneError> {
        let p = self;
        if let Some(n) = p.tick_map_substeps {
            check_range(
                "optical_tweezers.tick_map_substeps",
                f64::from(n),
                1.0,
                1000.0,
            )?;
        }
        if let Some(r) = p.tick_map_rtol {
            check_range("optical_tweezers.tick_map_rtol", r, 1e-14, 1e-2)?;
        }
        let tol_m = match p.tick_map_tol_nm {
            Some(t) => {
                check_range("optical_tweezers.tick_map_tol_nm", t, 1e-4, 100.0)?;
                t * 1e-9
            }
            None => ot_physics::DEFAULT_TOL_M,
        };
        let name = match (p.rk4_substeps, p.tick_map.as_deref()) {
            (Some(n), None) => {
                check_range("optical_tweezers.rk4_substeps", f64::from(n), 1.0, 1000.0)?;
                return Ok(TickMap::Named {
                    name: "rk4".into(),
                    substeps: Some(n),
                    rtol: None,
                });
            }
            (Some(_), Some(_)) => {
                return Err(SceneError::World {
                    section: "optical_tweezers".into(),
                    field: Some("rk4_substeps".into()),
                    message: "`rk4_substeps` is the older form of `tick_map = \"rk4\"` with \
                              `tick_map_substeps`: give one of them, not both"
                        .into(),
                });
            }
            (None, None) | (None, Some("budget")) => return Ok(TickMap::Budget { tol_m }),
            (None, Some(name)) => name,
        };
        if p.tick_map_tol_nm.is_some() {
            return Err(SceneError::World {
                section: "optical_tweezers".into(),
                field: Some("tick_map_tol_nm".into()),
                message: format!(
                    "`tick_map_tol_nm` is the budget of `tick_map = \"budget\"`; the named map \
                     `{name}` is set by `tick_map_substeps` or `tick_map_rtol`"
                ),
            });
        }
        let mut allowed = String::from("\"budget\", ");
        allowed.push_str(ot_physics::integrate::METHOD_NAMES);
        ot_physics::Method::from_name(name, p.tick_map_rtol, p.tick_map_substeps).map_err(|e| {
            SceneError::World {
                section: "optical_tweezers".into(),
                field: Some("tick_map".into()),
                message: match e {
                    ot_physics::PhysicsError::UnknownMethod { .. } => {
                        format!("`tick_map` = \"{name}\" is not a tick map (allowed: {allowed})")
                    }
                    other => other.to_string(),
                },
            }
        })?;
        Ok(TickMap::Named {
            name: name.to_string(),
            substeps: p.tick_map_substeps,
            rtol: p.tick_map_rtol,
        })
    }
}

/// The optical-tweezers scene: the world and how it is drawn.
pub struct OpticalScene {
    world: World,
    look: Look,
}

impl OpticalScene {
    /// Builds the scene from its table; `limits` are the device's limits in the world
    /// (`LoopConfig::world_limits`).
    pub fn new(p: OtParams, limits: &Limits) -> Result<Self, SceneError> {
        let params = p.world_params(limits)?;
        let world = World::new(&params, limits).map_err(ot_error)?;
        Ok(OpticalScene {
            world,
            look: Look::of(&p),
        })
    }

    /// The steering counters so far (rebuilds, warm ticks, solves).
    pub fn tick_stats(&self) -> ot_envelope::TickStats {
        self.world.tick_stats()
    }

    /// The tick map in use.
    pub fn tick_map(&self) -> &Propagator<2> {
        self.world.tick_map()
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
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
        let r = self.world.step(&Input {
            cursor_m: [input.cursor_m[0], input.cursor_m[1]],
            grab: input.buttons.pressed(0),
        });
        for e in &r.events {
            out.events.push(Event::new(
                format!("ot.{}", e.name()),
                serde_json::to_string(e).unwrap_or_default(),
            ));
        }
        out.force_n = [r.force_n[0], r.force_n[1], 0.0];
        out.stiffness_n_per_m = r.stiffness_n_per_m;
    }

    fn state(&self, out: &mut Vec<f64>) {
        let w = &self.world;
        let (p, v, t, c) = (
            w.position_m(),
            w.velocity_m_per_s(),
            w.trap_m(),
            w.cursor_m(),
        );
        out.extend_from_slice(&[
            p[0],
            p[1],
            v[0],
            v[1],
            t[0],
            t[1],
            f64::from(u8::from(w.grabbed())),
            w.excess_m(),
            (V2::new(c[0], c[1]) - V2::new(p[0], p[1])).norm(),
            w.envelope().len() as f64,
        ]);
    }

    fn draw(&self, out: &mut Vec<Primitive>) {
        let w = &self.world;
        let (p, f, t, c) = (w.position_m(), w.force_n(), w.trap_m(), w.cursor_m());
        let s = self.look.draw_scale;
        let envelope: Vec<Vec3> = w
            .envelope()
            .iter()
            .map(|q| [p[0] + s * q.x, p[1] + s * q.y, 0.0])
            .collect();
        self.look.draw(
            &Shown {
                position: V2::new(p[0], p[1]),
                trap: V2::new(t[0], t[1]),
                cursor: V2::new(c[0], c[1]),
                grabbed: w.grabbed(),
                force: V2::new(f[0], f[1]),
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

/// An optical-tweezers model or steering error as a scene error (located at the
/// `[optical_tweezers]` table: the model's field names are not the scene's).
fn ot_error(e: WorldError) -> SceneError {
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

    fn limits() -> Limits {
        Limits::FALCON.in_world(1e6, 1e-3)
    }

    fn first_events(p: OtParams) -> Vec<Event> {
        let mut s = OpticalScene::new(p, &limits()).unwrap();
        let mut out = SceneOutput::default();
        let input = SceneInput {
            tick: 0,
            dt_s: 1e-3,
            cursor_m: [0.0; 3],
            buttons: haptic_devices::Buttons(0),
            input_valid: true,
        };
        s.step(&input, &mut out);
        out.events
    }

    fn build_error(extra: &str) -> String {
        match OpticalScene::new(params(extra), &limits()) {
            Ok(_) => panic!("accepted {extra}"),
            Err(e) => e.to_string(),
        }
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
                .starts_with(r#"{"type":"envelope_grid","chosen_by":"budget","margin_waists":"#),
            "{}",
            ev[1].detail
        );
        assert!(
            ev[0].detail.starts_with(
                r#"{"type":"tick_map","chosen_by":"budget","method":"rk4×2","error_m":"#
            ),
            "{}",
            ev[0].detail
        );
        // the older form, and the same map by name: one choice, one report
        for form in [
            "rk4_substeps = 8",
            "tick_map = \"rk4\"\ntick_map_substeps = 8",
        ] {
            let fixed = first_events(params(form));
            assert!(
                fixed[0].detail.starts_with(
                    r#"{"type":"tick_map","chosen_by":"named","method":"rk4×8","error_m":"#
                ),
                "{form}: {}",
                fixed[0].detail
            );
        }
        let adaptive = first_events(params("tick_map = \"dopri5\"\ntick_map_rtol = 1e-9"));
        assert!(
            adaptive[0]
                .detail
                .contains(r#""chosen_by":"named","method":"dopri5×1""#),
            "{}",
            adaptive[0].detail
        );
    }

    #[test]
    fn the_tick_map_is_chosen_by_name_with_clear_errors() {
        assert_eq!(
            build_error("tick_map = \"euler\""),
            "scene: optical_tweezers: `tick_map` = \"euler\" is not a tick map (allowed: \"budget\", \
             \"paper-rk4\", \"rk4\", \"rk8\", \"dopri5\", \"adaptive\", \"symplectic\", \
             \"yoshida4\", \"yoshida6\")"
        );
        assert_eq!(
            build_error("rk4_substeps = 4\ntick_map = \"rk8\""),
            "scene: optical_tweezers: `rk4_substeps` is the older form of \
             `tick_map = \"rk4\"` with `tick_map_substeps`: give one of them, not both"
        );
        assert_eq!(
            build_error("tick_map = \"rk8\"\ntick_map_tol_nm = 0.1"),
            "scene: optical_tweezers: `tick_map_tol_nm` is the budget of \
             `tick_map = \"budget\"`; the named map `rk8` is set by `tick_map_substeps` or \
             `tick_map_rtol`"
        );
        assert_eq!(
            build_error("tick_map = \"rk4\"\ntick_map_substeps = 0"),
            "scene: `optical_tweezers.tick_map_substeps` = 0 is out of range: allowed 1 ≤ \
             optical_tweezers.tick_map_substeps ≤ 1000"
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
    fn the_spread_build_fields_are_checked_and_reach_the_world() {
        assert_eq!(
            build_error("envelope_build_evals_per_tick = 0"),
            "scene: `optical_tweezers.envelope_build_evals_per_tick` = 0 is out of range: \
             allowed 1 ≤ optical_tweezers.envelope_build_evals_per_tick ≤ 1e6"
        );
        assert_eq!(
            build_error("spread_build = false\nenvelope_build_evals_per_tick = 64"),
            "scene: optical_tweezers: `envelope_build_evals_per_tick` sets the spread rebuild \
             that `spread_build = false` switches off: give one of them, not both"
        );
        let l = limits();
        let world = |extra: &str| params(extra).world_params(&l).unwrap();
        assert_eq!(
            world("tick_map_tol_nm = 0.01").envelope_build_evals_per_tick,
            Some(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK)
        );
        assert_eq!(
            world("envelope_build_evals_per_tick = 64").envelope_build_evals_per_tick,
            Some(64)
        );
        assert_eq!(
            world("spread_build = false").envelope_build_evals_per_tick,
            None
        );
        // the first envelope is built when the scene loads
        let s = OpticalScene::new(params("tick_map_tol_nm = 0.01"), &l).unwrap();
        assert_eq!((s.tick_stats().rebuilds, s.tick_stats().ticks), (1, 0));
    }

    #[test]
    fn budget_fields_are_validated_with_their_range() {
        let err = build_error;
        assert_eq!(
            err("tick_map_tol_nm = 0.0"),
            "scene: `optical_tweezers.tick_map_tol_nm` = 0 is out of range: allowed 1e-4 ≤ \
             optical_tweezers.tick_map_tol_nm ≤ 100"
        );
        assert_eq!(
            err("tick_map_speed_m_per_s = -1.0"),
            "scene: `optical_tweezers.tick_map_speed_m_per_s` = -1 is out of range: allowed 0 ≤ \
             optical_tweezers.tick_map_speed_m_per_s ≤ 1000"
        );
        assert_eq!(
            err("rk4_substeps = 0"),
            "scene: `optical_tweezers.rk4_substeps` = 0 is out of range: allowed 1 ≤ \
             optical_tweezers.rk4_substeps ≤ 1000"
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
            OpticalScene::new(p, &limits()).err().map(|e| e.to_string())
        };
        // Paper constants: period 2π·√(1e-15 kg · (300 nm)² / (4e-15 J)) = 0.942 µs.
        assert_eq!(
            with("dt_us = 0.2", "dt_us = 5.0").as_deref(),
            Some(
                "scene: `optical_tweezers.dt_us` = 5 is out of range: allowed 0 < dt_us ≤ 1.88 \
                 µs, two periods of the particle's small oscillation in this trap (period \
                 2π·√(mass·waist²/(4·depth)), narrower waist); a longer tick makes the envelope \
                 too costly for a haptic loop"
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
