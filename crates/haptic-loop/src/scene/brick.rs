//! The macro world (crate `brickworld`) as a scene: bricks under gravity on rapier, a
//! god-object cursor, grab / carry / rotate / throw, blueprint score.
//!
//! A thin adapter. `[brickworld.params]` is the world's own [`brickworld::Params`] table
//! (every field has a default). The world is built with the device's limits mapped to the world
//! ([`super::LoopConfig::world_limits`]), so its proxy stiffness is checked against the real
//! device. The device's buttons become the hand's [`Grip`] commands by their roles
//! (`haptic_types::buttons`): the button playing `grip` holds, those playing `turn_x` /
//! `turn_y` / `turn_z` turn (a Falcon: centre, plus / minus / forward; a Touch: button1, and
//! button2 turns about z; any other device by index unless the scene or the command line maps
//! them).
//! The world's `dt_s` must equal the loop's tick.

use super::score::{self, DROP_HEIGHT_M, HouseScore};
use super::{WorldKind, world_table};
use brickworld::{CursorInput, Grip, Params, World};
use haptic_engine::check::{SceneError, check_positive, out_of_range};
use haptic_engine::scene::Scene;
use haptic_engine::scene::SceneInput;
use haptic_engine::scene::SceneOutput;
use haptic_types::Event;
use haptic_types::Rgba;
use haptic_types::SwitchSpec;
use haptic_types::vec3::Vec3;
use haptic_types::{Ball, OrientedBox, Primitive};
use haptic_types::{ButtonRoles, Role};
use serde::Deserialize;
use world_form::Limits;
use world_form::fmt_num;

/// The brick world in the scene registry: `kind = "brickworld"`, table `[brickworld]`.
pub const WORLD: WorldKind = WorldKind {
    kind: "brickworld",
    check: |text| super::table::pick::<BrickSection>(text, "brickworld").map(drop),
    build: |text, config| {
        let p: BrickSection = world_table(text, "brickworld")?;
        let scene = BrickScene::new(
            p,
            &config.world_limits(),
            config.dt_s(),
            super::device::roles_in(text, &config.specs)?,
        )?;
        Ok(Box::new(scene))
    },
};

/// `[brickworld]`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct BrickSection {
    /// The world's parameters (defaults for what is left out).
    #[serde(default)]
    pub params: Params,
    /// Half side of the drawn ground square, m (the physical ground is 100 m wide).
    #[serde(default = "default_ground")]
    pub draw_ground_half_m: f64,
}

fn default_ground() -> f64 {
    1.0
}

/// The brick-world scene.
pub struct BrickScene {
    world: World,
    /// Which button plays each role.
    roles: ButtonRoles,
    last_input: Option<CursorInput>,
    rejected: bool,
    force_n: Vec3,
    penetration_m: f64,
    ground_half_m: f64,
    score: HouseScore,
    /// Bricks let go by the hand that have not hit anything since.
    released: Vec<(brickworld::BrickId, f64)>,
    /// What the `inertia` switch's 1 means: the scene's method (`coupling` unless the scene
    /// chose `paper`).
    inertia_on: brickworld::Inertia,
}

/// The macro world's switches (the paper's menu), named as in `[brickworld.params]`.
pub const BRICK_SWITCHES: [SwitchSpec; 5] = [
    SwitchSpec::number("gravity_m_per_s2", 0.0, 100.0, "gravity, m/s² (0: off)")
        .or_old_name("gravity_m_s2"),
    SwitchSpec::number("restitution", 0.0, 1.0, "restitution of every contact"),
    SwitchSpec::number(
        "friction",
        0.0,
        10.0,
        "friction coefficient of every contact",
    ),
    SwitchSpec::on_off(
        "inertia",
        "the carried brick's inertia (0: weight only; 1: the scene's method, the coupling by default)",
    ),
    SwitchSpec::number("brick_mass_kg", 1e-3, 100.0, "mass of every brick, kg"),
];

impl BrickScene {
    /// Builds the scene: `limits` are the device's limits mapped to the world, `dt_s` the
    /// tick, `roles` the device's buttons by role.
    pub fn new(
        s: BrickSection,
        limits: &Limits,
        dt_s: f64,
        roles: ButtonRoles,
    ) -> Result<Self, SceneError> {
        if s.params.dt_s != dt_s {
            return Err(out_of_range(
                "brickworld.params.dt_s",
                s.params.dt_s,
                format!("{} s, the loop's tick (1 / loop.rate_hz)", fmt_num(dt_s)),
            ));
        }
        check_positive("brickworld.draw_ground_half_m", s.draw_ground_half_m, 50.0)?;
        let slots = s.params.blueprint.slots.len();
        let inertia_on = match s.params.inertia {
            brickworld::Inertia::Paper => brickworld::Inertia::Paper,
            _ => brickworld::Inertia::Coupling,
        };
        let world = World::new(&s.params, limits).map_err(|e| SceneError::World {
            section: "brickworld.params".into(),
            field: Some(e.field().to_string()),
            message: e.to_string(),
        })?;
        Ok(BrickScene {
            world,
            roles,
            last_input: None,
            rejected: false,
            force_n: [0.0; 3],
            penetration_m: 0.0,
            ground_half_m: s.draw_ground_half_m,
            score: HouseScore::new(slots, limits.max_force_n, dt_s),
            released: Vec::new(),
            inertia_on,
        })
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }
}

fn event_name(e: &brickworld::Event) -> &'static str {
    use brickworld::Event as E;
    match e {
        E::Spawned { .. } => "brick.spawned",
        E::Grabbed { .. } => "brick.grabbed",
        E::GrabMissed => "brick.grab_missed",
        E::Released { .. } => "brick.released",
        E::Thrown { .. } => "brick.thrown",
        E::Rotated { .. } => "brick.rotated",
        E::RotationBlocked { .. } => "brick.rotation_blocked",
        E::TouchBegan { .. } => "brick.touch_began",
        E::TouchEnded { .. } => "brick.touch_ended",
        E::SlotFilled { .. } => "brick.slot_filled",
        E::SlotVacated { .. } => "brick.slot_vacated",
        E::Impact { .. } => "brick.impact",
    }
}

/// An event's detail: its JSON form (`{"type":"impact","a":"cursor",...}`).
fn event_detail(e: &brickworld::Event) -> String {
    serde_json::to_string(e).unwrap_or_default()
}

/// Counts drops for the score: a brick let go by the hand whose centre is [`DROP_HEIGHT_M`]
/// or more below where it was let go at its first impact (a brick set down and let go rests
/// where it was; one struck later by another brick has not fallen; a thrown brick falls).
/// `height_of` reads a brick's centre height now, m.
fn track_drops(
    e: &brickworld::Event,
    released: &mut Vec<(brickworld::BrickId, f64)>,
    height_of: impl Fn(brickworld::BrickId) -> Option<f64>,
    score: &mut HouseScore,
) {
    use brickworld::{Body, Event as E};
    match e {
        E::Released { brick, .. } => {
            if let Some(z) = height_of(*brick) {
                released.push((*brick, z));
            }
        }
        E::Grabbed { brick } => released.retain(|(b, _)| b != brick),
        E::Impact { a, b, .. } => {
            for body in [a, b] {
                if let Body::Brick(id) = body
                    && let Some(i) = released.iter().position(|(r, _)| r == id)
                {
                    let (_, z0) = released.swap_remove(i);
                    if height_of(*id).is_some_and(|z| z0 - z >= DROP_HEIGHT_M) {
                        score.drop_one();
                    }
                }
            }
        }
        _ => {}
    }
}

impl Scene for BrickScene {
    fn kind(&self) -> &'static str {
        "brickworld"
    }

    fn state_fields(&self) -> Vec<String> {
        score::with_score_fields(&[
            "proxy_x_m",
            "proxy_y_m",
            "proxy_z_m",
            "holding",
            "bricks",
            "awake_bricks",
            "slots_filled",
            "proxy_penetration_m",
            "nearest_m",
        ])
    }

    fn switches(&self) -> &'static [SwitchSpec] {
        &BRICK_SWITCHES
    }

    fn set_switch(&mut self, name: &str, value: f64) -> Result<(), String> {
        let w = &mut self.world;
        match name {
            "gravity_m_per_s2" => w.set_gravity(value),
            "restitution" => w.set_restitution(value),
            "friction" => w.set_friction(value),
            "inertia" => {
                w.set_inertia(if value != 0.0 {
                    self.inertia_on
                } else {
                    brickworld::Inertia::Off
                });
                Ok(())
            }
            "brick_mass_kg" => w.set_brick_mass(value),
            other => return Err(format!("the brickworld scene has no switch `{other}`")),
        }
        .map_err(|e| e.to_string())
    }

    fn switch_value(&self, name: &str) -> Option<f64> {
        let p = self.world.params();
        Some(match name {
            "gravity_m_per_s2" => p.gravity_m_per_s2,
            "restitution" => p.restitution,
            "friction" => p.friction,
            "inertia" => f64::from(u8::from(p.inertia != brickworld::Inertia::Off)),
            "brick_mass_kg" => p.brick_mass_kg,
            _ => return None,
        })
    }

    fn local_primitives(&self, out: &mut haptic_types::local::WorldPrimitives) {
        // The world fills the one local-model type itself (world frame).
        *out = self.world.local_primitives();
    }

    fn step(&mut self, input: &SceneInput, out: &mut SceneOutput) {
        let pressed = |role: Role| self.roles.pressed(role, input.buttons);
        let grip = Grip {
            hold: pressed(Role::Grip),
            turn_x: pressed(Role::TurnX),
            turn_y: pressed(Role::TurnY),
            turn_z: pressed(Role::TurnZ),
        };
        let cursor_input = match self.world.input(input.cursor_m, grip) {
            Ok(i) => {
                self.rejected = false;
                Some(i)
            }
            Err(e) => {
                if !self.rejected {
                    out.events
                        .push(Event::new("brick.input_rejected", e.to_string()));
                }
                self.rejected = true;
                // Time goes on: step with the last accepted input (the cursor held there).
                self.last_input
            }
        };
        let Some(ci) = cursor_input else {
            return;
        };
        self.last_input = Some(ci);
        let r = self.world.step(&ci);
        for e in &r.events {
            out.events.push(Event::new(event_name(e), event_detail(e)));
            let world = &self.world;
            track_drops(
                e,
                &mut self.released,
                |id| world.brick(id).ok().map(|v| v.position_m[2]),
                &mut self.score,
            );
        }
        self.force_n = if self.rejected { [0.0; 3] } else { r.force_n };
        self.score
            .update(input.tick, self.force_n, self.world.score().filled);
        self.penetration_m = r.proxy_penetration_m;
        out.force_n = self.force_n;
        out.stiffness_n_per_m = r.stiffness_n_per_m;
    }

    fn state(&self, out: &mut Vec<f64>) {
        let p = self.world.proxy_position_m();
        out.extend_from_slice(&p);
        out.push(f64::from(u8::from(self.world.held_brick().is_some())));
        out.push(self.world.brick_count() as f64);
        out.push(self.world.awake_brick_count() as f64);
        out.push(self.world.score().filled as f64);
        out.push(self.penetration_m);
        out.push(self.world.nearest_m());
        self.score.state(out);
    }

    fn draw(&self, out: &mut Vec<Primitive>) {
        let g = self.ground_half_m;
        out.push(Primitive::Box(OrientedBox {
            center_m: [0.0, 0.0, -0.01],
            half_extents_m: [g, g, 0.01],
            rotation: [0.0, 0.0, 0.0, 1.0],
            color: Rgba([0.3, 0.6, 0.25, 1.0]),
        }));
        let boxed = |center_m, half_extents_m, rotation, color| {
            Primitive::Box(OrientedBox {
                center_m,
                half_extents_m,
                rotation,
                color,
            })
        };
        for o in self.world.obstacles() {
            let grey = Rgba([0.5, 0.5, 0.5, 1.0]);
            out.push(boxed(
                o.position_m,
                o.half_extents_m,
                o.orientation_xyzw,
                grey,
            ));
        }
        let h = self.world.params().brick_half_extents_m;
        for s in self.world.slots().filter(|s| s.filled_by.is_none()) {
            let ghost = Rgba([0.4, 0.6, 1.0, 0.3]);
            out.push(boxed(s.position_m, h, s.orientation_xyzw, ghost));
        }
        for b in self.world.bricks() {
            out.push(Primitive::Box(OrientedBox {
                center_m: b.position_m,
                half_extents_m: b.half_extents_m,
                rotation: b.orientation_xyzw,
                color: if b.held {
                    Rgba([0.85, 0.35, 0.2, 1.0])
                } else {
                    Rgba([0.7, 0.25, 0.15, 1.0])
                },
            }));
        }
        if let Some(z) = &self.world.params().loading_zone {
            let (a, b) = (z.min_m, z.max_m);
            out.push(Primitive::Polyline {
                points_m: vec![
                    [a[0], a[1], 0.001],
                    [b[0], a[1], 0.001],
                    [b[0], b[1], 0.001],
                    [a[0], b[1], 0.001],
                ],
                closed: true,
                color: Rgba([1.0, 0.85, 0.2, 1.0]),
            });
        }
        let p = self.world.proxy_position_m();
        out.push(Primitive::Sphere(Ball {
            center_m: p,
            radius_m: self.world.params().proxy_radius_m.max(0.01),
            color: Rgba([0.2, 0.5, 0.95, 1.0]),
        }));
        let f = self.force_n;
        if f.iter().any(|c| *c != 0.0) {
            // Arrow length: 1 cm per newton of world force (drawing only).
            out.push(Primitive::Arrow {
                from_m: p,
                to_m: [p[0] + 0.01 * f[0], p[1] + 0.01 * f[1], p[2] + 0.01 * f[2]],
                color: Rgba([1.0, 0.9, 0.1, 1.0]),
            });
        }
        let s = self.world.score();
        out.push(Primitive::Label {
            position_m: [0.0, -0.6, 0.0],
            text: format!("blueprint {}/{}", s.filled, s.total),
            color: Rgba([1.0, 1.0, 1.0, 1.0]),
        });
    }
}
