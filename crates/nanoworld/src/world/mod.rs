//! The world state (MuJoCo's `mjData`) and the step that advances it.
//!
//! One [`World::step`] per haptic tick: the cursor position goes in; the tip moves (game
//! mode: the tip is the cursor; physical mode: the tip hangs from the cursor on a
//! cantilever spring and sits at its quasi-static equilibrium), contacts snap and break,
//! atoms spawn and transfer, and the force to render comes out with typed events.

use nalgebra::Vector3;
use world_form::Limits;

use crate::error::{ParamError, StepError};
use crate::house::{HouseChange, HouseStatus};
use crate::law::{PairKind, PairLaws};
use crate::params::{Interaction, LoadingZone, Params};
use crate::substrate::Substrate;

mod types;

pub(crate) use types::Disarm;
use types::check_position;
pub use types::{
    Anchor, BrokenLink, Event, Member, MovableAtom, StepReport, Target, TipContact, TipInput,
};

/// The nano world: parameters, derived laws, substrate and state.
#[derive(Debug, Clone)]
pub struct World {
    pub(crate) params: Params,
    /// What the device renders, in the world's units.
    pub(crate) limits: Limits,
    pub(crate) laws: PairLaws,
    pub(crate) substrate: Substrate,
    pub(crate) atoms: Vec<MovableAtom>,
    pub(crate) carried: Vec<usize>,
    pub(crate) cursor: Vector3<f64>,
    pub(crate) tip: Vector3<f64>,
    pub(crate) contact: TipContact,
    pub(crate) disarmed: Vec<Disarm>,
    pub(crate) history: [Option<Vector3<f64>>; 2],
    pub(crate) tick: u64,
    pub(crate) time_s: f64,
    pub(crate) house: HouseStatus,
}

impl World {
    /// Build a world from its parameters and the limits of the device it renders to (in the
    /// world's units: N, N/m); the tip starts free at `start_m` (m). Fails with the first
    /// out-of-range parameter or limit, naming it.
    pub fn new(
        params: &Params,
        limits: &Limits,
        start_m: Vector3<f64>,
    ) -> Result<World, ParamError> {
        params.validate()?;
        params.validate_for_device(limits)?;
        let params = params.clone();
        for (k, v) in start_m.iter().enumerate() {
            if !v.is_finite() {
                return Err(ParamError::range(
                    format!("start_m[{k}]"),
                    *v,
                    "a finite number of metres",
                ));
            }
        }
        let laws = PairLaws::from_params(&params);
        let substrate = Substrate::new(&params.substrate, substrate_reach(&params, &laws));
        let mut w = World {
            laws,
            substrate,
            atoms: Vec::new(),
            carried: Vec::new(),
            cursor: start_m,
            tip: start_m,
            contact: TipContact::Free,
            disarmed: Vec::new(),
            history: [None, None],
            tick: 0,
            time_s: 0.0,
            house: HouseStatus::new(params.house.as_ref()),
            params,
            limits: *limits,
        };
        let xy = w.params.initial_atoms_xy_m.clone();
        for a in xy {
            let p = w.rest_position(a);
            w.atoms.push(MovableAtom {
                position: p,
                carried_offset: None,
                on_substrate: true,
                bonds: Vec::new(),
            });
        }
        // Initial atoms that touch are bonded.
        let touch =
            2.0 * w.params.atoms.radius_m + w.contact_gap() + 1e-6 * w.params.atoms.radius_m;
        for i in 0..w.atoms.len() {
            for j in 0..i {
                if (w.atoms[i].position - w.atoms[j].position).norm() <= touch {
                    w.atoms[i].bonds.push(j);
                    w.atoms[j].bonds.push(i);
                }
            }
        }
        for a in &mut w.atoms {
            a.bonds.sort_unstable();
        }
        let mut ev = Vec::new();
        w.update_house(&mut ev);
        Ok(w)
    }

    /// Replace the parameters at run time. Strengths, stiffnesses, pull-off ratio, masses,
    /// gravity, inertia, loading zone and house may change; the mode and the geometry
    /// (substrate, radii, contact gap) may not, and the stiffest spring must stay within the
    /// device's limits.
    pub fn set_params(&mut self, params: Params) -> Result<(), ParamError> {
        params.validate()?;
        params.validate_for_device(&self.limits)?;
        let old = &self.params;
        if params.substrate != old.substrate {
            return Err(ParamError::NotChangeableAtRunTime { field: "substrate" });
        }
        if params.tip.radius_m != old.tip.radius_m {
            return Err(ParamError::NotChangeableAtRunTime {
                field: "tip.radius_m",
            });
        }
        if params.atoms.radius_m != old.atoms.radius_m {
            return Err(ParamError::NotChangeableAtRunTime {
                field: "atoms.radius_m",
            });
        }
        match (&params.interaction, &old.interaction) {
            (Interaction::Game(_), Interaction::Game(_)) => {}
            (Interaction::Physical(a), Interaction::Physical(b)) => {
                if a.contact_gap_m != b.contact_gap_m {
                    return Err(ParamError::NotChangeableAtRunTime {
                        field: "interaction.physical.contact_gap_m",
                    });
                }
            }
            _ => {
                return Err(ParamError::NotChangeableAtRunTime {
                    field: "interaction (game/physical mode)",
                });
            }
        }
        let laws = PairLaws::from_params(&params);
        // The cell list must cover the new reach (activation gaps may grow).
        let reach = substrate_reach(&params, &laws);
        if reach > self.substrate.cell_m() {
            self.substrate = Substrate::new(&params.substrate, reach);
        }
        self.house.reset_blueprint(params.house.as_ref());
        self.params = params;
        self.laws = laws;
        Ok(())
    }

    /// Advance one tick of length `dt_s` (s) with the cursor at `input`.
    pub fn step(&mut self, input: &TipInput, dt_s: f64) -> Result<StepReport, StepError> {
        input.check(dt_s)?;
        let mut events = Vec::new();
        self.tick += 1;
        self.time_s += dt_s;
        let prev = self.history;
        self.history = [Some(self.cursor), prev[0]];
        self.cursor = input.position_m;
        let mut load = self.load(dt_s);
        if self.contact == TipContact::Free && !self.carried.is_empty() {
            let hold = self.laws.get(PairKind::TipAtom).pull_off_n;
            if load.norm() >= hold {
                self.throw_off(load.norm(), hold, &mut events);
                load = Vector3::zeros();
            }
        }

        self.maybe_spawn(&mut events);
        if let TipContact::Anchored(a) = self.contact {
            self.maybe_release(&a, &mut events);
        }
        if self.contact == TipContact::Free {
            if self.laws.physical {
                self.free_physical(load, &mut events);
            } else {
                self.free_game(&mut events);
            }
        }
        let unlimited = match self.contact {
            TipContact::Anchored(a) => {
                self.laws.get(a.pair).stiffness_n_per_m * (a.tip_position_m - self.cursor)
            }
            TipContact::Free => {
                if self.laws.physical {
                    self.laws.get(PairKind::TipSubstrate).stiffness_n_per_m
                        * (self.tip - self.cursor)
                } else {
                    self.assembly_force_game(self.tip) + load
                }
            }
        };
        self.update_house(&mut events);
        let (force, saturated) = limit_force(unlimited, self.limits.max_force_n);
        Ok(StepReport {
            force_n: force,
            unlimited_force_n: unlimited,
            saturated,
            events,
        })
    }

    /// The attraction the tip assembly (the tip and what it carries) would feel with the tip
    /// centre at `tip_m` (m), in N, from the pair laws alone: a probe that changes nothing — no
    /// snap, no release, no tick. Game mode: the summed pair laws (what a free tip renders,
    /// less weight and inertia). Physical mode: the Hamaker forces on the tip and its carried
    /// particles (what the cantilever balances at equilibrium). Inside a snap gap the laws
    /// hold their floor value, so the result is always finite.
    pub fn force_at(&self, tip_m: Vector3<f64>) -> Result<Vector3<f64>, StepError> {
        check_position(&tip_m)?;
        Ok(if self.laws.physical {
            self.force_jacobian(tip_m).0
        } else {
            self.assembly_force_game(tip_m)
        })
    }

    /// Weight and inertial force on the carried atoms (N).
    fn load(&self, dt_s: f64) -> Vector3<f64> {
        let m = self.params.atoms.mass_kg * self.carried.len() as f64;
        if m == 0.0 {
            return Vector3::zeros();
        }
        let mut f = Vector3::new(0.0, 0.0, -m * self.params.gravity_m_per_s2);
        if self.params.inertia
            && let [Some(c1), Some(c2)] = self.history
        {
            let a = (self.cursor - 2.0 * c1 + c2) / (dt_s * dt_s);
            f -= m * a;
        }
        f
    }

    fn maybe_spawn(&mut self, events: &mut Vec<Event>) {
        let Some(zone) = self.params.loading_zone.clone() else {
            return;
        };
        if self.atoms.len() >= self.params.atoms.max_count || !in_zone(&zone, &self.cursor) {
            return;
        }
        if self
            .atoms
            .iter()
            .any(|a| !a.is_carried() && in_zone(&zone, &a.position))
        {
            return;
        }
        // The new atom must appear out of reach of every other body, so that spawning
        // never snaps anything on the tick it happens.
        let p = self.rest_position(zone.spawn_xy_m);
        let ra = self.params.atoms.radius_m;
        let clear = 2.0 * ra + self.laws.get(PairKind::AtomAtom).reach_m();
        if self.atoms.iter().any(|a| (a.position - p).norm() < clear) {
            return;
        }
        let tip_clear = self.params.tip.radius_m + ra + self.laws.get(PairKind::TipAtom).reach_m();
        if (self.tip - p).norm() < tip_clear {
            return;
        }
        self.atoms.push(MovableAtom {
            position: p,
            carried_offset: None,
            on_substrate: true,
            bonds: Vec::new(),
        });
        events.push(Event::AtomSpawned {
            atom: self.atoms.len() - 1,
        });
    }

    /// Centre of a movable atom resting on the substrate at `xy` (m).
    pub fn rest_position(&self, xy: [f64; 2]) -> Vector3<f64> {
        let r = self.params.atoms.radius_m;
        let rs = self.substrate.radius_m();
        if self.laws.physical {
            return Vector3::new(xy[0], xy[1], rs + self.contact_gap() + r);
        }
        let reach = r + rs;
        let probe = Vector3::new(xy[0], xy[1], 0.0);
        let mut z = r;
        self.substrate.for_each_within(&probe, reach, |_, q| {
            let d2 = (q.x - xy[0]).powi(2) + (q.y - xy[1]).powi(2);
            z = z.max(q.z + (reach * reach - d2).max(0.0).sqrt());
        });
        Vector3::new(xy[0], xy[1], z)
    }

    pub(crate) fn contact_gap(&self) -> f64 {
        self.laws.get(PairKind::AtomAtom).contact_gap_m
    }

    pub(crate) fn member_pos_radius(&self, m: Member) -> (Vector3<f64>, f64) {
        match m {
            Member::Tip => (self.tip, self.params.tip.radius_m),
            Member::Atom(i) => (self.atoms[i].position, self.params.atoms.radius_m),
        }
    }

    /// Members of the tip assembly: the tip, then carried atoms in ascending index order.
    pub(crate) fn members(&self) -> impl Iterator<Item = Member> + '_ {
        std::iter::once(Member::Tip).chain(self.carried.iter().map(|&i| Member::Atom(i)))
    }

    /// Move the tip and its carried atoms so the tip centre is at `p`.
    pub(crate) fn place_tip(&mut self, p: Vector3<f64>) {
        self.tip = p;
        for &i in &self.carried {
            if let Some(o) = self.atoms[i].carried_offset {
                self.atoms[i].position = p + o;
            }
        }
    }

    /// The carried atoms leave the tip (see [`Event::AtomsThrownOff`]).
    fn throw_off(&mut self, load_n: f64, pull_off_n: f64, events: &mut Vec<Event>) {
        let cluster = std::mem::take(&mut self.carried);
        let r = self.params.atoms.radius_m;
        for &c in &cluster {
            self.atoms[c].carried_offset = None;
            self.disarm(Member::Tip, Some(c));
            let p = self.atoms[c].position;
            let rest = self.rest_position([p.x, p.y]);
            let (sx, sy) = self.substrate_extent_m();
            let over = p.x >= 0.0 && p.x <= sx && p.y >= 0.0 && p.y <= sy;
            let taken = self
                .atoms
                .iter()
                .enumerate()
                .find(|(j, a)| *j != c && (a.position - rest).norm() < 2.0 * r * (1.0 - 1e-9))
                .map(|(j, _)| j);
            match taken {
                None if over => {
                    self.atoms[c].position = rest;
                    self.atoms[c].on_substrate = true;
                }
                _ => {
                    // Bonded where it is, to the nearest other atom (or, off the substrate,
                    // resting on nothing: it stays put, unbound).
                    let nearest = self
                        .atoms
                        .iter()
                        .enumerate()
                        .filter(|(j, _)| *j != c && !cluster.contains(j))
                        .min_by(|(_, a), (_, b)| {
                            (a.position - p).norm().total_cmp(&(b.position - p).norm())
                        })
                        .map(|(j, _)| j);
                    if let (Some(j), Some(_)) = (nearest, taken) {
                        for (x, y) in [(c, j), (j, c)] {
                            if !self.atoms[x].bonds.contains(&y) {
                                self.atoms[x].bonds.push(y);
                                self.atoms[x].bonds.sort_unstable();
                            }
                        }
                    }
                }
            }
        }
        events.push(Event::AtomsThrownOff {
            atoms: cluster.len(),
            load_n,
            pull_off_n,
        });
    }

    /// Extent of the substrate's atom centres, m: x and y from 0 to these.
    fn substrate_extent_m(&self) -> (f64, f64) {
        let s = &self.params.substrate;
        (
            (s.nx - 1) as f64 * s.spacing_m,
            (s.ny - 1) as f64 * s.spacing_m,
        )
    }

    /// Gap between the tip assembly and the nearest body it does not carry, m: the smallest
    /// surface-to-surface distance from the tip or a carried atom to a substrate atom (game) or
    /// the substrate plane (physical) or an uncarried movable atom. 0 in contact (never
    /// negative); the proximity sound's input.
    pub fn nearest_gap_m(&self) -> f64 {
        let mut members: Vec<(Vector3<f64>, f64)> = vec![(self.tip, self.params.tip.radius_m)];
        for &c in &self.carried {
            members.push((self.atoms[c].position, self.params.atoms.radius_m));
        }
        let rs = self.substrate.radius_m();
        let ra = self.params.atoms.radius_m;
        let mut best = f64::INFINITY;
        for (p, r) in members {
            if self.laws.physical {
                best = best.min(p.z - r - self.plane_z());
            } else {
                // The nearest lattice site under the member (the lattice is regular).
                let s = &self.params.substrate;
                let i = (p.x / s.spacing_m).round().clamp(0.0, (s.nx - 1) as f64);
                let j = (p.y / s.spacing_m).round().clamp(0.0, (s.ny - 1) as f64);
                let q = Vector3::new(i * s.spacing_m, j * s.spacing_m, 0.0);
                best = best.min((p - q).norm() - r - rs);
            }
            for a in self.atoms.iter().filter(|a| !a.is_carried()) {
                best = best.min((a.position - p).norm() - r - ra);
            }
        }
        best.max(0.0)
    }

    /// Pull-off force holding an uncarried atom where it is (N): the strongest of its bonds.
    pub(crate) fn binding(&self, i: usize) -> f64 {
        let a = &self.atoms[i];
        let mut b: f64 = 0.0;
        if a.on_substrate {
            b = b.max(self.laws.get(PairKind::AtomSubstrate).pull_off_n);
        }
        if !a.bonds.is_empty() {
            b = b.max(self.laws.get(PairKind::AtomAtom).pull_off_n);
        }
        b
    }

    // ---- read access -------------------------------------------------------------------

    /// Recompute slot fills and report the changes as events.
    pub(crate) fn update_house(&mut self, events: &mut Vec<Event>) {
        let atoms = &self.atoms;
        self.house.update(
            atoms.len(),
            |i| (!atoms[i].is_carried()).then_some(atoms[i].position),
            |c| {
                events.push(match c {
                    HouseChange::Filled(slot) => Event::SlotFilled { slot },
                    HouseChange::Emptied(slot) => Event::SlotEmptied { slot },
                    HouseChange::Complete => Event::HouseComplete,
                })
            },
        );
    }

    /// The device limits this world renders to, in the world's units.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The parameters in force.
    pub fn params(&self) -> &Params {
        &self.params
    }
    /// The derived pair laws (snap gaps, snap and pull-off forces, stiffnesses).
    pub fn laws(&self) -> &PairLaws {
        &self.laws
    }
    /// The substrate atoms.
    pub fn substrate(&self) -> &Substrate {
        &self.substrate
    }
    /// The movable atoms, by index.
    pub fn atoms(&self) -> &[MovableAtom] {
        &self.atoms
    }
    /// Indices of the carried atoms, ascending.
    pub fn carried(&self) -> &[usize] {
        &self.carried
    }
    /// Tip (apex) centre (m).
    pub fn tip_position_m(&self) -> Vector3<f64> {
        self.tip
    }
    /// Tip apex radius (m).
    pub fn tip_radius_m(&self) -> f64 {
        self.params.tip.radius_m
    }
    /// Movable atom radius (m).
    pub fn atom_radius_m(&self) -> f64 {
        self.params.atoms.radius_m
    }
    /// Last cursor position (m).
    pub fn cursor_m(&self) -> Vector3<f64> {
        self.cursor
    }
    /// The tip's contact state.
    pub fn tip_contact(&self) -> TipContact {
        self.contact
    }
    /// The pull-off force of the anchored tip's weakest link, N (`None` when the tip is free):
    /// the anchor lets go once `|k (cursor − anchor)|`, counting the pull away from the
    /// contact and the shear but not a press into it, reaches it.
    pub fn anchor_pull_off_n(&self) -> Option<f64> {
        match self.contact {
            TipContact::Anchored(a) => Some(self.weakest_link(&a).1),
            TipContact::Free => None,
        }
    }
    /// The loading zone, if any.
    pub fn loading_zone(&self) -> Option<&LoadingZone> {
        self.params.loading_zone.as_ref()
    }
    /// Blueprint slots, their fill state and the score.
    pub fn house(&self) -> &HouseStatus {
        &self.house
    }
    /// Ticks stepped so far.
    pub fn tick(&self) -> u64 {
        self.tick
    }
    /// Simulated time: the sum of all tick lengths (s).
    pub fn time_s(&self) -> f64 {
        self.time_s
    }
}

/// Largest |coordinate| of a cursor position (m): a nano world is far smaller, and with every
/// coordinate within 1 m every distance, force and norm the step computes stays finite.
pub const MAX_POSITION_M: f64 = 1.0;

/// Shortest tick (s): with positions within [`MAX_POSITION_M`] the inertial acceleration
/// (a three-sample difference over dt²) stays below 4·10¹⁸ m/s², so the force stays finite.
pub const MIN_DT_S: f64 = 1e-9;

/// `f` scaled down to magnitude `max` (N) if larger, and whether it was. The norm is taken
/// after dividing by the largest component, so it never overflows; an infinite component
/// gives a force of magnitude `max` along it (flagged), never NaN.
pub(crate) fn limit_force(f: Vector3<f64>, max: f64) -> (Vector3<f64>, bool) {
    let big = f.amax();
    if big == 0.0 || big.is_nan() {
        return (Vector3::zeros(), big.is_nan());
    }
    let unit = if big.is_infinite() {
        f.map(|v| if v.is_infinite() { v.signum() } else { 0.0 })
    } else {
        f / big
    };
    let n = unit.norm();
    if big.is_infinite() || big * n > max {
        (unit * (max / n), true)
    } else {
        (f, false)
    }
}

fn in_zone(z: &LoadingZone, p: &Vector3<f64>) -> bool {
    p.x >= z.min_xy_m[0] && p.x <= z.max_xy_m[0] && p.y >= z.min_xy_m[1] && p.y <= z.max_xy_m[1]
}

/// Largest centre distance at which anything interacts with a substrate atom (m).
fn substrate_reach(p: &Params, laws: &PairLaws) -> f64 {
    let rs = p.substrate.atom_radius_m;
    let reach = |r: f64, k: PairKind| {
        let l = laws.get(k);
        let g = if l.cutoff_gap_m.is_finite() {
            l.cutoff_gap_m
        } else {
            l.snap_gap_m
        };
        r + rs + g.max(l.snap_gap_m)
    };
    reach(p.tip.radius_m, PairKind::TipSubstrate)
        .max(reach(p.atoms.radius_m, PairKind::AtomSubstrate))
}
