//! The device and the hand between two ticks of the loop: moving mass, friction, a held force
//! rendered at the device's servo rate, encoder counts, and the hand's spring-damper.

use crate::{Grip, Mechanics};
use haptic_types::Vec3;

/// What the loop commanded until its next tick: the force `F0` (N, device frame) computed at
/// the reading `p0` (m), and the local stiffness `K` (N/m, row-major 3×3) the device renders
/// around it between packets: `F(p) = F0 − K (p − p0)`, with `p` the encoder reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hold {
    /// Force at `p0`, N.
    pub force_n: Vec3,
    /// Local stiffness, N/m, row-major 3×3.
    pub stiffness_n_per_m: [f64; 9],
    /// The reading the command answers, m.
    pub p0_m: Vec3,
}

impl Hold {
    /// A constant force (no local stiffness): a pure zero-order hold.
    pub fn constant(force_n: Vec3) -> Hold {
        Hold {
            force_n,
            stiffness_n_per_m: [0.0; 9],
            p0_m: [0.0; 3],
        }
    }
}

/// Longest integration substep, ns.
const MAX_SUBSTEP_NS: u64 = 50_000;

/// A device held by a hand, integrated in time.
///
/// Per axis, with `M` the device's moving mass plus the grip's mass:
/// `M ẍ = k (x_i − x) + b (ẋ_i − ẋ) − c ẋ + F_dev`, where `(x_i, ẋ_i)` is the operator's
/// intended path, `k, b` the grip, `c` the device's viscous friction and `F_dev` the force the
/// device renders: constant over each servo period, computed from the encoder reading at the
/// period's start, clamped to the device's largest force and rounded to its force resolution.
/// Integrated with backward (implicit) Euler in the spring and dampers, in substeps of at most
/// 50 µs: unconditionally stable for any grip, so an oscillation seen in closed loop is the
/// rendering's, not the integrator's. The stylus stops at the workspace sphere (its outward
/// velocity removed), as a linkage does.
#[derive(Clone, Debug)]
pub struct Plant {
    mech: Mechanics,
    grip: Grip,
    x: Vec3,
    v: Vec3,
    /// Time integrated so far, ns (an integer clock: servo instants never drift).
    clock_ns: u64,
    /// The device's next servo instant, ns.
    next_servo_ns: u64,
    energy_to_hand_j: f64,
    last_force_n: Vec3,
}

/// `F0 − K (p − p0)` of a hold at `p`, N.
fn hold_force(hold: &Hold, p: Vec3) -> Vec3 {
    let d = [
        p[0] - hold.p0_m[0],
        p[1] - hold.p0_m[1],
        p[2] - hold.p0_m[2],
    ];
    let k = &hold.stiffness_n_per_m;
    let mut f = [0.0; 3];
    for (i, fi) in f.iter_mut().enumerate() {
        *fi = hold.force_n[i] - (k[3 * i] * d[0] + k[3 * i + 1] * d[1] + k[3 * i + 2] * d[2]);
    }
    f
}

fn quantize(x: f64, q: f64) -> f64 {
    if q > 0.0 { (x / q).round() * q } else { x }
}

impl Plant {
    /// A device at rest at `start_m` (device frame, m), held with `grip`.
    pub fn new(mech: Mechanics, grip: Grip, start_m: Vec3) -> Plant {
        Plant {
            mech,
            grip,
            x: start_m,
            v: [0.0; 3],
            clock_ns: 0,
            next_servo_ns: 0,
            energy_to_hand_j: 0.0,
            last_force_n: [0.0; 3],
        }
    }

    /// The device's mechanics.
    pub fn mechanics(&self) -> &Mechanics {
        &self.mech
    }

    /// The grip.
    pub fn grip(&self) -> &Grip {
        &self.grip
    }

    /// True position of the end effector, m.
    pub fn position_m(&self) -> Vec3 {
        self.x
    }

    /// True velocity of the end effector, m/s.
    pub fn velocity_m_per_s(&self) -> Vec3 {
        self.v
    }

    /// What the encoders report: the position rounded to whole counts, m.
    pub fn reading_m(&self) -> Vec3 {
        self.x.map(|c| quantize(c, self.mech.encoder_quantum_m))
    }

    /// Time integrated so far, s.
    pub fn time_s(&self) -> f64 {
        self.clock_ns as f64 * 1e-9
    }

    /// Work the device's motors have done on the stylus and hand since the start, J (positive:
    /// energy went into the hand).
    pub fn energy_to_hand_j(&self) -> f64 {
        self.energy_to_hand_j
    }

    /// Force the motors rendered in the last servo period, N (after the clamp and the force
    /// resolution).
    pub fn last_force_n(&self) -> Vec3 {
        self.last_force_n
    }

    /// The force the device renders at reading `p` under `hold`: `F0 − K (p − p0)`, scaled
    /// down to the largest force (direction kept), each component rounded to the force
    /// resolution.
    pub fn rendered_force(&self, hold: &Hold, p: Vec3) -> Vec3 {
        self.motors(hold_force(hold, p))
    }

    /// What the motors make of the force `f`: scaled down to the largest force (direction
    /// kept), each component rounded to the force resolution; zero for a non-finite force.
    pub fn motors(&self, mut f: Vec3) -> Vec3 {
        let n = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        let max = self.mech.limits.max_force_n;
        if !n.is_finite() {
            return [0.0; 3];
        }
        if n > max {
            f = f.map(|c| c * (max / n));
        }
        f.map(|c| quantize(c, self.mech.force_quantum_n))
    }

    /// Advances by one tick of `dt_s` under `hold`. `intent(t)` gives the operator's intended
    /// position (m) and velocity (m/s) at `t` seconds after the start of this tick.
    ///
    /// The device renders on its own servo clock: at each of its servo instants (every
    /// `1 / servo_rate_hz`, counted in whole nanoseconds from the start) it reads its encoders
    /// and renders the latest hold; a loop faster than the servo has its answers sampled, a
    /// slower one has each answer rendered over several servo periods.
    pub fn advance(&mut self, dt_s: f64, intent: impl Fn(f64) -> (Vec3, Vec3), hold: &Hold) {
        let h = *hold;
        self.advance_with(dt_s, intent, &mut |p, _| hold_force(&h, p));
    }

    /// Advances by `dt_s` as [`Plant::advance`] does, with the force at each servo instant
    /// from `render(reading, servo_period_s)` (N, before the motors' clamp and resolution): a
    /// device side with a model of its own ([`crate::local::DeviceSide`]).
    pub fn advance_with(
        &mut self,
        dt_s: f64,
        intent: impl Fn(f64) -> (Vec3, Vec3),
        render: &mut dyn FnMut(Vec3, f64) -> Vec3,
    ) {
        let dt_ns = (dt_s * 1e9).round().max(1.0) as u64;
        let servo_ns = (1e9 / self.mech.servo_rate_hz).round().max(1.0) as u64;
        let n = dt_ns.div_ceil(MAX_SUBSTEP_NS).max(1);
        let m = self.mech.moving_mass_kg + self.grip.mass_kg;
        let k = self.grip.stiffness_n_per_m;
        let b = self.grip.damping_n_s_per_m;
        let c = self.mech.viscous_n_s_per_m;
        let start = self.clock_ns;
        for s in 0..n {
            let t0 = start + s * dt_ns / n;
            let t1 = start + (s + 1) * dt_ns / n;
            if t0 >= self.next_servo_ns {
                let f = render(self.reading_m(), servo_ns as f64 * 1e-9);
                self.last_force_n = self.motors(f);
                while self.next_servo_ns <= t0 {
                    self.next_servo_ns += servo_ns;
                }
            }
            let f = self.last_force_n;
            let h = (t1 - t0) as f64 * 1e-9;
            let denom = m + h * (b + c) + h * h * k;
            let (xi, vi) = intent((t1 - start) as f64 * 1e-9);
            for a in 0..3 {
                let v_new =
                    (m * self.v[a] + h * (k * (xi[a] - self.x[a]) + b * vi[a] + f[a])) / denom;
                let dx = h * v_new;
                self.energy_to_hand_j += f[a] * dx;
                self.x[a] += dx;
                self.v[a] = v_new;
            }
            self.end_stop();
        }
        self.clock_ns = start + dt_ns;
    }

    fn end_stop(&mut self) {
        let r = (self.x[0] * self.x[0] + self.x[1] * self.x[1] + self.x[2] * self.x[2]).sqrt();
        let rmax = self.mech.workspace_radius_m;
        if r > rmax {
            let n = self.x.map(|c| c / r);
            self.x = n.map(|c| c * rmax);
            let vn = n[0] * self.v[0] + n[1] * self.v[1] + n[2] * self.v[2];
            if vn > 0.0 {
                for (vi, ni) in self.v.iter_mut().zip(n) {
                    *vi -= vn * ni;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    const T: f64 = 1e-3;

    /// A hand holding an ideal device still: the step response of the mass–spring–damper
    /// matches the analytic one (ω = √(k/M), ζ = (b + c) / (2 √(k M))) to the integrator's
    /// first order.
    #[test]
    fn free_response_matches_the_damped_oscillator() {
        let mech = Mechanics::FALCON.without_quantization();
        let grip = Grip::LOOSE;
        let x0 = 0.005;
        let mut p = Plant::new(mech, grip, [x0, 0.0, 0.0]);
        let (m, k, b) = (
            mech.moving_mass_kg,
            grip.stiffness_n_per_m,
            grip.damping_n_s_per_m,
        );
        let c = b + mech.viscous_n_s_per_m;
        let w0 = (k / m).sqrt();
        let z = c / (2.0 * (k * m).sqrt());
        let wd = w0 * (1.0 - z * z).sqrt();
        let mut worst: f64 = 0.0;
        for n in 1..=200 {
            p.advance(T, |_| ([0.0; 3], [0.0; 3]), &Hold::constant([0.0; 3]));
            let t = n as f64 * T;
            let exact = x0 * (-z * w0 * t).exp() * ((wd * t).cos() + z * w0 / wd * (wd * t).sin());
            worst = worst.max((p.position_m()[0] - exact).abs());
        }
        // Backward Euler at 50 µs: error O(h), about 1 % of the amplitude here.
        assert!(worst < 0.01 * x0, "worst {worst}");
    }

    #[test]
    fn encoder_and_force_resolution_are_applied() {
        let mut p = Plant::new(Mechanics::FALCON, Grip::FIRM, [0.0; 3]);
        let hold = Hold::constant([0.0, 0.0, 0.1234]);
        for _ in 0..100 {
            p.advance(T, |_| ([0.0; 3], [0.0; 3]), &hold);
        }
        let q = Mechanics::FALCON.force_quantum_n;
        let f = p.last_force_n()[2];
        assert_eq!(f, (0.1234 / q).round() * q);
        let r = p.reading_m()[2] / Mechanics::FALCON.encoder_quantum_m;
        assert_eq!(r, r.round());
        // A force above the limit is scaled down to it.
        let big = p.rendered_force(&Hold::constant([30.0, 40.0, 0.0]), [0.0; 3]);
        let n = (big[0] * big[0] + big[1] * big[1]).sqrt();
        assert!((n - 8.0).abs() <= 2.0 * q, "{n}");
        assert!(p.rendered_force(&Hold::constant([f64::NAN; 3]), [0.0; 3]) == [0.0; 3]);
    }

    /// The local stiffness of a hold is rendered at the servo rate: a hand pressing 2 N into a
    /// 2000 N/m spring settles 1 mm in, and the energy the device took is the spring's ½ k x²
    /// less what the sampled spring generated (Colgate's `K T / 2`), which shrinks with the
    /// servo period: first order in T.
    #[test]
    fn local_stiffness_is_rendered_between_packets() {
        let mut k = [0.0; 9];
        k[0] = 2000.0;
        let hold = Hold {
            force_n: [0.0; 3],
            stiffness_n_per_m: k,
            p0_m: [0.0; 3],
        };
        let stored = 0.5 * 2000.0 * 0.001f64.powi(2);
        let shortfall = |rate: f64| {
            let mech = Mechanics {
                servo_rate_hz: rate,
                ..Mechanics::DELTA3.without_quantization()
            };
            let mut p = Plant::new(mech, Grip::FIRM, [0.0; 3]);
            // The hand wants to be 3 mm in: 1000 (3 − x) = 2000 x → x = 1 mm.
            for _ in 0..2000 {
                p.advance(T, |_| ([0.003, 0.0, 0.0], [0.0; 3]), &hold);
            }
            assert!((p.position_m()[0] - 0.001).abs() < 1e-7);
            (stored + p.energy_to_hand_j()) / stored
        };
        let (slow, fast) = (shortfall(1000.0), shortfall(4000.0));
        assert!(slow > 0.0 && slow < 0.2, "{slow}");
        let order = (slow / fast).log(4.0);
        assert!(
            (order - 1.0).abs() < 0.15,
            "order {order} ({slow} vs {fast})"
        );
    }

    /// A 10 kHz loop on a 1 kHz device: the device samples the latest answer once per its
    /// own servo period, so ten answers make one rendered force.
    #[test]
    fn a_loop_faster_than_the_servo_is_sampled_at_the_servo_rate() {
        let mut p = Plant::new(
            Mechanics::FALCON.without_quantization(),
            Grip::FIRM,
            [0.0; 3],
        );
        let mut rendered = Vec::new();
        for i in 0..100 {
            let hold = Hold::constant([0.0, 0.0, 0.01 * i as f64]);
            p.advance(1e-4, |_| ([0.0; 3], [0.0; 3]), &hold);
            rendered.push(p.last_force_n()[2]);
        }
        // Ticks 0–9 render the answer of tick 0, ticks 10–19 that of tick 10, ...
        for (i, f) in rendered.iter().enumerate() {
            assert_eq!(*f, 0.01 * (i / 10 * 10) as f64, "tick {i}");
        }
        assert_eq!(p.time_s(), 0.01);
    }

    #[test]
    fn the_stylus_stops_at_the_workspace_sphere() {
        let mut p = Plant::new(Mechanics::FALCON, Grip::FIRM, [0.0; 3]);
        for _ in 0..500 {
            p.advance(
                T,
                |_| ([0.1, 0.0, 0.0], [0.0; 3]),
                &Hold::constant([0.0; 3]),
            );
        }
        assert!((p.position_m()[0] - 0.04).abs() < 1e-12);
        assert!(p.velocity_m_per_s()[0] <= 0.0);
    }
}
