//! Pair force laws derived from [`Params`]: one [`PairLaw`] per [`PairKind`].
//!
//! Every law is an attraction of magnitude f(z) along the line of centres, z being the
//! surface gap. Game mode: f = A·(1/z² − 1/w²) for z < w (the shift makes f continuous at
//! the activation gap w), 0 beyond. Physical mode: f = C/z² with C = A·R_eff/6
//! (Hamaker sphere–plane, R_eff = R, or sphere–sphere, R_eff = R₁R₂/(R₁+R₂)). Below the
//! law's floor gap (game: the snap gap, physical: z0) f is held at its floor value, so it
//! stays finite when a body sits inside another's snap gap.

use crate::params::{Interaction, Params};

/// The four pair types of the nano world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PairKind {
    /// Tip ↔ substrate.
    TipSubstrate,
    /// Tip ↔ movable atom.
    TipAtom,
    /// Movable atom ↔ movable atom.
    AtomAtom,
    /// Movable atom ↔ substrate.
    AtomSubstrate,
}

impl PairKind {
    /// All four, in a fixed order.
    pub const ALL: [PairKind; 4] = [
        PairKind::TipSubstrate,
        PairKind::TipAtom,
        PairKind::AtomAtom,
        PairKind::AtomSubstrate,
    ];

    fn index(self) -> usize {
        self as usize
    }
}

/// The derived law of one pair type (all SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLaw {
    /// Coefficient of 1/z² (N·m²): A (game) or A·R_eff/6 (physical). 0: pair off.
    pub coef_n_m2: f64,
    /// Constant subtracted inside the activation gap (N): A/w² (game), 0 (physical).
    pub shift_n: f64,
    /// Gap beyond which the force is zero (m); infinite in physical mode.
    pub cutoff_gap_m: f64,
    /// Gap below which the force is held constant (m): snap gap (game) or z0 (physical).
    pub floor_gap_m: f64,
    /// Gap at which contact snaps (m). Game: the snap gap. Physical, tip pairs: the
    /// jump-to-contact gap (A·R_eff/(3·k_c))^{1/3}; atom pairs: z0 (informational, the
    /// physical mode detects jumps from the cantilever equilibrium itself).
    pub snap_gap_m: f64,
    /// Surface gap held in contact (m): 0 (game) or z0 (physical).
    pub contact_gap_m: f64,
    /// Adhesion stiffness while in contact (N/m): k (game) or the cantilever k_c (physical).
    pub stiffness_n_per_m: f64,
    /// Force at the snap gap (N).
    pub snap_force_n: f64,
    /// Pull force that breaks the contact (N): ratio × snap force (game) or DMT 2π·R_eff·W
    /// = A·R_eff/(6·z0²) with W = A/(12π·z0²) (physical).
    pub pull_off_n: f64,
}

impl PairLaw {
    /// Attraction magnitude at surface gap `gap_m` (N), ≥ 0 and finite.
    pub fn force(&self, gap_m: f64) -> f64 {
        if self.coef_n_m2 == 0.0 || gap_m >= self.cutoff_gap_m {
            return 0.0;
        }
        let z = gap_m.max(self.floor_gap_m);
        self.coef_n_m2 / (z * z) - self.shift_n
    }

    /// −d(force)/d(gap) (N/m): how fast the attraction grows as the gap closes; 0 where
    /// the force is held or cut.
    pub fn stiffening(&self, gap_m: f64) -> f64 {
        if self.coef_n_m2 == 0.0 || gap_m >= self.cutoff_gap_m || gap_m <= self.floor_gap_m {
            return 0.0;
        }
        2.0 * self.coef_n_m2 / (gap_m * gap_m * gap_m)
    }

    /// Gap beyond which the pair is out of reach (m): the activation gap (game) or ten
    /// snap gaps, where the Hamaker force has fallen below 1 % of its snap value (physical).
    pub fn reach_m(&self) -> f64 {
        if self.cutoff_gap_m.is_finite() {
            self.cutoff_gap_m
        } else {
            10.0 * self.snap_gap_m
        }
    }

    /// Whether the pair interacts at all.
    pub fn is_on(&self) -> bool {
        self.coef_n_m2 > 0.0
    }
}

/// The four derived laws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLaws {
    laws: [PairLaw; 4],
    /// Whether these are physical-mode laws (cantilever tip) rather than game laws.
    pub physical: bool,
}

impl PairLaws {
    /// Derive the laws from valid parameters.
    pub fn from_params(p: &Params) -> Self {
        let (r_t, r_a) = (p.tip.radius_m, p.atoms.radius_m);
        match &p.interaction {
            Interaction::Game(g) => {
                let mk = |gp: &crate::params::GamePair| {
                    let shift = gp.strength_n_m2 / (gp.activation_gap_m * gp.activation_gap_m);
                    let snap_force = gp.strength_n_m2 / (gp.snap_gap_m * gp.snap_gap_m) - shift;
                    PairLaw {
                        coef_n_m2: gp.strength_n_m2,
                        shift_n: shift,
                        cutoff_gap_m: gp.activation_gap_m,
                        floor_gap_m: gp.snap_gap_m,
                        snap_gap_m: gp.snap_gap_m,
                        contact_gap_m: 0.0,
                        stiffness_n_per_m: gp.stiffness_n_per_m,
                        snap_force_n: snap_force,
                        pull_off_n: g.pull_off_ratio * snap_force,
                    }
                };
                let q = &g.pairs;
                PairLaws {
                    laws: [
                        mk(&q.tip_substrate),
                        mk(&q.tip_atom),
                        mk(&q.atom_atom),
                        mk(&q.atom_substrate),
                    ],
                    physical: false,
                }
            }
            Interaction::Physical(ph) => {
                let z0 = ph.contact_gap_m;
                let kc = ph.cantilever_stiffness_n_per_m;
                let mk = |a: f64, r_eff: f64, tip: bool| {
                    let coef = a * r_eff / 6.0;
                    let snap_gap = if tip {
                        (a * r_eff / (3.0 * kc)).cbrt().max(z0)
                    } else {
                        z0
                    };
                    PairLaw {
                        coef_n_m2: coef,
                        shift_n: 0.0,
                        cutoff_gap_m: f64::INFINITY,
                        floor_gap_m: z0,
                        snap_gap_m: snap_gap,
                        contact_gap_m: z0,
                        stiffness_n_per_m: kc,
                        snap_force_n: coef / (snap_gap * snap_gap),
                        pull_off_n: coef / (z0 * z0),
                    }
                };
                let h = &ph.hamaker_j;
                PairLaws {
                    laws: [
                        mk(h.tip_substrate, r_t, true),
                        mk(h.tip_atom, r_t * r_a / (r_t + r_a), true),
                        mk(h.atom_atom, r_a / 2.0, false),
                        mk(h.atom_substrate, r_a, false),
                    ],
                    physical: true,
                }
            }
        }
    }

    /// The law of one pair type.
    pub fn get(&self, kind: PairKind) -> &PairLaw {
        &self.laws[kind.index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The game law is continuous at the activation gap, equals the snap force at the snap
    /// gap, is held there below it, and its stiffening is minus its derivative.
    #[test]
    fn game_law_shape() {
        let laws = PairLaws::from_params(&Params::game_default());
        for k in PairKind::ALL {
            let l = laws.get(k);
            let w = l.cutoff_gap_m;
            assert!(l.force(w * (1.0 - 1e-12)) < 1e-9 * l.snap_force_n);
            assert_eq!(l.force(w), 0.0);
            assert_eq!(l.force(l.snap_gap_m), l.snap_force_n);
            assert_eq!(l.force(0.5 * l.snap_gap_m), l.snap_force_n);
            assert_eq!(l.force(-1.0), l.snap_force_n);
            let z = 0.3e-9;
            let h = 1e-16;
            let numeric = -(l.force(z + h) - l.force(z - h)) / (2.0 * h);
            assert!((numeric - l.stiffening(z)).abs() < 1e-6 * l.stiffening(z));
        }
    }

    /// Physical pull-off is DMT 2π·R_eff·W with W = A/(12π·z0²).
    #[test]
    fn physical_pull_off_is_dmt() {
        let p = Params::physical_default();
        let laws = PairLaws::from_params(&p);
        let Interaction::Physical(ph) = &p.interaction else {
            unreachable!("physical default")
        };
        let z0 = ph.contact_gap_m;
        let (rt, ra) = (p.tip.radius_m, p.atoms.radius_m);
        let cases = [
            (PairKind::TipSubstrate, ph.hamaker_j.tip_substrate, rt),
            (
                PairKind::TipAtom,
                ph.hamaker_j.tip_atom,
                rt * ra / (rt + ra),
            ),
            (PairKind::AtomAtom, ph.hamaker_j.atom_atom, ra / 2.0),
            (PairKind::AtomSubstrate, ph.hamaker_j.atom_substrate, ra),
        ];
        for (k, a, r_eff) in cases {
            let w_adh = a / (12.0 * std::f64::consts::PI * z0 * z0);
            let dmt = 2.0 * std::f64::consts::PI * r_eff * w_adh;
            let l = laws.get(k);
            assert!((l.pull_off_n - dmt).abs() < 1e-14 * dmt, "{k:?}");
            assert_eq!(l.contact_gap_m, z0);
        }
    }
}
