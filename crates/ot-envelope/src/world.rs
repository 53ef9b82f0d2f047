//! The optical-tweezers world (Lee, Lyons & LeBrun, §2.4 and §3.3), in the form every
//! nanohaptics world shares: SI [`Params`] (what never changes), a [`World`] built from them and
//! the device's [`Limits`], and [`World::step`] taking an [`Input`] (cursor and button) and
//! returning a [`StepReport`] (force N, stiffness felt N/m, typed [`Event`]s).
//!
//! A 1 µm particle sits in an elliptic Gaussian trap; a cursor sphere rides on the stylus. Press
//! the button with the cursor touching the particle to grab it; release the button to let go.
//! Each step advances the particle by `dt_s` of particle time (the paper's control cycle).
//! While grabbed, the [`TickController`] builds this step's working envelope from the particle's
//! velocity, clips the command (cursor − particle) to it, places the trap so that the particle
//! makes the allowed displacement, and returns the spring force `−k·excess` felt on the stylus
//! (when `feedback` is on). The particle is then moved by the trap's flow map — not by the
//! command — so the state is the physics, not the wish. Not grabbed, the particle evolves in the
//! last trap. The paper's viscous simplification (velocity kept to a fraction each cycle) is
//! `velocity_retain` (1: none).
//!
//! The tick map's integrator is model data ([`TickMap`]): the cheapest RK4/RK8 map within an
//! error budget from converged dynamics ([`TickMap::Budget`], `ot_physics::budget`), or a method
//! chosen by name ([`TickMap::Named`], `ot_physics::Method::from_name`). The choice and its
//! measured error, and the envelope grid's, are reported as events on the first step.
//!
//! ```
//! use ot_envelope::world::{Event, Input, Params, World};
//! use world_form::Limits;
//! let mut w = World::new(&Params::paper(), &Limits::FALCON.in_world(1e6, 1e-3))?;
//! // Touch the particle (at the origin) with the cursor and press the button: grabbed.
//! let r = w.step(&Input { cursor_m: [0.0, 0.0], grab: true });
//! assert!(r.events.iter().any(|e| matches!(e, Event::Grab { .. })));
//! assert!(w.grabbed());
//! # Ok::<(), ot_envelope::world::WorldError>(())
//! ```

use crate::ClipMode;
use crate::grid::choose_grid;
use crate::steer::{ParticleState, SteerParams};
use crate::tick::{TickController, TickParams, TickStats};
use nalgebra::Vector2;
use ot_physics::budget::{choose_tick_map, measure};
use ot_physics::{Method, Propagator, TrapModel};
use serde::{Deserialize, Serialize};
use world_form::Limits;

type V2 = Vector2<f64>;

/// How the tick map (one step of particle time) is integrated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TickMap {
    /// The cheapest fixed-step RK4/RK8 map whose displacement is within `tol_m` of converged
    /// dynamics for start speeds up to the world's `map_speed_m_per_s`.
    Budget {
        /// Error budget, m (1e-13 to 1e-7).
        tol_m: f64,
    },
    /// A method chosen by its `ot_physics` name (`rk4`, `rk8`, `dopri5`, `adaptive`, …; see
    /// `ot_physics::METHOD_NAMES`), with its substeps (fixed-step methods) or relative tolerance
    /// (adaptive methods); its error from converged dynamics is measured and reported.
    Named {
        /// Method name.
        name: String,
        /// Substeps of a fixed-step method (1–1000; `None`: the method's default).
        substeps: Option<u32>,
        /// Relative tolerance of an adaptive method (`None`: the method's default).
        rtol: Option<f64>,
    },
}

/// The optical-tweezers world's parameters, SI: what never changes during a session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Well depth P0, J (paper: 1e-15).
    pub depth_j: f64,
    /// Beam waists a (along x) and b (along y), m (paper: 600e-9, 300e-9).
    pub waists_m: [f64; 2],
    /// Particle mass, kg (paper: 1e-15).
    pub mass_kg: f64,
    /// Particle time per step, s (paper: 1e-6). At most two periods of the particle's small
    /// oscillation ([`Params::max_dt_s`]).
    pub dt_s: f64,
    /// How the tick map is integrated.
    pub tick_map: TickMap,
    /// Largest particle speed the tick map and the envelope grid are checked for, m/s (paper:
    /// 0.1, i.e. 100 nm/µs).
    pub map_speed_m_per_s: f64,
    /// Warm-start the working envelope from the last full build (false: rebuild every step).
    pub warm_start: bool,
    /// Particle radius, m (paper: 0.5e-6).
    pub particle_radius_m: f64,
    /// Cursor sphere radius, m.
    pub cursor_radius_m: f64,
    /// Spring stiffness on the excess (command beyond the envelope), N/m. At most the device's
    /// `max_stiffness_n_per_m`.
    pub stiffness_n_per_m: f64,
    /// Force feedback on the stylus (the paper's experiment switches it off).
    pub feedback: bool,
    /// Clipping rule of a command outside the envelope.
    pub clip: ClipMode,
    /// Fraction of the velocity kept after each step (paper §3.3: 0.1; 1: no damping).
    pub velocity_retain: f64,
    /// Particle (and trap) start, m.
    pub start_m: [f64; 2],
    /// Geometric tolerance of the working envelope, m.
    pub envelope_tol_m: f64,
    /// Grid spacing of a full envelope build, waists per cell (`None`: chosen from
    /// `envelope_tol_m` by `grid::choose_grid`).
    pub envelope_cell_waists: Option<f64>,
    /// Half-width of the envelope's offset region beyond the drift path, waists (`None`: chosen
    /// from `envelope_tol_m`).
    pub envelope_margin_waists: Option<f64>,
    /// Force evaluations of a spread envelope build per step (1 to 1e6; `None`: a rebuild runs
    /// whole in the step that needs it). See [`crate::tick`] and [`crate::spread`].
    pub envelope_build_evals_per_tick: Option<u64>,
}

impl Params {
    /// The paper's constants (a = 600 nm, b = 300 nm, P0 = 1e-15 J, m = 1e-15 kg, 1 µm particle)
    /// at a 0.2 µs step, a 0.5 µm cursor, 1e-6 N/m spring, radial clipping, tick map within
    /// 0.01 nm of converged dynamics.
    pub fn paper() -> Self {
        Params {
            depth_j: 1e-15,
            waists_m: [600e-9, 300e-9],
            mass_kg: 1e-15,
            dt_s: 0.2e-6,
            tick_map: TickMap::Budget {
                tol_m: ot_physics::DEFAULT_TOL_M,
            },
            map_speed_m_per_s: 0.1,
            warm_start: true,
            particle_radius_m: 0.5e-6,
            cursor_radius_m: 0.5e-6,
            stiffness_n_per_m: 1e-6,
            feedback: true,
            clip: ClipMode::Radial,
            velocity_retain: 1.0,
            start_m: [0.0, 0.0],
            envelope_tol_m: crate::DEFAULT_TOL,
            envelope_cell_waists: None,
            envelope_margin_waists: None,
            envelope_build_evals_per_tick: Some(crate::tick::DEFAULT_BUILD_EVALS_PER_TICK),
        }
    }

    /// Period of the particle's small oscillation about the well's centre along the narrower
    /// waist, s: ω² = 4·P0 / (m·w²) for the well −P0·e^{−2x²/w²} (paper constants: 0.942 µs).
    pub fn small_oscillation_period_s(&self) -> f64 {
        let w = self.waists_m[0].min(self.waists_m[1]);
        let omega = (4.0 * self.depth_j / (self.mass_kg * w * w)).sqrt();
        2.0 * std::f64::consts::PI / omega
    }

    /// Longest step a haptic loop can afford, s: two small-oscillation periods. The envelope's
    /// cost grows with the oscillations one step holds (their folds multiply its boundary): at
    /// paper constants 1 µs steps cost ~2 ms at p99, 5 µs steps up to 0.5 s.
    pub fn max_dt_s(&self) -> f64 {
        2.0 * self.small_oscillation_period_s()
    }

    /// Checks every field: finite, in range, `dt_s` within [`Params::max_dt_s`], the spring
    /// within the device's stiffness. The error names the field and its allowed range.
    pub fn validate(&self, limits: &Limits) -> Result<(), WorldError> {
        positive("depth_j", self.depth_j, 1e-6)?;
        positive("waists_m[0]", self.waists_m[0], 1e-3)?;
        positive("waists_m[1]", self.waists_m[1], 1e-3)?;
        positive("mass_kg", self.mass_kg, 1e-3)?;
        positive("dt_s", self.dt_s, 1.0)?;
        let max_dt = self.max_dt_s();
        if !max_dt.is_finite() || self.dt_s > max_dt {
            return Err(WorldError::Param {
                field: "dt_s",
                value: self.dt_s,
                allowed: format!(
                    "0 < dt_s ≤ {max_dt:.3e} s, two periods of the particle's small oscillation"
                ),
            });
        }
        match &self.tick_map {
            TickMap::Budget { tol_m } => closed("tick_map.tol_m", *tol_m, 1e-13, 1e-7)?,
            TickMap::Named { substeps, rtol, .. } => {
                if let Some(n) = substeps {
                    closed("tick_map.substeps", f64::from(*n), 1.0, 1000.0)?;
                }
                if let Some(r) = rtol {
                    closed("tick_map.rtol", *r, 1e-14, 1e-2)?;
                }
            }
        }
        closed("map_speed_m_per_s", self.map_speed_m_per_s, 0.0, 1e3)?;
        positive("particle_radius_m", self.particle_radius_m, 1e-3)?;
        positive("cursor_radius_m", self.cursor_radius_m, 1e-3)?;
        positive(
            "stiffness_n_per_m",
            self.stiffness_n_per_m,
            limits.max_stiffness_n_per_m,
        )?;
        closed("velocity_retain", self.velocity_retain, 0.0, 1.0)?;
        closed("start_m[0]", self.start_m[0], -1.0, 1.0)?;
        closed("start_m[1]", self.start_m[1], -1.0, 1.0)?;
        positive("envelope_tol_m", self.envelope_tol_m, 1e-6)?;
        if let Some(c) = self.envelope_cell_waists {
            closed("envelope_cell_waists", c, 0.01, 2.0)?;
        }
        if let Some(m) = self.envelope_margin_waists {
            closed("envelope_margin_waists", m, 1.0, 10.0)?;
        }
        if let Some(b) = self.envelope_build_evals_per_tick {
            closed("envelope_build_evals_per_tick", b as f64, 1.0, 1e6)?;
        }
        Ok(())
    }
}

/// A parameter out of range, or a model the trap or envelope code refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WorldError {
    /// A parameter outside its allowed range (or not finite).
    #[error("`{field}` = {value} is out of range: allowed {allowed}")]
    Param {
        /// The field, as named in [`Params`].
        field: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range, in words.
        allowed: String,
    },
    /// The device limits themselves are invalid.
    #[error("device limits: {0}")]
    Limits(#[from] world_form::LimitsError),
    /// The trap model or tick map cannot be built.
    #[error("{0}")]
    Physics(#[from] ot_physics::PhysicsError),
    /// The envelope grid or the steering controller cannot be set up.
    #[error("{0}")]
    Envelope(#[from] crate::EnvelopeError),
}

fn positive(field: &'static str, value: f64, max: f64) -> Result<(), WorldError> {
    if value.is_finite() && value > 0.0 && value <= max {
        Ok(())
    } else {
        Err(WorldError::Param {
            field,
            value,
            allowed: format!("0 < {field} ≤ {max}"),
        })
    }
}

fn closed(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<(), WorldError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(WorldError::Param {
            field,
            value,
            allowed: format!("{lo} ≤ {field} ≤ {hi}"),
        })
    }
}

/// One step's input: the cursor and the grab button.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Input {
    /// Cursor centre, world frame, m.
    pub cursor_m: [f64; 2],
    /// The grab button is down.
    pub grab: bool,
}

/// Something that happened during a step. Serialized with a `type` tag and named fields
/// (`{"type":"grab","gap_m":1e-7}`), the form recordings, the Foxglove log and Python share.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Event {
    /// The tick map in use (first step only).
    TickMap {
        /// `"budget"`: chosen from the error budget; `"named"`: the method asked for by name.
        chosen_by: &'static str,
        /// Method name and substeps, e.g. `rk4×2`.
        method: String,
        /// Largest displacement error from converged dynamics at the probes, m.
        error_m: f64,
        /// Force evaluations per flow.
        evals_per_flow: u64,
        /// The error budget, m (a named map: `null`, its error is only measured).
        budget_m: Option<f64>,
        /// Probe flows the error was measured at (offsets × velocities).
        probes: usize,
        /// Largest start speed probed, m/s.
        speed_m_per_s: f64,
    },
    /// The envelope grid in use (first step only).
    EnvelopeGrid {
        /// `"budget"`: chosen from `envelope_tol_m`; `"fixed"`: both fixed in the parameters.
        chosen_by: &'static str,
        /// Region half-width beyond the drift path, waists.
        margin_waists: f64,
        /// Grid spacing, waists per cell.
        cell_waists: f64,
        /// Largest distance between this grid's envelope and a 0.05-waist reference grid's at
        /// the probed speeds, m (`null` when both were fixed).
        grid_error_m: Option<f64>,
        /// Bound on the distance the region's cut costs, m (`null` when both were fixed).
        region_bound_m: Option<f64>,
        /// Grid vertices of a build at rest (`null` when both were fixed).
        vertices: Option<usize>,
    },
    /// The button went down with the cursor touching the particle: grabbed.
    Grab {
        /// Cursor centre to particle centre, m.
        gap_m: f64,
    },
    /// The button went down with the cursor away from the particle: nothing grabbed.
    GrabMissed {
        /// Cursor centre to particle centre, m.
        gap_m: f64,
    },
    /// The button went up: the particle is let go.
    Release,
    /// The command left the working envelope (first step of a run of clipped steps).
    Clipped {
        /// Length of the command beyond the envelope, m.
        excess_m: f64,
    },
    /// The steering controller failed this step (the trap stays where it was).
    ControllerError {
        /// What failed.
        message: String,
    },
    /// The particle's flow failed this step (the particle stays where it was).
    PhysicsError {
        /// What failed.
        message: String,
    },
}

impl Event {
    /// The event's short name, e.g. `grab` (the `type` tag of its serialized form).
    pub fn name(&self) -> &'static str {
        match self {
            Event::TickMap { .. } => "tick_map",
            Event::EnvelopeGrid { .. } => "envelope_grid",
            Event::Grab { .. } => "grab",
            Event::GrabMissed { .. } => "grab_missed",
            Event::Release => "release",
            Event::Clipped { .. } => "clipped",
            Event::ControllerError { .. } => "controller_error",
            Event::PhysicsError { .. } => "physics_error",
        }
    }
}

/// What one step returns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepReport {
    /// Force on the stylus, world frame, N (zero when not grabbed or feedback is off). Its norm
    /// is at most the device's `max_force_n`.
    pub force_n: [f64; 2],
    /// Stiffness of the spring the hand feels, N/m (0 when none acts).
    pub stiffness_n_per_m: f64,
    /// Events of this step, in order (empty: no allocation).
    pub events: Vec<Event>,
}

/// The optical-tweezers world: its parameters and model data (trap, tick map, controller) and
/// its state (particle, trap, cursor, grab).
pub struct World {
    params: Params,
    limits: Limits,
    prop: Propagator<2>,
    controller: TickController,
    /// The first step's reports (tick map, envelope grid), taken by the first step.
    first_events: Vec<Event>,
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

impl World {
    /// Builds the world: checks `params` against `limits`, builds the trap model, the tick map
    /// (measuring its error), the envelope grid and (with warm start) the first working envelope,
    /// for the particle at rest, so that the first grabbed step is warm.
    pub fn new(params: &Params, limits: &Limits) -> Result<World, WorldError> {
        limits.validate()?;
        params.validate(limits)?;
        let p = params;
        let model = TrapModel::builder(p.depth_j, p.waists_m)
            .mass(p.mass_kg)
            .build()?;
        let (prop, map, chosen_by) = match &p.tick_map {
            TickMap::Budget { tol_m } => {
                let (prop, c) = choose_tick_map(model, p.dt_s, *tol_m, p.map_speed_m_per_s)?;
                (prop, c, "budget")
            }
            TickMap::Named {
                name,
                substeps,
                rtol,
            } => {
                let method = Method::from_name(name, *rtol, *substeps)?;
                let c = measure(model, method, p.dt_s, p.map_speed_m_per_s)?;
                (Propagator::new(model, method, p.dt_s)?, c, "named")
            }
        };
        let substeps = match map.method {
            Method::Rk4 { substeps } | Method::Rk8 { substeps } => substeps,
            _ => 1,
        };
        let (margin, cell, grid) = match (p.envelope_margin_waists, p.envelope_cell_waists) {
            (Some(m), Some(c)) => (m, c, None),
            (m, c) => {
                let g = choose_grid(&prop, p.envelope_tol_m, p.map_speed_m_per_s)?;
                (
                    m.unwrap_or(g.margin_waists),
                    c.unwrap_or(g.cell_waists),
                    Some(g),
                )
            }
        };
        let mut tick = TickParams::new(SteerParams {
            stiffness: p.stiffness_n_per_m,
            mode: p.clip,
            tol: p.envelope_tol_m,
            margin_waists: margin,
        });
        tick.warm_start = p.warm_start;
        tick.cell_waists = Some(cell);
        tick.build_evals_per_tick = p.envelope_build_evals_per_tick;
        let mut controller = TickController::new(tick)?;
        // the first envelope, for the particle at rest, before the first grab
        controller.prebuild(&prop, &V2::zeros())?;
        let start = V2::new(p.start_m[0], p.start_m[1]);
        Ok(World {
            params: p.clone(),
            limits: *limits,
            prop,
            controller,
            first_events: vec![
                Event::TickMap {
                    chosen_by,
                    method: format!("{}×{substeps}", map.method.name()),
                    error_m: map.error_m,
                    evals_per_flow: map.evals_per_flow,
                    budget_m: (chosen_by == "budget").then_some(map.tol_m),
                    probes: map.probes,
                    speed_m_per_s: map.v_max,
                },
                Event::EnvelopeGrid {
                    chosen_by: if grid.is_some() { "budget" } else { "fixed" },
                    margin_waists: margin,
                    cell_waists: cell,
                    grid_error_m: grid.map(|g| g.grid_error_m),
                    region_bound_m: grid.map(|g| g.region_bound_m),
                    vertices: grid.map(|g| g.vertices),
                },
            ],
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

    /// Advances the world by one step of `dt_s` particle time.
    pub fn step(&mut self, input: &Input) -> StepReport {
        let mut events = std::mem::take(&mut self.first_events);
        self.cursor = V2::new(input.cursor_m[0], input.cursor_m[1]);
        if input.grab && !self.button_was && !self.grabbed {
            let gap_m = (self.cursor - self.position).norm();
            if gap_m <= self.params.particle_radius_m + self.params.cursor_radius_m {
                self.grabbed = true;
                // continue from the trap the particle sits in
                self.controller.continue_from(&self.trap);
                events.push(Event::Grab { gap_m });
            } else {
                events.push(Event::GrabMissed { gap_m });
            }
        }
        if !input.grab && self.grabbed {
            self.grabbed = false;
            events.push(Event::Release);
        }
        self.button_was = input.grab;
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
                    if self.params.feedback {
                        self.force = limit_norm(s.force, self.limits.max_force_n);
                    }
                    // reuse the buffer: no allocation once it has grown
                    self.envelope.clear();
                    self.envelope.extend_from_slice(self.controller.envelope());
                }
                Err(e) => events.push(Event::ControllerError {
                    message: e.to_string(),
                }),
            }
        } else {
            self.envelope.clear();
            // keep the envelope fresh for the next grab (one bounded slice)
            if let Err(e) = self.controller.prepare(&self.prop, &self.velocity) {
                events.push(Event::ControllerError {
                    message: e.to_string(),
                });
            }
        }
        let excess_m = self.excess.norm();
        let clipping = excess_m > 0.0;
        if clipping && !self.clipping {
            events.push(Event::Clipped { excess_m });
        }
        self.clipping = clipping;
        let offset = self.trap - self.position;
        match self.prop.flow(&offset, &self.velocity) {
            Ok((d, v, _)) => {
                self.position += d;
                self.velocity = v * self.params.velocity_retain;
            }
            Err(e) => events.push(Event::PhysicsError {
                message: e.to_string(),
            }),
        }
        StepReport {
            force_n: [self.force.x, self.force.y],
            stiffness_n_per_m: if self.grabbed && self.params.feedback {
                self.params.stiffness_n_per_m
            } else {
                0.0
            },
            events,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Particle centre, world frame, m.
    pub fn position_m(&self) -> [f64; 2] {
        [self.position.x, self.position.y]
    }

    /// Particle velocity, m/s.
    pub fn velocity_m_per_s(&self) -> [f64; 2] {
        [self.velocity.x, self.velocity.y]
    }

    /// Trap centre, world frame, m.
    pub fn trap_m(&self) -> [f64; 2] {
        [self.trap.x, self.trap.y]
    }

    /// Cursor centre of the last step, world frame, m.
    pub fn cursor_m(&self) -> [f64; 2] {
        [self.cursor.x, self.cursor.y]
    }

    /// Whether the particle is held.
    pub fn grabbed(&self) -> bool {
        self.grabbed
    }

    /// Length of the last command beyond the envelope, m (0: inside).
    pub fn excess_m(&self) -> f64 {
        self.excess.norm()
    }

    /// Force of the last step on the stylus, world frame, N.
    pub fn force_n(&self) -> [f64; 2] {
        [self.force.x, self.force.y]
    }

    /// The last step's working envelope (displacements from the particle, m; empty when not
    /// grabbed).
    pub fn envelope(&self) -> &[V2] {
        &self.envelope
    }

    /// The steering counters so far (rebuilds, warm steps, solves).
    pub fn tick_stats(&self) -> TickStats {
        self.controller.stats()
    }

    /// The tick map in use.
    pub fn tick_map(&self) -> &Propagator<2> {
        &self.prop
    }
}

/// `f` scaled down to norm `max` if longer (direction kept).
fn limit_norm(f: V2, max: f64) -> V2 {
    let n = f.norm();
    if n > max { f * (max / n) } else { f }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn limits() -> Limits {
        Limits::FALCON.in_world(1e6, 1e-3)
    }

    /// The error text of building a world from `p` with the Falcon's limits in the OT scene.
    fn refused(p: Params) -> String {
        World::new(&p, &limits()).err().unwrap().to_string()
    }

    #[test]
    fn the_paper_period_and_step_bound() {
        let p = Params::paper();
        // 2π·√(1e-15 kg · (300 nm)² / (4e-15 J)) = 0.942 µs
        assert!((p.small_oscillation_period_s() - 0.942_477_796e-6).abs() < 1e-15);
        let e = refused(Params {
            dt_s: 5e-6,
            ..Params::paper()
        });
        assert_eq!(
            e,
            "`dt_s` = 0.000005 is out of range: allowed 0 < dt_s ≤ 1.885e-6 s, two periods of \
             the particle's small oscillation"
        );
    }

    #[test]
    fn a_spring_stiffer_than_the_device_is_refused() {
        let e = refused(Params {
            stiffness_n_per_m: 5.0,
            ..Params::paper()
        });
        assert_eq!(
            e,
            "`stiffness_n_per_m` = 5 is out of range: allowed 0 < stiffness_n_per_m ≤ 3"
        );
        let e = refused(Params {
            depth_j: f64::NAN,
            ..Params::paper()
        });
        assert_eq!(
            e,
            "`depth_j` = NaN is out of range: allowed 0 < depth_j ≤ 0.000001"
        );
    }

    #[test]
    fn an_unknown_method_names_the_allowed_ones() {
        let p = Params {
            tick_map: TickMap::Named {
                name: "euler".into(),
                substeps: None,
                rtol: None,
            },
            ..Params::paper()
        };
        let e = World::new(&p, &limits()).err().unwrap().to_string();
        assert!(
            e.starts_with("unknown method \"euler\": allowed \"paper-rk4\""),
            "{e}"
        );
    }

    #[test]
    fn a_named_map_is_measured_and_reported_first() {
        let p = Params {
            tick_map: TickMap::Named {
                name: "rk4".into(),
                substeps: Some(8),
                rtol: None,
            },
            ..Params::paper()
        };
        let mut w = World::new(&p, &limits()).unwrap();
        let r = w.step(&Input {
            cursor_m: [5e-6, 0.0],
            grab: false,
        });
        match &r.events[0] {
            Event::TickMap {
                chosen_by,
                method,
                error_m,
                evals_per_flow,
                budget_m,
                ..
            } => {
                assert_eq!(*budget_m, None);
                assert_eq!((*chosen_by, method.as_str()), ("named", "rk4×8"));
                assert!(*error_m > 0.0 && *error_m < 1e-11, "{error_m}");
                assert_eq!(*evals_per_flow, 32);
            }
            e => panic!("first event {}", e.name()),
        }
        assert_eq!(r.events[1].name(), "envelope_grid");
        assert_eq!(r.events.len(), 2);
        // reported once
        let r = w.step(&Input {
            cursor_m: [5e-6, 0.0],
            grab: false,
        });
        assert!(r.events.is_empty());
    }

    #[test]
    fn grab_steer_clip_and_release() {
        let mut w = World::new(&Params::paper(), &limits()).unwrap();
        let far = Input {
            cursor_m: [2e-6, 0.0],
            grab: true,
        };
        let r = w.step(&far);
        assert!(matches!(r.events[2], Event::GrabMissed { gap_m } if gap_m == 2e-6));
        assert!(!w.grabbed());
        w.step(&Input {
            cursor_m: [0.0, 0.0],
            grab: false,
        });
        let r = w.step(&Input {
            cursor_m: [0.0, 0.0],
            grab: true,
        });
        assert!(matches!(r.events[..], [Event::Grab { gap_m }] if gap_m == 0.0));
        // A command far outside the envelope (1 µm in one 0.2 µs step): clipped, and the hand
        // feels the spring on the excess, −k·excess, pointing back to the particle.
        let r = w.step(&Input {
            cursor_m: [1e-6, 0.0],
            grab: true,
        });
        let excess = w.excess_m();
        assert!(excess > 0.5e-6 && excess < 1e-6, "{excess}");
        assert!(matches!(r.events[..], [Event::Clipped { excess_m }] if excess_m == excess));
        assert!(
            (r.force_n[0] + 1e-6 * excess).abs() < 1e-18,
            "{:?}",
            r.force_n
        );
        assert_eq!(r.stiffness_n_per_m, 1e-6);
        // the particle moved towards the cursor, by the physics
        assert!(w.position_m()[0] > 0.0);
        let r = w.step(&Input {
            cursor_m: [1e-6, 0.0],
            grab: false,
        });
        assert_eq!(r.events, vec![Event::Release]);
        assert_eq!((r.force_n, r.stiffness_n_per_m), ([0.0, 0.0], 0.0));
    }

    #[test]
    fn the_felt_force_never_exceeds_the_device() {
        // A device that renders at most 1e-13 N in this world: the spring force is scaled down
        // to it, its direction kept.
        let tiny = Limits {
            max_force_n: 1e-13,
            max_stiffness_n_per_m: 1e-3,
        };
        let mut w = World::new(&Params::paper(), &tiny).unwrap();
        w.step(&Input {
            cursor_m: [0.0, 0.0],
            grab: true,
        });
        let r = w.step(&Input {
            cursor_m: [0.0, 1e-6],
            grab: true,
        });
        let n = (r.force_n[0].powi(2) + r.force_n[1].powi(2)).sqrt();
        assert!((n - 1e-13).abs() < 1e-25, "{n}");
        assert!(r.force_n[1] < 0.0);
    }

    #[test]
    fn events_serialize_with_a_tag_and_named_fields() {
        let json = |e: &Event| serde_json::to_string(e).unwrap();
        assert_eq!(
            json(&Event::Grab { gap_m: 1e-7 }),
            r#"{"type":"grab","gap_m":1e-7}"#
        );
        assert_eq!(json(&Event::Release), r#"{"type":"release"}"#);
        assert_eq!(
            json(&Event::EnvelopeGrid {
                chosen_by: "fixed",
                margin_waists: 3.0,
                cell_waists: 0.25,
                grid_error_m: None,
                region_bound_m: None,
                vertices: None,
            }),
            r#"{"type":"envelope_grid","chosen_by":"fixed","margin_waists":3.0,"cell_waists":0.25,"grid_error_m":null,"region_bound_m":null,"vertices":null}"#
        );
    }
}
