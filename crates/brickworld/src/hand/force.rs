//! The force the device renders each tick: the proxy spring, the weight and inertia of a
//! rigidly carried brick or the pull of a coupled one, scaled down to the device's largest
//! force.

use rapier3d_f64::math::Vector;
use world_form::Limits;

use super::Hand;
use crate::bricks::BrickSet;
use crate::params::{Inertia, Params};

/// The force one step of the hand sends to the device, and its parts (N, world frame).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Felt {
    /// Spring + weight + inertia, scaled down to [`Limits::max_force_n`] if larger.
    pub force: Vector,
    /// Whether `force` was scaled down.
    pub saturated: bool,
    /// Proxy spring `k (p - c)`, N.
    pub spring: Vector,
    /// Weight of the carried brick, N.
    pub weight: Vector,
    /// Inertial force of the carried brick (the paper's `−M a`), N.
    pub inertia: Vector,
    /// The virtual coupling's pull on the hand (the reaction of its pull on the brick), N,
    /// before the scale-down.
    pub coupling: Vector,
    /// Grip-point acceleration estimate, m/s².
    pub acceleration: Vector,
    /// Deepest penetration found before the proxy was pushed out, m.
    pub penetration_m: f64,
}

impl Hand {
    /// The force the device renders this tick: spring + weight + inertia (or the coupling's
    /// pull), scaled down to the device limit; and the spring's part of it as felt (scaled
    /// alike). The hand pushes the world with exactly the reaction of that part (action =
    /// reaction at the coupling): a proxy pressed deep into a brick pushes with at most the
    /// device's force, not with the stretched spring's. A coupled brick gets the reaction of
    /// the coupling's felt pull.
    pub(super) fn device_force(
        &mut self,
        c: Vector,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        penetration_m: f64,
    ) -> (Felt, Vector) {
        let spring = (self.proxy - c) * params.proxy_stiffness_n_per_m;
        let m = params.brick_mass_kg;
        let accel = Vector::from_array(self.motion.acceleration());
        let (weight, inertia, coupling) = match self.held {
            Some(h) if h.coupled => {
                let (pull, d) = self.coupling_pull(&h, params, limits, bricks);
                self.damper = d;
                (Vector::ZERO, Vector::ZERO, -pull)
            }
            Some(_) => {
                let w = Vector::new(0.0, 0.0, -m * params.gravity_m_per_s2);
                let i = if params.inertia == Inertia::Paper {
                    -accel * m
                } else {
                    Vector::ZERO
                };
                (w, i, Vector::ZERO)
            }
            None => (Vector::ZERO, Vector::ZERO, Vector::ZERO),
        };
        let total = spring + weight + inertia + coupling;
        let mag = total.length();
        let scale = if mag > limits.max_force_n {
            limits.max_force_n / mag
        } else {
            1.0
        };
        let (force, saturated) = (total * scale, scale < 1.0);
        if let Some(h) = self.held.filter(|h| h.coupled) {
            // The brick gets exactly the reaction of what the hand feels of the coupling: the
            // same force both ways, the scale-down included.
            if let Some(rb) = bricks.phys.bodies.get_mut(bricks.body(h.brick)) {
                rb.apply_impulse(-coupling * (scale * params.dt_s), true);
            }
        }
        let felt = Felt {
            force,
            saturated,
            spring,
            weight,
            inertia,
            coupling,
            acceleration: accel,
            penetration_m,
        };
        (felt, spring * scale)
    }
}
