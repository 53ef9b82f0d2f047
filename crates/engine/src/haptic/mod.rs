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

pub use crate::loop_config::{LoopConfig, Mapping};
use crate::scene::{Scene, SceneOutput};
use haptic_types::Buttons;
use haptic_types::DeviceSample;
use haptic_types::DeviceSpecs;
use haptic_types::Event;
use haptic_types::ForceCommand;
use haptic_types::switch::{self, Switch, SwitchError};
use haptic_types::vec3::{self, Vec3};

use haptic_types::tick::{TickResult, status};

mod force;
mod input;
mod local;
mod safety;

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
    /// Device newtons per world newton of the last tick's force before the safety layer: the
    /// mapping's scale times engagement, watchdog and clamp (0 when the force was zeroed). The
    /// local model's primitives are felt through it.
    local_gain: f64,
    /// The scene's local primitives (reused).
    primitives: std::cell::RefCell<haptic_types::local::WorldPrimitives>,
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
                .unwrap_or(crate::loop_config::DEFAULT_PASSIVITY_RESERVE_J),
            last_position_m: None,
            passivity_active: false,
            rate_limiting: false,
            local_gain: 0.0,
            primitives: Default::default(),
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
        let problem = Self::check_sample(&self.config.specs, &sample);
        // The force held over the last tick (zero after a missed deadline) and the displacement
        // it acted over: the passivity observer's energy flow (device frame, J).
        let f_prev = self.result.device_force_n;
        let dp = self.observe(&sample, problem.is_none(), f_prev);
        self.begin(tick);
        // 1. Input validation and mapping, and the watchdog on the sample's age.
        let valid = self.take_input(tick, &sample, problem);
        self.watch_link(tick, sample.age_ticks, watchdog);
        // 2. The world.
        self.step_scene(tick, valid);
        // 3. Force to the device.
        let (f, k_gain, force_ok) = self.device_force(tick, valid);
        // 4. The safety layer at the device port (only on a force the loop did not zero).
        let f = self.safety_layer(tick, f, f_prev, dp, force_ok);
        let k_gain = k_gain.min(self.config.specs.limits.max_stiffness_n_per_m);
        let r = &mut self.result;
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

    /// The observer's tank at the start, J: the scene's reserve (or the default).
    fn initial_tank_j(&self) -> f64 {
        self.config
            .safety
            .passivity_reserve_j
            .unwrap_or(crate::loop_config::DEFAULT_PASSIVITY_RESERVE_J)
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
