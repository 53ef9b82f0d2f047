//! What the device may render on its own between two ticks (bridge protocol 2): the planes of
//! the surfaces at and near the cursor sphere, and the carried brick on its coupling, in the
//! one local-model type every world and device shares (`haptic_types::local`: `Plane`, `Body`,
//! `WorldPrimitives`), world frame and units; the haptic loop maps them to the device. This
//! module holds how far ahead and how many the brick world announces; the world fills them
//! (`World::local_primitives`), the hand supplies the carried brick's parts.

/// How far from the cursor sphere a surface is announced before it is touched, m: a contact
/// that begins between two answers is then felt at once.
pub const NEAR_SURFACE_M: f64 = 0.02;

/// How far ahead the carried brick's surfaces are announced, s of its motion: a device on a
/// link of up to 50 ms one way meets a surface no sooner than the plane arrives.
pub const LOOKAHEAD_S: f64 = 0.1;

/// Most planes announced.
pub const MAX_PLANES: usize = 4;
