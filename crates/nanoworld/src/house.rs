//! The house-building task: a blueprint of slots and the score.

use nalgebra::Vector3;

use crate::params::HouseParams;
use crate::world::{Event, World};

/// Blueprint slots and which are filled.
#[derive(Debug, Clone, PartialEq)]
pub struct HouseStatus {
    slots: Vec<Vector3<f64>>,
    tolerance_m: f64,
    filled: Vec<Option<usize>>,
    complete: bool,
}

impl HouseStatus {
    pub(crate) fn new(p: Option<&HouseParams>) -> Self {
        let mut s = HouseStatus {
            slots: Vec::new(),
            tolerance_m: 0.0,
            filled: Vec::new(),
            complete: false,
        };
        s.reset_blueprint(p);
        s
    }

    pub(crate) fn reset_blueprint(&mut self, p: Option<&HouseParams>) {
        let slots: Vec<Vector3<f64>> = p
            .map(|h| {
                h.slots_m
                    .iter()
                    .map(|s| Vector3::new(s[0], s[1], s[2]))
                    .collect()
            })
            .unwrap_or_default();
        if slots != self.slots {
            self.filled = vec![None; slots.len()];
            self.complete = false;
        }
        self.slots = slots;
        self.tolerance_m = p.map_or(0.0, |h| h.tolerance_m);
    }

    /// Slot centres (m).
    pub fn slots_m(&self) -> &[Vector3<f64>] {
        &self.slots
    }
    /// Fill distance (m).
    pub fn tolerance_m(&self) -> f64 {
        self.tolerance_m
    }
    /// For each slot, the index of the atom filling it.
    pub fn filled(&self) -> &[Option<usize>] {
        &self.filled
    }
    /// Number of filled slots.
    pub fn score(&self) -> usize {
        self.filled.iter().filter(|f| f.is_some()).count()
    }
    /// Whether every slot is filled (false for an empty blueprint).
    pub fn is_complete(&self) -> bool {
        self.complete
    }
}

impl World {
    /// Recompute slot fills: each slot takes the lowest-index uncarried atom within the
    /// tolerance not already used by an earlier slot.
    pub(crate) fn update_house(&mut self, events: &mut Vec<Event>) {
        let n = self.house.slots.len();
        if n == 0 {
            return;
        }
        let mut used = vec![false; self.atoms.len()];
        let mut filled = vec![None; n];
        for (k, s) in self.house.slots.iter().enumerate() {
            for (i, a) in self.atoms.iter().enumerate() {
                if !used[i] && !a.is_carried() && (a.position - s).norm() <= self.house.tolerance_m
                {
                    used[i] = true;
                    filled[k] = Some(i);
                    break;
                }
            }
        }
        for (k, (old, new)) in self.house.filled.iter().zip(&filled).enumerate() {
            match (old.is_some(), new.is_some()) {
                (false, true) => events.push(Event::SlotFilled { slot: k }),
                (true, false) => events.push(Event::SlotEmptied { slot: k }),
                _ => {}
            }
        }
        let complete = filled.iter().all(|f| f.is_some());
        if complete && !self.house.complete {
            events.push(Event::HouseComplete);
        }
        self.house.filled = filled;
        self.house.complete = complete;
    }
}
