//! The fixed-tick haptic loop: device input → world cursor → scene → force → device.
//!
//! One call of [`HapticLoop::tick`] is one tick. The tick index is the only clock; nothing in
//! here reads the wall clock. What the loop guarantees about the force it sends:
//!
//! - **mapping**: cursor = `origin + workspace_scale · p_device`; device force =
//!   `force_scale · F_world` (scene file `[mapping]`);
//! - **stiffness cap**: the scene is given the world-frame stiffness that maps to the device's
//!   maximum (`k_max / (force_scale · workspace_scale)`) and reports the stiffness it rendered;
//!   a scene exceeding it gets zero force and a `scene.stiffness_over_cap` event;
//! - **soft engagement**: the force is multiplied by a smoothstep ramp `3x² − 2x³` over
//!   `engage_s` at start and again after an invalid-input episode;
//! - **clamp**: a force above the device maximum is scaled down to it, direction kept
//!   (`force.clamped` event at the onset of each clamped episode, status bit every tick);
//! - **invalid input** (non-finite position, outside the workspace sphere, unknown button
//!   bits): zero force, the cursor held at the last valid position, `input.invalid` event;
//! - **missed deadline** (real-time mode): zero force, `deadline.missed` event. The flag is an
//!   input of the tick (logged with the device input), so replay reproduces it.
//! - **watchdog** (a bridged device whose samples stop): the sample's age in ticks is an input of
//!   the tick (a stale tick of age `a` runs `a + 0.5` periods after the last sample). While the
//!   age is within `watchdog_grace_ticks` the force is untouched; then it ramps linearly to zero,
//!   zero from age `watchdog_timeout_ticks` on (defaults at 1 kHz: full force through 2.5 ms,
//!   zero from 9.5 ms after the last sample: `[loop] watchdog_grace_s = 0.003`,
//!   `watchdog_timeout_s = 0.010`). Events: `device.sample_late` at the first stale tick of
//!   an episode, `device.lost` when the force reaches zero, `device.resumed` on the next fresh
//!   sample; after a loss, soft engagement restarts.
//! - **local stiffness**: the device also gets the 3×3 stiffness of the rendered field (scaled
//!   by mapping, engagement, watchdog and clamp), so a driver may render between packets.
//!
//! - **switches**: [`HapticLoop::switch`] changes what the teaching game's menu changes
//!   (gravity, friction, …) between two ticks; the change is an input of the next tick
//!   ([`TickResult::switches`], a `switch.set` event), recorded on `/scene/switch`.
//!
//! The world force, the sent force and the status of every tick are returned in
//! [`TickResult`]; the sent force is always finite and of norm ≤ the device maximum.

pub use crate::scene::loop_config::{LoopConfig, Mapping};
use crate::scene::{Event, Scene, SceneInput, SceneOutput};
use haptic_devices::{Buttons, DeviceSample, DeviceSpecs, ForceCommand};
use haptic_types::switch::{self, Switch, SwitchError};
use haptic_types::vec3::{self, Vec3};

pub use haptic_types::tick::{TickResult, status};

/// The haptic loop around one scene.
pub struct HapticLoop {
    config: LoopConfig,
    scene: Box<dyn Scene>,
    next_tick: u64,
    last_cursor_m: Vec3,
    last_buttons: Buttons,
    engage_start: u64,
    input_invalid: bool,
    clamping: bool,
    link_lost: bool,
    out: SceneOutput,
    result: TickResult,
    pending: Vec<Switch>,
    /// The passivity observer (Hannaford and Ryu 2002), J: the reserve plus the energy the
    /// rendering has taken from the hand minus what it returned. A spring pressed stores what
    /// it took and may return it; the controller acts only below 0.
    tank_j: f64,
    /// The last valid device position, m, device frame (for the observer's displacement).
    last_position_m: Option<Vec3>,
    passivity_active: bool,
    rate_limiting: bool,
}

/// Largest damping the passivity controller adds, N·s/m (device side): the damping of a loose
/// grip (2 N·s/m), the least a hand brings to absorb it.
pub const PASSIVITY_MAX_DAMPING_N_S_PER_M: f64 = 2.0;

/// `k a aᵀ` for a unit axis `a`, `k I` without one (row-major).
fn stiffness_matrix(k: f64, axis: Option<Vec3>) -> [f64; 9] {
    let mut m = [0.0; 9];
    if k == 0.0 {
        return m;
    }
    match axis {
        Some(a) if vec3::is_finite(a) && vec3::norm(a) > 0.0 => {
            let a = vec3::scale(a, 1.0 / vec3::norm(a));
            for i in 0..3 {
                for j in 0..3 {
                    m[3 * i + j] = k * a[i] * a[j];
                }
            }
        }
        _ => {
            m[0] = k;
            m[4] = k;
            m[8] = k;
        }
    }
    m
}

/// Smoothstep `3x² − 2x³` on [0, 1].
fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl HapticLoop {
    /// A loop around `scene` with `config`.
    pub fn new(config: LoopConfig, scene: Box<dyn Scene>) -> Self {
        let origin = config.mapping.origin_m;
        HapticLoop {
            scene,
            next_tick: 0,
            last_cursor_m: origin,
            last_buttons: Buttons(0),
            engage_start: 0,
            input_invalid: false,
            clamping: false,
            link_lost: false,
            out: SceneOutput::default(),
            result: TickResult::default(),
            pending: Vec::new(),
            tank_j: config
                .safety
                .passivity_reserve_j
                .unwrap_or(crate::scene::loop_config::DEFAULT_PASSIVITY_RESERVE_J),
            last_position_m: None,
            passivity_active: false,
            rate_limiting: false,
            config,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LoopConfig {
        &self.config
    }

    /// The scene.
    pub fn scene(&self) -> &dyn Scene {
        self.scene.as_ref()
    }

    /// Index of the next tick.
    pub fn next_tick(&self) -> u64 {
        self.next_tick
    }

    /// The config's watchdog factor for a sample `age_ticks` old: 1 within the grace, then a
    /// linear ramp reaching 0 at the timeout.
    pub fn watchdog_factor(&self, age_ticks: u32) -> f64 {
        let c = &self.config;
        if age_ticks <= c.watchdog_grace_ticks {
            1.0
        } else if age_ticks >= c.watchdog_timeout_ticks {
            0.0
        } else {
            f64::from(c.watchdog_timeout_ticks - age_ticks)
                / f64::from(c.watchdog_timeout_ticks - c.watchdog_grace_ticks)
        }
    }

    /// The command for the device after the last tick.
    pub fn command(&self, seq: u64) -> ForceCommand {
        ForceCommand {
            tick: self.result.tick,
            seq,
            force_n: self.result.device_force_n,
            stiffness_n_per_m: self.result.device_stiffness_n_per_m,
            status: self.result.status,
        }
    }

    /// Sets a run-time switch of the scene (see [`haptic_types::switch`]): checked against the
    /// scene's switches, applied at once, and recorded as an input of the next tick (its
    /// [`TickResult::switches`] and a `switch.set` event).
    pub fn switch(&mut self, name: &str, value: f64) -> Result<(), SwitchError> {
        let kind = self.scene.kind();
        // An old name is applied and recorded under the switch's own name.
        let name = switch::check(kind, self.scene.switches(), name, value)?.name;
        self.scene
            .set_switch(name, value)
            .map_err(|message| SwitchError::Refused {
                name: name.to_string(),
                value,
                message,
            })?;
        self.pending.push(Switch {
            name: name.to_string(),
            value,
        });
        Ok(())
    }

    /// Why a device sample is invalid, or `None` when it is valid.
    pub fn check_sample(specs: &DeviceSpecs, s: &DeviceSample) -> Option<String> {
        let [x, y, z] = s.position_m;
        if !vec3::is_finite(s.position_m) {
            return Some(format!("non-finite position ({x}, {y}, {z}) m"));
        }
        let r = vec3::norm(s.position_m);
        if r.is_nan() || r > specs.workspace_radius_m {
            return Some(format!(
                "position ({x}, {y}, {z}) m is {r} m from the origin, outside the {} m workspace",
                specs.workspace_radius_m
            ));
        }
        let extra = s.buttons.0 & !specs.button_mask();
        if extra != 0 {
            return Some(format!(
                "button bits {extra:#x} do not exist on a {}",
                specs.name
            ));
        }
        None
    }

    /// Runs one tick with the device reading `sample`; `deadline_missed` forces zero force.
    pub fn tick(&mut self, sample: DeviceSample, deadline_missed: bool) -> &TickResult {
        let tick = self.next_tick;
        self.next_tick += 1;
        let watchdog = self.watchdog_factor(sample.age_ticks);
        // The force held over the last tick (zero after a missed deadline) and the displacement
        // it acted over: the passivity observer's energy flow (device frame, J).
        let f_prev = self.result.device_force_n;
        let dp = match (
            self.last_position_m,
            Self::check_sample(&self.config.specs, &sample),
        ) {
            (Some(p0), None) if sample.age_ticks == 0 => Some(vec3::sub(sample.position_m, p0)),
            _ => None,
        };
        // The observer always observes (its reading is reported); the controller acts only
        // when the scene has it on.
        if let Some(d) = dp {
            self.tank_j -= vec3::dot(f_prev, d);
        }
        // (a fresh valid sample gave `dp`; the first valid one starts the observer)
        if dp.is_some()
            || (self.last_position_m.is_none()
                && HapticLoop::check_sample(&self.config.specs, &sample).is_none())
        {
            self.last_position_m = Some(sample.position_m);
        }
        let r = &mut self.result;
        r.tick = tick;
        r.status = 0;
        r.events.clear();
        r.switches.clear();
        for sw in self.pending.drain(..) {
            r.events
                .push(Event::new("switch.set", switch::event_detail(&sw)));
            r.switches.push(sw);
        }

        // 1. Input validation and mapping.
        let problem = Self::check_sample(&self.config.specs, &sample);
        let valid = problem.is_none();
        if let Some(why) = problem {
            r.status |= status::INPUT_INVALID;
            if !self.input_invalid {
                r.events.push(Event::new("input.invalid", why));
            }
            self.input_invalid = true;
        } else {
            if self.input_invalid {
                r.events
                    .push(Event::new("input.valid", "soft engagement restarts"));
                self.engage_start = tick;
            }
            self.input_invalid = false;
            self.last_cursor_m = self.config.mapping.to_world(sample.position_m);
            let changed = sample.buttons.0 ^ self.last_buttons.0;
            for (i, name) in self.config.specs.button_names.iter().enumerate() {
                if changed & (1 << i) != 0 {
                    let kind = if sample.buttons.pressed(i as u32) {
                        "button.down"
                    } else {
                        "button.up"
                    };
                    r.events.push(Event::new(kind, name.as_ref()));
                }
            }
            self.last_buttons = sample.buttons;
        }
        r.cursor_m = self.last_cursor_m;
        r.buttons = self.last_buttons;

        // 1b. Watchdog on the sample's age.
        let age = sample.age_ticks;
        if age == 1 {
            r.events.push(Event::new(
                "device.sample_late",
                "no new device sample this tick",
            ));
        }
        if watchdog == 0.0 && !self.link_lost {
            self.link_lost = true;
            r.events.push(Event::new(
                "device.lost",
                format!("no device sample for {age} ticks: force ramped to zero"),
            ));
        }
        if age == 0 && self.link_lost {
            self.link_lost = false;
            r.events.push(Event::new(
                "device.resumed",
                "device samples resumed: soft engagement restarts",
            ));
            self.engage_start = tick;
        }
        if watchdog < 1.0 {
            r.status |= status::WATCHDOG;
        }
        r.watchdog = watchdog;

        // 2. The world.
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

        // 3. Force to the device.
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
        let max = self.config.specs.limits.max_force_n;
        let mag = vec3::norm(f);
        let mut k_gain = if force_ok && vec3::is_finite(f) {
            self.out.stiffness_n_per_m * gain * self.config.mapping.workspace_scale
        } else {
            0.0
        };
        if mag > max {
            // On the saturated part of the field the force no longer grows: scale the local
            // stiffness with the force.
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
        } else {
            self.clamping = false;
        }
        // 4. The safety layer at the device port (only on a force the loop did not zero).
        if force_ok && tick == 0 {
            r.events.push(Event::new(
                "safety.config",
                self.config
                    .safety
                    .describe(self.config.specs.limits.max_stiffness_n_per_m),
            ));
        }
        let dt = self.config.dt_s();
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
        k_gain = k_gain.min(self.config.specs.limits.max_stiffness_n_per_m);
        r.device_force_n = f;
        r.device_stiffness_n_per_m = stiffness_matrix(
            if k_gain.is_finite() { k_gain } else { 0.0 },
            self.out.stiffness_axis,
        );
        if deadline_missed {
            self.mark_deadline_missed();
        }
        &self.result
    }

    /// Marks the last tick's deadline as missed: zero force, status bit, `deadline.missed`
    /// event. Exactly what `tick(sample, true)` does; the loop's own state is not affected, so a
    /// real-time run that decides after computing and a replay that knows beforehand agree.
    pub fn mark_deadline_missed(&mut self) {
        let r = &mut self.result;
        if r.status & status::DEADLINE_MISSED == 0 {
            r.status |= status::DEADLINE_MISSED;
            r.events
                .push(Event::new("deadline.missed", "zero force sent this tick"));
            r.device_force_n = [0.0; 3];
            r.device_stiffness_n_per_m = [0.0; 9];
        }
    }

    /// The passivity observer's energy tank, J (device side): the reserve minus the energy the
    /// device has returned to the hand beyond what it took; the controller acts below 0.
    pub fn passivity_tank_j(&self) -> f64 {
        self.tank_j
    }

    /// The result of the last tick.
    pub fn last_result(&self) -> &TickResult {
        &self.result
    }

    /// Appends the scene's state fields to `out`.
    pub fn scene_state(&self, out: &mut Vec<f64>) {
        self.scene.state(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;
    use haptic_devices::FALCON;

    const WALL: &str = r#"
[scene]
name = "w"
kind = "wall"
[loop]
engage_s = 0.0
[wall]
normal = [0.0, 0.0, 1.0]
stiffness_n_per_m = 5000.0
"#;

    fn looped(text: &str) -> HapticLoop {
        let s = load_scene(text, None).unwrap();
        HapticLoop::new(s.config, s.scene)
    }

    fn at(z: f64) -> DeviceSample {
        DeviceSample::new([0.0, 0.0, z], Buttons(0))
    }

    #[test]
    fn stiffness_is_capped_and_force_clamped_along_its_direction() {
        let mut l = looped(WALL);
        // 1 mm deep: the 5000 N/m wall is capped at the Falcon's 3000 N/m -> 3 N.
        let r = l.tick(at(-0.001), false).clone();
        assert!((r.device_force_n[2] - 3.0).abs() < 1e-12);
        assert_eq!(r.status, 0);
        // 2 mm -> 6 N; felt stiffness ΔF/Δx = 3000 N/m exactly (to rounding).
        let f2 = l.tick(at(-0.002), false).device_force_n[2];
        assert!(((f2 - r.device_force_n[2]) / 0.001 - 3000.0).abs() < 1e-6);
        // 5 mm -> 15 N requested, clamped to 8 N, still along +z.
        let r = l.tick(at(-0.005), false).clone();
        assert_eq!(r.status, status::CLAMPED);
        assert!(vec3::norm(r.device_force_n) <= FALCON.limits.max_force_n);
        assert!((r.device_force_n[2] - 8.0).abs() < 1e-12);
        assert_eq!(r.events[0].name, "force.clamped");
        // The clamp event fires once per episode.
        assert!(l.tick(at(-0.006), false).events.is_empty());
    }

    /// A force limit of 4e-159 N (the libFuzzer bridge target's find: clamping to it stepped
    /// the force down one ulp at a time, 12 s for 20 ticks) still clamps, in a bounded number
    /// of steps, to a force within the limit.
    #[test]
    fn a_limit_with_subnormal_squares_still_clamps() {
        let mut specs = FALCON.clone();
        specs.limits.max_force_n = 3.7555737088373936e-159;
        let s = crate::scene::load_scene_for(WALL, specs).unwrap();
        let mut l = HapticLoop::new(s.config, s.scene);
        for k in 1..=20 {
            let r = l.tick(at(-0.0001 * f64::from(k)), false).clone();
            assert!(vec3::norm(r.device_force_n) <= 3.7555737088373936e-159);
            assert!(r.device_force_n.iter().all(|x| x.is_finite()));
            assert_eq!(r.status & status::CLAMPED, status::CLAMPED);
        }
    }

    #[test]
    fn invalid_input_gives_zero_force_and_holds_the_cursor() {
        let mut l = looped(WALL);
        l.tick(at(-0.001), false);
        let r = l
            .tick(DeviceSample::new([f64::NAN, 0.0, 0.0], Buttons(0)), false)
            .clone();
        assert_eq!(r.device_force_n, [0.0; 3]);
        assert_eq!(r.status, status::INPUT_INVALID);
        assert_eq!(r.cursor_m, [0.0, 0.0, -0.001]);
        assert_eq!(r.events[0].name, "input.invalid");
        let r = l.tick(at(0.05), false).clone();
        assert_eq!(r.device_force_n, [0.0; 3]);
        assert!(r.events.is_empty(), "one event per episode");
        let r = l
            .tick(DeviceSample::new([0.0; 3], Buttons(1 << 7)), false)
            .clone();
        assert_eq!(r.status, status::INPUT_INVALID);
        let r = l.tick(at(-0.001), false).clone();
        assert_eq!(r.events[0].name, "input.valid");
    }

    #[test]
    fn soft_engagement_ramps_with_smoothstep() {
        let mut l = looped(&WALL.replace("engage_s = 0.0", "engage_s = 0.1"));
        let f: Vec<f64> = (0..120)
            .map(|_| l.tick(at(-0.0005), false).device_force_n[2])
            .collect();
        assert_eq!(f[0], 0.0);
        assert!((f[50] - 1.5 * 0.5).abs() < 1e-12, "half way: half force");
        assert!(f.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(f[100], 1.5);
        assert_eq!(f[119], 1.5);
    }

    #[test]
    fn missed_deadline_sends_zero_force_and_buttons_raise_events() {
        let mut l = looped(WALL);
        let r = l
            .tick(DeviceSample::new([0.0, 0.0, -0.001], Buttons(0b101)), true)
            .clone();
        assert_eq!(r.device_force_n, [0.0; 3]);
        assert!((r.world_force_n[2] - 3.0).abs() < 1e-12);
        assert_eq!(r.status, status::DEADLINE_MISSED);
        let names: Vec<_> = r
            .events
            .iter()
            .map(|e| (e.name.as_str(), e.detail.as_str()))
            .collect();
        assert_eq!(names[0], ("button.down", "centre"));
        assert_eq!(names[1], ("button.down", "minus"));
        assert_eq!(names.last().unwrap().0, "deadline.missed");
    }

    /// The force-rate limit: a step into the wall that asks 6 N at once is rendered as 3 N
    /// (the Falcon's 3000 N/m × 1 m/s × 1 ms), then 6 N, with one event; off, at once.
    #[test]
    fn the_force_rate_limit_holds_a_step_to_k_max_times_one_metre_per_second() {
        let mut l = looped(WALL);
        l.tick(at(0.001), false);
        let r = l.tick(at(-0.002), false).clone();
        assert_eq!(r.device_force_n, [0.0, 0.0, 3.0]);
        assert_eq!(r.status, status::RATE_LIMITED);
        let ev = r
            .events
            .iter()
            .find(|e| e.name == "safety.rate_limited")
            .unwrap();
        assert_eq!(
            ev.detail,
            "force change of 6.000 N in one tick held to 3.000 N"
        );
        let r = l.tick(at(-0.002), false).clone();
        assert!((r.device_force_n[2] - 6.0).abs() < 1e-12);
        assert_eq!(r.status, 0);
        let mut off =
            looped(&WALL.replace("engage_s = 0.0", "engage_s = 0.0\nforce_rate_limit = false"));
        off.tick(at(0.001), false);
        assert!((off.tick(at(-0.002), false).device_force_n[2] - 6.0).abs() < 1e-12);
    }

    /// The passivity observer and controller: a stylus that starts deep in the wall and is
    /// pushed out by it takes energy the wall never took from it. Past the 20 mJ reserve the
    /// controller adds damping against the motion, α = −E / (T v²), at most 2 N·s/m; the
    /// observer reads the energy exactly; off, the force is the wall's.
    #[test]
    fn the_passivity_controller_damps_energy_returned_beyond_the_reserve() {
        let path = |n: usize| -0.005 + 5e-5 * n as f64; // out at 0.05 m/s
        let run = |text: &str| {
            let mut l = looped(text);
            let mut out = Vec::new();
            for n in 0..100 {
                let r = l.tick(at(path(n)), false).clone();
                out.push((r, l.passivity_tank_j()));
            }
            out
        };
        let on = run(WALL);
        let off = run(&WALL.replace("engage_s = 0.0", "engage_s = 0.0\npassivity = false"));
        // The observer, on or off: 0.02 J minus Σ F_(n−1) · (p_n − p_(n−1)).
        let mut e = 0.02;
        for n in 1..100 {
            e -= off[n - 1].0.device_force_n[2] * (path(n) - path(n - 1));
            assert!((off[n].1 - e).abs() < 1e-12, "tick {n}");
        }
        let first = on
            .iter()
            .position(|(r, _)| r.status & status::PASSIVITY != 0)
            .unwrap();
        assert!(on[first - 1].1 >= 0.0 && on[first].1 < 0.0);
        assert!(
            on[first]
                .0
                .events
                .iter()
                .any(|e| e.name == "safety.passivity")
        );
        let mut acted = 0;
        for n in first..100 {
            let (r, tank) = &on[n];
            if r.status & status::PASSIVITY == 0 {
                assert!(*tank >= 0.0, "tick {n}: a deficit left alone");
                continue;
            }
            acted += 1;
            // The reading at tick n holds the work of tick n − 1's force: the deficit the
            // controller damps, against the motion (+z at 0.05 m/s), at most 2 N·s/m.
            let alpha = (-tank / (1e-3 * 0.05 * 0.05)).min(2.0);
            let wall = off[n].0.device_force_n[2];
            let cut = wall - r.device_force_n[2];
            assert!((cut - alpha * 0.05).abs() < 1e-9, "tick {n}: cut {cut} N");
        }
        assert!(acted > 10);
        for (n, (r, _)) in off.iter().enumerate() {
            assert_eq!(r.status & status::PASSIVITY, 0, "tick {n}");
        }
    }

    use proptest::prelude::*;

    fn coord() -> impl Strategy<Value = f64> {
        prop_oneof![
            -0.05f64..0.05,
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(-1e300),
            Just(1e300)
        ]
    }

    proptest! {
        /// Whatever the device reports, the force sent is finite, within the device maximum,
        /// and zero whenever the input is invalid.
        #[test]
        fn sent_force_is_always_finite_and_bounded(
            samples in proptest::collection::vec(((coord(), coord(), coord()), 0u32..64), 1..200),
            k in 1.0f64..1e9,
        ) {
            let text = WALL.replace("5000.0", &format!("{k:?}"));
            let mut l = looped(&text);
            for ((x, y, z), b) in samples {
                let s = DeviceSample::new([x, y, z], Buttons(b));
                let invalid = HapticLoop::check_sample(&FALCON, &s).is_some();
                let r = l.tick(s, false);
                prop_assert!(vec3::is_finite(r.device_force_n));
                prop_assert!(vec3::norm(r.device_force_n) <= FALCON.limits.max_force_n);
                if invalid {
                    prop_assert_eq!(r.device_force_n, [0.0; 3]);
                    prop_assert!(r.status & status::INPUT_INVALID != 0);
                }
            }
        }
    }
}
