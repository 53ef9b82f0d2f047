//! The interface every world plugs into: what the loop tells a scene each tick
//! ([`SceneInput`]), what it answers ([`SceneOutput`]) and the [`Scene`] trait itself.
//!
//! A scene receives the cursor (world frame, m) and the buttons once per tick and answers with
//! the force on the cursor (world frame, N), events, and on request its state (named f64
//! fields) and the primitives a renderer draws. The worlds' adapters and scene files live
//! above the engine (`haptic_loop::scene`).

use haptic_types::Buttons;
use haptic_types::Event;
// Drawable primitives and colours (world frame, metres; RGBA in 0–1) are haptic-types', shared
// with the renderer and the Foxglove channels, so a scene's drawing goes to both without
// conversion.
use haptic_types::Primitive;
use haptic_types::local::WorldPrimitives;
use haptic_types::switch::SwitchSpec;
use haptic_types::vec3::Vec3;

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

/// A world as the haptic loop sees it.
///
/// Implementations hold their world's parameters and state; `step` advances by one tick of
/// `input.dt_s`. It must be deterministic: same inputs, same bits. A scene is `Send`: a session
/// may be set up on one thread and ticked on another (the classroom's workers).
pub trait Scene: Send {
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

    /// The value switch `name` has now (a boolean switch: 0 or 1); `None` when the scene has
    /// no such switch. Menus show it (the live view's Parameters).
    fn switch_value(&self, _name: &str) -> Option<f64> {
        None
    }

    /// Every switch of [`Scene::switches`] that has a value, with its value now, in the
    /// menu's order (what a menu or a teacher's status shows).
    fn switch_values(&self) -> Vec<(String, f64)> {
        self.switches()
            .iter()
            .filter_map(|s| Some((s.name.to_string(), self.switch_value(s.name)?)))
            .collect()
    }

    /// Writes what the device may render on its own until the next tick (after the last
    /// step; world frame and units): the contact planes at and near the cursor and a carried
    /// body (bridge protocol 2, `haptic_types::local`). None by default: the device then
    /// renders the answered force with its local stiffness.
    fn local_primitives(&self, _out: &mut WorldPrimitives) {}
}
