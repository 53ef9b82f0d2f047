//! The nano world (crate `nanoworld`) as a scene: AFM tip on the cursor, van der Waals
//! attraction, snap-to-contact, tenfold pull-off, atom transfer, house blueprint.
//!
//! A thin adapter: the world's own [`nanoworld::Params`] come from the scene file (a preset or
//! a full table), the world is created at the first tick with the tip at the cursor, and each
//! tick calls [`nanoworld::World::step`]. Its typed events become `nano.*` events (detail:
//! the event's fields).
//!
//! Limits: the world is built with the device's limits mapped to the world
//! ([`super::LoopConfig::world_limits`]); it scales its force down to their largest force, and
//! refuses a stiffest spring ([`nanoworld::Params::max_render_stiffness`]: the largest
//! game-mode adhesion `k`, or the physical-mode cantilever `k_c`) beyond their stiffness —
//! checked when the scene loads, with a hint at the mapping (lower `mapping.force_scale` or
//! `mapping.workspace_scale`). Each tick the scene reports the adhesion `k` of the anchored
//! contact (game mode) or `k_c` (physical).

use super::score::{self, HouseScore};
use super::{WorldKind, world_table};
use haptic_engine::check::{SceneError, check_positive, out_of_range, out_of_range_text};
use haptic_engine::scene::Scene;
use haptic_engine::scene::SceneInput;
use haptic_engine::scene::SceneOutput;
use haptic_types::Event;
use haptic_types::Rgba;
use haptic_types::SwitchSpec;
use haptic_types::vec3::Vec3;
use haptic_types::{Ball, OrientedBox, Primitive};
use nalgebra::Vector3;
use nanoworld::{BodyKind, Interaction, Params, TipContact, TipInput, World};
use serde::Deserialize;
use world_form::Limits;
use world_form::fmt_num;

/// The nano world in the scene registry: `kind = "nanoworld"`, table `[nanoworld]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "nanoworld",
    check: |text| super::table::pick::<NanoSection>(text, "nanoworld").map(drop),
    build: |text, config| {
        let p: NanoSection = world_table(text, "nanoworld")?;
        let scene = NanoScene::new(p, &config.world_limits(), config.dt_s())?;
        Ok(Box::new(scene))
    },
};

/// `[nanoworld]`: a preset or a full parameter table.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct NanoSection {
    /// `game` (the paper's laws) or `physical` (real constants).
    #[serde(default)]
    pub preset: Option<String>,
    /// Full world parameters (instead of a preset).
    #[serde(default)]
    pub params: Option<Params>,
    /// Substrate atoms are drawn within this distance of the tip, m (default 1.5 nm).
    #[serde(default = "default_draw_radius")]
    pub draw_radius_m: f64,
}

fn default_draw_radius() -> f64 {
    1.5e-9
}

/// The nano-world scene.
pub struct NanoScene {
    /// The parameters in force (the scene file's, with the switches applied).
    params: Params,
    /// The device's limits mapped to the world.
    limits: Limits,
    /// The scene file's parameters (switch scales apply to these).
    base: Params,
    /// Strength scales: all pairs, then tip–substrate, tip–atom, atom–atom, atom–substrate.
    scales: [f64; 5],
    world: Option<World>,
    dt_s: f64,
    draw_radius_m: f64,
    saturated: bool,
    force_n: Vec3,
    score: HouseScore,
}

/// The nano world's switches (the paper's menu: pair strengths and masses; gravity and
/// inertia too). A strength scale multiplies the scene file's pair strength A (game) or
/// Hamaker constant (physical); below 1 it also scales the game's adhesion stiffness k, so that
/// the contact still holds after it snaps (k must stay below pull_off_ratio × snap force / snap
/// gap, which scales with A).
pub const NANO_SWITCHES: [SwitchSpec; 8] = [
    SwitchSpec::number("adhesion_scale", 0.0, 10.0, "every pair strength × this"),
    SwitchSpec::number(
        "tip_substrate_scale",
        0.0,
        10.0,
        "tip–substrate strength × this",
    ),
    SwitchSpec::number("tip_atom_scale", 0.0, 10.0, "tip–atom strength × this"),
    SwitchSpec::number("atom_atom_scale", 0.0, 10.0, "atom–atom strength × this"),
    SwitchSpec::number(
        "atom_substrate_scale",
        0.0,
        10.0,
        "atom–substrate strength × this",
    ),
    SwitchSpec::number("atom_mass_kg", 0.0, 1.0, "mass of every movable atom, kg"),
    SwitchSpec::number("gravity_m_per_s2", 0.0, 1000.0, "gravity, m/s² (0: off)")
        .or_old_name("gravity_m_s2"),
    SwitchSpec::on_off("inertia", "the carried atoms' inertial force −m a"),
];

/// `base` with the strength `scales` applied (see [`NANO_SWITCHES`]).
fn scaled(base: &Params, scales: [f64; 5]) -> Params {
    let mut p = base.clone();
    let s = |k: usize| scales[0] * scales[k];
    match &mut p.interaction {
        Interaction::Game(g) => {
            for (pair, f) in [
                (&mut g.pairs.tip_substrate, s(1)),
                (&mut g.pairs.tip_atom, s(2)),
                (&mut g.pairs.atom_atom, s(3)),
                (&mut g.pairs.atom_substrate, s(4)),
            ] {
                pair.strength_n_m2 *= f;
                if f < 1.0 && f > 0.0 {
                    pair.stiffness_n_per_m *= f;
                }
            }
        }
        Interaction::Physical(ph) => {
            ph.hamaker_j.tip_substrate *= s(1);
            ph.hamaker_j.tip_atom *= s(2);
            ph.hamaker_j.atom_atom *= s(3);
            ph.hamaker_j.atom_substrate *= s(4);
        }
    }
    p
}

impl NanoScene {
    /// Builds the scene from its section, the device's limits mapped to the world (N, N/m; the
    /// largest force is also the score's comfort limit) and the tick (s).
    pub fn new(s: NanoSection, limits: &Limits, dt_s: f64) -> Result<Self, SceneError> {
        let params = match (&s.preset, s.params) {
            (Some(name), None) => match name.as_str() {
                "game" => Params::game_default(),
                "physical" => Params::physical_default(),
                other => {
                    return Err(out_of_range_text(
                        "nanoworld.preset",
                        format!("\"{other}\""),
                        "\"game\" or \"physical\"",
                    ));
                }
            },
            (None, Some(p)) => p,
            _ => {
                return Err(out_of_range_text(
                    "nanoworld",
                    "a table with both or neither of `preset` and `params`",
                    "exactly one of `preset` or `[nanoworld.params]`",
                ));
            }
        };
        params.validate().map_err(|e| SceneError::World {
            section: "nanoworld.params".into(),
            field: Some(e.field().to_string()),
            message: e.to_string(),
        })?;
        let (field, k) = params.max_render_stiffness();
        let cap_n_per_m = limits.max_stiffness_n_per_m;
        if k > cap_n_per_m {
            return Err(out_of_range(
                &format!("nanoworld.params.{field}"),
                k,
                format!(
                    "≤ {} N/m, the device's stiffness limit mapped to the world \
                     (lower mapping.force_scale or mapping.workspace_scale)",
                    fmt_num(cap_n_per_m)
                ),
            ));
        }
        params
            .validate_for_device(limits)
            .map_err(|e| SceneError::World {
                section: "nanoworld.params".into(),
                field: Some(e.field().to_string()),
                message: e.to_string(),
            })?;
        check_positive("nanoworld.draw_radius_m", s.draw_radius_m, 1e-6)?;
        let slots = params.house.as_ref().map_or(0, |h| h.slots_m.len());
        Ok(NanoScene {
            base: params.clone(),
            params,
            limits: *limits,
            scales: [1.0; 5],
            world: None,
            dt_s,
            draw_radius_m: s.draw_radius_m,
            saturated: false,
            force_n: [0.0; 3],
            score: HouseScore::new(slots, limits.max_force_n, dt_s),
        })
    }

    /// The world (after the first tick).
    pub fn world(&self) -> Option<&World> {
        self.world.as_ref()
    }
}

fn v(p: Vector3<f64>) -> Vec3 {
    [p.x, p.y, p.z]
}

fn event_name(e: &nanoworld::Event) -> &'static str {
    use nanoworld::Event as E;
    match e {
        E::AtomSpawned { .. } => "nano.atom_spawned",
        E::Snap { .. } => "nano.snap",
        E::AtomAttached { .. } => "nano.atom_attached",
        E::PullOff { .. } => "nano.pull_off",
        E::AtomTransferred { .. } => "nano.atom_transferred",
        E::AtomPickedUp { .. } => "nano.atom_picked_up",
        E::SlotFilled { .. } => "nano.slot_filled",
        E::SlotEmptied { .. } => "nano.slot_emptied",
        E::HouseComplete => "nano.house_complete",
        E::AtomsThrownOff { .. } => "nano.atoms_thrown_off",
    }
}

impl Scene for NanoScene {
    fn kind(&self) -> &'static str {
        "nanoworld"
    }

    fn state_fields(&self) -> Vec<String> {
        score::with_score_fields(&[
            "tip_x_m",
            "tip_y_m",
            "tip_z_m",
            "anchored",
            "carried_atoms",
            "movable_atoms",
            "house_score",
            "nearest_m",
        ])
    }

    fn switches(&self) -> &'static [SwitchSpec] {
        &NANO_SWITCHES
    }

    fn set_switch(&mut self, name: &str, value: f64) -> Result<(), String> {
        let mut scales = self.scales;
        let mut base = self.base.clone();
        match name {
            "adhesion_scale" => scales[0] = value,
            "tip_substrate_scale" => scales[1] = value,
            "tip_atom_scale" => scales[2] = value,
            "atom_atom_scale" => scales[3] = value,
            "atom_substrate_scale" => scales[4] = value,
            "atom_mass_kg" => base.atoms.mass_kg = value,
            "gravity_m_per_s2" => base.gravity_m_per_s2 = value,
            "inertia" => base.inertia = value != 0.0,
            other => return Err(format!("the nanoworld scene has no switch `{other}`")),
        }
        let params = scaled(&base, scales);
        match self.world.as_mut() {
            Some(w) => w.set_params(params.clone()).map_err(|e| e.to_string())?,
            None => params
                .validate()
                .and_then(|()| params.validate_for_device(&self.limits))
                .map_err(|e| e.to_string())?,
        }
        self.params = params;
        self.base = base;
        self.scales = scales;
        Ok(())
    }

    fn switch_value(&self, name: &str) -> Option<f64> {
        Some(match name {
            "adhesion_scale" => self.scales[0],
            "tip_substrate_scale" => self.scales[1],
            "tip_atom_scale" => self.scales[2],
            "atom_atom_scale" => self.scales[3],
            "atom_substrate_scale" => self.scales[4],
            "atom_mass_kg" => self.base.atoms.mass_kg,
            "gravity_m_per_s2" => self.base.gravity_m_per_s2,
            "inertia" => f64::from(u8::from(self.base.inertia)),
            _ => return None,
        })
    }

    fn step(&mut self, input: &SceneInput, out: &mut SceneOutput) {
        let cursor = Vector3::new(input.cursor_m[0], input.cursor_m[1], input.cursor_m[2]);
        if self.world.is_none() {
            match World::new(&self.params, &self.limits, cursor) {
                Ok(w) => self.world = Some(w),
                Err(e) => {
                    out.events.push(Event::new("nano.error", e.to_string()));
                    return;
                }
            }
        }
        let Some(world) = self.world.as_mut() else {
            return;
        };
        match world.step(&TipInput { position_m: cursor }, self.dt_s) {
            Ok(r) => {
                for e in &r.events {
                    out.events.push(Event::new(
                        event_name(e),
                        serde_json::to_string(e).unwrap_or_default(),
                    ));
                    if let nanoworld::Event::AtomsThrownOff { atoms, .. } = e {
                        for _ in 0..*atoms {
                            self.score.drop_one();
                        }
                    }
                }
                if r.saturated && !self.saturated {
                    // A recorded event detail: `{:e}` stays, so that the recordings replay
                    // byte for byte (recordings/*.mcap are goldens).
                    out.events.push(Event::new(
                        "nano.saturated",
                        format!(
                            "world force {:e} N scaled to max_force_n",
                            r.unlimited_force_n.norm()
                        ),
                    ));
                }
                self.saturated = r.saturated;
                self.force_n = v(r.force_n);
            }
            Err(e) => {
                out.events
                    .push(Event::new("nano.step_error", e.to_string()));
                self.force_n = [0.0; 3];
            }
        }
        out.force_n = self.force_n;
        self.score
            .update(input.tick, self.force_n, world.house().score());
        out.stiffness_n_per_m = match (&self.params.interaction, world.tip_contact()) {
            (Interaction::Physical(p), _) => p.cantilever_stiffness_n_per_m,
            (Interaction::Game(_), TipContact::Anchored(a)) => {
                world.laws().get(a.pair).stiffness_n_per_m
            }
            (Interaction::Game(_), TipContact::Free) => 0.0,
        };
    }

    /// The anchored tip's contact as a bond (protocol 3): the adhesion's spring `k`, which
    /// breaks at the weakest link's pull-off (game mode; the physical cantilever has none).
    fn local_primitives(&self, out: &mut haptic_types::local::WorldPrimitives) {
        let Some(world) = &self.world else {
            return;
        };
        let (Interaction::Game(_), TipContact::Anchored(a), Some(pull_off_n)) = (
            &self.params.interaction,
            world.tip_contact(),
            world.anchor_pull_off_n(),
        ) else {
            return;
        };
        let k = world.laws().get(a.pair).stiffness_n_per_m;
        if k > 0.0 && pull_off_n > 0.0 {
            out.bond = Some(haptic_types::local::Bond {
                anchor_m: v(a.tip_position_m),
                normal: v(a.normal),
                stiffness_n_per_m: k,
                break_m: pull_off_n / k,
            });
        }
    }

    fn state(&self, out: &mut Vec<f64>) {
        match &self.world {
            Some(w) => {
                let t = w.tip_position_m();
                out.extend_from_slice(&[t.x, t.y, t.z]);
                out.push(f64::from(u8::from(matches!(
                    w.tip_contact(),
                    TipContact::Anchored(_)
                ))));
                out.push(w.carried().len() as f64);
                out.push(w.atoms().len() as f64);
                out.push(w.house().score() as f64);
                out.push(w.nearest_gap_m());
            }
            None => {
                out.extend_from_slice(&[0.0; 7]);
                out.push(f64::INFINITY);
            }
        }
        self.score.state(out);
    }

    fn draw(&self, out: &mut Vec<Primitive>) {
        let Some(w) = &self.world else {
            return;
        };
        let teal = Rgba([0.0, 0.55, 0.55, 1.0]);
        let orange = Rgba([1.0, 0.55, 0.1, 1.0]);
        let tip = w.tip_position_m();
        // The substrate as a slab, and its atoms near the tip.
        let s = &self.params.substrate;
        let (lx, ly) = (s.nx as f64 * s.spacing_m, s.ny as f64 * s.spacing_m);
        out.push(Primitive::Box(OrientedBox {
            center_m: [
                0.5 * (lx - s.spacing_m),
                0.5 * (ly - s.spacing_m),
                -s.atom_radius_m,
            ],
            half_extents_m: [0.5 * lx, 0.5 * ly, 0.5 * s.atom_radius_m],
            rotation: [0.0, 0.0, 0.0, 1.0],
            color: Rgba([0.0, 0.35, 0.35, 0.6]),
        }));
        let near = Vector3::new(tip.x, tip.y, 0.0);
        w.substrate()
            .for_each_within(&near, self.draw_radius_m, |_, q| {
                out.push(Primitive::Sphere(Ball {
                    center_m: v(*q),
                    radius_m: s.atom_radius_m,
                    color: teal,
                }));
            });
        for b in w.bodies().filter(|b| b.kind != BodyKind::Substrate) {
            let color = match b.kind {
                BodyKind::Tip => Rgba([0.75, 0.75, 0.8, 1.0]),
                _ => orange,
            };
            out.push(Primitive::Sphere(Ball {
                center_m: v(b.position_m),
                radius_m: b.radius_m,
                color,
            }));
        }
        if let Some(h) = &self.params.house {
            for (k, slot) in h.slots_m.iter().enumerate() {
                let filled = w.house().filled().get(k).is_some_and(Option::is_some);
                if !filled {
                    out.push(Primitive::Sphere(Ball {
                        center_m: *slot,
                        radius_m: self.params.atoms.radius_m,
                        color: Rgba([1.0, 1.0, 1.0, 0.25]),
                    }));
                }
            }
        }
        if let Some(z) = &self.params.loading_zone {
            let (a, b) = (z.min_xy_m, z.max_xy_m);
            out.push(Primitive::Polyline {
                points_m: vec![
                    [a[0], a[1], 0.0],
                    [b[0], a[1], 0.0],
                    [b[0], b[1], 0.0],
                    [a[0], b[1], 0.0],
                ],
                closed: true,
                color: Rgba([1.0, 0.8, 0.2, 1.0]),
            });
        }
        let f = self.force_n;
        let fmag = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        if fmag > 0.0 {
            // Arrow length: 1 nm per nN (drawing only).
            let tip_v = v(tip);
            out.push(Primitive::Arrow {
                from_m: tip_v,
                to_m: [tip_v[0] + f[0], tip_v[1] + f[1], tip_v[2] + f[2]],
                color: Rgba([1.0, 0.9, 0.1, 1.0]),
            });
        }
        out.push(Primitive::Label {
            position_m: [0.5 * lx, -0.1 * ly, 0.0],
            text: format!("house {}/{}", w.house().score(), w.house().slots_m().len()),
            color: Rgba([1.0, 1.0, 1.0, 1.0]),
        });
    }
}
