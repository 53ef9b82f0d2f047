//! The world's vocabulary of what happens: brick ids, touch targets, impact bodies, axes and
//! the typed [`Event`]s a step reports (with their stable serialized form).

use serde::Serialize;

/// Identifier of a brick: its index in creation order (stable, never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct BrickId(pub u32);

/// What the cursor can touch (serialized `"ground"`, `{"brick": 3}`, `{"obstacle": 0}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Touch {
    /// The ground plane `z = 0`.
    Ground,
    /// A brick.
    Brick(BrickId),
    /// A fixed obstacle, by its index in [`crate::Params::obstacles`].
    Obstacle(usize),
}

/// A body taking part in an impact (serialized `"cursor"`, `"ground"`, `{"brick": 3}`,
/// `{"obstacle": 0}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Body {
    /// The cursor sphere (the hand).
    Cursor,
    /// The ground plane.
    Ground,
    /// A brick.
    Brick(BrickId),
    /// A fixed obstacle, by its index in [`crate::Params::obstacles`].
    Obstacle(usize),
}

impl From<Touch> for Body {
    fn from(t: Touch) -> Body {
        match t {
            Touch::Ground => Body::Ground,
            Touch::Brick(b) => Body::Brick(b),
            Touch::Obstacle(i) => Body::Obstacle(i),
        }
    }
}

/// A world axis (for the rotate buttons).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// x.
    X,
    /// y.
    Y,
    /// z (up).
    Z,
}

/// Something that happened during a step, in the order it happened.
///
/// Its serialized form (the recording's event detail) is JSON with a `type` tag and named
/// fields, e.g. `{"type":"impact","a":{"brick":0},"b":"ground","impulse_n_s":1.2,...}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Event {
    /// A brick appeared in the loading zone.
    Spawned {
        /// The new brick.
        brick: BrickId,
    },
    /// The centre button was pressed near a brick, which is now carried.
    Grabbed {
        /// The carried brick.
        brick: BrickId,
    },
    /// The centre button was pressed with no brick within reach.
    GrabMissed,
    /// The centre button was released; the brick left the hand with this velocity (m/s).
    Released {
        /// The brick let go.
        brick: BrickId,
        /// Its initial velocity, m/s (the grip point's velocity).
        velocity_m_per_s: [f64; 3],
    },
    /// Same release, faster than [`crate::Params::throw_min_speed_m_per_s`]: a throw.
    Thrown {
        /// The thrown brick.
        brick: BrickId,
        /// Its initial velocity, m/s.
        velocity_m_per_s: [f64; 3],
    },
    /// The carried brick turned by +90° about a world axis (through the grip point).
    Rotated {
        /// The carried brick.
        brick: BrickId,
        /// The axis.
        axis: Axis,
    },
    /// A rotate button was pressed but the turned brick would overlap something; nothing moved.
    RotationBlocked {
        /// The carried brick.
        brick: BrickId,
        /// The axis.
        axis: Axis,
    },
    /// The cursor (or carried brick) started touching something.
    TouchBegan {
        /// What is touched.
        target: Touch,
    },
    /// The cursor (or carried brick) stopped touching something.
    TouchEnded {
        /// What was touched.
        target: Touch,
    },
    /// A blueprint slot became filled by a resting brick.
    SlotFilled {
        /// Slot index in [`crate::Params::blueprint`].
        slot: usize,
        /// The brick in it.
        brick: BrickId,
    },
    /// A blueprint slot lost its brick.
    SlotVacated {
        /// Slot index.
        slot: usize,
        /// The brick that left.
        brick: BrickId,
    },
    /// A collision: a contact that began this step with bodies approaching faster than
    /// [`crate::impact::IMPACT_MIN_SPEED_M_PER_S`] (see [`crate::impact::events`]). Between the cursor and what it touches,
    /// the impulse is the brick mass × the cursor's approach speed (the cursor has no mass in
    /// the world; this is the impulse that would stop a brick arriving at that speed).
    Impact {
        /// One body.
        a: Body,
        /// The other.
        b: Body,
        /// Normal impulse of the contact over the step, N·s.
        impulse_n_s: f64,
        /// Approach speed along the contact normal just before the step, m/s.
        speed_m_per_s: f64,
        /// Centroid of the contact, m.
        point_m: [f64; 3],
    },
}
