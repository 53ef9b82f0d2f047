//! A scripted player that builds the blueprint: the default session of the house task.
//!
//! It closes the loop on the world's read access only (never on its internals): for each slot
//! in order it enters the loading zone, waits for a brick, touches its top, grabs it, lifts it,
//! carries it over the slot, turns it about z if the slot asks for it, lowers it to 1 mm above
//! the slot, lets go, waits for it to rest and leaves the zone's reach. The cursor moves in
//! straight lines at [`WallScript::SPEED_M_PER_S`]. Deterministic: same world, same inputs.

use crate::blueprint::cuboid_orientation_error_rad;
use crate::error::InputError;
use crate::event::BrickId;
use crate::input::{CursorInput, Grip};
use crate::params::BrickPlacement;
use crate::world::World;
use rapier3d_f64::math::{Rotation, Vector};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Leave the loading zone sideways at carry height.
    Leave,
    /// Go above the spawn spot (inside the zone).
    ToSpawn,
    /// Wait for a free brick at the spawn spot.
    WaitBrick,
    /// Press down onto the brick's top.
    Touch(BrickId),
    /// Hold down.
    Grab(BrickId),
    /// Lift to carry height.
    Lift,
    /// Fly above the slot.
    ToSlot,
    /// Press turn-z for one tick, then release it.
    Turn(u8),
    /// Lower into the slot.
    Lower,
    /// Hold up; wait for the brick to rest.
    Release(u32),
    /// Back up to carry height.
    Up,
    /// All slots done.
    Done,
}

/// The scripted wall builder.
#[derive(Debug, Clone)]
pub struct WallScript {
    slots: Vec<BrickPlacement>,
    next_slot: usize,
    phase: Phase,
    cursor: Vector,
    grip: Grip,
    spawn: Vector,
    away: Vector,
    carry_z: f64,
    ticks_in_phase: u32,
    /// Where the cursor goes to set the brick down, fixed when lowering starts (a brick in the
    /// coupling sags and stops on its slot before the hand does: a target that followed it
    /// would recede for ever).
    lower_target: Option<Vector>,
}

impl WallScript {
    /// Cursor speed along straight segments, m/s.
    pub const SPEED_M_PER_S: f64 = 0.5;
    /// Height the cursor carries bricks at, m.
    pub const CARRY_Z_M: f64 = 0.35;

    /// A script for `world`'s blueprint, starting with the cursor at `start_m` (m), which must be
    /// outside the loading zone. Returns `None` if the world has no loading zone.
    pub fn new(world: &World, start_m: [f64; 3]) -> Option<WallScript> {
        let z = world.params().loading_zone.clone()?;
        Some(WallScript {
            slots: world.params().blueprint.slots.clone(),
            next_slot: 0,
            phase: Phase::ToSpawn,
            cursor: Vector::from_array(start_m),
            grip: Grip::default(),
            spawn: Vector::new(z.spawn_m[0], z.spawn_m[1], Self::CARRY_Z_M),
            away: Vector::new(z.max_m[0] + 0.15, z.spawn_m[1], Self::CARRY_Z_M),
            carry_z: Self::CARRY_Z_M,
            ticks_in_phase: 0,
            lower_target: None,
        })
    }

    /// Whether every slot has been served.
    pub fn done(&self) -> bool {
        self.phase == Phase::Done
    }

    fn go(&mut self, target: Vector, dt: f64) -> bool {
        let d = target - self.cursor;
        let step = Self::SPEED_M_PER_S * dt;
        if d.length() <= step {
            self.cursor = target;
            true
        } else {
            self.cursor += d.normalize() * step;
            false
        }
    }

    fn set(&mut self, p: Phase) {
        self.phase = p;
        self.ticks_in_phase = 0;
    }

    /// The next device sample, given the world after the previous step.
    pub fn next_input(&mut self, world: &World) -> Result<CursorInput, InputError> {
        let dt = world.params().dt_s;
        let h = world.params().brick_half_extents_m;
        let r = world.params().proxy_radius_m;
        self.ticks_in_phase += 1;
        match self.phase {
            Phase::Leave => {
                if self.go(self.away, dt) {
                    self.set(if self.next_slot < self.slots.len() {
                        Phase::ToSpawn
                    } else {
                        Phase::Done
                    });
                }
            }
            Phase::ToSpawn => {
                if self.go(self.spawn, dt) {
                    self.set(Phase::WaitBrick);
                }
            }
            Phase::WaitBrick => self.wait_brick(world, h),
            Phase::Touch(id) => self.touch(world, id, dt, h, r),
            Phase::Grab(_) => {
                self.grip.hold = true;
                if self.ticks_in_phase > 2 {
                    self.set(Phase::Lift);
                }
            }
            Phase::Lift => {
                let t = Vector::new(self.cursor.x, self.cursor.y, self.carry_z);
                if self.go(t, dt) {
                    self.set(Phase::ToSlot);
                }
            }
            Phase::ToSlot => {
                let slot = Vector::from_array(self.slots[self.next_slot].center_m);
                let t = Vector::new(slot.x, slot.y, self.carry_z);
                if self.go(t, dt) {
                    self.set(Phase::Turn(0));
                }
            }
            Phase::Turn(n) => self.turn(world, n),
            Phase::Lower => self.lower(world, dt, h, r),
            Phase::Release(_) => {
                self.grip.hold = false;
                if self.ticks_in_phase > 300 {
                    self.next_slot += 1;
                    self.set(Phase::Up);
                }
            }
            Phase::Up => {
                let t = Vector::new(self.cursor.x, self.cursor.y, self.carry_z);
                if self.go(t, dt) {
                    self.set(Phase::Leave);
                }
            }
            Phase::Done => {}
        }
        world.input(self.cursor.to_array(), self.grip)
    }

    /// [`Phase::WaitBrick`]: a free brick lying at the spawn spot (within its half extents
    /// `h`, m) is the one to touch next.
    fn wait_brick(&mut self, world: &World, h: [f64; 3]) {
        let s = self.spawn;
        let found = world.bricks().find(|b| {
            !b.held
                && (b.position_m[0] - s.x).abs() < h[0]
                && (b.position_m[1] - s.y).abs() < h[1]
                && b.position_m[2] < 2.0 * h[2]
        });
        if let Some(b) = found {
            self.set(Phase::Touch(b.id));
        }
    }

    /// [`Phase::Touch`]: down onto brick `id`'s top (half extents `h`, proxy radius `r`, m).
    fn touch(&mut self, world: &World, id: BrickId, dt: f64, h: [f64; 3], r: f64) {
        let top = world.brick(id).map(|b| b.position_m).unwrap_or([0.0; 3]);
        // Aim 1 mm below the top: the proxy rests on it, the spring presses lightly.
        let target = Vector::new(top[0], top[1], top[2] + h[2] + r - 1e-3);
        if self.go(target, dt) {
            self.set(Phase::Grab(id));
        }
    }

    /// [`Phase::Turn`] after `n` turns: press turn-z for one tick at a time until the carried
    /// brick lines up with its slot.
    fn turn(&mut self, world: &World, n: u8) {
        // Turn about z until the held brick matches the slot's orientation (≤ 3 turns).
        let held = world.held_brick().and_then(|id| world.brick(id).ok());
        let target = self.slots[self.next_slot].rotation();
        let aligned = held.is_none_or(|b| {
            let q = b.orientation_xyzw;
            let q = Rotation::from_xyzw(q[0], q[1], q[2], q[3]);
            cuboid_orientation_error_rad(target, q) < 0.1
        });
        if self.grip.turn_z {
            self.grip.turn_z = false;
        } else if aligned || n >= 3 {
            self.set(Phase::Lower);
        } else {
            self.grip.turn_z = true;
            self.phase = Phase::Turn(n + 1);
        }
    }

    /// [`Phase::Lower`]: down to 1 mm above the slot, the target fixed on the first tick
    /// (half extents `h`, proxy radius `r`, m).
    fn lower(&mut self, world: &World, dt: f64, h: [f64; 3], r: f64) {
        let t = *self.lower_target.get_or_insert_with(|| {
            let slot = Vector::from_array(self.slots[self.next_slot].center_m);
            // Grip point above the brick centre as the brick hangs now (h_z + r + skin
            // when grabbed on top, plus the coupling's sag).
            let held = world.held_brick().and_then(|id| world.brick(id).ok());
            let offset = held
                .map(|b| {
                    Vector::from_array(world.proxy_position_m()) - Vector::from_array(b.position_m)
                })
                .unwrap_or(Vector::new(0.0, 0.0, h[2] + r));
            slot + offset + Vector::new(0.0, 0.0, 1e-3)
        });
        if self.go(t, dt) {
            self.lower_target = None;
            self.set(Phase::Release(0));
        }
    }
}
