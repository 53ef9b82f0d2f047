//! The world's vocabulary: the tick's input, the typed events and report of a step, and the
//! bodies' state as callers read it (movable atoms, anchors, the tip's contact).

use nalgebra::Vector3;
use world_form::ValueError;

use super::{MAX_POSITION_M, MIN_DT_S};
use crate::error::StepError;
use crate::law::PairKind;

/// Device input for one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipInput {
    /// Cursor position in the world frame (m): the tip apex centre in game mode, the
    /// cantilever base (where the undeflected tip centre would be) in physical mode.
    pub position_m: Vector3<f64>,
}

impl TipInput {
    /// Checks what [`World::step`] checks before it changes anything: every coordinate finite
    /// and within ±[`MAX_POSITION_M`], and `dt_s` (s) in [[`MIN_DT_S`], 1]. Lets a batch be
    /// checked in full before its first tick.
    pub fn check(&self, dt_s: f64) -> Result<(), StepError> {
        check_position(&self.position_m)?;
        if !(MIN_DT_S..=1.0).contains(&dt_s) {
            return Err(StepError::BadDt(ValueError::out_of_range(
                "dt_s",
                dt_s,
                "1e-9 <= dt_s <= 1 s",
            )));
        }
        Ok(())
    }
}

pub(super) fn check_position(p: &Vector3<f64>) -> Result<(), StepError> {
    for (k, v) in p.iter().enumerate() {
        let axis = ['x', 'y', 'z'][k];
        if !v.is_finite() {
            return Err(StepError::NonFinitePosition {
                axis,
                error: ValueError::out_of_range(
                    format!("tip position {axis}"),
                    *v,
                    "a finite number of metres",
                ),
            });
        }
        if v.abs() > MAX_POSITION_M {
            return Err(StepError::PositionOutOfRange {
                axis,
                error: ValueError::out_of_range(
                    format!("tip position {axis}"),
                    *v,
                    format!("|{axis}| <= 1 m"),
                ),
            });
        }
    }
    Ok(())
}

/// A body of the tip assembly: the tip itself or an atom it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Member {
    /// The AFM tip apex.
    Tip,
    /// Carried movable atom with this index.
    Atom(usize),
}

/// What a member of the tip assembly touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// Substrate atom with this index (game mode).
    SubstrateAtom(usize),
    /// The substrate as a Hamaker half-space (physical mode).
    SubstratePlane,
    /// Uncarried movable atom with this index.
    Atom(usize),
}

impl Target {
    pub(crate) fn is_substrate(&self) -> bool {
        matches!(self, Target::SubstrateAtom(_) | Target::SubstratePlane)
    }
}

/// Which link of the chain tip → (carried atom) → target → target's support broke at pull-off.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BrokenLink {
    /// The tip's own contact with the target (tip–substrate or tip–atom).
    TipContact,
    /// The tip's hold on its carried atoms: they stay on the target (atom transfer).
    TipCarried,
    /// The carried atom's contact with the target: the tip leaves with its atoms.
    CarriedContact,
    /// The target atom's own support (substrate or bonds): the target leaves with the tip.
    TargetSupport,
}

/// A typed event, listed in the order it happened within the tick.
///
/// Its serialized form (the recording's event detail) is JSON with a `type` tag and named
/// fields: `{"type":"snap","member":"tip","target":{"substrate_atom":12},...}`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Event {
    /// A movable atom appeared in the loading zone.
    AtomSpawned {
        /// Index of the new atom.
        atom: usize,
    },
    /// The tip assembly jumped into contact (snap-to-contact / jump-to-contact).
    Snap {
        /// The assembly member that touches.
        member: Member,
        /// What it touches.
        target: Target,
        /// Pair type of the contact.
        pair: PairKind,
        /// Surface gap just before the jump (m).
        gap_m: f64,
        /// The pair's snap force (N).
        snap_force_n: f64,
    },
    /// An uncarried atom jumped onto the tip (it was less bound than the tip holds it).
    AtomAttached {
        /// Index of the atom.
        atom: usize,
        /// Tip–atom surface gap just before the jump (m).
        gap_m: f64,
    },
    /// The pull on an anchored tip exceeded the weakest link's pull-off force.
    PullOff {
        /// The member that was in contact.
        member: Member,
        /// What it was touching.
        target: Target,
        /// The link that broke.
        broken: BrokenLink,
        /// Pull the bond resisted at release (N): the spring pull less any push into the
        /// target, in any direction.
        pull_n: f64,
        /// Pull-off force of the broken link (N).
        pull_off_n: f64,
    },
    /// An atom left the tip and stays bonded to `onto`.
    AtomTransferred {
        /// Index of the atom.
        atom: usize,
        /// What it now rests on (for a carried cluster: the member's target).
        onto: Target,
    },
    /// An uncarried atom was pulled off its support and is now carried.
    AtomPickedUp {
        /// Index of the atom.
        atom: usize,
    },
    /// The load on the carried atoms (their weight and the inertial force −m·a of the hand's
    /// acceleration) exceeded the tip's hold on them (the tip–atom pull-off force): they left
    /// the tip. At this scale a freed atom does not fly: it meets the surface below within
    /// nanoseconds and sticks there (it is placed at its rest position under the point where
    /// it left, or bonded where it is when that spot is taken).
    AtomsThrownOff {
        /// How many atoms left the tip.
        atoms: usize,
        /// Magnitude of the load on them, N.
        load_n: f64,
        /// The tip–atom pull-off force it exceeded, N.
        pull_off_n: f64,
    },
    /// A blueprint slot became filled.
    SlotFilled {
        /// Slot index.
        slot: usize,
    },
    /// A blueprint slot became empty.
    SlotEmptied {
        /// Slot index.
        slot: usize,
    },
    /// Every slot is filled (emitted on the tick it becomes true).
    HouseComplete,
}

/// What one tick produced.
#[derive(Debug, Clone, PartialEq)]
pub struct StepReport {
    /// Force to render on the device (N, world frame), finite, |F| ≤
    /// [`Limits::max_force_n`].
    pub force_n: Vector3<f64>,
    /// The force before the device limit was applied (N).
    pub unlimited_force_n: Vector3<f64>,
    /// Whether `force_n` was scaled down to [`Limits::max_force_n`].
    pub saturated: bool,
    /// Events in the order they happened.
    pub events: Vec<Event>,
}

/// A movable (orange) atom.
#[derive(Debug, Clone, PartialEq)]
pub struct MovableAtom {
    pub(crate) position: Vector3<f64>,
    pub(crate) carried_offset: Option<Vector3<f64>>,
    pub(crate) on_substrate: bool,
    pub(crate) bonds: Vec<usize>,
}

impl MovableAtom {
    /// Centre (m).
    pub fn position_m(&self) -> Vector3<f64> {
        self.position
    }
    /// Whether the tip carries it.
    pub fn is_carried(&self) -> bool {
        self.carried_offset.is_some()
    }
    /// Offset from the tip centre while carried (m).
    pub fn carried_offset_m(&self) -> Option<Vector3<f64>> {
        self.carried_offset
    }
    /// Whether it is bonded to the substrate.
    pub fn on_substrate(&self) -> bool {
        self.on_substrate
    }
    /// Indices of the movable atoms it is bonded to, ascending.
    pub fn bonds(&self) -> &[usize] {
        &self.bonds
    }
}

/// A contact holding the tip assembly in place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// The member in contact.
    pub member: Member,
    /// What it touches.
    pub target: Target,
    /// Pair type of the contact.
    pub pair: PairKind,
    /// Where the tip centre is held (m).
    pub tip_position_m: Vector3<f64>,
    /// Unit contact normal, from the target towards the member.
    pub normal: Vector3<f64>,
}

/// The tip's contact state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TipContact {
    /// Free: the tip follows the cursor (game) or its cantilever equilibrium (physical).
    Free,
    /// Held by a contact until the pull exceeds the weakest link's pull-off force.
    Anchored(Anchor),
}

/// A member–target pair that may not snap again until its gap exceeds the snap gap
/// (so a released contact does not re-form on the next tick).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Disarm {
    pub member: Member,
    /// `None`: the whole substrate.
    pub target_atom: Option<usize>,
}
