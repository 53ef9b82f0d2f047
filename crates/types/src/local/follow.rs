//! Bridge protocol 4's primitive: a particle that follows the stylus through its working
//! envelope (the optical-tweezers world, Lee, Lyons & LeBrun §2.4).
//!
//! Each tick the world lets the held particle move by at most its working envelope: the
//! command (stylus − particle) is clipped radially to the envelope, the particle makes the
//! allowed displacement, and the stylus feels a spring on the excess, `F = −k (d − clip(d))`.
//! Protocols 1–3 send that spring as the residual's linear `F0 − K (p − p0)` about a reading a
//! round trip old, while the world's particle has moved on with the hand: inside the envelope,
//! where the world answers nothing, the device renders a drag of `K` times the hand's travel
//! over the round trip (issue 40: a loose Delta.3 behind 10 ms felt 4.53 N where the world gave
//! at most 0.145 N). A [`Follower`] carries the particle and its envelope instead, and the
//! device steps it with each reading as the world does.
//!
//! The follower acts in the device's x–y plane (the trap's focal plane); it pushes nothing
//! along z.
//!
//! ```
//! use haptic_types::local::Follower;
//! // A particle at the origin whose envelope is the square of half-width 1 mm, 100 N/m.
//! let square = vec![[1e-3, -1e-3], [1e-3, 1e-3], [-1e-3, 1e-3], [-1e-3, -1e-3]];
//! let mut f = Follower {
//!     position_m: [0.0; 2],
//!     drift_m: [0.0; 2],
//!     reach_m: square,
//!     retain: 0.0,
//!     stiffness_n_per_m: 100.0,
//! };
//! assert_eq!(f.force([0.5e-3, 0.0, 0.0]), [0.0; 3]); // inside: nothing
//! assert!((f.force([3e-3, 0.0, 0.0])[0] + 0.2).abs() < 1e-12); // 2 mm beyond: 0.2 N back
//! f.step([3e-3, 0.0, 0.0]); // the particle makes 1 mm toward the stylus
//! assert!((f.position_m[0] - 1e-3).abs() < 1e-15);
//! ```

use super::{LocalModel, range};
use crate::vec3::Vec3;
use world_form::fmt_num;

/// Most vertices of a follower's envelope.
pub const MAX_REACH_VERTICES: usize = 24;

/// A particle that follows the stylus, in the device's x–y plane: each sample it moves by the
/// command `d = p − x` clipped to its working envelope, radially from an anchor (the paper's
/// rule: along the segment from the anchor to `d`, stop at the first crossing of the
/// envelope's boundary); the stylus feels `F = −k (d − clip(d))`.
///
/// The envelope moves with the particle's velocity: it is `reach_m` shifted by the free drift
/// `u` (where the particle would go in one sample with no trap force, `v·h` for a particle of
/// mass without drag), and the anchor is zero displacement when the envelope holds it, else
/// the free drift. After a displacement `a` the drift becomes `retain · (2a − u)`: the end
/// velocity of a step of uniform acceleration, kept to `retain` (the paper's viscous
/// simplification).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Follower {
    /// The particle's centre, m, as the next sample meets it (device frame, x and y).
    pub position_m: [f64; 2],
    /// Its free drift over one sample, m (its velocity times the sample's period).
    pub drift_m: [f64; 2],
    /// The working envelope less the free drift: the displacements it can make in one sample
    /// from rest, m, a polygon (counter-clockwise, 3 to [`MAX_REACH_VERTICES`] vertices).
    pub reach_m: Vec<[f64; 2]>,
    /// The share of its velocity the particle keeps from one sample to the next (0–1).
    pub retain: f64,
    /// The spring on the excess, N/m (0 ≤ k ≤ the device's largest stiffness).
    pub stiffness_n_per_m: f64,
}

impl Follower {
    /// The command `d` (m, from the particle) clipped to the envelope: the displacement the
    /// particle makes.
    pub fn clip(&self, d: [f64; 2]) -> [f64; 2] {
        let u = self.drift_m;
        // In the frame of the free drift the envelope is `reach_m`; zero displacement is `−u`.
        let rel = [d[0] - u[0], d[1] - u[1]];
        let c = if contains(&self.reach_m, rel) {
            rel
        } else {
            let zero = [-u[0], -u[1]];
            let anchor = [zero, [0.0; 2]]
                .into_iter()
                .find(|a| contains(&self.reach_m, *a));
            match anchor.and_then(|a| first_crossing(&self.reach_m, a, rel).map(|t| (a, t))) {
                Some((a, t)) => [a[0] + (rel[0] - a[0]) * t, a[1] + (rel[1] - a[1]) * t],
                // The world's fallback too (no anchor inside, or a ray that only grazes a
                // vertex).
                None => nearest_on_boundary(&self.reach_m, rel),
            }
        };
        [c[0] + u[0], c[1] + u[1]]
    }

    /// The command beyond the envelope for a stylus at `p`, m.
    pub fn excess_m(&self, p: Vec3) -> [f64; 2] {
        let d = [p[0] - self.position_m[0], p[1] - self.position_m[1]];
        let c = self.clip(d);
        [d[0] - c[0], d[1] - c[1]]
    }

    /// The spring on the excess at `p`, N (nothing along z).
    pub fn force(&self, p: Vec3) -> Vec3 {
        let e = self.excess_m(p);
        let k = self.stiffness_n_per_m;
        [-k * e[0], -k * e[1], 0.0]
    }

    /// One sample with the stylus at `p`: the particle makes the clipped command, and its
    /// drift becomes what it keeps of its end velocity.
    pub fn step(&mut self, p: Vec3) {
        let d = [p[0] - self.position_m[0], p[1] - self.position_m[1]];
        let a = self.clip(d);
        self.position_m = [self.position_m[0] + a[0], self.position_m[1] + a[1]];
        let u = self.drift_m;
        self.drift_m = [
            self.retain * (2.0 * a[0] - u[0]),
            self.retain * (2.0 * a[1] - u[1]),
        ];
    }
}

/// Whether `p` lies inside the polygon (even–odd rule).
fn contains(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let mut j = poly.len().wrapping_sub(1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// The first `t` in `(0, 1]` where the segment `a + t (b − a)` meets the polygon's boundary.
fn first_crossing(poly: &[[f64; 2]], a: [f64; 2], b: [f64; 2]) -> Option<f64> {
    let r = [b[0] - a[0], b[1] - a[1]];
    let n = poly.len();
    let mut best: Option<f64> = None;
    for i in 0..n {
        let (q, q2) = (poly[i], poly[(i + 1) % n]);
        let s = [q2[0] - q[0], q2[1] - q[1]];
        let den = cross(r, s);
        if den == 0.0 {
            continue;
        }
        let qa = [q[0] - a[0], q[1] - a[1]];
        let t = cross(qa, s) / den;
        let u = cross(qa, r) / den;
        // A ray through a vertex meets both its edges, however the rounding falls.
        let on_edge = (-1e-12..=1.0 + 1e-12).contains(&u);
        if t > 0.0 && t <= 1.0 && on_edge && best.is_none_or(|bt| t < bt) {
            best = Some(t);
        }
    }
    best
}

/// The point of the polygon's boundary nearest `p`.
fn nearest_on_boundary(poly: &[[f64; 2]], p: [f64; 2]) -> [f64; 2] {
    let mut best = (f64::INFINITY, p);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let l2 = d[0] * d[0] + d[1] * d[1];
        let t = if l2 > 0.0 {
            (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + d[0] * t, a[1] + d[1] * t];
        let dist = (p[0] - q[0]).hypot(p[1] - q[1]);
        if dist < best.0 {
            best = (dist, q);
        }
    }
    best.1
}

/// The envelope `poly` (counter-clockwise, displacements, m) as seen from `anchor` in `n`
/// evenly spaced directions (the first from +x): each vertex is where the ray from the anchor
/// first leaves the polygon, so the radial clip of the result follows the original's to within
/// the chord between two directions. `None` when the anchor is outside the polygon or `n < 3`.
pub fn radial_reach(poly: &[[f64; 2]], anchor: [f64; 2], n: usize) -> Option<Vec<[f64; 2]>> {
    if n < 3 || poly.len() < 3 || !contains(poly, anchor) {
        return None;
    }
    let far = poly
        .iter()
        .map(|v| (v[0] - anchor[0]).hypot(v[1] - anchor[1]))
        .fold(0.0f64, f64::max)
        * 2.0;
    if !(far > 0.0 && far.is_finite()) {
        return None;
    }
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let th = std::f64::consts::TAU * k as f64 / n as f64;
        let b = [anchor[0] + far * th.cos(), anchor[1] + far * th.sin()];
        let t = first_crossing(poly, anchor, b)?;
        out.push([
            anchor[0] + (b[0] - anchor[0]) * t,
            anchor[1] + (b[1] - anchor[1]) * t,
        ]);
    }
    Some(out)
}

/// Checks protocol 4's part of a model: a finite follower whose envelope has 3 to
/// [`MAX_REACH_VERTICES`] vertices and holds its anchor, with a stiffness within the device's
/// cap.
pub(super) fn check(m: &LocalModel, max_stiffness_n_per_m: f64) -> Result<(), String> {
    let Some(f) = &m.follower else {
        return Ok(());
    };
    let finite2 = |v: [f64; 2]| v[0].is_finite() && v[1].is_finite();
    if !finite2(f.position_m) || !finite2(f.drift_m) || !f.reach_m.iter().all(|v| finite2(*v)) {
        return Err("follower: the position, drift and envelope must be finite".into());
    }
    let n = f.reach_m.len();
    if !(3..=MAX_REACH_VERTICES).contains(&n) {
        return Err(range(
            "follower.reach_m (vertices)",
            n as f64,
            format!("3 ≤ n ≤ {MAX_REACH_VERTICES}"),
        ));
    }
    let zero = [-f.drift_m[0], -f.drift_m[1]];
    if !contains(&f.reach_m, [0.0; 2]) && !contains(&f.reach_m, zero) {
        return Err("follower: the envelope must hold zero displacement or the free drift".into());
    }
    if !(0.0..=1.0).contains(&f.retain) {
        return Err(range("follower.retain", f.retain, "0 ≤ r ≤ 1"));
    }
    if !(0.0..=max_stiffness_n_per_m).contains(&f.stiffness_n_per_m) {
        return Err(range(
            "follower.stiffness_n_per_m",
            f.stiffness_n_per_m,
            format!("0 ≤ k ≤ {} N/m", fmt_num(max_stiffness_n_per_m)),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(h: f64) -> Vec<[f64; 2]> {
        vec![[h, -h], [h, h], [-h, h], [-h, -h]]
    }

    fn follower() -> Follower {
        Follower {
            position_m: [0.0; 2],
            drift_m: [0.0; 2],
            reach_m: square(1e-3),
            retain: 0.0,
            stiffness_n_per_m: 100.0,
        }
    }

    /// Inside the envelope the particle keeps up and nothing is felt; beyond it the spring
    /// acts on the excess only, along the ray from the anchor.
    #[test]
    fn a_follower_pushes_only_on_the_excess_along_the_ray_from_its_anchor() {
        let f = follower();
        assert_eq!(f.force([0.9e-3, -0.9e-3, 0.5]), [0.0; 3]);
        // 3 mm along the diagonal: the ray leaves the square at its corner.
        let e = f.excess_m([3e-3, 3e-3, 0.0]);
        assert!((e[0] - 2e-3).abs() < 1e-15 && (e[1] - 2e-3).abs() < 1e-15);
        // A particle drifting 2 mm a sample, whose envelope no longer holds zero displacement:
        // the clip starts from the free drift. From it, the command (5, 1) mm leaves the
        // envelope (x from 1 to 3 mm) at x = 3 mm, y = 1/3 mm.
        let g = Follower {
            drift_m: [2e-3, 0.0],
            ..follower()
        };
        let c = g.clip([5e-3, 1e-3]);
        assert!((c[0] - 3e-3).abs() < 1e-15 && (c[1] - 1e-3 / 3.0).abs() < 1e-15);
        // Inside the shifted envelope the command is made whole.
        assert_eq!(g.clip([2.5e-3, -0.5e-3]), [2.5e-3, -0.5e-3]);
        // The force is −k times the excess, and nothing along z.
        let f3 = f.force([3e-3, 0.0, 7.0]);
        assert!((f3[0] + 0.2).abs() < 1e-12 && f3[1] == 0.0 && f3[2] == 0.0);
    }

    /// Stepped with a stylus held still beyond the envelope, the particle walks to it at one
    /// envelope a sample and then rests there, the force falling to zero.
    #[test]
    fn a_follower_catches_a_still_stylus_at_one_envelope_a_sample() {
        let mut f = follower();
        let p = [3.5e-3, 0.0, 0.0];
        let mut forces = Vec::new();
        for _ in 0..5 {
            forces.push(f.force(p)[0]);
            f.step(p);
        }
        assert!((forces[0] + 0.25).abs() < 1e-12);
        assert!((forces[1] + 0.15).abs() < 1e-12);
        assert!((forces[2] + 0.05).abs() < 1e-12);
        assert_eq!(&forces[3..], &[0.0, 0.0]);
        assert!((f.position_m[0] - 3.5e-3).abs() < 1e-15);
    }

    /// The drift follows the step's end velocity kept to `retain`: from rest with the stylus
    /// far ahead, 1 mm, then 1.2 mm (the envelope shifted by the 0.2 mm drift), the drift
    /// 0.2 then 0.22 mm.
    #[test]
    fn a_follower_drifts_by_what_it_keeps_of_its_end_velocity() {
        let mut f = Follower {
            retain: 0.1,
            ..follower()
        };
        let p = [0.1, 0.0, 0.0];
        f.step(p);
        assert!((f.position_m[0] - 1e-3).abs() < 1e-15);
        assert!((f.drift_m[0] - 0.2e-3).abs() < 1e-15);
        f.step(p);
        assert!((f.position_m[0] - 2.2e-3).abs() < 1e-15);
        assert!((f.drift_m[0] - 0.22e-3).abs() < 1e-15);
        assert_eq!(f.drift_m[1], 0.0);
    }

    /// The radial resampling reaches the original's boundary in every direction sampled, and
    /// a 2:1 ellipse seen in 24 directions clips within its chord error (3.0 % of the reach).
    #[test]
    fn the_radial_reach_follows_the_envelope_within_its_chord() {
        let ellipse: Vec<[f64; 2]> = (0..400)
            .map(|k| {
                let th = std::f64::consts::TAU * f64::from(k) / 400.0;
                [2e-3 * th.cos(), 1e-3 * th.sin()]
            })
            .collect();
        let r = radial_reach(&ellipse, [0.0; 2], MAX_REACH_VERTICES).unwrap();
        assert_eq!(r.len(), 24);
        assert!((r[0][0] - 2e-3).abs() < 1e-9 && r[0][1].abs() < 1e-12);
        assert!((r[6][1] - 1e-3).abs() < 1e-9 && r[6][0].abs() < 1e-9);
        let full = Follower {
            reach_m: ellipse.clone(),
            ..follower()
        };
        let coarse = Follower {
            reach_m: r,
            ..follower()
        };
        let mut worst = 1.0f64;
        for k in 0..3600 {
            let th = (f64::from(k) / 10.0).to_radians();
            let d = [5e-3 * th.cos(), 5e-3 * th.sin()];
            let (a, b) = (full.clip(d), coarse.clip(d));
            let (ra, rb) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
            assert!(rb <= ra * (1.0 + 1e-9), "{k}: {rb} of {ra}");
            worst = worst.min(rb / ra);
        }
        // The chord's worst, at the 2:1 ellipse's sharp ends: 3.0 % of the reach short.
        assert!((0.968..0.972).contains(&worst), "{worst}");
        assert!(radial_reach(&ellipse, [3e-3, 0.0], 32).is_none());
    }

    /// Protocol 4's part is checked by field and range.
    #[test]
    fn a_bad_follower_is_refused_by_name() {
        let mut m = LocalModel {
            follower: Some(Follower {
                reach_m: square(1e-3)[..2].to_vec(),
                ..follower()
            }),
            ..LocalModel::default()
        };
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "follower.reach_m (vertices) = 2 is out of range: allowed 3 ≤ n ≤ 24"
        );
        m.follower = Some(Follower {
            reach_m: square(1e-3).iter().map(|v| [v[0] + 3e-3, v[1]]).collect(),
            ..follower()
        });
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "follower: the envelope must hold zero displacement or the free drift"
        );
        m.follower = Some(Follower {
            retain: 1.5,
            ..follower()
        });
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "follower.retain = 1.5 is out of range: allowed 0 ≤ r ≤ 1"
        );
        m.follower = Some(Follower {
            stiffness_n_per_m: 2000.0,
            ..follower()
        });
        assert_eq!(
            m.check(1000.0).unwrap_err(),
            "follower.stiffness_n_per_m = 2000 is out of range: allowed 0 ≤ k ≤ 1000 N/m"
        );
        m.follower = Some(follower());
        assert_eq!(m.check(1000.0), Ok(()));
    }
}
