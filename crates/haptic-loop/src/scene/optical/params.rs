//! `[optical_tweezers]`: the scene file's table (human units: nm, µs, nJ, g) and its mapping
//! to the world's SI parameters and tick map, every field checked with its range.

use super::three_digits_down;
use haptic_engine::check::{SceneError, check_positive, check_range, out_of_range};
use ot_envelope::ClipMode;
use ot_envelope::world::{Params, TickMap};
use serde::Deserialize;
use world_form::Limits;
use world_form::fmt_num;

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
                format!(
                    "0 < stiffness ≤ {} N/m, the device's limit mapped to the world",
                    fmt_num(cap)
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
        let (tol, build_evals) = self.envelope_choice()?;
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
        self.check_tick_length(&params)?;
        Ok(params)
    }

    /// The envelope's settings, checked: its tolerance, m, and the evaluations per tick of
    /// its spread rebuild (`None`: rebuilt whole when needed).
    fn envelope_choice(&self) -> Result<(f64, Option<u64>), SceneError> {
        let p = self;
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
        Ok((tol, build_evals))
    }

    /// A haptic tick must be cheap: `dt_us` within the world's bound of a tick's length.
    fn check_tick_length(&self, params: &Params) -> Result<(), SceneError> {
        let p = self;
        // The world's bound (ot_envelope::tick_length, the one
        // bound of a tick's length), said in the scene's unit.
        let max_dt_us = params.max_dt_s() * 1e6;
        if !max_dt_us.is_finite() || p.dt_us > max_dt_us {
            return Err(out_of_range(
                "optical_tweezers.dt_us",
                p.dt_us,
                format!(
                    "0 < dt_us ≤ {} µs, {} period of the particle's fastest oscillation in \
                     this trap (2π·√(mass/κ), κ = 2·ln2·depth/waist², narrower waist); a longer \
                     tick makes the envelope too costly for a haptic loop",
                    three_digits_down(max_dt_us),
                    ot_envelope::tick_length::HAPTIC_OSCILLATIONS_PER_TICK
                ),
            ));
        }
        Ok(())
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
