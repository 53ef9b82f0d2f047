//! Game mode: the tip is the cursor; forces are the summed pair laws; contacts snap
//! inside the snap gap.

use nalgebra::Vector3;

use crate::contact::{Candidate, pair_of};
use crate::law::PairKind;
use crate::world::{Event, Member, Target, World};

/// The tip–substrate force at one tip position computed three ways (N), for the error report.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubstrateForceCheck {
    /// Cell-list sum (what the world renders).
    pub cell_list_n: Vector3<f64>,
    /// Same law summed over every substrate atom (exact reference).
    pub brute_force_n: Vector3<f64>,
    /// Plain A/z² without the activation cutoff or its shift, summed over every atom
    /// (held at the snap-gap value below it): the law the game truncates.
    pub untruncated_n: Vector3<f64>,
    /// Atoms inside the activation range.
    pub atoms_in_range: usize,
}

impl World {
    pub(crate) fn free_game(&mut self, events: &mut Vec<Event>) {
        self.place_tip(self.cursor);
        self.rearm();
        if let Some(c) = self.game_candidate() {
            match (c.member, c.target) {
                (Member::Tip, Target::Atom(i))
                    if self.binding(i) < self.laws.get(PairKind::TipAtom).pull_off_n =>
                {
                    self.attach(i, c.gap, events)
                }
                _ => self.anchor(c, events),
            }
        }
    }

    /// Drop disarm entries whose gap has grown past the snap gap.
    fn rearm(&mut self) {
        let list = std::mem::take(&mut self.disarmed);
        let mut keep = Vec::with_capacity(list.len());
        for d in list {
            let still_member = match d.member {
                Member::Tip => true,
                Member::Atom(i) => self.atoms[i].is_carried(),
            };
            if !still_member {
                continue;
            }
            let (pm, rm) = self.member_pos_radius(d.member);
            let close = match d.target_atom {
                Some(i) => {
                    if self.atoms[i].is_carried() {
                        false
                    } else {
                        let pair = pair_of(d.member, Target::Atom(i));
                        let (gap, _) = self.gap_normal(d.member, Target::Atom(i));
                        gap < self.laws.get(pair).snap_gap_m
                    }
                }
                None => {
                    let pair = pair_of(d.member, Target::SubstratePlane);
                    let reach = rm + self.substrate.radius_m() + self.laws.get(pair).snap_gap_m;
                    let mut any = false;
                    self.substrate
                        .for_each_within(&pm, reach, |_, _| any = true);
                    any
                }
            };
            if close {
                keep.push(d);
            }
        }
        self.disarmed = keep;
    }

    /// The armed contact deepest inside its snap gap, if any (ties: first found, in the
    /// order tip then carried atoms ascending; atoms before substrate, ascending index).
    fn game_candidate(&self) -> Option<Candidate> {
        let mut best: Option<Candidate> = None;
        let mut offer = |c: Candidate| {
            if best.is_none_or(|b| c.depth < b.depth) {
                best = Some(c);
            }
        };
        let rs = self.substrate.radius_m();
        for m in self.members() {
            let (pm, rm) = self.member_pos_radius(m);
            for (i, a) in self.atoms.iter().enumerate() {
                if a.is_carried() {
                    continue;
                }
                let t = Target::Atom(i);
                let pair = pair_of(m, t);
                let law = self.laws.get(pair);
                if !law.is_on() || self.is_disarmed(m, t) {
                    continue;
                }
                let gap = (pm - a.position).norm() - rm - self.params.atoms.radius_m;
                if gap < law.snap_gap_m {
                    offer(Candidate {
                        member: m,
                        target: t,
                        pair,
                        gap,
                        depth: gap / law.snap_gap_m,
                    });
                }
            }
            let pair = pair_of(m, Target::SubstratePlane);
            let law = self.laws.get(pair);
            if !law.is_on() || self.is_disarmed(m, Target::SubstratePlane) {
                continue;
            }
            self.substrate
                .for_each_within(&pm, rm + rs + law.snap_gap_m, |j, q| {
                    let gap = (pm - q).norm() - rm - rs;
                    offer(Candidate {
                        member: m,
                        target: Target::SubstrateAtom(j),
                        pair,
                        gap,
                        depth: gap / law.snap_gap_m,
                    });
                });
        }
        best
    }

    /// Sum of the pair attractions on the tip assembly with the tip centre at `tip` (N).
    pub(crate) fn assembly_force_game(&self, tip: Vector3<f64>) -> Vector3<f64> {
        let mut f = Vector3::zeros();
        let rs = self.substrate.radius_m();
        let ra = self.params.atoms.radius_m;
        for m in self.members() {
            let (pm, rm) = match m {
                Member::Tip => (tip, self.params.tip.radius_m),
                Member::Atom(i) => (tip + self.atoms[i].carried_offset.unwrap_or_default(), ra),
            };
            for a in &self.atoms {
                if a.is_carried() {
                    continue;
                }
                let law = self.laws.get(pair_of(m, Target::Atom(0)));
                f += central(law, &pm, &a.position, rm + ra);
            }
            let law = self.laws.get(pair_of(m, Target::SubstratePlane));
            if law.is_on() {
                self.substrate
                    .for_each_within(&pm, rm + rs + law.cutoff_gap_m, |_, q| {
                        f += central(law, &pm, q, rm + rs);
                    });
            }
        }
        f
    }

    /// Tip–substrate force on a bare tip centred at `tip_m` (m), by cell list, by brute
    /// force, and without the activation cutoff. `None` in physical mode (the substrate is
    /// a continuum plane there, with no sum to approximate).
    pub fn substrate_force_check(&self, tip_m: Vector3<f64>) -> Option<SubstrateForceCheck> {
        if self.laws.physical {
            return None;
        }
        let law = self.laws.get(PairKind::TipSubstrate);
        let (rt, rs) = (self.params.tip.radius_m, self.substrate.radius_m());
        let reach = rt + rs + law.cutoff_gap_m;
        let mut cell = Vector3::zeros();
        let mut n = 0;
        self.substrate.for_each_within(&tip_m, reach, |_, q| {
            cell += central(law, &tip_m, q, rt + rs);
            n += 1;
        });
        let mut brute = Vector3::zeros();
        self.substrate
            .for_each_within_brute_force(&tip_m, reach, |_, q| {
                brute += central(law, &tip_m, q, rt + rs);
            });
        let mut plain = *law;
        plain.shift_n = 0.0;
        plain.cutoff_gap_m = f64::INFINITY;
        let mut untruncated = Vector3::zeros();
        for q in self.substrate.positions() {
            untruncated += central(&plain, &tip_m, q, rt + rs);
        }
        Some(SubstrateForceCheck {
            cell_list_n: cell,
            brute_force_n: brute,
            untruncated_n: untruncated,
            atoms_in_range: n,
        })
    }
}

/// Attraction on a sphere at `p` from a sphere at `q` (radii summing to `radii`) (N).
pub(crate) fn central(
    law: &crate::law::PairLaw,
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    radii: f64,
) -> Vector3<f64> {
    let d = p - q;
    let r = d.norm();
    if r == 0.0 {
        return Vector3::zeros();
    }
    let f = law.force(r - radii);
    if f == 0.0 {
        return Vector3::zeros();
    }
    d * (-f / r)
}
