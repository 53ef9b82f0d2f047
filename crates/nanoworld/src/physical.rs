//! Physical mode: the tip hangs from the cursor (cantilever base) on a spring k_c and sits
//! at its quasi-static equilibrium k_c·(x_base − x_tip) + F(x_tip) + load = 0.
//!
//! The equilibrium is followed from tick to tick by Newton's method on the 3 × 3 system
//! (k_c·I − ∂F/∂x)·Δ = residual. It is stable while k_c·I − ∂F/∂x is positive definite.
//! When no stable equilibrium is left (the force gradient exceeds k_c, at the
//! sphere–plane gap z_jtc = (A·R/(3·k_c))^{1/3}), the tip jumps to contact.

use nalgebra::{Matrix3, Vector3};

use crate::contact::{Candidate, pair_of};
use crate::law::PairKind;
use crate::world::{Event, Member, Target, World};

/// Newton iterations before a missing equilibrium is declared a jump.
const MAX_ITERATIONS: usize = 200;

enum Solve {
    Stable(Vector3<f64>),
    Fold,
}

impl World {
    pub(crate) fn free_physical(&mut self, load: Vector3<f64>, events: &mut Vec<Event>) {
        let start = self.tip;
        match self.solve(start, load) {
            Solve::Stable(x) => {
                self.place_tip(x);
                // The less-bound body jumps: an atom whose support is weaker than the tip's pull.
                let mut best: Option<(usize, f64, f64)> = None;
                let law = *self.laws.get(PairKind::TipAtom);
                if law.is_on() {
                    for i in 0..self.atoms.len() {
                        if self.atoms[i].is_carried() {
                            continue;
                        }
                        let (gap, _) = self.gap_normal(Member::Tip, Target::Atom(i));
                        let ratio = law.force(gap) / self.binding(i);
                        if ratio >= 1.0 && best.is_none_or(|b| ratio > b.1) {
                            best = Some((i, ratio, gap));
                        }
                    }
                }
                if let Some((i, _, gap)) = best {
                    self.attach(i, gap, events);
                    if let Solve::Stable(x) = self.solve(self.tip, load) {
                        self.place_tip(x);
                    } else {
                        self.jump(self.tip, events);
                    }
                }
            }
            Solve::Fold => self.jump(start, events),
        }
    }

    /// Anchor on the strongest-pulling pair at the last stable position `at`.
    fn jump(&mut self, at: Vector3<f64>, events: &mut Vec<Event>) {
        self.place_tip(at);
        let mut best: Option<(Candidate, f64)> = None;
        self.for_each_pair(|w, m, t| {
            let pair = pair_of(m, t);
            let law = w.laws.get(pair);
            let (gap, _) = w.gap_normal(m, t);
            let f = law.force(gap);
            if f > 0.0 && best.is_none_or(|b| f > b.1) {
                best = Some((
                    Candidate {
                        member: m,
                        target: t,
                        pair,
                        gap,
                        depth: 0.0,
                    },
                    f,
                ));
            }
        });
        if let Some((c, _)) = best {
            self.anchor(c, events);
        }
    }

    /// Visit every (assembly member, target) pair that can interact.
    fn for_each_pair(&self, mut f: impl FnMut(&World, Member, Target)) {
        for m in self.members() {
            f(self, m, Target::SubstratePlane);
            for (i, a) in self.atoms.iter().enumerate() {
                if !a.is_carried() {
                    f(self, m, Target::Atom(i));
                }
            }
        }
    }

    /// Force on the assembly (N), its Jacobian ∂F/∂x_tip (N/m), and the smallest
    /// (gap − contact gap) over all pairs (m), with the tip centre at `x`.
    pub(crate) fn force_jacobian(&self, x: Vector3<f64>) -> (Vector3<f64>, Matrix3<f64>, f64) {
        let mut f = Vector3::zeros();
        let mut j = Matrix3::zeros();
        let mut margin = f64::INFINITY;
        let plane = self.plane_z();
        let ra = self.params.atoms.radius_m;
        for m in self.members() {
            let (pm, rm) = match m {
                Member::Tip => (x, self.params.tip.radius_m),
                Member::Atom(i) => (x + self.atoms[i].carried_offset.unwrap_or_default(), ra),
            };
            let law = self.laws.get(pair_of(m, Target::SubstratePlane));
            if law.is_on() {
                let gap = pm.z - rm - plane;
                margin = margin.min(gap - law.contact_gap_m);
                f.z -= law.force(gap);
                j[(2, 2)] += law.stiffening(gap);
            }
            let law = self.laws.get(pair_of(m, Target::Atom(0)));
            if !law.is_on() {
                continue;
            }
            for a in &self.atoms {
                if a.is_carried() {
                    continue;
                }
                let d = pm - a.position;
                let r = d.norm();
                if r == 0.0 {
                    margin = margin.min(-1.0);
                    continue;
                }
                let u = d / r;
                let gap = r - rm - ra;
                margin = margin.min(gap - law.contact_gap_m);
                let mag = law.force(gap);
                f -= u * mag;
                let uu = u * u.transpose();
                j += uu * law.stiffening(gap) - (Matrix3::identity() - uu) * (mag / r);
            }
        }
        (f, j, margin)
    }

    /// Newton's method for the cantilever equilibrium, from `start`.
    fn solve(&self, start: Vector3<f64>, load: Vector3<f64>) -> Solve {
        let kc = self.laws.get(PairKind::TipSubstrate).stiffness_n_per_m;
        let base = self.cursor;
        let z0 = self.contact_gap();
        let tol = 1e-9 * z0;
        let mut x = start;
        for _ in 0..MAX_ITERATIONS {
            let (f, j, margin) = self.force_jacobian(x);
            if margin <= 0.0 {
                return Solve::Fold;
            }
            let m = Matrix3::identity() * kc - j;
            let Some(chol) = m.cholesky() else {
                return Solve::Fold;
            };
            let g = (base - x) * kc + f + load;
            let dx = chol.solve(&g);
            if !dx.iter().all(|v| v.is_finite()) {
                return Solve::Fold;
            }
            x += dx;
            if dx.norm() <= tol {
                let (_, j, margin) = self.force_jacobian(x);
                if margin <= 0.0 || (Matrix3::identity() * kc - j).cholesky().is_none() {
                    return Solve::Fold;
                }
                return Solve::Stable(x);
            }
        }
        Solve::Fold
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

    /// The analytic Jacobian used by Newton's method matches central differences of the
    /// force, for a tip carrying a particle near the plane and two other particles.
    #[test]
    fn jacobian_matches_central_differences() {
        let mut p = Params::physical_default();
        p.loading_zone = None;
        p.initial_atoms_xy_m = vec![[20e-9, 20e-9], [38e-9, 22e-9], [45e-9, 40e-9]];
        let mut w =
            World::new(&p, &p.default_limits(), Vector3::new(20e-9, 20e-9, 40e-9)).expect("valid");
        // Carry particle 0 below the tip with a lateral tilt.
        let tip = Vector3::new(21e-9, 19.5e-9, 33e-9);
        w.place_tip(tip);
        w.atoms[0].carried_offset = Some(Vector3::new(3e-9, 1e-9, -24.6e-9));
        w.atoms[0].on_substrate = false;
        w.carried = vec![0];
        w.place_tip(tip);
        let x = Vector3::new(24e-9, 21e-9, 33.2e-9);
        let (_, j, margin) = w.force_jacobian(x);
        assert!(margin > 0.0);
        let h = 1e-13;
        let mut worst: f64 = 0.0;
        let scale = j.abs().max();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = h;
            let (fp, _, _) = w.force_jacobian(x + e);
            let (fm, _, _) = w.force_jacobian(x - e);
            let col = (fp - fm) / (2.0 * h);
            for r in 0..3 {
                worst = worst.max((col[r] - j[(r, k)]).abs() / scale);
            }
        }
        assert!(
            scale > 0.0 && worst < 1e-6,
            "relative Jacobian error {worst:e}"
        );
    }
}
