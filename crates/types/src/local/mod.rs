//! The local model a device renders between the simulator's answers (bridge protocol 2): an
//! intermediate representation in the sense of Adachi et al. (1995) and Mark et al. (1996).
//!
//! Everything is in the device's frame and units (m, N, N/m, N·s/m, kg), with the mapping's
//! scales and the safety layer's gain already applied by the simulator. The device evaluates it
//! at its own servo rate at the position it reads *now*, so a contact that begins between two
//! answers is felt at once, not a round trip late:
//!
//! `F(p) = F_r − K_r (p − p0) + Σ planes(p) + body(p)`
//!
//! - `F_r, K_r`: the residual — the world's force at the answered reading `p0` less what the
//!   local primitives give there, and the world's stiffness less theirs;
//! - a [`Plane`] pushes along its normal in proportion to how far the stylus is behind it;
//! - a [`Body`] is the carried body's coupling: the device integrates the body itself (its
//!   mass on the coupling's spring-damper, under the force the world puts on it), starting
//!   from the state the simulator reports for the answered sample and replaying its own
//!   readings since, so the coupling's dynamics never wait for the link;
//! - a [`Bond`] (protocol 3) is a spring that breaks where the world's contact lets go;
//! - a [`Follower`] (protocol 4) is a particle that follows the stylus through its working
//!   envelope, stepped by the device with its readings as the body is.
//!
//! ```
//! use haptic_types::local::{LocalModel, Plane};
//! let floor = Plane { normal: [0.0, 0.0, 1.0], offset_m: 0.0, stiffness_n_per_m: 1000.0 };
//! let m = LocalModel { planes: vec![floor], ..LocalModel::default() };
//! // 2 mm below the floor: 2 N up.
//! let f = m.static_force([0.0, 0.0, -0.002], [0.0; 3]);
//! assert!((f[2] - 2.0).abs() < 1e-12);
//! ```

mod bond;
mod follow;

pub use bond::Bond;
pub use follow::{Follower, MAX_REACH_VERTICES, radial_reach};

use crate::value::ValueError;
use crate::vec3::{self, Vec3};
use world_form::fmt_num;

/// Most planes one answer carries.
pub const MAX_PLANES: usize = 4;

/// A unilateral contact plane: `F = k · max(0, offset − n·p) · n`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Plane {
    /// Unit outward normal, device frame.
    pub normal: Vec3,
    /// The plane is `n·p = offset_m`, m; the stylus is in contact where `n·p < offset_m`.
    pub offset_m: f64,
    /// Stiffness, N/m (0 ≤ k ≤ the device's largest stiffness).
    pub stiffness_n_per_m: f64,
}

impl Plane {
    /// The plane's push at `p`, N.
    pub fn force(&self, p: Vec3) -> Vec3 {
        let depth = self.offset_m - vec3::dot(self.normal, p);
        if depth > 0.0 {
            vec3::scale(self.normal, self.stiffness_n_per_m * depth)
        } else {
            [0.0; 3]
        }
    }

    /// Its stiffness matrix at `p`: `k n nᵀ` in contact, 0 outside (row-major).
    pub fn stiffness_at(&self, p: Vec3) -> [f64; 9] {
        let mut m = [0.0; 9];
        if self.offset_m - vec3::dot(self.normal, p) > 0.0 {
            for i in 0..3 {
                for j in 0..3 {
                    m[3 * i + j] = self.stiffness_n_per_m * self.normal[i] * self.normal[j];
                }
            }
        }
        m
    }
}

/// The carried body and its coupling to the stylus (device frame and units): a spring `k` in
/// parallel with a damper `b` that acts through a series spring `k_s` (a Maxwell element,
/// written in positions so no velocity is estimated from encoder counts). With `lead = p − x`
/// (the stylus's lead on the body's grip point) and `e` the dashpot's share of it, one step of
/// `h` is `e ← (e + r·lead) / (1 + r)` with `r = h k_s / b`, the pull on the body
/// `k·lead + k_s (lead − e)` (the stylus feels `−pull`), and the body's step as a rigid-body
/// engine with `n` substeps makes it: the pull as an impulse, then the external force in `n`
/// symplectic Euler substeps: `v ← v + h (pull + F_ext) / m`,
/// `x ← x + h (v₀ + h pull / m) + h² F_ext / m · (n + 1) / (2n)`. Contact planes of the body
/// ([`LocalModel::body_planes`]) then hold it: a body behind one is put back on it and loses
/// its normal velocity into it (or leaves at `restitution` times it).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Body {
    /// The body's grip point, m, in the state from which the next sample is stepped.
    pub position_m: Vec3,
    /// Its velocity, m/s.
    pub velocity_m_per_s: Vec3,
    /// The body's mass as the device feels it (`M · force_scale · workspace_scale`), kg.
    pub mass_kg: f64,
    /// The coupling's spring `k`, N/m.
    pub stiffness_n_per_m: f64,
    /// The damper's series spring `k_s`, N/m.
    pub series_stiffness_n_per_m: f64,
    /// The damper `b`, N·s/m.
    pub damping_n_s_per_m: f64,
    /// The dashpot's share `e` of the lead, m.
    pub damper_m: Vec3,
    /// The force the world puts on the body besides the coupling (its weight), N.
    pub external_force_n: Vec3,
    /// Substeps of the world's rigid-body engine per step (1 for plain symplectic Euler).
    pub substeps: u32,
    /// Restitution of the body's contacts: a body meeting a plane at normal speed `vₙ`
    /// leaves it at `restitution · vₙ`. Range `[0, 1]`.
    pub restitution: f64,
}

impl Body {
    /// The pull on the body for a stylus at `p` over a step of `h_s`, N, and the dashpot's new
    /// share (the state is not changed).
    pub fn pull(&self, p: Vec3, h_s: f64) -> (Vec3, Vec3) {
        let lead = vec3::sub(p, self.position_m);
        let (k, ks, b) = (
            self.stiffness_n_per_m,
            self.series_stiffness_n_per_m,
            self.damping_n_s_per_m,
        );
        if b > 0.0 && ks > 0.0 {
            let r = h_s * ks / b;
            let e = vec3::scale(
                vec3::add(self.damper_m, vec3::scale(lead, r)),
                1.0 / (1.0 + r),
            );
            let pull = vec3::add(vec3::scale(lead, k), vec3::scale(vec3::sub(lead, e), ks));
            (pull, e)
        } else {
            (vec3::scale(lead, k), [0.0; 3])
        }
    }

    /// One step of `h_s` with the stylus at `p`: the body moves under the pull and its
    /// external force and stays in front of `planes`; returns the pull, N.
    pub fn step(&mut self, p: Vec3, h_s: f64, planes: &[Plane]) -> Vec3 {
        let (pull, e) = self.pull(p, h_s);
        self.damper_m = e;
        let n = f64::from(self.substeps.max(1));
        let im = 1.0 / self.mass_kg;
        let v0 = vec3::add(self.velocity_m_per_s, vec3::scale(pull, h_s * im));
        let g = vec3::scale(self.external_force_n, im);
        self.velocity_m_per_s = vec3::add(v0, vec3::scale(g, h_s));
        let dx = vec3::add(
            vec3::scale(v0, h_s),
            vec3::scale(g, h_s * h_s * (n + 1.0) / (2.0 * n)),
        );
        self.position_m = vec3::add(self.position_m, dx);
        for pl in planes {
            let depth = pl.offset_m - vec3::dot(pl.normal, self.position_m);
            if depth > 0.0 {
                self.position_m = vec3::add(self.position_m, vec3::scale(pl.normal, depth));
                let vn = vec3::dot(pl.normal, self.velocity_m_per_s);
                if vn < 0.0 {
                    self.velocity_m_per_s = vec3::sub(
                        self.velocity_m_per_s,
                        vec3::scale(pl.normal, (1.0 + self.restitution) * vn),
                    );
                }
            }
        }
        pull
    }
}

/// The felt-mass ratio of a body of mass `m` (kg) carried through the coupling of [`Body`]
/// (spring `k`, damper `b` through the series spring `k_s`; N/m, N·s/m) by a hand moving at
/// `omega` (rad/s): the amplitude of the force the hand feels over `m ω²` times the hand's
/// amplitude, `|K / (K − m ω²)|` with the coupling's impedance
/// `K(iω) = k + iω b k_s / (k_s + iω b)` (continuous time; the code's steps change it by a
/// fraction of `ω h`). It lies between the dashpot's two limits, locked
/// (`1 / (1 − m ω² / (k + k_s))`) and free (`1 / (1 − m ω² / k)`), and is 1 for a rigid
/// coupling: the felt inertia's error is this less 1, about `m ω² / k` while that is small.
///
/// ```
/// use haptic_types::local::felt_mass_ratio;
/// // The brick world's 0.5 kg brick on a Falcon (issue 31): +15.86 % at 2 Hz.
/// let w = 4.0 * std::f64::consts::PI;
/// let h = felt_mass_ratio(360.0, 360.0, 2.0 * 0.9 * (360.0f64 * 0.5).sqrt(), 0.5, w);
/// assert!((h - 1.1586).abs() < 5e-5);
/// ```
pub fn felt_mass_ratio(k: f64, k_s: f64, b: f64, m: f64, omega: f64) -> f64 {
    // iω b k_s / (k_s + iω b) = (ω² b² k_s + iω b k_s²) / (k_s² + ω² b²); a free dashpot
    // (b = 0 or k_s = 0) adds nothing.
    let (wb, den) = (omega * b, k_s * k_s + (omega * b).powi(2));
    let (re, im) = if den > 0.0 {
        (k + wb * wb * k_s / den, wb * k_s * k_s / den)
    } else {
        (k, 0.0)
    };
    re.hypot(im) / (re - m * omega * omega).hypot(im)
}

/// The scene's primitives in the world frame and units (m, N, N/m, kg), before the loop maps
/// them to the device ([`LocalModel`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorldPrimitives {
    /// Contact planes near the cursor.
    pub planes: Vec<Plane>,
    /// The carried body.
    pub body: Option<Body>,
    /// Surfaces the carried body touches or nears (hard contacts on its grip point).
    pub body_planes: Vec<Plane>,
    /// The anchored contact of an adhesive world: a spring that breaks (protocol 3).
    pub bond: Option<Bond>,
    /// The held particle of the optical-tweezers world, as the answered sample met it
    /// (protocol 4).
    pub follower: Option<Follower>,
}

impl WorldPrimitives {
    /// Empties the list for reuse.
    pub fn clear(&mut self) {
        self.planes.clear();
        self.body = None;
        self.body_planes.clear();
        self.bond = None;
        self.follower = None;
    }
}

/// What one answer asks the device to render until the next (see the module docs).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LocalModel {
    /// The world's force at the answered reading less the primitives' there, N.
    pub residual_force_n: Vec3,
    /// The world's stiffness less the primitives', N/m, row-major.
    pub residual_stiffness_n_per_m: [f64; 9],
    /// Contact planes (at most [`MAX_PLANES`]).
    pub planes: Vec<Plane>,
    /// The carried body, when one is carried through a coupling.
    pub body: Option<Body>,
    /// Surfaces the carried body touches or nears (at most [`MAX_PLANES`]): the body's grip
    /// point stays where `n·x ≥ offset` (hard contacts; their stiffness is not used).
    pub body_planes: Vec<Plane>,
    /// The net energy the world has delivered to the hand through this port since the start
    /// (the work of the forces it answered on the readings it received), J: the device never
    /// gives the hand more than this plus its reserve (the two-port passivity layer).
    pub world_energy_j: f64,
    /// A spring that breaks (protocol 3; none in a version-2 session).
    pub bond: Option<Bond>,
    /// A particle that follows the stylus through its envelope (protocol 4; none before): its
    /// state is the one the answered sample met, and the device steps it from that sample on.
    pub follower: Option<Follower>,
}

impl Default for LocalModel {
    fn default() -> Self {
        LocalModel {
            residual_force_n: [0.0; 3],
            residual_stiffness_n_per_m: [0.0; 9],
            planes: Vec::new(),
            body: None,
            body_planes: Vec::new(),
            world_energy_j: 0.0,
            bond: None,
            follower: None,
        }
    }
}

impl LocalModel {
    /// The residual and the planes at `p` for the answered reading `p0` (the body excluded: it
    /// has a state of its own) and the bond, N.
    pub fn static_force(&self, p: Vec3, p0: Vec3) -> Vec3 {
        let d = vec3::sub(p, p0);
        let k = &self.residual_stiffness_n_per_m;
        let mut f = self.residual_force_n;
        for (i, fi) in f.iter_mut().enumerate() {
            *fi -= k[3 * i] * d[0] + k[3 * i + 1] * d[1] + k[3 * i + 2] * d[2];
        }
        for pl in &self.planes {
            f = vec3::add(f, pl.force(p));
        }
        if let Some(b) = &self.bond {
            f = vec3::add(f, b.force(p));
        }
        f
    }

    /// Whether every number is finite and every stiffness, damping and mass in range
    /// (`max_stiffness_n_per_m` the device's cap); the reason when not.
    pub fn check(&self, max_stiffness_n_per_m: f64) -> Result<(), String> {
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        if !finite(&self.residual_force_n)
            || !finite(&self.residual_stiffness_n_per_m)
            || !self.world_energy_j.is_finite()
        {
            return Err("a residual force, stiffness or energy is not finite".into());
        }
        check_planes("plane", &self.planes)?;
        for (i, p) in self.planes.iter().enumerate() {
            if !(0.0..=max_stiffness_n_per_m).contains(&p.stiffness_n_per_m) {
                return Err(range(
                    format!("plane[{i}].stiffness_n_per_m"),
                    p.stiffness_n_per_m,
                    format!("0 ≤ k ≤ {} N/m", fmt_num(max_stiffness_n_per_m)),
                ));
            }
        }
        check_planes("body plane", &self.body_planes)?;
        bond::check(self, max_stiffness_n_per_m)?;
        follow::check(self, max_stiffness_n_per_m)?;
        if let Some(b) = &self.body {
            if !(0.0..=1.0).contains(&b.restitution) {
                return Err(range("body.restitution", b.restitution, "0 ≤ e ≤ 1"));
            }
            if !(1..=64).contains(&b.substeps) {
                return Err(range("body.substeps", f64::from(b.substeps), "1 ≤ n ≤ 64"));
            }
            if !finite(&b.position_m)
                || !finite(&b.velocity_m_per_s)
                || !finite(&b.external_force_n)
                || !finite(&b.damper_m)
            {
                return Err("the body's state or force is not finite".into());
            }
            if !(b.mass_kg > 0.0 && b.mass_kg <= 1e4) {
                return Err(range("body.mass_kg", b.mass_kg, "0 < m ≤ 10000 kg"));
            }
            if !(0.0..=max_stiffness_n_per_m)
                .contains(&(b.stiffness_n_per_m + b.series_stiffness_n_per_m))
                || b.stiffness_n_per_m < 0.0
                || b.series_stiffness_n_per_m < 0.0
            {
                return Err(range(
                    format!(
                        "body.stiffness_n_per_m + body.series_stiffness_n_per_m ({} + {} N/m)",
                        fmt_num(b.stiffness_n_per_m),
                        fmt_num(b.series_stiffness_n_per_m)
                    ),
                    b.stiffness_n_per_m + b.series_stiffness_n_per_m,
                    format!(
                        "0 ≤ k + k_s ≤ {} N/m, each ≥ 0",
                        fmt_num(max_stiffness_n_per_m)
                    ),
                ));
            }
            if !(0.0..=1e4).contains(&b.damping_n_s_per_m) {
                return Err(range(
                    "body.damping_n_s_per_m",
                    b.damping_n_s_per_m,
                    "0 ≤ b ≤ 10000 N·s/m",
                ));
            }
        }
        Ok(())
    }
}

/// The message of a local-model number out of range (the one wording, [`ValueError`]).
pub(crate) fn range(
    field: impl Into<std::borrow::Cow<'static, str>>,
    value: f64,
    allowed: impl Into<std::borrow::Cow<'static, str>>,
) -> String {
    ValueError::out_of_range(field, value, allowed).to_string()
}

/// At most [`MAX_PLANES`] planes (`what`: how errors name them), each with a finite unit
/// normal and a finite offset.
fn check_planes(what: &str, planes: &[Plane]) -> Result<(), String> {
    if planes.len() > MAX_PLANES {
        return Err(format!(
            "{} {what}s: allowed at most {MAX_PLANES}",
            planes.len()
        ));
    }
    for (i, p) in planes.iter().enumerate() {
        let n = vec3::norm(p.normal);
        if !vec3::is_finite(p.normal) || (n - 1.0).abs() > 1e-6 || !p.offset_m.is_finite() {
            return Err(format!(
                "{what} {i}: the normal must be a finite unit vector"
            ));
        }
    }
    Ok(())
}
