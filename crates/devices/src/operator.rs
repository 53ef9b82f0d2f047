//! The simulated operator: a hand holding the stylus, modelled as a mass–spring–damper pulled
//! toward the scripted intent and pushed by the force the device renders.
//!
//! `m ẍ = k (x_intent − x) + c (ẋ_intent − ẋ) + F_device`, integrated with semi-implicit
//! (symplectic) Euler at the tick length. This is the impedance model of the human arm around an
//! intended trajectory; the defaults (0.3 kg, 300 N/m, 12 N·s/m, damping ratio ≈ 0.63) are of
//! the order measured for a hand holding a stylus. The rendered force of tick `n` acts during
//! the step from `n` to `n + 1` (one tick of device latency, as on hardware).
//!
//! Optionally (`yield_force_n > 0`) the operator also *slows down* when pushed, as the paper's
//! operators did ("the reaction force made it natural for the operator to slow down"): the
//! script's clock advances at `1 / (1 + |F| / yield_force_n)` of real time, so a felt force of
//! `yield_force_n` halves the intended speed. Off by default (a purely passive hand).
//!
//! The device's mechanical end stop is modelled too: the stylus cannot leave the workspace
//! sphere (its outward velocity is removed at the boundary), as a real linkage cannot.

use crate::script::{OperatorParams, Script};
use haptic_types::device::{
    DeviceError, DeviceSample, DeviceSpecs, ForceCommand, HapticDevice, TickTime, in_order,
};
use haptic_types::vec3::{self, Vec3};

/// A scripted intent played through a simulated hand.
#[derive(Clone, Debug)]
pub struct SimulatedOperator {
    script: Script,
    specs: DeviceSpecs,
    params: OperatorParams,
    position_m: Vec3,
    velocity_m_per_s: Vec3,
    force_n: Vec3,
    next_tick: u64,
    intent_time_s: f64,
}

impl SimulatedOperator {
    /// A hand with `params` following `script` on a device with `specs`.
    pub fn new(script: Script, specs: DeviceSpecs, params: OperatorParams) -> Self {
        let p0 = script.position(0.0);
        SimulatedOperator {
            script,
            specs,
            params,
            position_m: p0,
            velocity_m_per_s: [0.0; 3],
            force_n: [0.0; 3],
            next_tick: 0,
            intent_time_s: 0.0,
        }
    }

    /// Hand velocity, m/s.
    pub fn velocity_m_per_s(&self) -> Vec3 {
        self.velocity_m_per_s
    }

    /// The script's clock, s (equal to the session time unless the operator slows down).
    pub fn intent_time_s(&self) -> f64 {
        self.intent_time_s
    }

    /// One step from tick `time.index − 1` to `time.index`.
    fn step(&mut self, time: TickTime) {
        let p = &self.params;
        let dt_s = time.dt_s;
        // Rate of the operator's plan: 1 (its clock is the exact tick time), or slower under a
        // felt force.
        let (t_s, rate) = if p.yield_force_n > 0.0 {
            let rate = 1.0 / (1.0 + vec3::norm(self.force_n) / p.yield_force_n);
            let t = self.intent_time_s;
            self.intent_time_s += rate * dt_s;
            (t, rate)
        } else {
            self.intent_time_s = time.time_s;
            (time.time_s - dt_s, 1.0)
        };
        let xi = self.script.position(t_s);
        let vi = vec3::scale(self.script.velocity(t_s), rate);
        let spring = vec3::scale(vec3::sub(xi, self.position_m), p.stiffness_n_per_m);
        let damper = vec3::scale(vec3::sub(vi, self.velocity_m_per_s), p.damping_n_s_per_m);
        let acc = vec3::scale(
            vec3::add(vec3::add(spring, damper), self.force_n),
            1.0 / p.mass_kg,
        );
        self.velocity_m_per_s = vec3::add(self.velocity_m_per_s, vec3::scale(acc, dt_s));
        self.position_m = vec3::add(self.position_m, vec3::scale(self.velocity_m_per_s, dt_s));
        // Mechanical end stop at the workspace sphere.
        let r = vec3::norm(self.position_m);
        let rmax = self.specs.workspace_radius_m;
        if r > rmax {
            let n = vec3::scale(self.position_m, 1.0 / r);
            self.position_m = vec3::scale(n, rmax);
            let vn = vec3::dot(self.velocity_m_per_s, n);
            if vn > 0.0 {
                self.velocity_m_per_s = vec3::sub(self.velocity_m_per_s, vec3::scale(n, vn));
            }
        }
    }
}

impl HapticDevice for SimulatedOperator {
    fn specs(&self) -> &DeviceSpecs {
        &self.specs
    }

    fn sample(&mut self, time: TickTime) -> Result<DeviceSample, DeviceError> {
        in_order(time, self.next_tick)?;
        if time.index > 0 {
            // Advance from the previous tick to this one under the last rendered force.
            self.step(time);
        }
        self.next_tick += 1;
        Ok(DeviceSample::new(
            self.position_m,
            self.script.buttons(self.intent_time_s),
        ))
    }

    fn set_force(&mut self, cmd: &ForceCommand) -> Result<(), DeviceError> {
        self.force_n = cmd.force_n;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_types::device::{FALCON, ForceCommand};

    fn hold_script() -> Script {
        Script::from_toml(
            "[script]\nname='hold'\nduration_s=5.0\n[[waypoint]]\nt_s=0.0\nposition_mm=[0.0,0.0,0.0]\n",
            &FALCON,
        )
        .unwrap()
    }

    #[test]
    fn constant_force_gives_static_deflection_f_over_k() {
        // Equilibrium of k x = F: a steady 3 N push on a 300 N/m hand deflects it by 10 mm.
        let mut op = SimulatedOperator::new(hold_script(), FALCON, OperatorParams::default());
        let mut last = [0.0; 3];
        for n in 0..5000 {
            last = op.sample(TickTime::new(n, 1000)).unwrap().position_m;
            op.set_force(&ForceCommand {
                force_n: [3.0, 0.0, 0.0],
                ..Default::default()
            })
            .unwrap();
        }
        assert!((last[0] - 0.01).abs() < 1e-6, "x = {}", last[0]);
    }

    #[test]
    fn free_oscillation_matches_damped_frequency() {
        // Undamped hand released from 5 mm: period 2π√(m/k) within the O(dt²) phase error of
        // symplectic Euler.
        let params = OperatorParams {
            damping_n_s_per_m: 0.0,
            ..OperatorParams::default()
        };
        let mut op = SimulatedOperator::new(hold_script(), FALCON, params);
        op.position_m = [0.005, 0.0, 0.0];
        let mut crossings = Vec::new();
        let mut prev = 0.005;
        for n in 0..3000 {
            let x = op.sample(TickTime::new(n, 1000)).unwrap().position_m[0];
            if prev > 0.0 && x <= 0.0 {
                crossings.push(n);
            }
            prev = x;
        }
        let period_ticks = (crossings[2] - crossings[0]) as f64 / 2.0;
        let expected = 2.0 * std::f64::consts::PI * (0.3f64 / 300.0).sqrt() * 1000.0;
        assert!(
            (period_ticks - expected).abs() <= 1.0,
            "{period_ticks} vs {expected}"
        );
    }

    #[test]
    fn end_stop_holds_the_stylus_in_the_workspace() {
        let mut op = SimulatedOperator::new(hold_script(), FALCON, OperatorParams::default());
        for n in 0..2000 {
            let p = op.sample(TickTime::new(n, 1000)).unwrap().position_m;
            assert!(vec3::norm(p) <= FALCON.workspace_radius_m * (1.0 + 1e-15));
            op.set_force(&ForceCommand {
                force_n: [8.0, 8.0, 0.0],
                ..Default::default()
            })
            .unwrap();
        }
        assert!(matches!(
            op.sample(TickTime::new(7, 1000)),
            Err(DeviceError::OutOfOrder {
                got: 7,
                expected: 2000
            })
        ));
    }

    #[test]
    fn overrides_parse_and_validate() {
        let p = OperatorParams::default()
            .with_overrides("mass_kg=0.5, stiffness_n_per_m=100")
            .unwrap();
        assert_eq!((p.mass_kg, p.stiffness_n_per_m), (0.5, 100.0));
        assert_eq!(
            OperatorParams::default()
                .with_overrides("mass_kg=0")
                .unwrap_err()
                .to_string(),
            "script: `mass_kg` = 0 is out of range: allowed 0.01 ≤ mass_kg ≤ 10"
        );
    }

    #[test]
    fn a_yielding_hand_runs_its_plan_at_half_speed_under_its_yield_force() {
        let params = OperatorParams {
            yield_force_n: 2.0,
            ..OperatorParams::default()
        };
        let mut op = SimulatedOperator::new(hold_script(), FALCON, params);
        let mut free = SimulatedOperator::new(hold_script(), FALCON, OperatorParams::default());
        for n in 0..1001 {
            op.sample(TickTime::new(n, 1000)).unwrap();
            free.sample(TickTime::new(n, 1000)).unwrap();
            op.set_force(&ForceCommand {
                force_n: [0.0, 2.0, 0.0],
                ..Default::default()
            })
            .unwrap();
            free.set_force(&ForceCommand {
                force_n: [0.0, 2.0, 0.0],
                ..Default::default()
            })
            .unwrap();
        }
        // 1000 steps of 1 ms at rate 1 / (1 + 2/2): the plan is at 0.5 s, the free one at 1 s.
        assert!(
            (op.intent_time_s() - 0.5).abs() < 1e-12,
            "{}",
            op.intent_time_s()
        );
        assert_eq!(free.intent_time_s(), 1.0);
    }
}
