//! What the device may render on its own between two ticks (bridge protocol 2): the planes of
//! the surfaces at and near the cursor sphere, and the carried brick on its coupling. World
//! frame and units; the haptic loop maps them to the device. The types only: the world fills
//! them (`World::local_primitives`), the hand supplies the carried brick's parts.

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
