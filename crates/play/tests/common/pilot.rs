//! A keyboard pilot for the play page: it reads what the page shows (`window.__play`: the
//! hand's point of the unit ball, the last frame's shapes and state, the lesson's place) and
//! acts only through key events, as a student at the keyboard does. The arrows move the hand
//! relative to the camera (their directions are learned by pressing them), Page Up / Page Down
//! move it up and down, Shift makes a move fine (0.2 ×), Space toggles the grip, `3` turns a
//! carried brick a quarter turn about the vertical.
//!
//! Moves are closed loops: keys are held towards the target, coarse far from it and fine
//! (Shift) near it, and let go when the hand is there. Targets come from the frame: the bricks,
//! atoms and the blueprint's ghost slots the page draws, the loading zone's outline, mapped to
//! the hand's unit ball through the hello's mapping (`world = origin + scale · 0.999 · r · n`).
#![allow(dead_code)]

use super::cdp::Browser;
use serde_json::{Value, json};
use std::thread::sleep;
use std::time::{Duration, Instant};

/// A point, m (world) or unit-ball units (the hand).
pub type V3 = [f64; 3];

/// Beyond this distance (unit-ball units) a key is held at full speed; nearer, fine (Shift).
const FINE_ZONE: f64 = 0.05;

/// A body the frame draws: its centre (world m), its quaternion (boxes), whether the hand
/// carries it (bricks).
#[derive(Clone, Copy, Debug)]
pub struct Body {
    /// Centre, m (world).
    pub c: V3,
    /// Orientation `[x, y, z, w]` (boxes; identity for spheres).
    pub q: [f64; 4],
    /// Held (a brick drawn in the held colour).
    pub held: bool,
}

fn v3(v: &Value) -> V3 {
    [
        v[0].as_f64().unwrap_or(f64::NAN),
        v[1].as_f64().unwrap_or(f64::NAN),
        v[2].as_f64().unwrap_or(f64::NAN),
    ]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn norm(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

fn norm_xy(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1]).sqrt()
}

/// The yaw (rad) of a quaternion turning only about the vertical.
pub fn yaw(q: [f64; 4]) -> f64 {
    2.0 * q[2].atan2(q[3])
}

/// A brick whose centre is higher than this (m) floats: it is not taken (gravity off lets a
/// nudged one drift up out of the hand's reach).
const LYING_BELOW_M: f64 = 0.12;

/// The pilot of one page.
pub struct Pilot<'a> {
    /// The browser it drives.
    pub b: &'a mut Browser,
    /// Device-plane directions of ArrowRight and ArrowUp (unit vectors), once learned.
    right: [f64; 2],
    away: [f64; 2],
    /// Keys held now, with Shift.
    down: Vec<(&'static str, bool)>,
    /// World m per unit-ball unit, and the world point at the ball's centre.
    k: f64,
    origin: V3,
}

impl<'a> Pilot<'a> {
    /// A pilot of the page in `b` (its arrows not yet learned).
    pub fn new(b: &'a mut Browser) -> Pilot<'a> {
        Pilot {
            b,
            right: [1.0, 0.0],
            away: [0.0, 1.0],
            down: Vec::new(),
            k: 1.0,
            origin: [0.0; 3],
        }
    }

    /// Evaluates `expr` in the page.
    pub fn eval(&mut self, expr: &str) -> Value {
        self.b.eval(expr).unwrap_or_else(|e| panic!("{e}"))
    }

    /// A key pressed and let go.
    pub fn press(&mut self, key: &str) {
        self.b.press(key);
    }

    /// Reads the world's mapping from the page's hello (after each new world).
    pub fn read_mapping(&mut self) {
        let h = self.eval("window.__play.hello");
        let r = h["workspace_radius_m"].as_f64().unwrap();
        let s = h["mapping"]["workspace_scale"].as_f64().unwrap();
        self.k = 0.999 * r * s;
        self.origin = v3(&h["mapping"]["origin_m"]);
    }

    /// World metres per unit-ball unit.
    pub fn scale(&self) -> f64 {
        self.k
    }

    /// The hand's point of the unit ball now.
    pub fn hand(&mut self) -> V3 {
        v3(&self.eval("window.__play.hand.n"))
    }

    /// The world point (m) of the hand now.
    pub fn hand_world(&mut self) -> V3 {
        let n = self.hand();
        self.world_of(n)
    }

    /// The world point (m) of the hand's point `n`.
    pub fn world_of(&self, n: V3) -> V3 {
        [
            self.origin[0] + self.k * n[0],
            self.origin[1] + self.k * n[1],
            self.origin[2] + self.k * n[2],
        ]
    }

    /// The hand's point for world point `w` (m).
    pub fn hand_of(&self, w: V3) -> V3 {
        [
            (w[0] - self.origin[0]) / self.k,
            (w[1] - self.origin[1]) / self.k,
            (w[2] - self.origin[2]) / self.k,
        ]
    }

    /// A state field of the last frame (NaN before one).
    pub fn state(&mut self, name: &str) -> f64 {
        self.eval(&format!(
            "(() => {{ const f = window.__play.lastFrame; return f && f.state ? f.state['{name}'] : null; }})()"
        ))
        .as_f64()
        .unwrap_or(f64::NAN)
    }

    /// The last frame's tick.
    pub fn tick(&mut self) -> u64 {
        self.eval("window.__play.lastFrame ? window.__play.lastFrame.tick : 0")
            .as_u64()
            .unwrap_or(0)
    }

    /// Waits until the page shows a frame newer than the one it shows now.
    pub fn next_frame(&mut self) {
        let t = self.tick();
        let t0 = Instant::now();
        while self.tick() == t && t0.elapsed() < Duration::from_secs(2) {
            sleep(Duration::from_millis(5));
        }
    }

    /// Holds exactly `keys` (each with or without Shift): lets go of the others.
    fn hold(&mut self, keys: &[(&'static str, bool)]) {
        let old = std::mem::take(&mut self.down);
        for (k, s) in &old {
            if !keys.contains(&(k, *s)) {
                self.b.key(k, false, *s).unwrap();
            }
        }
        for (k, s) in keys {
            if !old.contains(&(k, *s)) {
                self.b.key(k, true, *s).unwrap();
            }
        }
        self.down = keys.to_vec();
    }

    /// Lets go of every key held.
    pub fn let_go(&mut self) {
        self.hold(&[]);
    }

    /// Learns the device-plane direction of ArrowRight and ArrowUp by holding each briefly
    /// (the page moves the hand relative to its camera).
    pub fn learn_arrows(&mut self) {
        self.right = self.learn_one("ArrowRight");
        self.away = self.learn_one("ArrowUp");
        let dot = self.right[0] * self.away[0] + self.right[1] * self.away[1];
        assert!(dot.abs() < 0.2, "the arrows are not square: {dot}");
    }

    /// The device-plane direction (a unit vector) in which `key` moves the hand.
    fn learn_one(&mut self, key: &'static str) -> [f64; 2] {
        let a = self.hand();
        self.hold(&[(key, false)]);
        sleep(Duration::from_millis(120));
        self.let_go();
        sleep(Duration::from_millis(40));
        let b = self.hand();
        let d = [b[0] - a[0], b[1] - a[1]];
        let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
        assert!(l > 1e-3, "{key} did not move the hand: {a:?} → {b:?}");
        [d[0] / l, d[1] / l]
    }

    /// Steers the hand to `target` (unit ball) within `tol` on each axis, or until the page
    /// expression `until` is true; returns whether `until` stopped it.
    pub fn steer(&mut self, target: V3, tol: f64, until: Option<&str>, secs: f64) -> bool {
        let t0 = Instant::now();
        let probe = format!("[window.__play.hand.n, {}]", until.unwrap_or("false"));
        let mut calm = 0;
        loop {
            let v = self.eval(&probe);
            if v[1] == json!(true) {
                self.let_go();
                return true;
            }
            let n = v3(&v[0]);
            let e = sub(target, n);
            let a = e[0] * self.right[0] + e[1] * self.right[1];
            let b = e[0] * self.away[0] + e[1] * self.away[1];
            let mut keys: Vec<(&'static str, bool)> = Vec::new();
            for (x, pos, neg) in [
                (a, "ArrowRight", "ArrowLeft"),
                (b, "ArrowUp", "ArrowDown"),
                (e[2], "PageUp", "PageDown"),
            ] {
                if x.abs() > tol {
                    keys.push((if x > 0.0 { pos } else { neg }, x.abs() < FINE_ZONE));
                }
            }
            if keys.is_empty() {
                self.let_go();
                calm += 1;
                if calm >= 2 {
                    return false;
                }
                sleep(Duration::from_millis(30));
                continue;
            }
            calm = 0;
            self.hold(&keys);
            assert!(
                t0.elapsed().as_secs_f64() < secs,
                "the hand did not reach {target:?} within {secs} s (at {n:?})"
            );
            sleep(Duration::from_millis(4));
        }
    }

    /// Steers the hand to the world point `w` (m) within `tol_m`.
    pub fn go_to(&mut self, w: V3, tol_m: f64) {
        let n = self.hand_of(w);
        self.steer(n, tol_m / self.k, None, 20.0);
    }

    /// Holds `key` (coarse or fine) until `until` is true in the page; false on time-out.
    pub fn hold_until(&mut self, key: &'static str, fine: bool, until: &str, secs: f64) -> bool {
        self.hold(&[(key, fine)]);
        let r = self.b.wait_for(until, secs);
        self.let_go();
        r.is_ok()
    }

    /// Toggles the grip (Space).
    pub fn grip(&mut self) {
        self.press(" ");
    }

    /// Whether the page's hand grips.
    pub fn gripping(&mut self) -> bool {
        self.eval("window.__play.hand.grip") == json!(true)
    }

    /// The loading zone's outline (the yellow closed line): its corners' min and max (m).
    pub fn loading_zone(&mut self) -> ([f64; 2], [f64; 2]) {
        let p = self.eval("window.__play.lastFrame.prims.find(p => p.k === 'line' && p.closed).p");
        let pts: Vec<V3> = p.as_array().unwrap().iter().map(v3).collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for q in pts {
            for i in 0..2 {
                lo[i] = lo[i].min(q[i]);
                hi[i] = hi[i].max(q[i]);
            }
        }
        (lo, hi)
    }

    // ---- the brick world ----------------------------------------------------------------

    /// The boxes of the last frame that the page expression `filter` (of a primitive `p` and
    /// its index `i`) keeps; held: drawn in the held brick's colour.
    fn boxes(&mut self, filter: &str) -> Vec<Body> {
        let v = self.eval(&format!(
            "window.__play.lastFrame.prims.filter((p, i) => p.k === 'box' && ({filter})).map(p => [p.c, p.q, p.col[3] >= 0.5 && p.col[0] > 0.8])"
        ));
        v.as_array()
            .unwrap()
            .iter()
            .map(|b| Body {
                c: v3(&b[0]),
                q: quat(&b[1]),
                held: b[2] == json!(true),
            })
            .collect()
    }

    /// The bricks drawn (solid boxes after the ground, not the grey obstacles).
    pub fn bricks(&mut self) -> Vec<Body> {
        self.boxes("i > 0 && p.col[3] >= 0.5 && !(p.col[0] === p.col[1] && p.col[1] === p.col[2])")
    }

    /// The blueprint's slots still empty (the translucent boxes the page draws).
    pub fn ghost_slots(&mut self) -> Vec<Body> {
        self.boxes("p.col[3] < 0.5")
    }

    /// The brick's half height (m): the drawn boxes' z half extent.
    pub fn brick_half_height(&mut self) -> f64 {
        self.eval("window.__play.lastFrame.prims.filter((p, i) => i > 0 && p.k === 'box')[0].h[2]")
            .as_f64()
            .unwrap()
    }

    /// The carried brick, if any.
    pub fn held_brick(&mut self) -> Option<Body> {
        self.bricks().into_iter().find(|b| b.held)
    }

    /// Makes a brick appear (the hand enters the loading zone) and takes it into the hand:
    /// down onto its top, Space. Returns the brick as it lay. A brick that floats off (gravity
    /// off: a nudged one drifts up out of the hand's reach) is left, and another taken.
    pub fn fetch_brick(&mut self) -> Body {
        for _ in 0..3 {
            if let Some(b) = self.try_fetch_brick() {
                return b;
            }
        }
        panic!("could not take a brick in three tries");
    }

    /// [`Pilot::fetch_brick`] once: `None` when the brick slipped the grip every time.
    fn try_fetch_brick(&mut self) -> Option<Body> {
        let (lo, hi) = self.loading_zone();
        let inside = |p: V3| p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
        let here = self.hand_world();
        self.go_to([here[0], here[1], 0.3], 0.02);
        // A brick at rest in or beside the zone (one let go of there may lie over the spawn
        // spot, so that no new one appears).
        let near = |p: V3| {
            p[0] >= lo[0] - 0.15
                && p[0] <= hi[0] + 0.15
                && p[1] >= lo[1] - 0.15
                && p[1] <= hi[1] + 0.15
        };
        let lying = |p: &mut Pilot| {
            p.bricks()
                .into_iter()
                .filter(|b| !b.held && near(b.c) && b.c[2] < LYING_BELOW_M)
                .min_by(|a, b| a.c[2].total_cmp(&b.c[2]))
        };
        // A brick the zone gave when the world began under the hand, or a new one: the hand
        // enters the zone from outside, beside its middle (the spawn spot must be clear of it).
        let brick = match lying(self) {
            Some(b) => b,
            None => {
                let count = self.state("bricks");
                let y = lo[1] + 0.2 * (hi[1] - lo[1]);
                if inside(here) {
                    self.go_to([hi[0] + 0.1, y, 0.3], 0.02);
                }
                let mid_x = (lo[0] + hi[0]) / 2.0;
                self.go_to([mid_x, y, 0.3], 0.02);
                self.go_to([mid_x, y, 0.15], 0.02);
                self.b
                    .wait_for(
                        &format!("window.__play.lastFrame.state.bricks > {count}"),
                        3.0,
                    )
                    .unwrap_or_else(|e| panic!("no brick appeared: {e}"));
                self.next_frame();
                lying(self).expect("the new brick in the zone")
            }
        };
        // A brick that drifts (gravity off: one nudged floats on) may slip the grip: take the
        // brick again from where the frame shows it now, a few times.
        let mut brick = brick;
        for _ in 0..4 {
            if self.try_grab_brick(brick) {
                return Some(brick);
            }
            self.next_frame();
            match lying(self) {
                Some(b) => brick = b,
                None => break,
            }
        }
        eprintln!("  could not take the brick at {:?}: another", brick.c);
        None
    }

    /// Takes the brick lying at `brick` into the hand (panics if it cannot).
    pub fn grab_brick(&mut self, brick: Body) {
        assert!(
            self.try_grab_brick(brick),
            "could not take the brick at {:?}",
            brick.c
        );
    }

    /// Takes the brick lying at `brick` into the hand: over its top, down onto it, Space;
    /// whether the world says the hand holds it.
    pub fn try_grab_brick(&mut self, brick: Body) -> bool {
        let hz = self.brick_half_height();
        let top = brick.c[2] + hz;
        let here = self.hand_world();
        let over = [brick.c[0], brick.c[1], top + 0.06];
        if here[2] < over[2] {
            self.go_to([here[0], here[1], over[2]], 0.01);
        }
        self.go_to(over, 0.003);
        // Just over the top, within the grip's reach without touching (a brick floating
        // with gravity off would be pushed away); then pressing onto it.
        for depth in [-0.007, 0.002, 0.008] {
            self.go_to([brick.c[0], brick.c[1], top - depth], 0.0015);
            self.grip();
            if self
                .b
                .wait_for("window.__play.lastFrame.state.holding === 1", 0.6)
                .is_ok()
            {
                return true;
            }
            if self.gripping() {
                self.grip();
            }
        }
        false
    }

    /// Moves the carried brick's centre to `w` (m) within `tol_m`, closing the loop on the
    /// brick the frame shows (it hangs from the hand).
    pub fn carry_to(&mut self, w: V3, tol_m: f64) -> Body {
        for _ in 0..8 {
            let b = self.held_brick().expect("a brick in the hand");
            let e = sub(w, b.c);
            if norm(e) <= tol_m {
                return b;
            }
            let n = add(self.hand(), [e[0] / self.k, e[1] / self.k, e[2] / self.k]);
            self.steer(n, 0.4 * tol_m / self.k, None, 20.0);
            // Let a swing settle before looking again.
            sleep(Duration::from_millis(150));
            self.next_frame();
        }
        self.held_brick().expect("a brick in the hand")
    }

    /// Puts the carried brick into the slot `slot`: up, over it, turned to its yaw, down,
    /// let go. Returns the brick's centre as it came to rest (`None`: the page moved on, its
    /// expression `done` true, when the brick left the hand).
    pub fn place_brick(&mut self, slot: Body, done: &str) -> Option<V3> {
        let carry_z = 0.25;
        let b = self.held_brick().expect("a brick in the hand");
        self.carry_to([b.c[0], b.c[1], carry_z], 0.02);
        self.carry_to([slot.c[0], slot.c[1], carry_z], 0.01);
        // Turn a quarter turn about the vertical while it is a quarter turn off (a brick
        // looks the same after a half turn).
        for _ in 0..3 {
            let b = self.held_brick().expect("a brick in the hand");
            let d = (yaw(slot.q) - yaw(b.q)).rem_euclid(std::f64::consts::PI);
            let off = d.min(std::f64::consts::PI - d);
            if off < 3f64.to_radians() {
                break;
            }
            self.press("3");
            sleep(Duration::from_millis(100));
            self.next_frame();
        }
        let hover = [slot.c[0], slot.c[1], slot.c[2] + 0.04];
        self.carry_to(hover, 0.002);
        self.carry_to([slot.c[0], slot.c[1], slot.c[2] + 0.004], 0.0025);
        self.grip();
        self.b
            .wait_for(
                &format!("window.__play.lastFrame.state.holding === 0 || ({done})"),
                2.0,
            )
            .unwrap();
        if self.eval(done) == json!(true) {
            return None;
        }
        let n = self.hand();
        self.steer([n[0], n[1], n[2] + 0.08 / self.k], 0.01, None, 10.0);
        sleep(Duration::from_millis(300));
        self.next_frame();
        self.bricks()
            .into_iter()
            .min_by(|a, b| norm(sub(a.c, slot.c)).total_cmp(&norm(sub(b.c, slot.c))))
            .map(|b| b.c)
    }

    /// Builds the brick house: each empty slot of the blueprint (lowest first) filled with a
    /// brick from the loading zone; a brick that missed its slot is taken again and put
    /// again. Returns the largest miss seen (m) and the number of tries.
    pub fn build_brick_house(&mut self, done: &str) -> (f64, usize) {
        let mut worst: f64 = 0.0;
        let mut tries = 0;
        let mut again: Option<Body> = None;
        loop {
            if self.eval(done) == json!(true) {
                return (worst, tries);
            }
            let mut slots = self.ghost_slots();
            assert!(
                !slots.is_empty(),
                "no empty slot, yet the house is not complete"
            );
            slots.sort_by(|a, b| a.c[2].total_cmp(&b.c[2]).then(a.c[0].total_cmp(&b.c[0])));
            let slot = slots[0];
            match again.take() {
                Some(b) => self.grab_brick(b),
                None => {
                    self.fetch_brick();
                }
            }
            let filled = self.state("slots_filled");
            tries += 1;
            let Some(at) = self.place_brick(slot, done) else {
                println!("  brick for slot {:?}: the house is complete", slot.c);
                continue;
            };
            let miss = norm(sub(at, slot.c));
            worst = worst.max(miss);
            println!(
                "  brick for slot {:?}: rests at {:?}, {:.1} mm off",
                slot.c,
                at,
                miss * 1e3
            );
            if self.state("slots_filled") <= filled && self.eval(done) != json!(true) {
                assert!(tries < 12, "the house is not getting built");
                again = self
                    .bricks()
                    .into_iter()
                    .min_by(|a, b| norm(sub(a.c, slot.c)).total_cmp(&norm(sub(b.c, slot.c))));
            }
        }
    }

    /// Takes a brick and lifts it `h_m` above where it was taken, until `done`.
    pub fn lift_brick(&mut self, h_m: f64, done: &str) {
        self.fetch_brick();
        let n = self.hand();
        let target = [n[0], n[1], n[2] + (h_m + 0.05) / self.k];
        assert!(
            self.steer(target, 0.01, Some(done), 10.0),
            "lifted, yet the step is not done"
        );
    }

    /// Takes a brick, lifts it and throws it: the hand moving at full key speed forwards,
    /// sideways and up, Space lets go while it moves; again with another brick until `done`.
    /// Returns the speed of each release (m/s, from the `brick.released` events).
    pub fn throw_brick(&mut self, done: &str, tries: usize) -> Vec<f64> {
        let mut speeds = Vec::new();
        for _ in 0..tries {
            let seen = self.eval("window.__play.events.length");
            // A brick from the zone each time (one let go of too slowly may drift on with
            // gravity off).
            self.fetch_brick();
            let n = self.hand();
            self.steer([n[0], n[1], n[2] + 0.15 / self.k], 0.01, None, 10.0);
            // Back over the middle, then the arrow whose direction is most along +x.
            let key = if self.right[0].abs() >= self.away[0].abs() {
                if self.right[0] > 0.0 {
                    "ArrowRight"
                } else {
                    "ArrowLeft"
                }
            } else if self.away[0] > 0.0 {
                "ArrowUp"
            } else {
                "ArrowDown"
            };
            let (lo, hi) = self.loading_zone();
            let here = self.hand_world();
            self.go_to(
                [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, here[2]],
                0.02,
            );
            // Forward, sideways and up at once: each key moves its own axis at full speed, so
            // the hand moves at √3 × the key speed, and the release is read on three axes.
            let side = if key.starts_with("ArrowL") || key.starts_with("ArrowR") {
                "ArrowUp"
            } else {
                "ArrowRight"
            };
            self.hold(&[(key, false), (side, false), ("PageUp", false)]);
            sleep(Duration::from_millis(250));
            self.grip();
            sleep(Duration::from_millis(60));
            self.let_go();
            let r = self.b.wait_for(done, 1.0);
            let v = self.eval(&format!(
                "(() => {{ const e = window.__play.events.slice({seen}).filter(e => e[1] === 'brick.released').pop(); return e ? JSON.parse(e[2]).velocity_m_per_s : null; }})()"
            ));
            let v = [v[0].as_f64(), v[1].as_f64(), v[2].as_f64()];
            if let [Some(x), Some(y), Some(z)] = v {
                speeds.push((x * x + y * y + z * z).sqrt());
            }
            if r.is_ok() {
                return speeds;
            }
        }
        panic!("{tries} throws, none a throw: release speeds {speeds:?} m/s");
    }

    // ---- the nano world -------------------------------------------------------------------

    /// The movable (orange) atoms drawn.
    pub fn atoms(&mut self) -> Vec<Body> {
        let v = self.eval(
            "window.__play.lastFrame.prims.filter(p => p.k === 'sphere' && p.col[3] >= 1 && p.col[0] === 1 && p.col[2] < 0.2).map(p => p.c)",
        );
        v.as_array()
            .unwrap()
            .iter()
            .map(|c| Body {
                c: v3(c),
                q: [0.0, 0.0, 0.0, 1.0],
                held: false,
            })
            .collect()
    }

    /// The house's slots still empty (the translucent spheres).
    pub fn ghost_atoms(&mut self) -> Vec<V3> {
        let v = self.eval(
            "window.__play.lastFrame.prims.filter(p => p.k === 'sphere' && p.col[3] < 0.5).map(p => p.c)",
        );
        v.as_array().unwrap().iter().map(v3).collect()
    }

    /// The tip's centre (m), from the frame's state.
    pub fn tip(&mut self) -> V3 {
        let v = self.eval(
            "(() => { const s = window.__play.lastFrame.state; return [s.tip_x_m, s.tip_y_m, s.tip_z_m]; })()",
        );
        v3(&v)
    }

    /// The atom the tip carries (the orange atom nearest the tip), once the state says one.
    pub fn carried_atom(&mut self) -> Option<V3> {
        if self.state("carried_atoms") < 1.0 {
            return None;
        }
        let t = self.tip();
        self.atoms()
            .into_iter()
            .map(|a| a.c)
            .min_by(|a, b| norm(sub(*a, t)).total_cmp(&norm(sub(*b, t))))
    }

    /// Comes down slowly towards the surface under the tip until `until` (the tip snaps):
    /// Page Down held for up to three spells of 10 s of wall time (a loaded machine slows the
    /// page's frames, and with them how fast a held key moves the tip: one fresh-clone run
    /// under the whole suite's load did not snap within the first 10 s).
    pub fn come_down_until(&mut self, until: &str) {
        let came = (1..=3).any(|spell| {
            let ok = self.hold_until("PageDown", false, until, 10.0);
            if !ok {
                println!("  came down for {} s, `{until}` not yet true", 10 * spell);
            }
            ok
        });
        assert!(came, "came down for 30 s, yet `{until}` is not true");
    }

    /// Takes an orange atom from the loading zone onto the tip (an atom appears while the tip
    /// is over the zone; the tip comes down onto it). Returns the tip's centre (m) on the
    /// tick the atom came onto it.
    pub fn fetch_atom(&mut self) -> V3 {
        let (lo, hi) = self.loading_zone();
        let high = 2.0e-9;
        let here = self.hand_world();
        if here[2] < high {
            self.go_to([here[0], here[1], high], 0.1e-9);
        }
        let inside = |p: V3| p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1];
        let corner = [
            lo[0] + 0.2 * (hi[0] - lo[0]),
            lo[1] + 0.2 * (hi[1] - lo[1]),
            high,
        ];
        self.go_to(corner, 0.1e-9);
        let t0 = Instant::now();
        let atom = loop {
            self.next_frame();
            if let Some(a) = self.atoms().into_iter().find(|a| inside(a.c)) {
                break a.c;
            }
            assert!(t0.elapsed() < Duration::from_secs(3), "no atom appeared");
        };
        self.go_to([atom[0], atom[1], atom[2] + 1.2e-9], 0.01e-9);
        let n = self.hand();
        let stop = "window.__play.lastFrame.state.carried_atoms >= 1";
        let low = [n[0], n[1], n[2] - 1.5e-9 / self.k];
        assert!(
            self.steer(low, 0.001, Some(stop), 10.0),
            "the tip came down over the atom at {atom:?}, yet took none"
        );
        let took = self.tip();
        let n = self.hand();
        self.steer([n[0], n[1], n[2] + 0.8e-9 / self.k], 0.01, None, 5.0);
        took
    }

    /// Puts the carried atom onto the house's slot `slot` (m): the atom over it, straight
    /// down until it snaps onto the atom below, then up until the tip lets it go. Returns the
    /// atom's centre as it stays (m; `None`: the page moved on, its expression `done` true).
    pub fn place_atom(&mut self, slot: V3, done: &str) -> Option<V3> {
        let above = slot[2] + 0.6e-9;
        for tol in [0.05e-9, 0.008e-9, 0.008e-9] {
            let a = self.carried_atom().expect("an atom on the tip");
            let e = [slot[0] - a[0], slot[1] - a[1], above - a[2]];
            if norm_xy(e) <= tol && e[2].abs() < 0.1e-9 {
                continue;
            }
            let n = add(self.hand(), [e[0] / self.k, e[1] / self.k, e[2] / self.k]);
            self.steer(n, 0.5 * tol / self.k, None, 20.0);
            self.next_frame();
            self.next_frame();
        }
        self.come_down_until("window.__play.lastFrame.state.anchored === 1");
        let free = "window.__play.lastFrame.state.carried_atoms === 0 && window.__play.lastFrame.state.anchored === 0";
        assert!(
            self.hold_until("PageUp", false, &format!("({free}) || ({done})"), 5.0),
            "pulled up, yet the atom stays on the tip"
        );
        if self.eval(done) == json!(true) {
            return None;
        }
        self.next_frame();
        self.atoms()
            .into_iter()
            .map(|a| a.c)
            .min_by(|a, b| norm(sub(*a, slot)).total_cmp(&norm(sub(*b, slot))))
    }

    /// Builds the atom house: each empty slot (lowest first) given an atom from the loading
    /// zone. Returns the largest miss seen (m) and the number of atoms placed.
    pub fn build_atom_house(&mut self, done: &str) -> (f64, usize) {
        let mut worst: f64 = 0.0;
        let mut n = 0;
        loop {
            if self.eval(done) == json!(true) {
                return (worst, n);
            }
            let mut slots = self.ghost_atoms();
            assert!(
                !slots.is_empty(),
                "no empty slot, yet the house is not complete"
            );
            slots.sort_by(|a, b| a[2].total_cmp(&b[2]).then(a[0].total_cmp(&b[0])));
            let slot = slots[0];
            let score = self.state("house_score");
            self.fetch_atom();
            n += 1;
            let Some(at) = self.place_atom(slot, done) else {
                println!(
                    "  atom for slot {:?} nm: the house is complete",
                    slot.map(|x| x * 1e9)
                );
                continue;
            };
            let miss = norm(sub(at, slot));
            worst = worst.max(miss);
            println!(
                "  atom for slot {:?} nm: stays {:.3} nm off",
                slot.map(|x| x * 1e9),
                miss * 1e9
            );
            assert!(
                self.state("house_score") > score || self.eval(done) == json!(true),
                "the atom missed its slot by {:.3} nm",
                miss * 1e9
            );
            assert!(n < 12, "the house is not getting built");
        }
    }
}

fn quat(v: &Value) -> [f64; 4] {
    [
        v[0].as_f64().unwrap_or(0.0),
        v[1].as_f64().unwrap_or(0.0),
        v[2].as_f64().unwrap_or(0.0),
        v[3].as_f64().unwrap_or(1.0),
    ]
}
