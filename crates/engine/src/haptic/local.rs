//! The local model sent with each answer (bridge protocol 2): the scene's contact planes and
//! carried body mapped to the device, and the residual that makes the model give exactly the
//! answered force at the answered reading.

use super::HapticLoop;
use haptic_types::local::{Body, Bond, Follower, LocalModel, Plane};
use haptic_types::tick::status;
use haptic_types::vec3::{self, Vec3};

impl HapticLoop {
    /// The local model of the last tick (see `haptic_types::local`), device frame and units.
    ///
    /// The scene's primitives are mapped to the device (`p = (x − origin) / workspace_scale`;
    /// stiffness, damping and mass times `force_scale · workspace_scale`; forces times
    /// `force_scale`) and felt through the tick's gain (engagement, watchdog and clamp; zero
    /// after a missed deadline). The residual is the answered force less the primitives' at
    /// the answered reading, so at that reading the device renders exactly
    /// [`HapticLoop::command`]'s force; a scene without primitives sends its force with its
    /// local stiffness as the residual (what protocol 1 renders). `world_energy_j` is the work
    /// the answered forces did on the readings received: the two-port layer's budget.
    ///
    /// `version` is the session's protocol: from 3 on, the model also carries the scene's bond
    /// (`haptic_types::local::Bond`, a spring that breaks), from 4 on its follower
    /// (`haptic_types::local::Follower`, the held particle and its working envelope); before
    /// them, the scene's answer and stiffness stand in for them in the residual, as protocol 2
    /// always did.
    pub fn local_model(&self, version: u8) -> LocalModel {
        let r = &self.result;
        let mut prims = self.primitives.borrow_mut();
        prims.clear();
        self.scene.local_primitives(&mut prims);
        if version < 3 {
            prims.bond = None;
        }
        if version < 4 {
            prims.follower = None;
        }
        let m = &self.config.mapping;
        let (ws, fs) = (m.workspace_scale, m.force_scale);
        let kd = fs * ws;
        let gain = if r.status & status::DEADLINE_MISSED != 0 {
            0.0
        } else {
            self.local_gain / fs
        };
        let to_device = |x: Vec3| vec3::scale(vec3::sub(x, m.origin_m), 1.0 / ws);
        // A plane `n·x ≥ o` in the world is `n·p ≥ (o − n·origin) / ws` at the device.
        let plane_to_device = |p: &Plane, stiffness_n_per_m: f64| Plane {
            normal: p.normal,
            offset_m: (p.offset_m - vec3::dot(p.normal, m.origin_m)) / ws,
            stiffness_n_per_m,
        };
        let planes: Vec<Plane> = prims
            .planes
            .iter()
            .map(|p| plane_to_device(p, p.stiffness_n_per_m * kd * gain))
            .collect();
        let body = prims.body.map(|b| Body {
            position_m: to_device(b.position_m),
            velocity_m_per_s: vec3::scale(b.velocity_m_per_s, 1.0 / ws),
            mass_kg: b.mass_kg * kd,
            stiffness_n_per_m: b.stiffness_n_per_m * kd * gain,
            series_stiffness_n_per_m: b.series_stiffness_n_per_m * kd * gain,
            damping_n_s_per_m: b.damping_n_s_per_m * kd * gain,
            damper_m: vec3::scale(b.damper_m, 1.0 / ws),
            external_force_n: vec3::scale(b.external_force_n, fs),
            substeps: b.substeps,
            restitution: b.restitution,
        });
        let body_planes: Vec<Plane> = prims
            .body_planes
            .iter()
            .map(|p| plane_to_device(p, 0.0))
            .collect();
        // A bond's breaking stretch is a length: the gain softens its spring, not where it
        // breaks.
        let bond = prims.bond.map(|b| Bond {
            anchor_m: to_device(b.anchor_m),
            normal: b.normal,
            stiffness_n_per_m: b.stiffness_n_per_m * kd * gain,
            break_m: b.break_m / ws,
        });
        let follower = prims
            .follower
            .take()
            .map(|f| follower_to_device(&f, m.origin_m, ws, [kd, gain]));
        let world_energy_j = self.initial_tank_j() - self.tank_j;
        let model = LocalModel {
            residual_force_n: r.device_force_n,
            residual_stiffness_n_per_m: r.device_stiffness_n_per_m,
            planes,
            body,
            body_planes,
            world_energy_j,
            bond,
            follower,
        };
        if model.planes.is_empty()
            && model.body.is_none()
            && model.bond.is_none()
            && model.follower.is_none()
        {
            return model;
        }
        let p0 = to_device(r.cursor_m);
        let model = LocalModel {
            residual_force_n: [0.0; 3],
            residual_stiffness_n_per_m: [0.0; 9],
            ..model
        };
        let mut local = model.static_force(p0, p0);
        if let Some(b) = &model.body {
            local = vec3::sub(local, b.pull(p0, self.config.dt_s()).0);
        }
        if let Some(f) = &model.follower {
            local = vec3::add(local, f.force(p0));
        }
        LocalModel {
            residual_force_n: vec3::sub(r.device_force_n, local),
            ..model
        }
    }
}

/// A follower mapped to the device: its position like a point (`(x − origin) / ws`), its drift
/// and envelope, which are displacements, scaled and not moved, its spring times
/// `force_scale · workspace_scale` and then the tick's gain (`[kd, gain]`, in that order, as
/// the planes' springs).
fn follower_to_device(f: &Follower, origin_m: Vec3, ws: f64, [kd, gain]: [f64; 2]) -> Follower {
    Follower {
        position_m: [
            (f.position_m[0] - origin_m[0]) / ws,
            (f.position_m[1] - origin_m[1]) / ws,
        ],
        drift_m: [f.drift_m[0] / ws, f.drift_m[1] / ws],
        reach_m: f.reach_m.iter().map(|v| [v[0] / ws, v[1] / ws]).collect(),
        retain: f.retain,
        stiffness_n_per_m: f.stiffness_n_per_m * kd * gain,
    }
}
