//! The check's own world, answered as the simulator answers: a contact plane (the wall), then
//! a brick carried through a coupling and resting on a floor where the wall was.
//!
//! Every answer is the world's force at the sample's reading, scaled down to the device's
//! maximum force as the simulator's clamp does, with the local stiffness (protocol 1) and, in
//! a version-2 session, the local model whose residual makes it exact at that reading
//! (`docs/device-bridge.md`, "Protocol, version 2"). The brick is integrated one step per
//! sequence number with the readings received (a skipped number takes the reading before it,
//! as the device side does), and the world energy is the work the answered forces did on the
//! readings received.

use super::super::protocol::ForceReply;
use super::stages::{ENGAGE_S, Stage};
use haptic_types::local::{Body, LocalModel, Plane};
use haptic_types::vec3::{self, Vec3};

/// The brick's mass as the device feels it, kg.
pub const BRICK_MASS_KG: f64 = 0.1;

/// Gravity on the brick, m/s² (its weight, `F_ext`, along −z).
const GRAVITY_M_PER_S2: f64 = 9.81;

/// The brick's damper, N·s/m (through a series spring as stiff as the coupling).
const BRICK_DAMPING_N_S_PER_M: f64 = 5.0;

/// What the check's world holds now.
#[derive(Clone, Debug)]
enum Prims {
    None,
    Wall,
    Brick(Body),
}

/// The check's world, in the device's frame and units.
#[derive(Clone, Debug)]
pub struct CheckWorld {
    /// The wall's (and the floor's) offset along +z, m (set when the wall stage begins).
    floor_m: Option<f64>,
    /// The wall's stiffness, N/m: the device's announced largest stiffness.
    pub wall_n_per_m: f64,
    /// The brick coupling's spring, N/m: half the wall's.
    pub coupling_n_per_m: f64,
    max_force_n: f64,
    period_s: f64,
    version: u8,
    prims: Prims,
    /// When the soft engagement after the silence began, s (`None`: full force).
    engage_from_s: Option<f64>,
    world_j: f64,
    last: Option<(u64, Vec3, Vec3)>,
}

impl CheckWorld {
    /// The world for a device of `max_force_n` (N) and `max_stiffness_n_per_m` (N/m), in a
    /// session of `version` at `rate_hz`.
    pub fn new(max_force_n: f64, max_stiffness_n_per_m: f64, version: u8, rate_hz: u32) -> Self {
        CheckWorld {
            floor_m: None,
            wall_n_per_m: max_stiffness_n_per_m,
            coupling_n_per_m: max_stiffness_n_per_m / 2.0,
            max_force_n,
            period_s: 1.0 / f64::from(rate_hz),
            version,
            prims: Prims::None,
            engage_from_s: None,
            world_j: 0.0,
            last: None,
        }
    }

    /// The wall's and floor's offset along +z, m, once the wall stage began.
    pub fn floor_m(&self) -> Option<f64> {
        self.floor_m
    }

    /// The answer of tick `tick` to sample `seq` read at `p` (m), which arrived at `t_s` (s
    /// from the welcome) in `stage`.
    pub fn answer(&mut self, stage: Stage, t_s: f64, tick: u64, seq: u64, p: Vec3) -> ForceReply {
        self.enter(stage, t_s, p);
        // Numbers the device skipped: the brick steps with the reading before them.
        let (floor, h) = (self.floor_plane(), self.period_s);
        if let (Some((last_seq, last_p, _)), Prims::Brick(b)) = (self.last, &mut self.prims) {
            for _ in last_seq.saturating_add(1)..seq.min(last_seq.saturating_add(1000)) {
                b.step(last_p, h, &floor);
            }
        }
        if let Some((_, lp, lf)) = self.last {
            let w = vec3::dot(lf, vec3::sub(p, lp));
            if w.is_finite() {
                self.world_j += w;
            }
        }
        let gain = match self.engage_from_s {
            Some(t0) => ((t_s - t0) / ENGAGE_S).clamp(0.0, 1.0),
            None => 1.0,
        };
        let reply = match self.prims.clone() {
            Prims::None => self.reply(tick, seq, [0.0; 3], [0.0; 9], LocalModel::default()),
            Prims::Wall => self.wall(tick, seq, p, gain),
            Prims::Brick(b) => self.brick(tick, seq, p, gain, b),
        };
        self.last = Some((seq, p, reply.force_n));
        reply
    }

    /// The world's primitives as `stage` begins.
    fn enter(&mut self, stage: Stage, t_s: f64, p: Vec3) {
        match (stage, &self.prims) {
            (Stage::Handshake, _) => {}
            (Stage::Wall, Prims::None) => {
                let z = self.last.map_or(p[2], |l| l.1[2]);
                self.floor_m = Some(z - super::stages::WALL_GAP_M);
                self.prims = Prims::Wall;
            }
            (
                Stage::Brick | Stage::Loss | Stage::Silence | Stage::Resume,
                Prims::None | Prims::Wall,
            ) => {
                let floor = *self.floor_m.get_or_insert(p[2] - super::stages::WALL_GAP_M);
                let k = self.coupling_n_per_m;
                self.prims = Prims::Brick(Body {
                    position_m: [p[0], p[1], p[2].max(floor)],
                    velocity_m_per_s: [0.0; 3],
                    mass_kg: BRICK_MASS_KG,
                    stiffness_n_per_m: k,
                    series_stiffness_n_per_m: k,
                    damping_n_s_per_m: BRICK_DAMPING_N_S_PER_M,
                    damper_m: [0.0; 3],
                    external_force_n: [0.0, 0.0, -BRICK_MASS_KG * GRAVITY_M_PER_S2],
                    substeps: 1,
                    restitution: 0.0,
                });
            }
            _ => {}
        }
        if stage == Stage::Resume && self.engage_from_s.is_none() {
            self.engage_from_s = Some(t_s);
        }
    }

    fn floor_plane(&self) -> [Plane; 1] {
        [Plane {
            normal: [0.0, 0.0, 1.0],
            offset_m: self.floor_m.unwrap_or(0.0),
            stiffness_n_per_m: 0.0,
        }]
    }

    /// The wall at `p` with the engagement `gain`: its push, clamped to the maximum force by
    /// scaling its stiffness (the clamp is part of the tick's gain, so the residual is zero).
    fn wall(&self, tick: u64, seq: u64, p: Vec3, gain: f64) -> ForceReply {
        let mut plane = Plane {
            normal: [0.0, 0.0, 1.0],
            offset_m: self.floor_m.unwrap_or(0.0),
            stiffness_n_per_m: self.wall_n_per_m * gain,
        };
        let f = plane.force(p);
        plane.stiffness_n_per_m *= self.clamp(f);
        let force = plane.force(p);
        let k = plane.stiffness_at(p);
        let model = LocalModel {
            planes: vec![plane],
            ..LocalModel::default()
        };
        self.reply(tick, seq, force, k, model)
    }

    /// The brick at `p`: the stylus feels −pull; the brick steps once with `p`, held by the
    /// floor; the model carries its state after the step.
    fn brick(&mut self, tick: u64, seq: u64, p: Vec3, gain: f64, mut b: Body) -> ForceReply {
        let h = self.period_s;
        let k = self.coupling_n_per_m * gain;
        b.stiffness_n_per_m = k;
        b.series_stiffness_n_per_m = k;
        b.damping_n_s_per_m = BRICK_DAMPING_N_S_PER_M * gain;
        let c = self.clamp(vec3::scale(b.pull(p, h).0, -1.0));
        b.stiffness_n_per_m *= c;
        b.series_stiffness_n_per_m *= c;
        b.damping_n_s_per_m *= c;
        let force = vec3::scale(b.pull(p, h).0, -1.0);
        let floor = self.floor_plane();
        b.step(p, h, &floor);
        self.prims = Prims::Brick(b);
        let r = if b.damping_n_s_per_m > 0.0 && b.series_stiffness_n_per_m > 0.0 {
            h * b.series_stiffness_n_per_m / b.damping_n_s_per_m
        } else {
            0.0
        };
        let ke = b.stiffness_n_per_m + b.series_stiffness_n_per_m / (1.0 + r);
        let stiffness = [ke, 0.0, 0.0, 0.0, ke, 0.0, 0.0, 0.0, ke];
        let model = LocalModel {
            residual_force_n: vec3::add(force, b.pull(p, h).0),
            body: Some(b),
            body_planes: floor.to_vec(),
            ..LocalModel::default()
        };
        self.reply(tick, seq, force, stiffness, model)
    }

    /// The factor that brings `f` within the maximum force (1 when it is).
    fn clamp(&self, f: Vec3) -> f64 {
        let n = vec3::norm(f);
        if n > self.max_force_n && n.is_finite() {
            self.max_force_n / n
        } else {
            1.0
        }
    }

    fn reply(
        &self,
        tick: u64,
        seq: u64,
        force_n: Vec3,
        stiffness_n_per_m: [f64; 9],
        model: LocalModel,
    ) -> ForceReply {
        let local = (self.version >= super::super::protocol::VERSION_2).then(|| {
            Box::new(LocalModel {
                world_energy_j: self.world_j,
                ..model
            })
        });
        ForceReply {
            seq,
            tick,
            force_n,
            stiffness_n_per_m,
            status: 0,
            local,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A device side rendering the model at the answered reading gets the answered force (the
    /// residual makes the model exact there), for the wall and the brick.
    #[test]
    fn the_model_gives_the_answered_force_at_the_answered_reading() {
        let mut w = CheckWorld::new(8.0, 3000.0, 2, 1000);
        w.answer(Stage::Handshake, 0.0, 0, 0, [0.0; 3]);
        // 1 mm into the wall (2 mm below the start): 3 N up.
        let p = [0.0, 0.0, -0.003];
        let r = w.answer(Stage::Wall, 0.6, 1, 1, p);
        assert!((r.force_n[2] - 3.0).abs() < 1e-9, "{:?}", r.force_n);
        let m = r.local.unwrap();
        assert_eq!(m.static_force(p, p), r.force_n);
        // 5 mm in: 15 N clamped to 8 N by the plane's stiffness.
        let r = w.answer(Stage::Wall, 0.7, 2, 2, [0.0, 0.0, -0.007]);
        assert!((r.force_n[2] - 8.0).abs() < 1e-9);
        let r = w.answer(Stage::Brick, 2.0, 3, 3, p);
        let m = r.local.unwrap();
        let b = m.body.unwrap();
        let at_p0 = vec3::sub(m.static_force(p, p), b.pull(p, 1e-3).0);
        assert!(vec3::norm(vec3::sub(at_p0, r.force_n)) < 1e-12);
        // The brick rests on the floor, the stylus 1 mm below it: pulled up.
        assert_eq!(b.position_m[2], -0.002);
        assert!(r.force_n[2] > 0.0);
    }
}
