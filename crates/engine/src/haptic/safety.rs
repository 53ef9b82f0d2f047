//! Step 4 of a tick: the safety layer at the device port, on a force the loop did not zero.
//! The passivity controller (Hannaford and Ryu 2002) adds damping while the observer's tank is
//! below zero; the rate limiter holds the change of force per tick.

use super::{HapticLoop, PASSIVITY_MAX_DAMPING_N_S_PER_M};
use haptic_types::Event;
use haptic_types::tick::status;
use haptic_types::vec3::{self, Vec3};

impl HapticLoop {
    /// The force `f` (N, device frame) after the safety layer: the configuration reported at
    /// tick 0 (`safety.config`), then passivity damping on the displacement `dp` and the rate
    /// limit against `f_prev`, the force held over the last tick.
    pub(super) fn safety_layer(
        &mut self,
        tick: u64,
        f: Vec3,
        f_prev: Vec3,
        dp: Option<Vec3>,
        force_ok: bool,
    ) -> Vec3 {
        if force_ok && tick == 0 {
            self.result.events.push(Event::new(
                "safety.config",
                self.config
                    .safety
                    .describe(self.config.specs.limits.max_stiffness_n_per_m),
            ));
        }
        let f = self.passivity(f, dp, force_ok);
        self.rate_limit(f, f_prev, force_ok)
    }

    fn passivity(&mut self, mut f: Vec3, dp: Option<Vec3>, force_ok: bool) -> Vec3 {
        let r = &mut self.result;
        let dt = self.config.dt_s();
        let max = self.config.specs.limits.max_force_n;
        let mut passivity_now = false;
        if let (Some(_), Some(d), true) = (self.config.safety.passivity_reserve_j, dp, force_ok) {
            let v = vec3::scale(d, 1.0 / dt);
            let v2 = vec3::dot(v, v);
            if self.tank_j < 0.0 && v2 > 0.0 {
                // Damping that removes the deficit over the next tick if the motion goes on,
                // at most the damping a ZOH-rendered damper keeps passive with the loosest hand
                // (Colgate: b_hand > K T / 2 + α): larger, the controller itself chatters.
                let alpha = (-self.tank_j / (dt * v2)).min(PASSIVITY_MAX_DAMPING_N_S_PER_M);
                f = vec3::sub(f, vec3::scale(v, alpha));
                let n = vec3::norm(f);
                if n > max {
                    f = vec3::scale(f, max / n);
                    while vec3::norm(f) > max {
                        f = vec3::scale(f, 1.0 - f64::EPSILON);
                    }
                }
                r.status |= status::PASSIVITY;
                passivity_now = true;
                if !self.passivity_active {
                    // A recorded event detail: `{:.3e}` stays, so that the recordings replay
                    // byte for byte (recordings/*.mcap are goldens).
                    r.events.push(Event::new(
                        "safety.passivity",
                        format!(
                            "the rendering returned {:.3e} J more than it took (reserve {} J): \
                             damping {alpha:.3} N·s/m added",
                            -self.tank_j,
                            self.config.safety.passivity_reserve_j.unwrap_or(0.0)
                        ),
                    ));
                }
            }
        }
        self.passivity_active = passivity_now;
        f
    }

    fn rate_limit(&mut self, mut f: Vec3, f_prev: Vec3, force_ok: bool) -> Vec3 {
        let r = &mut self.result;
        let dt = self.config.dt_s();
        let mut limiting_now = false;
        if let (Some(rate), true) = (self.config.safety.max_force_rate_n_per_s, force_ok) {
            let step = rate * dt;
            let delta = vec3::sub(f, f_prev);
            let n = vec3::norm(delta);
            if n > step {
                f = vec3::add(f_prev, vec3::scale(delta, step / n));
                r.status |= status::RATE_LIMITED;
                limiting_now = true;
                if !self.rate_limiting {
                    r.events.push(Event::new(
                        "safety.rate_limited",
                        format!("force change of {n:.3} N in one tick held to {step:.3} N"),
                    ));
                }
            }
        }
        self.rate_limiting = limiting_now;
        f
    }
}
