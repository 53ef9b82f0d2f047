//! What never changes during a run: the well, the particle and the effects
//! switched on (the `mjModel` of a trapped particle).

use crate::error::{PhysicsError, Result, finite, positive};
use crate::well::GaussianWell;
use nalgebra::SVector;

/// Boltzmann constant (J/K).
pub const BOLTZMANN: f64 = 1.380_649e-23;

/// A particle in an optical trap, with the effects a scene asked for.
///
/// * inertia on (a mass is given): `m r̈ = F(r) − γ ṙ + F_ext (+ noise)`, the
///   paper's Lagrangian dynamics when drag is off;
/// * inertia off (no mass): overdamped, `γ ṙ = F(r) + F_ext (+ noise)`; needs drag.
///
/// Effects left off cost nothing: no drag term is evaluated without drag, no
/// random numbers are drawn without temperature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrapModel<const D: usize> {
    /// The potential well.
    pub well: GaussianWell<D>,
    /// Particle mass (kg); `None` switches inertia off (overdamped).
    pub mass: Option<f64>,
    /// Stokes drag coefficient γ = 6πηr (kg/s); `None` when drag is off.
    pub drag: Option<f64>,
    /// Thermal energy kT (J); `None` when thermal noise is off.
    pub kt: Option<f64>,
    /// Constant external force (N), zero unless set.
    pub external_force: SVector<f64, D>,
}

/// Builder for [`TrapModel`]; every setter is validated in [`TrapBuilder::build`].
#[derive(Debug, Clone)]
pub struct TrapBuilder<const D: usize> {
    depth: f64,
    waists: [f64; D],
    mass: Option<f64>,
    radius: Option<f64>,
    viscosity: Option<f64>,
    temperature: Option<f64>,
    external_force: [f64; D],
}

impl<const D: usize> TrapModel<D> {
    /// Start a model from the well depth (J) and waists (m).
    pub fn builder(depth: f64, waists: [f64; D]) -> TrapBuilder<D> {
        TrapBuilder {
            depth,
            waists,
            mass: None,
            radius: None,
            viscosity: None,
            temperature: None,
            external_force: [0.0; D],
        }
    }

    /// Largest angular frequency of the dynamics near the centre (rad/s):
    /// `sqrt(κ_max/m)` with inertia, `κ_max/γ` (a rate) when overdamped, and
    /// with drag also `γ/m` if that is larger (the velocity relaxation rate).
    pub fn fastest_rate(&self) -> f64 {
        let kmax = self.well.stiffness().max();
        match (self.mass, self.drag) {
            (Some(m), Some(g)) => (kmax / m).sqrt().max(g / m),
            (Some(m), None) => (kmax / m).sqrt(),
            (None, Some(g)) => kmax / g,
            (None, None) => 0.0,
        }
    }

    /// Smallest waist (m), the natural length scale.
    pub fn length_scale(&self) -> f64 {
        self.well.waists().min()
    }

    /// Whether the model is conservative (inertia on, no drag, no noise).
    pub fn is_conservative(&self) -> bool {
        self.mass.is_some() && self.drag.is_none() && self.kt.is_none()
    }
}

impl<const D: usize> TrapBuilder<D> {
    /// Particle mass (kg); switches inertia on.
    pub fn mass(mut self, mass: f64) -> Self {
        self.mass = Some(mass);
        self
    }
    /// Stokes drag from particle radius (m) and fluid viscosity (Pa·s).
    pub fn stokes_drag(mut self, radius: f64, viscosity: f64) -> Self {
        self.radius = Some(radius);
        self.viscosity = Some(viscosity);
        self
    }
    /// Particle radius (m), used by drag.
    pub fn radius(mut self, radius: Option<f64>) -> Self {
        self.radius = radius;
        self
    }
    /// Fluid viscosity (Pa·s); with a radius switches drag on.
    pub fn viscosity(mut self, viscosity: Option<f64>) -> Self {
        self.viscosity = viscosity;
        self
    }
    /// Temperature (K); switches thermal noise on (needs drag).
    pub fn temperature(mut self, temperature: Option<f64>) -> Self {
        self.temperature = temperature;
        self
    }
    /// Optional mass (kg); `None` means overdamped.
    pub fn maybe_mass(mut self, mass: Option<f64>) -> Self {
        self.mass = mass;
        self
    }
    /// Constant external force (N).
    pub fn external_force(mut self, force: [f64; D]) -> Self {
        self.external_force = force;
        self
    }

    /// Validate and build.
    pub fn build(self) -> Result<TrapModel<D>> {
        let well = GaussianWell::new(self.depth, self.waists)?;
        let mass = self.mass.map(|m| positive("mass [kg]", m)).transpose()?;
        let radius = self.radius.map(|r| positive("radius [m]", r)).transpose()?;
        let viscosity = self
            .viscosity
            .map(|v| positive("viscosity [Pa s]", v))
            .transpose()?;
        let drag = match (radius, viscosity) {
            (Some(r), Some(eta)) => Some(6.0 * std::f64::consts::PI * eta * r),
            (None, None) => None,
            (Some(_), None) => {
                return Err(PhysicsError::Missing {
                    field: "viscosity [Pa s]",
                    needed_by: "Stokes drag (radius was given)",
                });
            }
            (None, Some(_)) => {
                return Err(PhysicsError::Missing {
                    field: "radius [m]",
                    needed_by: "Stokes drag (viscosity was given)",
                });
            }
        };
        let kt = match self.temperature {
            None => None,
            Some(t) => {
                let t = positive("temperature [K]", t)?;
                if drag.is_none() {
                    return Err(PhysicsError::Missing {
                        field: "radius [m] and viscosity [Pa s]",
                        needed_by: "thermal noise (fluctuation-dissipation needs drag)",
                    });
                }
                Some(BOLTZMANN * t)
            }
        };
        if mass.is_none() && drag.is_none() {
            return Err(PhysicsError::Missing {
                field: "mass [kg] (inertia) or radius [m] and viscosity [Pa s] (drag)",
                needed_by: "any dynamics",
            });
        }
        let mut f = SVector::<f64, D>::zeros();
        for (i, &fi) in self.external_force.iter().enumerate() {
            f[i] = finite("external_force [N]", fi)?;
        }
        Ok(TrapModel {
            well,
            mass,
            drag,
            kt,
            external_force: f,
        })
    }
}
