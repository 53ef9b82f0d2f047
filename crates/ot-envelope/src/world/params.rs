//! The world's parameters (SI, what never changes during a session), the tick map's choice,
//! and the errors a world refuses them with, each naming the field and its range.

use crate::ClipMode;
use crate::EnvelopeError;
use crate::tick_length::{HAPTIC_OSCILLATIONS_PER_TICK, check_tick, max_tick_s};
use ot_physics::TrapModel;
use serde::{Deserialize, Serialize};
use world_form::{Limits, ValueError, fmt_num};

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
    /// Particle time per step, s (paper: 1e-6). At most one period of the particle's fastest
    /// small oscillation ([`Params::max_dt_s`]).
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

    /// The trap model of these parameters (the well and the particle's inertia).
    pub fn model(&self) -> Result<TrapModel<2>, WorldError> {
        Ok(TrapModel::builder(self.depth_j, self.waists_m)
            .mass(self.mass_kg)
            .build()?)
    }

    /// Period of the particle's fastest small oscillation about the well's centre, s:
    /// `2π / ω`, `ω` of [`crate::tick_length::oscillation_rate`] (paper constants: 1.6009 µs);
    /// NaN when the parameters build no model.
    pub fn small_oscillation_period_s(&self) -> f64 {
        self.max_dt_s() / f64::from(HAPTIC_OSCILLATIONS_PER_TICK)
    }

    /// Longest step a haptic loop can afford, s: [`HAPTIC_OSCILLATIONS_PER_TICK`] periods of
    /// the fastest small oscillation ([`crate::tick_length::max_tick_s`], the one bound of a
    /// tick's length); NaN when the parameters build no model.
    pub fn max_dt_s(&self) -> f64 {
        self.model()
            .ok()
            .and_then(|m| max_tick_s(&m, HAPTIC_OSCILLATIONS_PER_TICK))
            .unwrap_or(f64::NAN)
    }

    /// Checks every field: finite, in range, `dt_s` within [`Params::max_dt_s`], the spring
    /// within the device's stiffness. The error names the field and its allowed range.
    pub fn validate(&self, limits: &Limits) -> Result<(), WorldError> {
        positive("depth_j", self.depth_j, 1e-6)?;
        positive("waists_m[0]", self.waists_m[0], 1e-3)?;
        positive("waists_m[1]", self.waists_m[1], 1e-3)?;
        positive("mass_kg", self.mass_kg, 1e-3)?;
        positive("dt_s", self.dt_s, 1.0)?;
        check_tick(&self.model()?, self.dt_s, HAPTIC_OSCILLATIONS_PER_TICK).map_err(
            |e| match e {
                EnvelopeError::TickTooLong { error, .. } => {
                    WorldError::Param(error.map_field(|_| "`dt_s`".to_string()))
                }
                e => WorldError::Envelope(e),
            },
        )?;
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
    /// A parameter outside its allowed range (or not finite), the field named as in
    /// [`Params`] (`` `dt_s` ``).
    #[error(transparent)]
    Param(ValueError),
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
        Err(WorldError::Param(ValueError::out_of_range(
            format!("`{field}`"),
            value,
            format!("0 < {field} ≤ {}", fmt_num(max)),
        )))
    }
}

fn closed(field: &'static str, value: f64, lo: f64, hi: f64) -> Result<(), WorldError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(WorldError::Param(ValueError::out_of_range(
            format!("`{field}`"),
            value,
            format!("{} ≤ {field} ≤ {}", fmt_num(lo), fmt_num(hi)),
        )))
    }
}
