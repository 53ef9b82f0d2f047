//! The hand: the cursor proxy (god-object), the grip commands (grab, release, throw, turn),
//! the force the device renders (proxy spring, weight and inertia of the carried brick,
//! scaled down to the device's largest force) and the hand's push on the bricks it touches.
//!
//! - [`grab`]: `hold` pressed, the nearest brick within reach taken into the hand;
//! - [`carry`]: how a held brick is carried (rigidly, or through the virtual coupling) and
//!   what the local model needs to know of it;
//! - [`turn`]: a turn command on the carried brick;
//! - [`release`]: `hold` released, the brick let go of (or thrown);
//! - [`contact`]: the god-object's move, its touches and its push on the bricks;
//! - [`force`]: the force the device renders.

mod carry;
mod contact;
mod force;
mod grab;
mod release;
mod turn;

use rapier3d_f64::math::{Rotation, Vector};
use rapier3d_f64::prelude::ColliderHandle;
use world_form::Limits;

use crate::bricks::BrickSet;
use crate::estimator::{AdaptiveWindow, MotionEstimator};
use crate::event::{Axis, BrickId, Event, Touch};
use crate::input::{CursorInput, Grip};
use crate::params::{AccelEstimator, Params};
use contact::push_bricks;
use force::Felt;

/// Range of [`crate::World::nearest_m`], m: farther solids count as none.
pub const NEAREST_MAX_M: f64 = 1.0;

/// The carried brick and how it sits in the hand.
#[derive(Debug, Clone, Copy)]
struct Held {
    brick: BrickId,
    /// Brick centre minus proxy centre, world frame, m.
    offset: Vector,
    /// Brick orientation.
    rotation: Rotation,
    /// Whether the brick is a dynamic body joined by the virtual coupling (else it is carried
    /// kinematically, the paper's way).
    coupled: bool,
}

/// The haptic cursor: proxy, device cursor, grip state, motion history and touches.
pub(crate) struct Hand {
    /// Centre of the cursor sphere (god-object), m.
    proxy: Vector,
    /// Last device cursor position, m.
    cursor: Vector,
    /// The grip commands of the last sample (for press and release edges).
    grip: Grip,
    /// Velocity and acceleration of the grip point from the proxy's history.
    motion: MotionEstimator,
    /// Velocity of the grip point for a rigidly carried brick's release (adaptive window).
    grip_velocity: AdaptiveWindow,
    /// The coupling dashpot's share of the grip point's lead on the brick, m.
    damper: Vector,
    held: Option<Held>,
    /// What the cursor (or carried brick) touches, sorted.
    touching: Vec<Touch>,
    /// Outward normals of the surfaces the god-object touched in the last update.
    contact_normals: Vec<Vector>,
    /// A brick just let go of that the cursor sphere still overlaps (a coupled brick's
    /// coupling lets the hand sink into it): passed through until they separate, so letting
    /// go never kicks the hand out of the brick.
    letting_go: Option<ColliderHandle>,
    /// The proxy's speed over the last tick, m/s (for cursor impacts).
    proxy_speed: f64,
    /// Whether a sample has arrived.
    started: bool,
}

impl Hand {
    /// A hand at the top centre of the workspace, holding nothing, until the first sample.
    pub(crate) fn new(params: &Params) -> Hand {
        let top = Vector::new(0.0, 0.0, params.workspace_half_extent_m);
        Hand {
            proxy: top,
            cursor: top,
            grip: Grip::default(),
            motion: MotionEstimator::new(params.dt_s, params.accel_estimator),
            grip_velocity: AdaptiveWindow::new(
                params.dt_s,
                params.release_velocity_band_m,
                params.release_velocity_max_window,
            ),
            damper: Vector::ZERO,
            held: None,
            touching: Vec::new(),
            contact_normals: Vec::new(),
            letting_go: None,
            proxy_speed: 0.0,
            started: false,
        }
    }

    /// Centre of the cursor sphere, m.
    pub(crate) fn proxy(&self) -> Vector {
        self.proxy
    }

    /// Last device cursor position, m.
    pub(crate) fn cursor(&self) -> Vector {
        self.cursor
    }

    /// The carried brick, if any.
    pub(crate) fn held_brick(&self) -> Option<BrickId> {
        self.held.map(|h| h.brick)
    }

    /// What the cursor (or carried brick) touches now, sorted.
    pub(crate) fn touching(&self) -> &[Touch] {
        &self.touching
    }

    /// Restarts the acceleration estimate with `kind`, from the proxy's current position.
    pub(crate) fn set_accel_estimator(&mut self, dt_s: f64, kind: AccelEstimator) {
        let newest = self.proxy.to_array();
        self.motion = MotionEstimator::new(dt_s, kind);
        self.motion.reset(newest);
    }

    /// Outward normals of the surfaces the god-object touched in the last update.
    pub(crate) fn contact_normals(&self) -> &[Vector] {
        &self.contact_normals
    }

    /// One tick of the hand with the device sample `input`: grip edges (release before grab, so
    /// one tick can't do both on one brick; then the turns), the god-object update, the force
    /// for the device, touch events and the hand's push on dynamic bricks.
    pub(crate) fn step(
        &mut self,
        input: &CursorInput,
        tick: u64,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) -> Felt {
        let c = Vector::from_array(input.position_m());
        self.cursor = c;
        if !self.started {
            // The first sample: the proxy comes down from the top of the workspace onto the
            // cursor, so it starts outside every solid even if the cursor starts inside one.
            self.proxy = Vector::new(c.x, c.y, params.workspace_half_extent_m);
            self.started = true;
        }
        // 1. Grip: release before grab so one tick can't do both on one brick.
        self.grip_edges(input.grip(), params, limits, bricks, events);
        // 2. God-object update (a coupled brick is a body of its own, not part of the proxy).
        let (upd, approach_speed) = self.move_proxy(c, tick, params, bricks);
        // 3. The force the device renders this tick.
        let (felt, felt_spring) =
            self.device_force(c, params, limits, bricks, upd.penetration_before_m);
        // 4. Touch bookkeeping and the hand's push on dynamic bricks.
        self.contact_normals.clear();
        self.contact_normals
            .extend(upd.contacts.iter().map(|ct| ct.normal));
        self.touches(&upd, tick, approach_speed, params, bricks, events);
        push_bricks(&upd, felt_spring, params, bricks);
        felt
    }

    /// The grip's edges since the last tick: a release, then a grab, then the turns.
    fn grip_edges(
        &mut self,
        grip: Grip,
        params: &Params,
        limits: &Limits,
        bricks: &mut BrickSet,
        events: &mut Vec<Event>,
    ) {
        let prev = self.grip;
        self.grip = grip;
        if prev.hold && !grip.hold {
            self.release(params, bricks, events);
        }
        if !prev.hold && grip.hold {
            self.grab(params, limits, bricks, events);
        }
        for (now, before, axis) in [
            (grip.turn_x, prev.turn_x, Axis::X),
            (grip.turn_y, prev.turn_y, Axis::Y),
            (grip.turn_z, prev.turn_z, Axis::Z),
        ] {
            if now && !before {
                self.turn(axis, params, bricks, events);
            }
        }
    }
}
