//! Snap, anchor, release and transfer: the contact state machine shared by both modes.
//!
//! Rules (the paper's, generalised to a chain of bonds):
//! - The less-bound body jumps. When the tip comes within the tip–atom snap range of an
//!   uncarried atom whose binding (the strongest pull-off of its bonds) is weaker than
//!   the tip–atom pull-off, the atom jumps onto the tip; otherwise the tip anchors on it.
//!   Substrate and uncarried atoms never move, so any other contact anchors the tip.
//! - While anchored the tip is held; the device feels the adhesion spring
//!   F = k·(anchor − cursor). The pull the bond resists is that spring's pull P =
//!   k·(cursor − anchor) less any push into the target (the normal component
//!   min(P·n, 0)·n, which the target's repulsion takes): P_bond = P − min(P·n, 0)·n, so a
//!   sideways pull counts in full and a press counts not at all. The contact breaks when
//!   |P_bond| reaches the pull-off force of the weakest link of the chain
//!   tip → carried atoms → target → target's support; ties break nearest the tip.
//! - Breaking tip→carried leaves the carried atoms bonded to the target (atom transfer);
//!   breaking the target's support makes the target a carried atom (pick-up).

use nalgebra::Vector3;

use crate::law::PairKind;
use crate::world::{Anchor, BrokenLink, Disarm, Event, Member, Target, TipContact, World};

/// A contact about to form.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Candidate {
    pub member: Member,
    pub target: Target,
    pub pair: PairKind,
    pub gap: f64,
    /// Sort key: gap / snap gap (smaller snaps first).
    pub depth: f64,
}

/// The part of the spring pull `p` (N) that the bond resists: `p` less its compressive
/// component along the contact normal `n` (unit, from target to member). Magnitude, N.
pub(crate) fn bond_pull(p: Vector3<f64>, n: Vector3<f64>) -> f64 {
    let along = p.dot(&n);
    (p - along.min(0.0) * n).norm()
}

pub(crate) fn pair_of(member: Member, target: Target) -> PairKind {
    match (member, target.is_substrate()) {
        (Member::Tip, true) => PairKind::TipSubstrate,
        (Member::Tip, false) => PairKind::TipAtom,
        (Member::Atom(_), false) => PairKind::AtomAtom,
        (Member::Atom(_), true) => PairKind::AtomSubstrate,
    }
}

impl World {
    /// Target centre and radius; the plane has no centre (`None`).
    pub(crate) fn target_pos_radius(&self, t: Target) -> Option<(Vector3<f64>, f64)> {
        match t {
            Target::SubstrateAtom(j) => {
                Some((self.substrate.positions()[j], self.substrate.radius_m()))
            }
            Target::SubstratePlane => None,
            Target::Atom(i) => Some((self.atoms[i].position, self.params.atoms.radius_m)),
        }
    }

    /// Height of the physical-mode substrate plane (m): the top of the atom layer.
    pub(crate) fn plane_z(&self) -> f64 {
        self.substrate.radius_m()
    }

    /// Surface gap (m) and unit normal from target to member.
    pub(crate) fn gap_normal(&self, m: Member, t: Target) -> (f64, Vector3<f64>) {
        let (pm, rm) = self.member_pos_radius(m);
        match self.target_pos_radius(t) {
            None => (pm.z - rm - self.plane_z(), Vector3::z()),
            Some((pt, rt)) => {
                let d = pm - pt;
                let r = d.norm();
                let n = if r > 0.0 { d / r } else { Vector3::z() };
                (r - rm - rt, n)
            }
        }
    }

    /// Move the assembly so `member` touches `target` at the contact gap and anchor it.
    pub(crate) fn anchor(&mut self, c: Candidate, events: &mut Vec<Event>) {
        let (gap, n) = self.gap_normal(c.member, c.target);
        let law = *self.laws.get(c.pair);
        let shift = -(gap - law.contact_gap_m) * n;
        self.place_tip(self.tip + shift);
        self.contact = TipContact::Anchored(Anchor {
            member: c.member,
            target: c.target,
            pair: c.pair,
            tip_position_m: self.tip,
            normal: n,
        });
        events.push(Event::Snap {
            member: c.member,
            target: c.target,
            pair: c.pair,
            gap_m: c.gap,
            snap_force_n: law.snap_force_n,
        });
    }

    /// Atom `i` jumps onto the tip and breaks its bonds.
    pub(crate) fn attach(&mut self, i: usize, gap: f64, events: &mut Vec<Event>) {
        let law = *self.laws.get(PairKind::TipAtom);
        let d = self.atoms[i].position - self.tip;
        let r = d.norm();
        let n = if r > 0.0 { d / r } else { -Vector3::z() };
        let offset =
            n * (self.params.tip.radius_m + self.params.atoms.radius_m + law.contact_gap_m);
        let former = std::mem::take(&mut self.atoms[i].bonds);
        for &j in &former {
            self.atoms[j].bonds.retain(|&k| k != i);
            self.disarm(Member::Atom(i), Some(j));
        }
        if self.atoms[i].on_substrate {
            self.disarm(Member::Atom(i), None);
        }
        self.atoms[i].on_substrate = false;
        self.atoms[i].carried_offset = Some(offset);
        self.atoms[i].position = self.tip + offset;
        self.carried.push(i);
        self.carried.sort_unstable();
        events.push(Event::AtomAttached {
            atom: i,
            gap_m: gap,
        });
    }

    pub(crate) fn disarm(&mut self, member: Member, target_atom: Option<usize>) {
        let d = Disarm {
            member,
            target_atom,
        };
        if !self.disarmed.contains(&d) {
            self.disarmed.push(d);
        }
    }

    pub(crate) fn is_disarmed(&self, member: Member, target: Target) -> bool {
        let t = match target {
            Target::Atom(i) => Some(i),
            _ => None,
        };
        self.disarmed
            .iter()
            .any(|d| d.member == member && d.target_atom == t)
    }

    /// The weakest link of an anchored tip's chain and its pull-off force, N: the pull at
    /// which the anchor lets go.
    pub(crate) fn weakest_link(&self, a: &Anchor) -> (BrokenLink, f64) {
        let po = |p: PairKind| self.laws.get(p).pull_off_n;
        let mut links: Vec<(BrokenLink, f64)> = Vec::with_capacity(3);
        match a.member {
            Member::Tip => links.push((BrokenLink::TipContact, po(a.pair))),
            Member::Atom(_) => {
                links.push((BrokenLink::TipCarried, po(PairKind::TipAtom)));
                links.push((BrokenLink::CarriedContact, po(a.pair)));
            }
        }
        if let Target::Atom(i) = a.target {
            links.push((BrokenLink::TargetSupport, self.binding(i)));
        }
        let mut weakest = links[0];
        for l in &links[1..] {
            if l.1 < weakest.1 {
                weakest = *l;
            }
        }
        weakest
    }

    /// Release the anchored tip if the pull reaches the weakest link's pull-off force.
    pub(crate) fn maybe_release(&mut self, a: &Anchor, events: &mut Vec<Event>) {
        let k = self.laws.get(a.pair).stiffness_n_per_m;
        let pull = bond_pull(k * (self.cursor - a.tip_position_m), a.normal);
        let weakest = self.weakest_link(a);
        if pull < weakest.1 {
            return;
        }
        events.push(Event::PullOff {
            member: a.member,
            target: a.target,
            broken: weakest.0,
            pull_n: pull,
            pull_off_n: weakest.1,
        });
        self.contact = TipContact::Free;
        let target_atom = match a.target {
            Target::Atom(i) => Some(i),
            _ => None,
        };
        match weakest.0 {
            BrokenLink::TipContact => self.disarm(Member::Tip, target_atom),
            BrokenLink::CarriedContact => self.disarm(a.member, target_atom),
            BrokenLink::TipCarried => {
                let cluster = std::mem::take(&mut self.carried);
                for &c in &cluster {
                    self.atoms[c].carried_offset = None;
                    self.disarm(Member::Tip, Some(c));
                }
                if let Member::Atom(c) = a.member {
                    match a.target {
                        Target::Atom(i) => self.bond(c, i),
                        _ => self.atoms[c].on_substrate = true,
                    }
                }
                for &c in &cluster {
                    events.push(Event::AtomTransferred {
                        atom: c,
                        onto: a.target,
                    });
                }
            }
            BrokenLink::TargetSupport => {
                if let Some(i) = target_atom {
                    let former = std::mem::take(&mut self.atoms[i].bonds);
                    for &j in &former {
                        self.atoms[j].bonds.retain(|&k| k != i);
                    }
                    if self.atoms[i].on_substrate {
                        self.disarm(Member::Atom(i), None);
                    }
                    self.atoms[i].on_substrate = false;
                    self.atoms[i].carried_offset = Some(self.atoms[i].position - self.tip);
                    if let Member::Atom(c) = a.member {
                        self.bond(c, i);
                    }
                    self.carried.push(i);
                    self.carried.sort_unstable();
                    events.push(Event::AtomPickedUp { atom: i });
                }
            }
        }
        // The tip (with whatever it still carries) leaves the contact and restarts from the
        // cursor (game: the tip is the cursor; physical: the undeflected cantilever).
        self.place_tip(self.cursor);
    }

    fn bond(&mut self, a: usize, b: usize) {
        for (x, y) in [(a, b), (b, a)] {
            if !self.atoms[x].bonds.contains(&y) {
                self.atoms[x].bonds.push(y);
                self.atoms[x].bonds.sort_unstable();
            }
        }
    }
}
