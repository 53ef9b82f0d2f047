//! Synthetic but physically sensible scenes for the report and the figures: the
//! optical-tweezers steering scene (paper Fig. 9 layout), a brick house being built and an
//! atom house on a substrate, each as a function of time so a 60 s session can be animated.

#![allow(dead_code)]

use render::{Camera, Frame, RenderError, Style, View};

use haptic_types::{Ball, OrientedBox, Primitive};

use haptic_types::Rgba;

pub type Vec3 = [f64; 3];

// ---------------------------------------------------------------- optical tweezers physics

/// Paper constants (SI): beam waists a, b (m), well depth P0 (J), particle mass m (kg).
pub const WAIST_X_M: f64 = 600e-9;
pub const WAIST_Y_M: f64 = 300e-9;
pub const DEPTH_J: f64 = 1e-15; // 1e-6 nJ
pub const MASS_KG: f64 = 1e-15; // 1e-12 g
/// The paper's cached-envelope cycle time, s.
pub const CYCLE_S: f64 = 0.2e-6;

/// Acceleration of the particle at offset `d` (m) from the trap centre, m/s².
fn accel(d: [f64; 2]) -> [f64; 2] {
    let ln2 = std::f64::consts::LN_2;
    let (a2, b2) = (WAIST_X_M * WAIST_X_M, WAIST_Y_M * WAIST_Y_M);
    let e = (-ln2 * (d[0] * d[0] / a2 + d[1] * d[1] / b2)).exp();
    // F = -∂P/∂x with P = -P0 exp(-ln2 (x²/a² + y²/b²))
    let fx = -DEPTH_J * e * 2.0 * ln2 * d[0] / a2;
    let fy = -DEPTH_J * e * 2.0 * ln2 * d[1] / b2;
    [fx / MASS_KG, fy / MASS_KG]
}

/// Displacement (m) after one RK4 step of `dt` (s) of a particle starting at the origin with
/// velocity `v0` (m/s) in a trap centred at `c` (m): the paper's difference equation.
pub fn step_displacement(c: [f64; 2], v0: [f64; 2], dt: f64) -> [f64; 2] {
    let f = |x: [f64; 2], v: [f64; 2]| -> ([f64; 2], [f64; 2]) {
        (v, accel([x[0] - c[0], x[1] - c[1]]))
    };
    let add = |a: [f64; 2], b: [f64; 2], k: f64| [a[0] + k * b[0], a[1] + k * b[1]];
    let (x0, v0_) = ([0.0, 0.0], v0);
    let (k1x, k1v) = f(x0, v0_);
    let (k2x, k2v) = f(add(x0, k1x, dt / 2.0), add(v0_, k1v, dt / 2.0));
    let (k3x, k3v) = f(add(x0, k2x, dt / 2.0), add(v0_, k2v, dt / 2.0));
    let (k4x, _) = f(add(x0, k3x, dt), add(v0_, k3v, dt));
    [
        dt / 6.0 * (k1x[0] + 2.0 * k2x[0] + 2.0 * k3x[0] + k4x[0]),
        dt / 6.0 * (k1x[1] + 2.0 * k2x[1] + 2.0 * k3x[1] + k4x[1]),
    ]
}

/// The working envelope for velocity `v0` (m/s) and cycle `dt` (s): the boundary of the set
/// of one-step displacements over all trap positions, as `bins` points around the drift
/// `v0 dt` (m, relative to the particle). Trap positions are sampled along the rays on which
/// the trap force points in a given direction (c ∝ (a² cos φ, b² sin φ)), out to three waists
/// where the force has vanished; each bin keeps its farthest displacement, and a bin no sample
/// fell in takes the mean of its neighbours.
pub fn working_envelope(v0: [f64; 2], dt: f64, bins: usize) -> Vec<[f64; 2]> {
    let drift = [v0[0] * dt, v0[1] * dt];
    let mut r_max = vec![f64::NAN; bins];
    let (n_dir, n_r) = (4 * bins, 160);
    let (a2, b2) = (WAIST_X_M * WAIST_X_M, WAIST_Y_M * WAIST_Y_M);
    for i in 0..n_dir {
        let phi = std::f64::consts::TAU * (i as f64 + 0.5) / n_dir as f64;
        let u = [a2 * phi.cos(), b2 * phi.sin()];
        let un = (u[0] * u[0] + u[1] * u[1]).sqrt();
        let u = [u[0] / un, u[1] / un];
        for j in 1..=n_r {
            let s = 3.0 * WAIST_X_M * j as f64 / n_r as f64;
            let d = step_displacement([s * u[0], s * u[1]], v0, dt);
            let (dx, dy) = (d[0] - drift[0], d[1] - drift[1]);
            let ang = dy.atan2(dx).rem_euclid(std::f64::consts::TAU);
            let k = ((ang / std::f64::consts::TAU * bins as f64) as usize).min(bins - 1);
            let r = (dx * dx + dy * dy).sqrt();
            if r_max[k].is_nan() || r > r_max[k] {
                r_max[k] = r;
            }
        }
    }
    let filled = r_max.clone();
    for k in 0..bins {
        if filled[k].is_nan() {
            let prev = (1..bins)
                .map(|o| filled[(k + bins - o) % bins])
                .find(|v| !v.is_nan());
            let next = (1..bins)
                .map(|o| filled[(k + o) % bins])
                .find(|v| !v.is_nan());
            r_max[k] = 0.5 * (prev.unwrap_or(0.0) + next.unwrap_or(0.0));
        }
    }
    (0..bins)
        .map(|k| {
            let phi = std::f64::consts::TAU * (k as f64 + 0.5) / bins as f64;
            [
                drift[0] + r_max[k] * phi.cos(),
                drift[1] + r_max[k] * phi.sin(),
            ]
        })
        .collect()
}

// ---------------------------------------------------------------- colours

pub fn particle_color() -> Rgba {
    Rgba::from_u8(214, 160, 40)
}
pub fn beam_color() -> Rgba {
    Rgba([0.85, 0.1, 0.1, 0.55])
}
pub fn cursor_color() -> Rgba {
    Rgba([0.15, 0.35, 0.9, 0.45])
}
pub fn envelope_color() -> Rgba {
    Rgba::from_u8(20, 120, 60)
}
pub fn force_color() -> Rgba {
    Rgba::from_u8(170, 0, 170)
}
pub fn ink() -> Rgba {
    Rgba::from_u8(30, 30, 30)
}
pub fn grid_color() -> Rgba {
    Rgba::from_u8(175, 180, 190)
}

// ---------------------------------------------------------------- tweezers scene

/// One state of the steering scene.
#[derive(Clone, Debug)]
pub struct Tweezers {
    /// Particle centre, m (z = 0 plane).
    pub particle_m: Vec3,
    /// Trap centre, m.
    pub trap_m: Vec3,
    /// Cursor centre, m.
    pub cursor_m: Vec3,
    /// Working envelope (displacements relative to the particle), m.
    pub envelope_m: Vec<[f64; 2]>,
    /// Force on the stylus, world frame, N.
    pub force_n: Vec3,
}

/// Fig. 9(b): the particle steered to the right faster than the trap can follow. The particle
/// moves at (50, 0) nm/µs; the command leads it by 250 nm (under the paper's 0.3 µm with
/// feedback on); the envelope for 0.2 µs reaches tens of nm, so the excess is felt as a spring
/// of 0.05 pN/nm pushing back.
pub fn fig9_state() -> Tweezers {
    let v0 = [0.05, 0.0]; // m/s = 50 nm/µs
    let env = working_envelope(v0, CYCLE_S, 180);
    let lead = 250e-9;
    // where the command crosses the envelope (rightmost envelope point on the x axis)
    let reach = env
        .iter()
        .filter(|p| p[1].abs() < 3e-9 && p[0] > 0.0)
        .map(|p| p[0])
        .fold(0.0f64, f64::max);
    let excess = lead - reach;
    let k_n_per_m = 5e-5; // 0.05 pN/nm
    Tweezers {
        particle_m: [0.0, 0.0, 0.0],
        trap_m: [0.18e-6, 0.0, 0.0],
        cursor_m: [lead, 0.0, 0.0],
        envelope_m: env,
        force_n: [-k_n_per_m * excess, 0.0, 0.0],
    }
}

/// Fig. 9(a): the initial screen, particle at rest in the trap, the cursor to its left, nothing
/// grabbed (so no envelope and no force).
pub fn fig9a_state() -> Tweezers {
    Tweezers {
        particle_m: [0.0, 0.0, 0.0],
        trap_m: [0.0, 0.0, 0.0],
        cursor_m: [-1.2e-6, 0.0, 0.0],
        envelope_m: Vec::new(),
        force_n: [0.0; 3],
    }
}

/// Envelopes for velocities of 50 nm/µs in 36 directions, for animation.
pub fn envelope_table() -> Vec<Vec<[f64; 2]>> {
    (0..36)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 36.0;
            working_envelope([0.05 * a.cos(), 0.05 * a.sin()], CYCLE_S, 120)
        })
        .collect()
}

/// The steering session at time `t` (s) of a 60 s run: the particle is dragged around a
/// 2 µm circle once a minute, the cursor leading it.
pub fn tweezers_at(t: f64, table: &[Vec<[f64; 2]>]) -> Tweezers {
    let w = std::f64::consts::TAU / 60.0;
    let ang = w * t;
    let r = 2e-6;
    let p = [r * ang.cos() - r, r * ang.sin(), 0.0];
    let heading = ang + std::f64::consts::FRAC_PI_2;
    let lead = 200e-9 + 80e-9 * (3.0 * t).sin();
    let c = [
        p[0] + lead * heading.cos(),
        p[1] + lead * heading.sin(),
        0.0,
    ];
    let k = ((heading.rem_euclid(std::f64::consts::TAU)) / std::f64::consts::TAU * 36.0).round()
        as usize
        % 36;
    let excess = (lead - 60e-9).max(0.0);
    Tweezers {
        particle_m: p,
        trap_m: [
            p[0] + 0.15e-6 * heading.cos(),
            p[1] + 0.15e-6 * heading.sin(),
            0.0,
        ],
        cursor_m: c,
        envelope_m: table[k].clone(),
        force_n: [
            -5e-5 * excess * heading.cos(),
            -5e-5 * excess * heading.sin(),
            0.0,
        ],
    }
}

/// Arrow length per newton for the tweezers force arrows, m/N (1 pN ↔ 0.1 µm).
pub const FORCE_SCALE_M_PER_N: f64 = 1e5;

/// Draws a steering state: grid, beam rod, particle, cursor, envelope ×100, force arrow,
/// labels and a scale bar.
pub fn draw_tweezers(f: &mut Frame, s: &Tweezers, labels: bool) -> Result<(), RenderError> {
    let grid = 2.9e-6;
    let z_floor = -0.5e-6;
    for i in -2..=2 {
        let u = f64::from(i) * grid;
        f.push(Primitive::Polyline {
            points_m: vec![[u, -2.0 * grid, z_floor], [u, 2.0 * grid, z_floor]],
            closed: false,
            color: grid_color(),
        })?;
        f.push(Primitive::Polyline {
            points_m: vec![[-2.0 * grid, u, z_floor], [2.0 * grid, u, z_floor]],
            closed: false,
            color: grid_color(),
        })?;
    }
    // the beam: a slender rod along z with an elliptic cross-section (waists a, b)
    let (zt, zb) = (2.5e-6, -2.5e-6);
    for z in [zb, zt] {
        f.push(Primitive::Ellipse {
            center_m: [s.trap_m[0], s.trap_m[1], z],
            semi_axes_m: [WAIST_X_M, WAIST_Y_M],
            color: beam_color(),
        })?;
    }
    let r = f.camera().right();
    // silhouette generators of the elliptic cylinder
    let t = (WAIST_Y_M * r[1]).atan2(WAIST_X_M * r[0]);
    for sgn in [1.0, -1.0] {
        let x = s.trap_m[0] + sgn * WAIST_X_M * t.cos();
        let y = s.trap_m[1] + sgn * WAIST_Y_M * t.sin();
        f.push(Primitive::Polyline {
            points_m: vec![[x, y, zb], [x, y, zt]],
            closed: false,
            color: beam_color(),
        })?;
    }
    f.push(Primitive::Sphere(Ball {
        center_m: s.particle_m,
        radius_m: 0.5e-6,
        color: particle_color(),
    }))?;
    f.push(Primitive::Cursor(Ball {
        center_m: s.cursor_m,
        radius_m: 0.15e-6,
        color: cursor_color(),
    }))?;
    let env: Vec<Vec3> = s
        .envelope_m
        .iter()
        .map(|d| {
            [
                s.particle_m[0] + d[0],
                s.particle_m[1] + d[1],
                s.particle_m[2],
            ]
        })
        .collect();
    if !env.is_empty() {
        f.scaled_loop(&env, s.particle_m, 100.0, envelope_color())?;
    }
    let tip = [
        s.cursor_m[0] + FORCE_SCALE_M_PER_N * s.force_n[0],
        s.cursor_m[1] + FORCE_SCALE_M_PER_N * s.force_n[1],
        s.cursor_m[2] + FORCE_SCALE_M_PER_N * s.force_n[2],
    ];
    f.push(Primitive::Arrow {
        from_m: s.cursor_m,
        to_m: tip,
        color: force_color(),
    })?;
    if labels {
        let fmag = (s.force_n[0].powi(2) + s.force_n[1].powi(2)).sqrt();
        let items: [(Vec3, String, Rgba); 5] = [
            (
                [s.particle_m[0] - 0.3e-6, s.particle_m[1] + 0.55e-6, 0.0],
                "particle (1 µm)".into(),
                ink(),
            ),
            (
                [s.trap_m[0] + 0.2e-6, s.trap_m[1] - 0.3e-6, zt],
                "beam, a = 600 nm, b = 300 nm".into(),
                Rgba::from_u8(150, 20, 20),
            ),
            (
                [s.cursor_m[0] + 0.1e-6, s.cursor_m[1] - 0.45e-6, 0.0],
                "cursor".into(),
                Rgba::from_u8(30, 60, 160),
            ),
            (
                [
                    s.particle_m[0] + 100.0 * env_extent(&s.envelope_m)[0] - 0.4e-6,
                    s.particle_m[1] - 100.0 * env_extent(&s.envelope_m)[1] - 0.3e-6,
                    0.0,
                ],
                "working envelope ×100".into(),
                envelope_color(),
            ),
            (
                [tip[0] - 1.2e-6, tip[1] - 1.0e-6, 0.0],
                format!("force {:.1} pN", fmag * 1e12),
                force_color(),
            ),
        ];
        let grabbed = !s.envelope_m.is_empty();
        for (k, (p, text, color)) in items.into_iter().enumerate() {
            if !grabbed && k >= 3 {
                break;
            }
            f.push(Primitive::Label {
                position_m: p,
                text,
                color,
            })?;
        }
    }
    Ok(())
}

fn env_extent(env: &[[f64; 2]]) -> [f64; 2] {
    let mut e = [0.0f64; 2];
    for p in env {
        e[0] = e[0].max(p[0]);
        e[1] = e[1].max(p[1]);
    }
    e
}

pub fn tweezers_camera(w: u32, h: u32) -> Result<Camera, RenderError> {
    let view = View::Oblique {
        azimuth_rad: -75f64.to_radians(),
        elevation_rad: 35f64.to_radians(),
    };
    Camera::fit(
        view,
        [-3.6e-6, -4.6e-6, -0.5e-6],
        [4.2e-6, 4.6e-6, 1.5e-6],
        w,
        h,
        0.02,
    )
}

pub fn tweezers_session_camera(w: u32, h: u32) -> Result<Camera, RenderError> {
    Camera::fit(
        View::Top,
        [-6.5e-6, -4.5e-6, 0.0],
        [2.5e-6, 4.5e-6, 0.0],
        w,
        h,
        0.03,
    )
}

// ---------------------------------------------------------------- brick world

const BRICK_HALF: Vec3 = [0.04, 0.02, 0.015];

/// Slot centres of a small house: 4 walls of 7 courses, a door gap, bricks in running bond.
pub fn house_slots() -> Vec<(Vec3, bool)> {
    let mut out = Vec::new();
    let (hx, hy, hz) = (BRICK_HALF[0], BRICK_HALF[1], BRICK_HALF[2]);
    let n_long = 5; // bricks per long wall course
    let len = 2.0 * hx * n_long as f64;
    for course in 0..7 {
        let z = hz + 2.0 * hz * f64::from(course);
        let shift = if course % 2 == 0 { -0.5 * hx } else { 0.5 * hx };
        for wall in 0..2 {
            let y = if wall == 0 { -0.12 } else { 0.12 };
            for i in 0..n_long {
                let x = -0.5 * len + hx + 2.0 * hx * i as f64 + shift;
                let door = wall == 0 && i == 2 && course < 4;
                if !door {
                    out.push(([x, y, z], false));
                }
            }
        }
        for side in 0..2 {
            let x = if side == 0 {
                -0.5 * len - 0.5 * hx - hy
            } else {
                0.5 * len + 0.5 * hx + hy
            };
            for j in 0..3 {
                let y = -0.08 + 0.08 * f64::from(j) + if course % 2 == 0 { 0.0 } else { 0.01 };
                out.push(([x, y, z], true));
            }
        }
    }
    out
}

/// The brick house at time `t` (s) of a 60 s session: a brick is laid every
/// 60 s / slot count; one brick is carried by the cursor toward the next slot.
pub fn draw_bricks(f: &mut Frame, t: f64, labels: bool) -> Result<(), RenderError> {
    let slots = house_slots();
    let per = 60.0 / slots.len() as f64;
    let laid = ((t / per) as usize).min(slots.len());
    let q_turn = [
        0.0,
        0.0,
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    ];
    let q_id = [0.0, 0.0, 0.0, 1.0];
    f.push(Primitive::Box(OrientedBox {
        center_m: [0.0, 0.0, -0.01],
        half_extents_m: [0.45, 0.35, 0.01],
        rotation: q_id,
        color: Rgba::from_u8(110, 160, 80),
    }))?;
    // loading zone
    f.push(Primitive::Box(OrientedBox {
        center_m: [0.33, -0.25, 0.001],
        half_extents_m: [0.09, 0.07, 0.001],
        rotation: q_id,
        color: Rgba::from_u8(200, 200, 150),
    }))?;
    for (k, (c, turned)) in slots.iter().enumerate() {
        let rot = if *turned { q_turn } else { q_id };
        let shade = 0.85 + 0.15 * (((k * 37) % 11) as f64 / 10.0);
        if k < laid {
            f.push(Primitive::Box(OrientedBox {
                center_m: *c,
                half_extents_m: BRICK_HALF,
                rotation: rot,
                color: Rgba([0.72 * shade, 0.3 * shade, 0.2 * shade, 1.0]),
            }))?;
        } else {
            f.push(Primitive::Slot(OrientedBox {
                center_m: *c,
                half_extents_m: BRICK_HALF,
                rotation: rot,
                color: Rgba([0.2, 0.35, 0.8, 0.55]),
            }))?;
        }
    }
    // spare bricks in the loading zone
    for i in 0..4 {
        f.push(Primitive::Box(OrientedBox {
            center_m: [
                0.29 + 0.0 * f64::from(i),
                -0.3 + 0.045 * f64::from(i),
                0.017,
            ],
            half_extents_m: BRICK_HALF,
            rotation: q_id,
            color: Rgba::from_u8(180, 80, 50),
        }))?;
    }
    if laid < slots.len() {
        // the carried brick travels from the loading zone to its slot
        let frac = (t / per).fract();
        let (target, turned) = slots[laid];
        let start = [0.33, -0.25, 0.2];
        let hop = 4.0 * frac * (1.0 - frac) * 0.15;
        let p = [
            start[0] + frac * (target[0] - start[0]),
            start[1] + frac * (target[1] - start[1]),
            start[2] + frac * (target[2] - start[2]) + hop,
        ];
        let rot = if turned && frac > 0.5 { q_turn } else { q_id };
        f.push(Primitive::Box(OrientedBox {
            center_m: p,
            half_extents_m: BRICK_HALF,
            rotation: rot,
            color: Rgba::from_u8(220, 110, 60),
        }))?;
        let cursor = [p[0], p[1], p[2] + BRICK_HALF[2] + 0.02];
        f.push(Primitive::Cursor(Ball {
            center_m: cursor,
            radius_m: 0.02,
            color: cursor_color(),
        }))?;
        // weight of the held brick (0.1 kg, 0.98 N) drawn at 0.1 m/N
        f.push(Primitive::Arrow {
            from_m: cursor,
            to_m: [cursor[0], cursor[1], cursor[2] - 0.098],
            color: force_color(),
        })?;
    }
    if labels {
        f.push(Primitive::Label {
            position_m: [0.3, -0.33, 0.0],
            text: "loading zone".into(),
            color: ink(),
        })?;
        f.push(Primitive::Label {
            position_m: [-0.25, 0.12, 0.23],
            text: format!("house: {laid}/{} bricks", slots.len()),
            color: ink(),
        })?;
    }
    Ok(())
}

pub fn bricks_camera(w: u32, h: u32) -> Result<Camera, RenderError> {
    Camera::fit(
        View::oblique_default(),
        [-0.45, -0.35, 0.0],
        [0.45, 0.35, 0.35],
        w,
        h,
        0.02,
    )
}

// ---------------------------------------------------------------- nano world

/// Substrate atoms (teal, fixed), a growing atom house (orange) and the AFM tip with its
/// cantilever, at time `t` (s) of a 60 s session. Atom diameter 0.3 nm.
pub fn draw_nano(f: &mut Frame, t: f64, labels: bool) -> Result<(), RenderError> {
    let r = 0.15e-9;
    let pitch = 0.3e-9;
    let n = 12;
    for i in 0..n {
        for j in 0..n {
            let x = (f64::from(i) - 5.5) * pitch;
            let y = (f64::from(j) - 5.5) * pitch;
            f.push(Primitive::Sphere(Ball {
                center_m: [x, y, -r],
                radius_m: r,
                color: Rgba::from_u8(40, 160, 160),
            }))?;
        }
    }
    // house footprint: a 4×3 ring, three layers, then a ridge
    let mut sites = Vec::new();
    for layer in 0..3 {
        for i in 0..4 {
            for j in 0..3 {
                if i == 0 || i == 3 || j == 0 || j == 2 {
                    let x = (f64::from(i) - 1.5) * pitch;
                    let y = (f64::from(j) - 1.0) * pitch;
                    sites.push([x, y, r + f64::from(layer) * 2.0 * r * 0.95]);
                }
            }
        }
    }
    for i in 0..4 {
        sites.push([(f64::from(i) - 1.5) * pitch, 0.0, r + 3.0 * 2.0 * r * 0.95]);
    }
    let per = 60.0 / sites.len() as f64;
    let placed = ((t / per) as usize).min(sites.len());
    for s in &sites[..placed] {
        f.push(Primitive::Sphere(Ball {
            center_m: *s,
            radius_m: r,
            color: Rgba::from_u8(235, 130, 40),
        }))?;
    }
    // loading zone atoms
    for k in 0..5 {
        f.push(Primitive::Sphere(Ball {
            center_m: [1.3e-9, -1.3e-9 + 0.3e-9 * f64::from(k), r],
            radius_m: r,
            color: Rgba::from_u8(235, 130, 40),
        }))?;
    }
    let frac = (t / per).fract();
    let target = sites.get(placed).copied().unwrap_or([0.0, 0.0, 1.5e-9]);
    let start = [1.3e-9, -1.3e-9, r];
    let hop = 4.0 * frac * (1.0 - frac) * 0.8e-9;
    let atom = [
        start[0] + frac * (target[0] - start[0]),
        start[1] + frac * (target[1] - start[1]),
        start[2] + frac * (target[2] - start[2]) + hop,
    ];
    if placed < sites.len() {
        f.push(Primitive::Sphere(Ball {
            center_m: atom,
            radius_m: r,
            color: Rgba::from_u8(245, 150, 60),
        }))?;
    }
    let tip = [atom[0], atom[1], atom[2] + 2.0 * r];
    f.push(Primitive::Cursor(Ball {
        center_m: tip,
        radius_m: 0.6 * r,
        color: Rgba([0.55, 0.55, 0.6, 0.9]),
    }))?;
    f.push(Primitive::Box(OrientedBox {
        center_m: [tip[0] + 0.7e-9, tip[1], tip[2] + 0.5e-9],
        half_extents_m: [0.7e-9, 0.12e-9, 0.03e-9],
        rotation: [0.0, 0.0, 0.0, 1.0],
        color: Rgba::from_u8(150, 150, 160),
    }))?;
    // adhesion on the tip, about 1 nN, drawn at 0.4 nm/nN
    f.push(Primitive::Arrow {
        from_m: tip,
        to_m: [tip[0], tip[1], tip[2] - 0.4e-9],
        color: force_color(),
    })?;
    if labels {
        f.push(Primitive::Label {
            position_m: [tip[0] + 0.2e-9, tip[1], tip[2] + 0.2e-9],
            text: "AFM tip".into(),
            color: ink(),
        })?;
        f.push(Primitive::Label {
            position_m: [-1.8e-9, -1.8e-9, 0.0],
            text: format!("atoms placed: {placed}/{}", sites.len()),
            color: ink(),
        })?;
    }
    Ok(())
}

pub fn nano_camera(w: u32, h: u32) -> Result<Camera, RenderError> {
    Camera::fit(
        View::Oblique {
            azimuth_rad: -55f64.to_radians(),
            elevation_rad: 35f64.to_radians(),
        },
        [-1.9e-9, -1.9e-9, -0.3e-9],
        [1.9e-9, 1.9e-9, 1.9e-9],
        w,
        h,
        0.02,
    )
}

pub fn new_frame(cam: Camera) -> Result<Frame, RenderError> {
    Frame::new(cam, Style::default())
}
