//! The house-building task: a blueprint of slots and the score.

use nalgebra::Vector3;

use crate::params::HouseParams;

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

/// A change of the house found by [`HouseStatus::update`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum HouseChange {
    /// Slot `k` became filled.
    Filled(usize),
    /// Slot `k` became empty.
    Emptied(usize),
    /// Every slot is filled (reported once, when it becomes so).
    Complete,
}

impl HouseStatus {
    /// Recompute slot fills: each slot takes the lowest-index free atom within the tolerance not
    /// already used by an earlier slot. `free(i)` is atom `i`'s position, `None` while carried.
    pub(crate) fn update(
        &mut self,
        n_atoms: usize,
        free: impl Fn(usize) -> Option<Vector3<f64>>,
        mut emit: impl FnMut(HouseChange),
    ) {
        let n = self.slots.len();
        if n == 0 {
            return;
        }
        let mut used = vec![false; n_atoms];
        let mut filled = vec![None; n];
        for (k, s) in self.slots.iter().enumerate() {
            for (i, u) in used.iter_mut().enumerate() {
                if let Some(p) = free(i)
                    && !*u
                    && (p - s).norm() <= self.tolerance_m
                {
                    *u = true;
                    filled[k] = Some(i);
                    break;
                }
            }
        }
        for (k, (old, new)) in self.filled.iter().zip(&filled).enumerate() {
            match (old.is_some(), new.is_some()) {
                (false, true) => emit(HouseChange::Filled(k)),
                (true, false) => emit(HouseChange::Emptied(k)),
                _ => {}
            }
        }
        let complete = filled.iter().all(|f| f.is_some());
        if complete && !self.complete {
            emit(HouseChange::Complete);
        }
        self.filled = filled;
        self.complete = complete;
    }
}
