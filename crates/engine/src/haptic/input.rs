//! Steps 0 and 1 of a tick: the passivity observer's reading, the result reset with the
//! pending switches, the device sample checked and mapped (button events), and the watchdog
//! on the sample's age.

use super::HapticLoop;
use haptic_types::DeviceSample;
use haptic_types::Event;
use haptic_types::switch;
use haptic_types::tick::status;
use haptic_types::vec3::{self, Vec3};

impl HapticLoop {
    /// The passivity observer: the device displacement since the last valid sample (`None`
    /// for an invalid one and the first valid one), after charging the tank with the work
    /// `f_prev` did over it: the work over the path the world's cursor took. A late sample
    /// (age > 0) counts as an on-time one: it is either a new reading (the tick's own came
    /// late, an earlier one came in its place) or the last one again, which moved nothing.
    /// The observer always observes (its reading is reported); the controller acts only when
    /// the scene has it on.
    pub(super) fn observe(
        &mut self,
        sample: &DeviceSample,
        valid: bool,
        f_prev: Vec3,
    ) -> Option<Vec3> {
        if !valid {
            return None;
        }
        let dp = self
            .last_position_m
            .map(|p0| vec3::sub(sample.position_m, p0));
        if let Some(d) = dp {
            self.tank_j -= vec3::dot(f_prev, d);
        }
        self.last_position_m = Some(sample.position_m);
        dp
    }

    /// Starts tick `tick`'s result: no status, no events but the switches set since the last
    /// tick (each a `switch.set` event and an input of this tick).
    pub(super) fn begin(&mut self, tick: u64) {
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
        if tick == 0 {
            if let Some(fit) = &self.config.device_fit {
                let specs = &self.config.specs;
                r.events.push(Event::new(
                    "device.fit",
                    fit.describe(&specs.name, specs.limits.max_stiffness_n_per_m),
                ));
            }
        }
    }

    /// Takes the sample: an invalid one (`problem` says why) holds the cursor and raises
    /// `input.invalid` at an episode's onset; a valid one maps to the world cursor, restarts
    /// soft engagement after an invalid episode and reports button changes. Returns whether
    /// it was valid.
    pub(super) fn take_input(
        &mut self,
        tick: u64,
        sample: &DeviceSample,
        problem: Option<String>,
    ) -> bool {
        let r = &mut self.result;
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
        valid
    }

    /// The watchdog on a sample `age` ticks old (its factor `watchdog`): `device.sample_late`
    /// at the first stale tick, `device.lost` when the force reaches zero, `device.resumed`
    /// (and soft engagement again) on the next fresh sample.
    pub(super) fn watch_link(&mut self, tick: u64, age: u32, watchdog: f64) {
        let r = &mut self.result;
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
    }
}
