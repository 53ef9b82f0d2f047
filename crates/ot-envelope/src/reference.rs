//! The dense brute-force reference an envelope is judged against: the
//! forward map sampled on a fine grid of offsets (by a reference propagator,
//! e.g. converged DOP853), and the two one-sided errors of a polygon:
//! * `outside`: how far sampled reachable displacements lie outside it;
//! * `overreach`: how far its boundary lies from any reachable displacement
//!   (nearest sample, then polished by Levenberg–Marquardt on `|F(o) − p|`).
//!
//! Their maximum is the Hausdorff distance between the polygon's region and
//! the reachable set (to the sampling's resolution, reported as `spacing`).

use crate::error::Result;
use crate::geometry::{PolygonIndex, nearest_on_boundary};
use crate::region::OffsetRegion;
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// A dense forward sampling of the tick map.
#[derive(Debug, Clone)]
pub struct Reference {
    /// Sampled offsets (m).
    pub offsets: Vec<V2>,
    /// Their displacements (m).
    pub images: Vec<V2>,
    /// Velocity (m/s).
    pub v0: V2,
    lo: V2,
    cell: f64,
    nb: [usize; 2],
    buckets: Vec<Vec<u32>>,
}

/// Errors of a polygon against the reference (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefErrors {
    /// Largest distance of a sampled displacement outside the polygon (m).
    pub outside: f64,
    /// Largest distance of a boundary point from the reachable set (m).
    pub overreach: f64,
}

impl RefErrors {
    /// `max(outside, overreach)` (m).
    pub fn hausdorff(&self) -> f64 {
        self.outside.max(self.overreach)
    }
}

impl Reference {
    /// Sample `n × n` offsets over `region` with `prop`.
    pub fn sample(prop: &Propagator<2>, v0: &V2, region: &OffsetRegion, n: usize) -> Result<Self> {
        let n = n.max(2);
        let mut offsets = Vec::with_capacity(n * n);
        let mut images = Vec::with_capacity(n * n);
        let ext = region.hi - region.lo;
        for i in 0..n {
            for j in 0..n {
                let o = region.lo
                    + V2::new(
                        ext.x * i as f64 / (n - 1) as f64,
                        ext.y * j as f64 / (n - 1) as f64,
                    );
                let (d, _, _) = prop.flow(&o, v0)?;
                offsets.push(o);
                images.push(d);
            }
        }
        let (mut lo, mut hi) = (images[0], images[0]);
        for p in &images {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let span = (hi - lo).max().max(1e-15);
        let cell = span / 400.0;
        let nb = [
            ((hi.x - lo.x) / cell) as usize + 1,
            ((hi.y - lo.y) / cell) as usize + 1,
        ];
        let mut buckets = vec![Vec::new(); nb[0] * nb[1]];
        for (k, p) in images.iter().enumerate() {
            let (i, j) = (
                ((p.x - lo.x) / cell) as usize,
                ((p.y - lo.y) / cell) as usize,
            );
            buckets[i.min(nb[0] - 1) * nb[1] + j.min(nb[1] - 1)].push(k as u32);
        }
        Ok(Self {
            offsets,
            images,
            v0: *v0,
            lo,
            cell,
            nb,
            buckets,
        })
    }

    /// Indices of the `k` samples whose images are nearest to `p`, nearest first.
    pub fn nearest_k(&self, p: &V2, k: usize) -> Vec<usize> {
        let ci = ((p.x - self.lo.x) / self.cell).floor() as i64;
        let cj = ((p.y - self.lo.y) / self.cell).floor() as i64;
        let mut found: Vec<(f64, usize)> = Vec::new();
        for r in 0i64.. {
            for i in ci - r..=ci + r {
                for j in cj - r..=cj + r {
                    if (i - ci).abs() != r && (j - cj).abs() != r {
                        continue;
                    }
                    if i < 0 || j < 0 || i >= self.nb[0] as i64 || j >= self.nb[1] as i64 {
                        continue;
                    }
                    for &q in &self.buckets[i as usize * self.nb[1] + j as usize] {
                        found.push(((self.images[q as usize] - p).norm(), q as usize));
                    }
                }
            }
            found.sort_by(|a, b| a.0.total_cmp(&b.0));
            let done = found.len() >= k && found[k - 1].0 < (r as f64) * self.cell;
            if done || r as usize > self.nb[0] + self.nb[1] {
                break;
            }
        }
        found.into_iter().take(k).map(|x| x.1).collect()
    }

    /// Index of the sample whose image is nearest to `p`.
    pub fn nearest(&self, p: &V2) -> usize {
        self.nearest_k(p, 1).first().copied().unwrap_or(0)
    }

    /// Distance (m) from `p` to the reachable set: Levenberg–Marquardt on
    /// `|F(o) − p|²` with `prop` from the offsets of the 8 nearest samples
    /// (a folded map has local minima on other sheets); the smallest wins.
    pub fn distance(&self, prop: &Propagator<2>, p: &V2) -> Result<f64> {
        let mut best = f64::INFINITY;
        for k in self.nearest_k(p, 8) {
            best = best.min(self.polish(prop, p, k)?);
            if best < 1e-13 {
                break;
            }
        }
        Ok(best)
    }

    fn polish(&self, prop: &Propagator<2>, p: &V2, k: usize) -> Result<f64> {
        let mut o = self.offsets[k];
        let mut best = (self.images[k] - p).norm();
        let mut mu = 1e-3;
        for _ in 0..30 {
            let f = prop.flow_offset_jacobian(&o, &self.v0)?;
            let r = f.displacement - p;
            best = best.min(r.norm());
            let j = f.d_offset;
            let a = j.transpose() * j
                + nalgebra::Matrix2::identity() * (mu * (j.norm_squared() + 1e-30));
            let Some(inv) = a.try_inverse() else { break };
            let step = -(inv * (j.transpose() * r));
            let (d2, _, _) = prop.flow(&(o + step), &self.v0)?;
            if (d2 - p).norm() < r.norm() {
                o += step;
                mu = (mu * 0.3).max(1e-12);
            } else {
                mu *= 10.0;
            }
        }
        Ok(best)
    }

    /// Errors of `poly` (m); boundary points every `step` (m).
    pub fn errors(&self, prop: &Propagator<2>, poly: &[V2], step: f64) -> Result<RefErrors> {
        let mut outside: f64 = 0.0;
        let index = PolygonIndex::new(poly, 512);
        for p in &self.images {
            if !index.contains(p) {
                outside = outside.max(nearest_on_boundary(poly, p).1);
            }
        }
        let mut overreach: f64 = 0.0;
        let n = poly.len();
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let k = (((b - a).norm() / step).ceil() as usize).max(1);
            for s in 0..k {
                let x = a + (b - a) * (s as f64 / k as f64);
                overreach = overreach.max(self.distance(prop, &x)?);
            }
        }
        Ok(RefErrors { outside, overreach })
    }
}
