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

mod look;
mod params;
#[cfg(test)]
mod tests;

pub use look::RecordedPicture;
pub use params::OtParams;

use crate::scene::{WorldKind, world_table};
use haptic_engine::check::SceneError;
use haptic_engine::scene::Scene;
use haptic_engine::scene::SceneInput;
use haptic_engine::scene::SceneOutput;
use haptic_types::Event;
use haptic_types::Primitive;
use haptic_types::local::{Follower, MAX_REACH_VERTICES, radial_reach};
use haptic_types::vec3::Vec3;
use look::{Look, Shown};
use nalgebra::Vector2;
use ot_envelope::world::{Input, World, WorldError};
use ot_physics::Propagator;
use world_form::Limits;

type V2 = Vector2<f64>;

/// The optical tweezers in the scene registry: `kind = "optical_tweezers"`, table
/// `[optical_tweezers]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "optical_tweezers",
    check: |text| super::table::pick::<OtParams>(text, "optical_tweezers").map(drop),
    build: |text, config| {
        let p: OtParams = world_table(text, "optical_tweezers")?;
        let roles = super::device::roles_in(text, &config.specs)?;
        let scene = OpticalScene::new(p, &config.world_limits())?;
        Ok(Box::new(
            scene.with_grip(roles.bit(haptic_types::Role::Grip)),
        ))
    },
};

/// The optical-tweezers scene: the world and how it is drawn.
pub struct OpticalScene {
    world: World,
    look: Look,
    /// The button bit that grabs (the device's `grip` role; `None`: none does).
    grip_bit: Option<u32>,
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
            grip_bit: Some(0),
        })
    }

    /// The same scene grabbing with button `bit` (the device's `grip` role; `None`: no button
    /// grabs). A new scene grabs with button 0.
    pub fn with_grip(mut self, bit: Option<u32>) -> Self {
        self.grip_bit = bit;
        self
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
            grab: self.grip_bit.is_some_and(|b| input.buttons.pressed(b)),
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

    /// The held particle and its working envelope as a follower (protocol 4): where the
    /// command met it, its free drift, the envelope seen from the clip's anchor in
    /// [`MAX_REACH_VERTICES`] directions less that drift, what it keeps of its velocity, and
    /// the spring on the excess. None when nothing is
    /// held, the spring is off, or the clip is not the paper's radial one.
    fn local_primitives(&self, out: &mut haptic_types::local::WorldPrimitives) {
        let w = &self.world;
        let p = w.params();
        if !(w.grabbed() && p.feedback && p.clip == ot_envelope::ClipMode::Radial) {
            return;
        }
        let Some((from, anchor, free)) = w.last_clip() else {
            return;
        };
        let poly: Vec<[f64; 2]> = w.envelope().iter().map(|v| [v.x, v.y]).collect();
        if let Some(reach) = radial_reach(&poly, anchor, MAX_REACH_VERTICES) {
            out.follower = Some(Follower {
                position_m: from,
                drift_m: free,
                reach_m: reach
                    .iter()
                    .map(|v| [v[0] - free[0], v[1] - free[1]])
                    .collect(),
                retain: p.velocity_retain,
                stiffness_n_per_m: p.stiffness_n_per_m,
            });
        }
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

/// `x` (> 0) rounded down to three significant digits, as text (a bound stated inside
/// itself), written by [`fmt_sig`](world_form::fmt_sig) (`1.6`, `12.3`, `1.23e7`).
fn three_digits_down(x: f64) -> String {
    let e = x.log10().floor() as i32;
    let unit = 10f64.powi(e - 2);
    world_form::fmt_sig((x / unit).floor() * unit, 3)
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
