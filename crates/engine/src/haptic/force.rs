//! Steps 2 and 3 of a tick: the scene stepped on the cursor, and its force mapped to the
//! device (finite and under the stiffness cap or zero, soft engagement, watchdog, clamp to
//! the device's maximum along the force's direction).

use super::{HapticLoop, smoothstep};
use crate::scene::SceneInput;
use haptic_types::Event;
use haptic_types::tick::status;
use haptic_types::vec3::{self, Vec3};

impl HapticLoop {
    /// Steps the scene on this tick's cursor and buttons; its events join the tick's.
    pub(super) fn step_scene(&mut self, tick: u64, valid: bool) {
        let r = &mut self.result;
        self.out.clear();
        let input = SceneInput {
            tick,
            dt_s: self.config.dt_s(),
            cursor_m: r.cursor_m,
            buttons: r.buttons,
            input_valid: valid,
        };
        self.scene.step(&input, &mut self.out);
        r.events.append(&mut self.out.events);
        r.world_force_n = self.out.force_n;
    }

    /// The scene's force for the device, N (device frame), the local stiffness's gain, N/m,
    /// and whether the force is the scene's (not zeroed for invalid input, a non-finite force
    /// or a stiffness over the cap).
    pub(super) fn device_force(&mut self, tick: u64, valid: bool) -> (Vec3, f64, bool) {
        let r = &mut self.result;
        let cap = self.config.world_stiffness_cap_n_per_m();
        let mut force_ok = valid;
        if !vec3::is_finite(self.out.force_n) {
            r.status |= status::FORCE_INVALID;
            r.events.push(Event::new(
                "force.invalid",
                format!(
                    "scene force ({}, {}, {}) N is not finite",
                    self.out.force_n[0], self.out.force_n[1], self.out.force_n[2]
                ),
            ));
            force_ok = false;
        } else if self.out.stiffness_n_per_m > cap * (1.0 + 1e-12) {
            r.status |= status::STIFFNESS_OVER_CAP;
            r.events.push(Event::new(
                "scene.stiffness_over_cap",
                format!(
                    "scene rendered {} N/m, the cap is {cap} N/m",
                    self.out.stiffness_n_per_m
                ),
            ));
            force_ok = false;
        }
        r.engagement = if self.config.engage_ticks == 0 {
            1.0
        } else {
            smoothstep((tick - self.engage_start) as f64 / self.config.engage_ticks as f64)
        };
        let gain = self.config.mapping.force_scale * r.engagement * r.watchdog;
        let mut f = if force_ok {
            vec3::scale(self.out.force_n, gain)
        } else {
            [0.0; 3]
        };
        if !vec3::is_finite(f) {
            // Finite world force times a finite scale can still overflow.
            r.status |= status::FORCE_INVALID;
            r.events
                .push(Event::new("force.invalid", "mapped force overflows"));
            f = [0.0; 3];
        }
        let k_gain = if force_ok && vec3::is_finite(f) {
            self.out.stiffness_n_per_m * gain * self.config.mapping.workspace_scale
        } else {
            0.0
        };
        let max = self.config.specs.limits.max_force_n;
        let mag = vec3::norm(f);
        let clamp_ratio = if mag > max { max / mag } else { 1.0 };
        self.local_gain = if force_ok && vec3::is_finite(f) {
            gain * clamp_ratio
        } else {
            0.0
        };
        let (f, k_gain) = self.clamp(f, k_gain);
        (f, k_gain, force_ok)
    }

    /// A force above the device's maximum scaled down to it, direction kept (the status bit
    /// every tick, `force.clamped` at an episode's onset), with the local stiffness gain
    /// scaled alike: on the saturated part of the field the force no longer grows.
    fn clamp(&mut self, mut f: Vec3, mut k_gain: f64) -> (Vec3, f64) {
        let r = &mut self.result;
        let max = self.config.specs.limits.max_force_n;
        let mag = vec3::norm(f);
        if mag <= max {
            self.clamping = false;
            return (f, k_gain);
        }
        k_gain *= max / mag;
        r.status |= status::CLAMPED;
        if !self.clamping {
            r.events.push(Event::new(
                "force.clamped",
                format!("requested {mag} N, rendering {max} N"),
            ));
        }
        self.clamping = true;
        f = vec3::scale(f, max / mag);
        // Rounding may leave the norm an ulp or two above the limit: step it down. A limit
        // whose squares are subnormal (below 1e-154 N: no device's) loses the norm's
        // precision; the steps are bounded and such a force then goes to zero.
        let mut steps = 0;
        while vec3::norm(f) > max {
            if steps == 8 {
                f = [0.0; 3];
                break;
            }
            f = vec3::scale(f, 1.0 - f64::EPSILON);
            steps += 1;
        }
        (f, k_gain)
    }
}
