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

mod params;
#[cfg(test)]
mod tests;

pub use params::{Params, TickMap, WorldError};

use crate::geometry::contains;
use crate::grid::choose_grid;
use crate::region::free_drift;
use crate::steer::{ParticleState, SteerParams};
use crate::tick::{TickController, TickParams, TickStats};
use nalgebra::Vector2;
use ot_physics::budget::{choose_tick_map, measure};
use ot_physics::{Method, Propagator};
use serde::Serialize;
use world_form::Limits;

type V2 = Vector2<f64>;

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
    /// The last grabbed step's particle as the command met it, the anchor of its clip and its
    /// free drift.
    clip_from: Option<(V2, V2, V2)>,
}

impl World {
    /// Builds the world: checks `params` against `limits`, builds the trap model, the tick map
    /// (measuring its error), the envelope grid and (with warm start) the first working envelope,
    /// for the particle at rest, so that the first grabbed step is warm.
    pub fn new(params: &Params, limits: &Limits) -> Result<World, WorldError> {
        limits.validate()?;
        params.validate(limits)?;
        let p = params;
        let model = p.model()?;
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
            clip_from: None,
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
        self.clip_from = None;
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
                    // The clip's anchor, as `clip_to_polygon` chose it.
                    let free = free_drift(self.prop.model(), &self.velocity, self.prop.dt());
                    let anchor = [V2::zeros(), free]
                        .into_iter()
                        .find(|a| contains(&self.envelope, a));
                    self.clip_from = anchor.map(|a| (self.position, a, free));
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

    /// The last step's clip as the held particle met it, world frame, m: its position before
    /// the step, the anchor the command was clipped from (zero displacement, or the free drift
    /// when zero is out of reach) and the free drift (where one step takes the particle with
    /// no trap force), with [`World::envelope`]. `None` when not held, or when neither anchor
    /// lies in the envelope (the clip then took the nearest boundary point).
    #[allow(clippy::type_complexity)]
    pub fn last_clip(&self) -> Option<([f64; 2], [f64; 2], [f64; 2])> {
        self.clip_from
            .map(|(p, a, u)| ([p.x, p.y], [a.x, a.y], [u.x, u.y]))
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
