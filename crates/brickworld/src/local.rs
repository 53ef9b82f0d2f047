//! What the device may render on its own between two ticks (bridge protocol 2): the planes of
//! the surfaces at and near the cursor sphere, and the carried brick on its coupling. World
//! frame and units; the haptic loop maps them to the device.

use crate::world::World;
use rapier3d_f64::math::Vector;

/// How far from the cursor sphere a surface is announced before it is touched, m: a contact
/// that begins between two answers is then felt at once.
pub const NEAR_SURFACE_M: f64 = 0.02;

/// How far ahead the carried brick's surfaces are announced, s of its motion: a device on a
/// link of up to 50 ms one way meets a surface no sooner than the plane arrives.
pub const LOOKAHEAD_S: f64 = 0.1;

/// Most planes announced.
pub const MAX_PLANES: usize = 4;

/// A surface the cursor sphere touches or nears: its centre must stay where `n·c ≥ offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPlane {
    /// Outward unit normal.
    pub normal: [f64; 3],
    /// `n·c` of the sphere's centre touching the surface, m.
    pub offset_m: f64,
    /// The proxy spring, N/m.
    pub stiffness_n_per_m: f64,
}

/// The brick carried through the coupling (see `Hand::coupling_pull`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarriedBody {
    /// The brick's centre less the grip offset, m.
    pub position_m: [f64; 3],
    /// The brick's velocity, m/s.
    pub velocity_m_per_s: [f64; 3],
    /// Its mass, kg.
    pub mass_kg: f64,
    /// The coupling's spring, N/m.
    pub stiffness_n_per_m: f64,
    /// The damper's series spring, N/m.
    pub series_stiffness_n_per_m: f64,
    /// The damper, N·s/m.
    pub damping_n_s_per_m: f64,
    /// The dashpot's share of the lead, m.
    pub damper_m: [f64; 3],
    /// Its weight, N.
    pub external_force_n: [f64; 3],
    /// The rigid-body engine's substeps per step.
    pub substeps: u32,
    /// Restitution of its contacts.
    pub restitution: f64,
}

/// The world's local primitives after a step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalPrimitives {
    /// Surfaces touched, then the nearest one not touched (at most [`MAX_PLANES`]).
    pub planes: Vec<ContactPlane>,
    /// The carried brick.
    pub body: Option<CarriedBody>,
    /// The surfaces the carried brick touches or nears, as planes on its grip point
    /// ([`CarriedBody::position_m`]): it stays where `n·x ≥ offset` (at most [`MAX_PLANES`]).
    pub body_planes: Vec<ContactPlane>,
}

impl World {
    /// The primitives the device may render until the next tick: a plane for each surface the
    /// god-object touches (deduplicated by normal) and for the nearest surface within
    /// [`NEAR_SURFACE_M`], each `n·c ≥ n·proxy` at the proxy stiffness; and the carried brick.
    pub fn local_primitives(&self) -> LocalPrimitives {
        let p = self.params();
        let proxy = Vector::from_array(self.proxy_position_m());
        let k = p.proxy_stiffness_n_per_m;
        let mut planes: Vec<ContactPlane> = Vec::with_capacity(MAX_PLANES);
        let mut push = |n: Vector, offset: f64| {
            let dup = planes
                .iter()
                .any(|q| Vector::from_array(q.normal).dot(n) > 1.0 - 1e-9);
            if !dup && planes.len() < MAX_PLANES && n.is_finite() && offset.is_finite() {
                planes.push(ContactPlane {
                    normal: n.to_array(),
                    offset_m: offset,
                    stiffness_n_per_m: k,
                });
            }
        };
        for n in self.hand_contact_normals() {
            push(*n, n.dot(proxy));
        }
        if let Some((point, n)) = self.nearest_surface(NEAR_SURFACE_M) {
            push(n, n.dot(point) + p.proxy_radius_m);
        }
        let body = self.carried_body();
        let body_planes = match &body {
            Some(b) => {
                let speed = Vector::from_array(b.velocity_m_per_s).length();
                self.carried_contacts(b.position_m, NEAR_SURFACE_M.max(speed * LOOKAHEAD_S))
            }
            None => Vec::new(),
        };
        LocalPrimitives {
            planes,
            body,
            body_planes,
        }
    }
}
