//! The scene interface every world plugs into, the drawable primitives, scene files, and the
//! stiff-wall calibration scene.
//!
//! A scene receives the cursor (world frame, m) and the buttons once per tick and answers with
//! the force on the cursor (world frame, N), events, and on request its state (named f64
//! fields) and the primitives a renderer draws.

pub mod brick;
pub mod file;
pub mod nano;
pub mod optical;
pub mod overrides;
pub mod score;
pub mod switch;
pub mod wall;

use crate::device::Buttons;
use crate::vec3::Vec3;

pub use file::{SceneError, SceneFile, load_scene, load_scene_for};
pub use switch::{Switch, SwitchError, SwitchSpec};

/// What the loop tells the scene each tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneInput {
    /// Tick index (the only clock).
    pub tick: u64,
    /// Tick length, s.
    pub dt_s: f64,
    /// Cursor position, world frame, m.
    pub cursor_m: Vec3,
    /// Button state of the device.
    pub buttons: Buttons,
    /// False when the device input was invalid this tick: the cursor is then the last valid one.
    pub input_valid: bool,
}

/// An event raised during a tick (logged, shown in Foxglove as a log line).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Event {
    /// Dotted event name, e.g. `wall.contact_begin`.
    pub name: String,
    /// Human-readable detail (may be empty).
    pub detail: String,
}

impl Event {
    /// A new event.
    pub fn new(name: impl Into<String>, detail: impl Into<String>) -> Self {
        Event {
            name: name.into(),
            detail: detail.into(),
        }
    }
}

/// What a scene answers each tick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneOutput {
    /// Force on the cursor, world frame, N.
    pub force_n: Vec3,
    /// Local stiffness of the rendered force field this tick, world frame, N/m (0 when no spring
    /// acts). The loop checks it against the cap it gave the scene.
    pub stiffness_n_per_m: f64,
    /// Unit vector along which `stiffness_n_per_m` acts (a plane constraint such as a wall:
    /// `K = k a aᵀ`); `None`: isotropic (`K = k I`, a spring to a proxy point).
    pub stiffness_axis: Option<Vec3>,
    /// Events raised this tick, in order.
    pub events: Vec<Event>,
}

impl SceneOutput {
    /// Clears the output for reuse.
    pub fn clear(&mut self) {
        self.force_n = [0.0; 3];
        self.stiffness_n_per_m = 0.0;
        self.stiffness_axis = None;
        self.events.clear();
    }
}

/// Drawable primitives and colours are the renderer's own types (world
/// frame, metres; RGBA in 0–1), so a scene's drawing goes to the renderer
/// and to the Foxglove channels without conversion.
pub use render::{Primitive, Rgba};

/// A world as the haptic loop sees it.
///
/// Implementations hold their world's parameters and state; `step` advances by one tick of
/// `input.dt_s`. It must be deterministic: same inputs, same bits.
pub trait Scene {
    /// Short scene kind name, e.g. `wall`.
    fn kind(&self) -> &'static str;
    /// Names of the state fields, in the order [`Scene::state`] writes them (lower snake case,
    /// with the unit as suffix, e.g. `penetration_m`).
    fn state_fields(&self) -> Vec<String>;
    /// Advances one tick and writes the force on the cursor and the events into `out` (which
    /// the caller has cleared).
    fn step(&mut self, input: &SceneInput, out: &mut SceneOutput);
    /// Appends the state fields (after the last step) to `out`.
    fn state(&self, out: &mut Vec<f64>);
    /// Appends the primitives to draw the current state to `out`.
    fn draw(&self, out: &mut Vec<Primitive>);
    /// The run-time switches this scene offers (the teaching game's menu); none by default.
    fn switches(&self) -> &'static [SwitchSpec] {
        &[]
    }
    /// Sets a switch, already checked against [`Scene::switches`] (name known, value in range);
    /// it takes effect from the next step. `Err` carries the world's reason when it cannot
    /// hold the value.
    fn set_switch(&mut self, name: &str, _value: f64) -> Result<(), String> {
        Err(format!("the {} scene has no switch `{name}`", self.kind()))
    }
}
