//! Game mode: the tip is the cursor; forces are the summed pair laws; contacts snap
//! inside the snap gap.

use nalgebra::Vector3;

use crate::contact::{Candidate, pair_of};
use crate::law::{PairKind, PairLaw};
use crate::world::{Event, Member, MovableAtom, Target, World};

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
        // Sweep the tip's move of this tick: the first armed snap gap it enters stops it
        // there, however long the move (no speed tunnels through an atom).
        let from = self.tip;
        let hit = self.sweep(from, self.cursor);
        let stop = hit.map_or(self.cursor, |(t, _)| from + (self.cursor - from) * t);
        self.place_tip(stop);
        self.rearm();
        let candidate = match hit {
            Some((_, mut c)) => {
                let (gap, _) = self.gap_normal(c.member, c.target);
                c.gap = gap;
                Some(c)
            }
            None => self.game_candidate(),
        };
        if let Some(c) = candidate {
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

    /// The pair type and law of member `m` and target `t` if `m` may snap to `t`: the law on
    /// and the contact not disarmed.
    fn armed_law(&self, m: Member, t: Target) -> Option<(PairKind, &PairLaw)> {
        let pair = pair_of(m, t);
        let law = self.laws.get(pair);
        (law.is_on() && !self.is_disarmed(m, t)).then_some((pair, law))
    }

    /// The movable atoms member `m` may snap to (not carried, [`World::armed_law`]), in
    /// ascending index, with their target, pair type and law.
    fn armed_atoms(
        &self,
        m: Member,
    ) -> impl Iterator<Item = (&MovableAtom, Target, PairKind, &PairLaw)> + '_ {
        self.atoms.iter().enumerate().filter_map(move |(i, a)| {
            if a.is_carried() {
                return None;
            }
            let t = Target::Atom(i);
            let (pair, law) = self.armed_law(m, t)?;
            Some((a, t, pair, law))
        })
    }

    /// The first point of the straight move `from` → `to` of the tip centre (m) at which a
    /// member of the tip assembly enters the snap gap of an armed target it was outside of:
    /// the fraction t ∈ [0, 1] of the move and the contact. `None` if the move enters none.
    /// Exact (ray against each target's snap sphere); the substrate is searched only along
    /// the part of the move that passes within snap reach of its lattice.
    fn sweep(&self, from: Vector3<f64>, to: Vector3<f64>) -> Option<(f64, Candidate)> {
        let d = to - from;
        if d == Vector3::zeros() {
            return None;
        }
        let mut best: Option<(f64, Candidate)> = None;
        let mut offer = |t: f64, c: Candidate| {
            if best.as_ref().is_none_or(|b| t < b.0) {
                best = Some((t, c));
            }
        };
        let rs = self.substrate.radius_m();
        let ra = self.params.atoms.radius_m;
        for m in self.members() {
            let (pm, rm) = self.member_pos_radius(m);
            let p0 = pm + (from - self.tip);
            for (a, t, pair, law) in self.armed_atoms(m) {
                if let Some(s) = ray_sphere(p0, d, a.position, rm + ra + law.snap_gap_m) {
                    offer(s, sweep_candidate(m, t, pair, law.snap_gap_m));
                }
            }
            let Some((pair, law)) = self.armed_law(m, Target::SubstratePlane) else {
                continue;
            };
            let r = rm + rs + law.snap_gap_m;
            if let Some((s, j)) = self.sweep_substrate(p0, d, r) {
                offer(
                    s,
                    sweep_candidate(m, Target::SubstrateAtom(j), pair, law.snap_gap_m),
                );
            }
        }
        best
    }

    /// First fraction of the move `p0` → `p0 + d` (m) at which a sphere of radius `r` (m)
    /// around the moving point touches a substrate atom centre, and that atom.
    fn sweep_substrate(&self, p0: Vector3<f64>, d: Vector3<f64>, r: f64) -> Option<(f64, usize)> {
        let sp = &self.params.substrate;
        let hi = [
            (sp.nx - 1) as f64 * sp.spacing_m + r,
            (sp.ny - 1) as f64 * sp.spacing_m + r,
            r,
        ];
        let lo = [-r, -r, -r];
        // Clip the move to the box that holds every atom's snap sphere.
        let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
        for k in 0..3 {
            if d[k] == 0.0 {
                if p0[k] < lo[k] || p0[k] > hi[k] {
                    return None;
                }
            } else {
                let a = (lo[k] - p0[k]) / d[k];
                let b = (hi[k] - p0[k]) / d[k];
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if t0 > t1 {
            return None;
        }
        // Walk the clipped move in windows of length h; an atom whose sphere a window
        // touches lies within r + h/2 of the window's middle.
        let len = d.norm();
        let cell = self.substrate.cell_m();
        let h = if cell > r {
            (2.0 * (cell - r)).min(r)
        } else {
            r
        };
        let windows = (((t1 - t0) * len / h).ceil() as usize).max(1);
        let dt = (t1 - t0) / windows as f64;
        for w in 0..windows {
            let mid = p0 + d * (t0 + (w as f64 + 0.5) * dt);
            let mut first: Option<(f64, usize)> = None;
            self.substrate
                .for_each_within(&mid, r + 0.5 * dt * len * (1.0 + 1e-9), |j, q| {
                    if let Some(s) = ray_sphere(p0, d, *q, r)
                        && first.is_none_or(|f| s < f.0)
                    {
                        first = Some((s, j));
                    }
                });
            if first.is_some() {
                return first;
            }
        }
        None
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
            for (a, t, pair, law) in self.armed_atoms(m) {
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
            let Some((pair, law)) = self.armed_law(m, Target::SubstratePlane) else {
                continue;
            };
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

/// First t ∈ [0, 1] with |p0 + t·d − q| ≤ r, for a point starting outside the sphere and
/// moving into it; `None` if it starts inside, moves away or misses.
fn ray_sphere(p0: Vector3<f64>, d: Vector3<f64>, q: Vector3<f64>, r: f64) -> Option<f64> {
    let w = p0 - q;
    let c = w.norm_squared() - r * r;
    let b = w.dot(&d);
    if c <= 0.0 || b >= 0.0 {
        return None;
    }
    let a = d.norm_squared();
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    // The smaller root, in the form that does not cancel: c / (−b + √disc).
    let t = c / (-b + disc.sqrt());
    (t <= 1.0).then_some(t)
}

fn sweep_candidate(member: Member, target: Target, pair: PairKind, snap_gap_m: f64) -> Candidate {
    Candidate {
        member,
        target,
        pair,
        gap: snap_gap_m,
        depth: 1.0,
    }
}
