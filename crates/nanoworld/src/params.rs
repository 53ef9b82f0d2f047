//! World parameters: what never changes during a step (MuJoCo's `mjModel`).
//!
//! Every field is SI. [`Params`] deserializes from a TOML table with
//! `deny_unknown_fields`; [`Params::validate`] returns a typed error naming the
//! field and its allowed range. Interaction strengths, masses and gravity may change at run
//! time through [`crate::World::set_params`]; geometry (substrate, radii, initial atoms) may
//! not. The largest force and stiffness the device renders are not parameters: they are the
//! device's [`Limits`], handed to [`crate::World::new`] ([`Params::validate_for_device`]).

use serde::{Deserialize, Serialize};
use world_form::{Limits, fmt_num};

use crate::error::ParamError;

/// Largest substrate the world accepts (atoms).
pub const MAX_SUBSTRATE_ATOMS: usize = 4_000_000;
/// Largest number of movable atoms the world accepts.
pub const MAX_MOVABLE_ATOMS: usize = 100_000;

/// The Novint Falcon ([`Limits::FALCON`]: 8 N, 3000 N/m) as `scenes/nanoworld.toml` maps it
/// into the game world (1 nN ↔ 1 N, `force_scale` 1e9; 0.15 nm ↔ 1 mm, `workspace_scale`
/// 1.5e-7): 8 nN and 3000 / (1e9 · 1.5e-7) = 20 N/m. The limits to build a
/// [`Params::game_default`] world with when no device mapping is at hand.
pub const GAME_FALCON_LIMITS: Limits = Limits {
    max_force_n: 8e-9,
    max_stiffness_n_per_m: 20.0,
};

/// The Novint Falcon mapped into the physical world (10 pN ↔ 1 mN: `force_scale` 1e8; 1 nm ↔
/// 1 mm, `workspace_scale` 1e-6): 80 nN and 3000 / (1e8 · 1e-6) = 30 N/m, above the
/// preset's 4.7 N/m cantilever. For [`Params::physical_default`].
pub const PHYSICAL_FALCON_LIMITS: Limits = Limits {
    max_force_n: 8e-8,
    max_stiffness_n_per_m: 30.0,
};

/// All parameters of a nano world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ParamsTable")]
pub struct Params {
    /// The fixed (teal) substrate layer.
    pub substrate: SubstrateParams,
    /// The AFM tip apex (the cursor).
    pub tip: TipParams,
    /// The movable (orange) atoms.
    pub atoms: AtomParams,
    /// Force laws: the teaching game's or real constants.
    pub interaction: Interaction,
    /// Gravitational acceleration along −z (m/s²); 0 switches weight off. Range [0, 1000].
    #[serde(default)]
    pub gravity_m_per_s2: f64,
    /// Include the inertial force −m·a of carried atoms (a from the last three cursor positions).
    #[serde(default)]
    pub inertia: bool,
    /// Where new movable atoms appear; `None` switches spawning off.
    #[serde(default)]
    pub loading_zone: Option<LoadingZone>,
    /// Movable atoms present at the start, resting on the substrate at these (x, y) (m).
    #[serde(default)]
    #[serde(deserialize_with = "world_form::exact::vec_of_arrays")]
    pub initial_atoms_xy_m: Vec<[f64; 2]>,
    /// The house blueprint; `None` switches scoring off.
    #[serde(default)]
    pub house: Option<HouseParams>,
}

/// The `[nanoworld.params]` table as written: [`Params`] plus the removed `max_force_n`, so
/// that an old file that still sets it gets [`ParamError::MovedToDevice`] rather than
/// "unknown field".
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamsTable {
    /// The fixed (teal) substrate layer.
    substrate: SubstrateParams,
    /// The AFM tip apex (the cursor).
    tip: TipParams,
    /// The movable (orange) atoms.
    atoms: AtomParams,
    /// Force laws: the teaching game's or real constants.
    interaction: Interaction,
    /// Gravitational acceleration along −z (m/s²); 0 switches weight off. Range [0, 1000].
    #[serde(default)]
    #[serde(alias = "gravity_m_s2")]
    gravity_m_per_s2: f64,
    /// Include the inertial force −m·a of carried atoms (a from the last three cursor positions).
    #[serde(default)]
    inertia: bool,
    /// Where new movable atoms appear; `None` switches spawning off.
    #[serde(default)]
    loading_zone: Option<LoadingZone>,
    /// Movable atoms present at the start, resting on the substrate at these (x, y) (m).
    #[serde(default)]
    #[serde(deserialize_with = "world_form::exact::vec_of_arrays")]
    initial_atoms_xy_m: Vec<[f64; 2]>,
    /// The house blueprint; `None` switches scoring off.
    #[serde(default)]
    house: Option<HouseParams>,
    /// Removed (the device's [`Limits::max_force_n`] replaces it); refused when present.
    #[serde(default)]
    max_force_n: Option<serde::de::IgnoredAny>,
}

impl TryFrom<ParamsTable> for Params {
    type Error = ParamError;

    fn try_from(t: ParamsTable) -> Result<Params, ParamError> {
        if t.max_force_n.is_some() {
            return Err(ParamError::MovedToDevice {
                field: "max_force_n",
            });
        }
        Ok(Params {
            substrate: t.substrate,
            tip: t.tip,
            atoms: t.atoms,
            interaction: t.interaction,
            gravity_m_per_s2: t.gravity_m_per_s2,
            inertia: t.inertia,
            loading_zone: t.loading_zone,
            initial_atoms_xy_m: t.initial_atoms_xy_m,
            house: t.house,
        })
    }
}

/// A square lattice of fixed substrate atoms with centres at z = 0,
/// at (i·spacing, j·spacing) for 0 ≤ i < nx, 0 ≤ j < ny.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SubstrateParams {
    /// Atoms along x. Range [1, 4·10⁶], nx·ny ≤ 4·10⁶.
    pub nx: usize,
    /// Atoms along y. Range [1, 4·10⁶], nx·ny ≤ 4·10⁶.
    pub ny: usize,
    /// Lattice spacing (m). Range (0, 1e-6].
    pub spacing_m: f64,
    /// Substrate atom radius (m). Range (0, spacing_m].
    pub atom_radius_m: f64,
}

/// The AFM tip apex, a sphere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TipParams {
    /// Apex radius (m). Range (0, 1e-6].
    pub radius_m: f64,
}

/// The movable atoms (in physical mode: nanoparticles), spheres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtomParams {
    /// Radius (m). Range (0, 1e-6].
    pub radius_m: f64,
    /// Mass of one atom (kg). Range [0, 1]; felt only through gravity and inertia.
    pub mass_kg: f64,
    /// Most movable atoms that may exist; spawning stops there. Range [0, 10⁵].
    pub max_count: usize,
}

/// Axis-aligned rectangle in the substrate plane; while the tip is above it and no
/// uncarried atom lies in it, one atom appears resting at `spawn_xy_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingZone {
    /// Lower corner (x, y) (m).
    #[serde(deserialize_with = "world_form::exact::array")]
    pub min_xy_m: [f64; 2],
    /// Upper corner (x, y) (m); each component > the lower one.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub max_xy_m: [f64; 2],
    /// Where a new atom appears (x, y) (m); inside the zone and over the substrate.
    #[serde(deserialize_with = "world_form::exact::array")]
    pub spawn_xy_m: [f64; 2],
}

/// The house blueprint: slots that must each hold an uncarried movable atom.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HouseParams {
    /// Slot centres (m).
    #[serde(deserialize_with = "world_form::exact::vec_of_arrays")]
    pub slots_m: Vec<[f64; 3]>,
    /// An atom fills a slot when its centre is within this distance (m). Range (0, 1e-6].
    pub tolerance_m: f64,
}

/// Which force laws the world uses.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "snake_case")]
pub enum Interaction {
    /// The teaching game's laws: F = A/z² inside an activation gap, snap inside a snap gap,
    /// adhesion F = k·z in contact, release at `pull_off_ratio` × the snap force.
    Game(GameParams),
    /// Real constants: Hamaker sphere–plane / sphere–sphere attraction, jump-to-contact where
    /// the force gradient exceeds the cantilever stiffness, DMT pull-off 2πR_eff·W.
    Physical(PhysicalParams),
}

/// One value per pair of body types.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pairs<T> {
    /// Tip ↔ substrate atom (physical mode: tip ↔ substrate plane).
    pub tip_substrate: T,
    /// Tip ↔ movable atom.
    pub tip_atom: T,
    /// Movable atom ↔ movable atom.
    pub atom_atom: T,
    /// Movable atom ↔ substrate atom (physical mode: ↔ substrate plane).
    pub atom_substrate: T,
}

/// Game-mode parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GameParams {
    /// Pull-off force over snap force (the paper: 10). Range [1, 1000].
    pub pull_off_ratio: f64,
    /// Per-pair laws.
    pub pairs: Pairs<GamePair>,
}

/// Game-mode law of one pair type. Surface gap z = centre distance − radii.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GamePair {
    /// A in F = A·(1/z² − 1/w²) (N·m²); 0 switches the pair off. Range [0, 1e-20].
    pub strength_n_m2: f64,
    /// Activation gap w (m): no force beyond it. Range (snap_gap_m, 1e-6].
    pub activation_gap_m: f64,
    /// Snap gap z_s (m): contact snaps inside it. Range (0, activation_gap_m).
    pub snap_gap_m: f64,
    /// Adhesion stiffness k in F = k·z while in contact (N/m). Range (0, 1e6] and below
    /// [`GamePair::max_stiffness_n_per_m`] = pull_off_ratio × snap force / snap gap, so that
    /// the contact holds after it snaps (the approach–retract hysteresis).
    pub stiffness_n_per_m: f64,
}

/// Physical-mode parameters (real constants).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicalParams {
    /// Hamaker constant per pair (J); 0 switches the pair off. Range [0, 1e-17].
    pub hamaker_j: Pairs<f64>,
    /// Contact (intermolecular cut-off) gap z0 (m), typically 0.165 nm. Range (0, 1e-8].
    pub contact_gap_m: f64,
    /// Cantilever spring constant k_c (N/m) between the cursor (cantilever base) and the tip.
    /// Range (0, 1e4].
    pub cantilever_stiffness_n_per_m: f64,
}

impl PhysicalParams {
    /// Cantilever stiffness k_c = A·R/(3·ratio^{3/2}·z0³) (N/m) for which a sphere–plane
    /// contact of Hamaker constant `hamaker_j` (J) and radius `radius_m` (m) pulls off at
    /// `ratio` × its jump-to-contact force. For ratio 10 this is A·R/(94.87·z0³) ≈ A·R/(95·z0³).
    pub fn stiffness_for_pull_off_ratio(
        hamaker_j: f64,
        radius_m: f64,
        contact_gap_m: f64,
        ratio: f64,
    ) -> f64 {
        hamaker_j * radius_m / (3.0 * ratio.powf(1.5) * contact_gap_m.powi(3))
    }
}

fn check(
    field: &str,
    value: f64,
    ok: bool,
    allowed: impl FnOnce() -> String,
) -> Result<(), ParamError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ParamError::range(field, value, allowed()))
    }
}

fn positive_up_to(field: &str, value: f64, max: f64) -> Result<(), ParamError> {
    check(field, value, value > 0.0 && value <= max, || {
        format!("0 < value <= {}", fmt_num(max))
    })
}

fn nonneg_up_to(field: &str, value: f64, max: f64) -> Result<(), ParamError> {
    check(field, value, (0.0..=max).contains(&value), || {
        format!("0 <= value <= {}", fmt_num(max))
    })
}

/// `v` rounded to six significant digits, in the one number form of errors
/// ([`world_form::fmt_sig`]): a derived bound reads `20`, not `19.999999999999996`.
fn short(v: f64) -> String {
    world_form::fmt_sig(v, 6)
}

fn finite(field: &str, value: f64) -> Result<(), ParamError> {
    check(field, value, true, || "a finite number".to_string())
}

impl GamePair {
    /// Force at the snap gap (N): A·(1/z_s² − 1/w²).
    pub fn snap_force_n(&self) -> f64 {
        self.strength_n_m2 / (self.snap_gap_m * self.snap_gap_m)
            - self.strength_n_m2 / (self.activation_gap_m * self.activation_gap_m)
    }

    /// Largest adhesion stiffness (N/m, exclusive) that keeps the hysteresis: a contact
    /// snaps with the cursor one snap gap from the anchor, so the spring pulls k·z_s at once;
    /// it must stay below the pull-off force `pull_off_ratio` × snap force.
    pub fn max_stiffness_n_per_m(&self, pull_off_ratio: f64) -> f64 {
        pull_off_ratio * self.snap_force_n() / self.snap_gap_m
    }

    fn validate(&self, prefix: &str, pull_off_ratio: f64) -> Result<(), ParamError> {
        nonneg_up_to(
            &format!("{prefix}.strength_n_m2"),
            self.strength_n_m2,
            1e-20,
        )?;
        positive_up_to(
            &format!("{prefix}.activation_gap_m"),
            self.activation_gap_m,
            1e-6,
        )?;
        let w = self.activation_gap_m;
        check(
            &format!("{prefix}.snap_gap_m"),
            self.snap_gap_m,
            self.snap_gap_m > 0.0 && self.snap_gap_m < w,
            || format!("0 < value < activation_gap_m = {}", fmt_num(w)),
        )?;
        positive_up_to(
            &format!("{prefix}.stiffness_n_per_m"),
            self.stiffness_n_per_m,
            1e6,
        )?;
        if self.strength_n_m2 > 0.0 {
            let bound = self.max_stiffness_n_per_m(pull_off_ratio);
            check(
                &format!("{prefix}.stiffness_n_per_m"),
                self.stiffness_n_per_m,
                self.stiffness_n_per_m < bound,
                || {
                    format!(
                        "0 < value < pull_off_ratio * snap force / snap_gap_m = {} N/m \
                         (stiffer contacts release on the tick after they snap)",
                        short(bound)
                    )
                },
            )?;
        }
        Ok(())
    }
}

impl<T> Pairs<T> {
    /// The four pair types with their field names, in declaration order.
    pub(crate) fn named(&self) -> [(&'static str, &T); 4] {
        [
            ("tip_substrate", &self.tip_substrate),
            ("tip_atom", &self.tip_atom),
            ("atom_atom", &self.atom_atom),
            ("atom_substrate", &self.atom_substrate),
        ]
    }
}

/// The part of the plane a coordinate must lie in: over the substrate's atoms, `0..=x_max_m`
/// and `0..=y_max_m` (m).
#[derive(Clone, Copy)]
struct SubstrateExtent {
    /// Largest x of a substrate atom, m.
    x_max_m: f64,
    /// Largest y of a substrate atom, m.
    y_max_m: f64,
}

impl SubstrateExtent {
    /// Whether coordinate `k` (0: x, 1: y) of value `v` (m) is over the substrate. One axis at
    /// a time, so that the error names the component that is out of range.
    fn over_axis(self, v: f64, k: usize) -> bool {
        v >= 0.0 && v <= if k == 0 { self.x_max_m } else { self.y_max_m }
    }

    /// The allowed range, as an error message says it.
    fn range(self) -> String {
        format!(
            "inside the substrate, 0..={} x 0..={} m",
            fmt_num(self.x_max_m),
            fmt_num(self.y_max_m)
        )
    }
}

impl Params {
    /// Check every field; the first violation is returned, naming the field and its range.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.validate_bodies()?;
        self.validate_interaction()?;
        let s = &self.substrate;
        let ext = SubstrateExtent {
            x_max_m: (s.nx - 1) as f64 * s.spacing_m,
            y_max_m: (s.ny - 1) as f64 * s.spacing_m,
        };
        self.validate_loading_zone(ext)?;
        self.validate_initial_atoms(ext)?;
        self.validate_house()
    }

    /// The substrate, the tip, the movable atoms and gravity.
    fn validate_bodies(&self) -> Result<(), ParamError> {
        let s = &self.substrate;
        check("substrate.nx", s.nx as f64, s.nx >= 1, || {
            format!("1 <= nx, nx*ny <= {MAX_SUBSTRATE_ATOMS}")
        })?;
        check("substrate.ny", s.ny as f64, s.ny >= 1, || {
            format!("1 <= ny, nx*ny <= {MAX_SUBSTRATE_ATOMS}")
        })?;
        let n = s.nx.saturating_mul(s.ny);
        check(
            "substrate.nx*ny",
            n as f64,
            n <= MAX_SUBSTRATE_ATOMS,
            || format!("1 <= nx*ny <= {MAX_SUBSTRATE_ATOMS}"),
        )?;
        positive_up_to("substrate.spacing_m", s.spacing_m, 1e-6)?;
        positive_up_to("substrate.atom_radius_m", s.atom_radius_m, s.spacing_m)?;
        positive_up_to("tip.radius_m", self.tip.radius_m, 1e-6)?;
        positive_up_to("atoms.radius_m", self.atoms.radius_m, 1e-6)?;
        nonneg_up_to("atoms.mass_kg", self.atoms.mass_kg, 1.0)?;
        check(
            "atoms.max_count",
            self.atoms.max_count as f64,
            self.atoms.max_count <= MAX_MOVABLE_ATOMS,
            || format!("0 <= value <= {MAX_MOVABLE_ATOMS}"),
        )?;
        nonneg_up_to("gravity_m_per_s2", self.gravity_m_per_s2, 1000.0)
    }

    /// The interaction: game mode's pull-off ratio and pair laws, or physical mode's Hamaker
    /// constants, contact gap and cantilever.
    fn validate_interaction(&self) -> Result<(), ParamError> {
        match &self.interaction {
            Interaction::Game(g) => {
                check(
                    "interaction.game.pull_off_ratio",
                    g.pull_off_ratio,
                    (1.0..=1000.0).contains(&g.pull_off_ratio),
                    || "1 <= value <= 1000".to_string(),
                )?;
                for (name, pair) in g.pairs.named() {
                    pair.validate(&format!("interaction.game.pairs.{name}"), g.pull_off_ratio)?;
                }
            }
            Interaction::Physical(p) => {
                let pre = "interaction.physical.hamaker_j";
                for (name, &a) in p.hamaker_j.named() {
                    nonneg_up_to(&format!("{pre}.{name}"), a, 1e-17)?;
                }
                positive_up_to("interaction.physical.contact_gap_m", p.contact_gap_m, 1e-8)?;
                positive_up_to(
                    "interaction.physical.cantilever_stiffness_n_per_m",
                    p.cantilever_stiffness_n_per_m,
                    1e4,
                )?;
            }
        }
        Ok(())
    }

    /// The loading zone: a box per axis, its spawn point inside it and over the substrate.
    fn validate_loading_zone(&self, ext: SubstrateExtent) -> Result<(), ParamError> {
        let Some(z) = &self.loading_zone else {
            return Ok(());
        };
        for k in 0..2 {
            finite(&format!("loading_zone.min_xy_m[{k}]"), z.min_xy_m[k])?;
            let lo = z.min_xy_m[k];
            check(
                &format!("loading_zone.max_xy_m[{k}]"),
                z.max_xy_m[k],
                z.max_xy_m[k] > lo,
                || format!("value > min_xy_m[{k}] = {}", fmt_num(lo)),
            )?;
            let hi = z.max_xy_m[k];
            check(
                &format!("loading_zone.spawn_xy_m[{k}]"),
                z.spawn_xy_m[k],
                z.spawn_xy_m[k] >= lo && z.spawn_xy_m[k] <= hi && ext.over_axis(z.spawn_xy_m[k], k),
                || {
                    format!(
                        "inside the zone [{}, {}] and {}",
                        fmt_num(lo),
                        fmt_num(hi),
                        ext.range()
                    )
                },
            )?;
        }
        Ok(())
    }

    /// The initial movable atoms: how many, over the substrate, and not overlapping.
    fn validate_initial_atoms(&self, ext: SubstrateExtent) -> Result<(), ParamError> {
        check(
            "initial_atoms_xy_m.len()",
            self.initial_atoms_xy_m.len() as f64,
            self.initial_atoms_xy_m.len() <= self.atoms.max_count,
            || format!("at most atoms.max_count = {}", self.atoms.max_count),
        )?;
        let min_sep = 2.0 * self.atoms.radius_m * (1.0 - 1e-9);
        for (i, a) in self.initial_atoms_xy_m.iter().enumerate() {
            for (k, &c) in a.iter().enumerate() {
                check(
                    &format!("initial_atoms_xy_m[{i}][{k}]"),
                    c,
                    ext.over_axis(c, k),
                    || ext.range(),
                )?;
            }
            for (j, b) in self.initial_atoms_xy_m[..i].iter().enumerate() {
                let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
                check(&format!("initial_atoms_xy_m[{i}]"), d, d >= min_sep, || {
                    format!(
                        "distance to initial_atoms_xy_m[{j}] >= 2*atoms.radius_m = {} m",
                        world_form::numbers::fmt_num(2.0 * self.atoms.radius_m)
                    )
                })?;
            }
        }
        Ok(())
    }

    /// The house: its tolerance and finite slots.
    fn validate_house(&self) -> Result<(), ParamError> {
        if let Some(h) = &self.house {
            positive_up_to("house.tolerance_m", h.tolerance_m, 1e-6)?;
            for (i, s) in h.slots_m.iter().enumerate() {
                for (k, v) in s.iter().enumerate() {
                    finite(&format!("house.slots_m[{i}][{k}]"), *v)?;
                }
            }
        }
        Ok(())
    }

    /// The stiffest spring the world renders, N/m, and the field that sets it: the largest
    /// game-mode adhesion stiffness `k` (over the pair types), or the physical-mode cantilever
    /// stiffness `k_c`.
    pub fn max_render_stiffness(&self) -> (String, f64) {
        match &self.interaction {
            Interaction::Game(g) => {
                let pairs = g.pairs.named().map(|(name, p)| (name, p.stiffness_n_per_m));
                let (name, k) =
                    pairs.iter().fold(
                        ("tip_substrate", 0.0),
                        |a, b| if b.1 > a.1 { *b } else { a },
                    );
                (
                    format!("interaction.game.pairs.{name}.stiffness_n_per_m"),
                    k,
                )
            }
            Interaction::Physical(ph) => (
                "interaction.physical.cantilever_stiffness_n_per_m".to_string(),
                ph.cantilever_stiffness_n_per_m,
            ),
        }
    }

    /// Checks what depends on the device: the limits themselves (named `device.max_force_n`,
    /// `device.max_stiffness_n_per_m`) and that the stiffest spring the world renders
    /// ([`Params::max_render_stiffness`]) is within [`Limits::max_stiffness_n_per_m`].
    pub fn validate_for_device(&self, limits: &Limits) -> Result<(), ParamError> {
        limits.validate().map_err(|e| {
            ParamError::Value(e.map_field(|f| format!("device.{}", f.trim_matches('`'))))
        })?;
        let (field, k) = self.max_render_stiffness();
        let cap = limits.max_stiffness_n_per_m;
        check(&field, k, k <= cap, || {
            format!(
                "<= {} N/m, the device's stiffness limit in the world",
                short(cap)
            )
        })
    }

    /// The Falcon mapped as the preset scenes map it: [`GAME_FALCON_LIMITS`] in game mode,
    /// [`PHYSICAL_FALCON_LIMITS`] in physical mode (for a world built without a device).
    pub fn default_limits(&self) -> Limits {
        match self.interaction {
            Interaction::Game(_) => GAME_FALCON_LIMITS,
            Interaction::Physical(_) => PHYSICAL_FALCON_LIMITS,
        }
    }

    /// The teaching game with the paper's behaviour, in nanometre-sized SI values:
    /// a 40 × 40 substrate (0.3 nm spacing), 0.3 nm tip, 0.15 nm atoms, snap force 0.3 nN
    /// for tip pairs, pull-off 10×, atom–atom bonds twice and atom–substrate bonds half as
    /// strong as tip–atom ones (the paper's ordering), a loading zone, a row of five
    /// foundation atoms and a seven-slot house (three columns, the middle one higher).
    pub fn game_default() -> Self {
        let a = 0.3e-9;
        let snap = 0.15e-9;
        let w = 0.6e-9;
        // A such that A·(1/z_s² − 1/w²) = 0.3 nN.
        let a_tip = 0.3e-9 / (1.0 / (snap * snap) - 1.0 / (w * w));
        let pair = |scale: f64| GamePair {
            strength_n_m2: a_tip * scale,
            activation_gap_m: w,
            snap_gap_m: snap,
            stiffness_n_per_m: 2.0,
        };
        let r = 0.15e-9;
        let hollow = |i: usize, j: usize| [(i as f64 + 0.5) * a, (j as f64 + 0.5) * a];
        let rest_z = ((2.0 * r) * (2.0 * r) - 2.0 * (a / 2.0) * (a / 2.0)).sqrt();
        let foundation: Vec<[f64; 2]> = (16..21).map(|i| hollow(i, 20)).collect();
        let above = |xy: [f64; 2], level: f64| [xy[0], xy[1], rest_z + level * 2.0 * r];
        Params {
            substrate: SubstrateParams {
                nx: 40,
                ny: 40,
                spacing_m: a,
                atom_radius_m: 0.15e-9,
            },
            tip: TipParams { radius_m: 0.3e-9 },
            atoms: AtomParams {
                radius_m: r,
                mass_kg: 1.0e-25,
                max_count: 64,
            },
            interaction: Interaction::Game(GameParams {
                pull_off_ratio: 10.0,
                pairs: Pairs {
                    tip_substrate: pair(1.0),
                    tip_atom: pair(1.0),
                    atom_atom: pair(2.0),
                    atom_substrate: pair(0.5),
                },
            }),
            gravity_m_per_s2: 9.81,
            inertia: true,
            loading_zone: Some(LoadingZone {
                min_xy_m: [1.0e-9, 1.0e-9],
                max_xy_m: [3.0e-9, 3.0e-9],
                spawn_xy_m: hollow(6, 6),
            }),
            house: Some(HouseParams {
                // Three columns one atom apart (windows between them), the middle one
                // higher: a gable. Columns are 0.6 nm apart, so a descending atom always
                // meets the atom below its slot before any neighbour.
                slots_m: vec![
                    above(foundation[0], 1.0),
                    above(foundation[2], 1.0),
                    above(foundation[4], 1.0),
                    above(foundation[0], 2.0),
                    above(foundation[2], 2.0),
                    above(foundation[4], 2.0),
                    above(foundation[2], 3.0),
                ],
                tolerance_m: 0.05e-9,
            }),
            initial_atoms_xy_m: foundation,
        }
    }

    /// Real constants: A = 1e-19 J tip–substrate, 20 nm tip, 5 nm gold-like particles
    /// (A = 2e-19 J to the tip, 4e-19 J to each other, 1e-19 J to the substrate), z0 = 0.165 nm,
    /// and the cantilever k_c = A·R/(95·z0³) ≈ 4.7 N/m that gives the paper's tenfold pull-off.
    pub fn physical_default() -> Self {
        let mut p = Self::game_default();
        let (a_ts, r_tip, z0) = (1e-19, 20e-9, 0.165e-9);
        p.tip.radius_m = r_tip;
        p.atoms.radius_m = 5e-9;
        p.atoms.mass_kg = 1.0e-21;
        p.interaction = Interaction::Physical(PhysicalParams {
            hamaker_j: Pairs {
                tip_substrate: a_ts,
                tip_atom: 2e-19,
                atom_atom: 4e-19,
                atom_substrate: 1e-19,
            },
            contact_gap_m: z0,
            cantilever_stiffness_n_per_m: a_ts * r_tip / (95.0 * z0 * z0 * z0),
        });
        p.substrate.nx = 200;
        p.substrate.ny = 200;
        p.loading_zone = Some(LoadingZone {
            min_xy_m: [5e-9, 5e-9],
            max_xy_m: [20e-9, 20e-9],
            spawn_xy_m: [12e-9, 12e-9],
        });
        p.initial_atoms_xy_m = Vec::new();
        p.house = None;
        p
    }
}
