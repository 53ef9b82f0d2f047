//! Plane geometry on displacement polygons: the outer boundary of a set of
//! polylines (a planar arrangement walked with the right-hand rule), point in
//! polygon, nearest boundary point, ray exit and Hausdorff distances.
//!
//! Coordinates are whatever the caller passes (the envelope uses metres).

use nalgebra::Vector2;
use std::collections::BTreeMap;

type V2 = Vector2<f64>;

#[inline]
fn cross(a: &V2, b: &V2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Union–find over vertex ids.
struct Dsu(Vec<usize>);
impl Dsu {
    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            self.0[hi] = lo;
        }
    }
}

/// Most segment pairs [`try_outer_boundary`] tests for crossings (pairs sharing a bucket of
/// its grid): about a second of work. A working envelope at the paper's constants needs at
/// most some 10⁴ (ticks up to 4 oscillation periods, an accurate tick map); a tangle of fold
/// images from a tick map too coarse for a long tick needs 10⁷ and more.
pub const MAX_SEGMENT_PAIRS: u64 = 2_000_000;

/// The outer boundary of the union of `polylines` (each closed when its flag
/// is true): the loop that separates the unbounded face of their planar
/// arrangement from the rest. Returned counter-clockwise, first vertex not
/// repeated. Points that are bit-identical are the same vertex; crossings
/// closer than `snap` (same unit as the points) to an endpoint snap onto it.
///
/// Returns an empty vector when there are no segments. Under a raised
/// [`ot_physics::cancel`] flag it returns an empty vector early: use
/// [`try_outer_boundary`] to tell the two apart.
/// It tests every candidate pair of segments, however many ([`try_outer_boundary`] bounds
/// them).
pub fn outer_boundary(polylines: &[(Vec<V2>, bool)], snap: f64) -> Vec<V2> {
    boundary(polylines, snap, u64::MAX).unwrap_or_default()
}

/// [`outer_boundary`] that stops with [`ot_physics::PhysicsError::OutOfRange`] when the
/// crossing search would test more than [`MAX_SEGMENT_PAIRS`] segment pairs, and with
/// [`ot_physics::PhysicsError::Interrupted`] when the
/// thread's [`ot_physics::cancel`] flag is raised (it checks once per segment of the
/// crossing search, its costly part: a tangled arrangement at a long Δt takes minutes).
pub fn try_outer_boundary(
    polylines: &[(Vec<V2>, bool)],
    snap: f64,
) -> Result<Vec<V2>, ot_physics::PhysicsError> {
    boundary(polylines, snap, MAX_SEGMENT_PAIRS)
}

fn boundary(
    polylines: &[(Vec<V2>, bool)],
    snap: f64,
    max_pairs: u64,
) -> Result<Vec<V2>, ot_physics::PhysicsError> {
    // 1. vertices (bit-identical points merged) and segments.
    let mut pts: Vec<V2> = Vec::new();
    let mut ids: BTreeMap<(u64, u64), usize> = BTreeMap::new();
    let mut segs: Vec<(usize, usize)> = Vec::new();
    let mut id_of = |p: &V2, pts: &mut Vec<V2>| -> usize {
        *ids.entry((p.x.to_bits(), p.y.to_bits()))
            .or_insert_with(|| {
                pts.push(*p);
                pts.len() - 1
            })
    };
    for (line, closed) in polylines {
        if line.len() < 2 {
            continue;
        }
        let vid: Vec<usize> = line.iter().map(|p| id_of(p, &mut pts)).collect();
        for w in vid.windows(2) {
            if w[0] != w[1] {
                segs.push((w[0], w[1]));
            }
        }
        if *closed && vid[0] != vid[vid.len() - 1] {
            segs.push((vid[vid.len() - 1], vid[0]));
        }
    }
    if segs.is_empty() {
        return Ok(Vec::new());
    }
    // 2. all crossings, found through a bucket grid.
    let (mut lo, mut hi) = (pts[0], pts[0]);
    for p in &pts {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let mean_len = segs
        .iter()
        .map(|&(a, b)| (pts[b] - pts[a]).norm())
        .sum::<f64>()
        / segs.len() as f64;
    let span = (hi - lo).max().max(f64::MIN_POSITIVE);
    let cell = (mean_len * 2.0).max(span / 512.0).max(f64::MIN_POSITIVE);
    let nbx = (((hi.x - lo.x) / cell) as usize + 1).min(1024);
    let nby = (((hi.y - lo.y) / cell) as usize + 1).min(1024);
    let bucket = |p: &V2| -> (usize, usize) {
        (
            (((p.x - lo.x) / cell) as usize).min(nbx - 1),
            (((p.y - lo.y) / cell) as usize).min(nby - 1),
        )
    };
    let mut grid: Vec<Vec<usize>> = vec![Vec::new(); nbx * nby];
    for (k, &(a, b)) in segs.iter().enumerate() {
        let (i0, j0) = bucket(&pts[a].inf(&pts[b]));
        let (i1, j1) = bucket(&pts[a].sup(&pts[b]));
        for i in i0..=i1 {
            for j in j0..=j1 {
                grid[i * nby + j].push(k);
            }
        }
    }
    // The crossing search tests every pair of segments sharing a bucket: bound it before
    // it starts (a tangle of fold images costs minutes, and its boundary is no envelope one
    // can use).
    let pairs: u64 = grid
        .iter()
        .map(|l| (l.len() as u64) * (l.len() as u64).saturating_sub(1) / 2)
        .sum();
    if pairs > max_pairs {
        return Err(ot_physics::PhysicsError::OutOfRange {
            field: "envelope boundary: segment pairs to test",
            value: pairs as f64,
            allowed: "≤ 2e6 (the images of the map's folds are tangled: take a shorter tick, \
                      a slower particle or a tick map with more substeps)",
        });
    }
    let mut dsu = Dsu((0..pts.len()).collect());
    // (segment, parameter, vertex) insertions
    let mut inserts: Vec<(usize, f64, usize)> = Vec::new();
    for (cell_idx, list) in grid.iter().enumerate() {
        let (ci, cj) = (cell_idx / nby, cell_idx % nby);
        for x in 0..list.len() {
            ot_physics::cancel::check()?;
            for y in x + 1..list.len() {
                let (s1, s2) = (list[x], list[y]);
                let (a, b) = segs[s1];
                let (c, d) = segs[s2];
                if a == c || a == d || b == c || b == d {
                    continue;
                }
                let (p, r) = (pts[a], pts[b] - pts[a]);
                let (q, s) = (pts[c], pts[d] - pts[c]);
                // process the pair only in the bucket holding the low corner of
                // the overlap of their boxes (each pair once).
                let olo = p.inf(&pts[b]).sup(&q.inf(&pts[d]));
                if bucket(&olo) != (ci, cj) {
                    continue;
                }
                let den = cross(&r, &s);
                if den.abs() <= 1e-14 * r.norm() * s.norm() {
                    continue;
                }
                let t = cross(&(q - p), &s) / den;
                let u = cross(&(q - p), &r) / den;
                let (lr, ls) = (r.norm(), s.norm());
                let (et, eu) = (snap / lr, snap / ls);
                if t < -et || t > 1.0 + et || u < -eu || u > 1.0 + eu {
                    continue;
                }
                let end1 = if t <= et {
                    Some(a)
                } else if t >= 1.0 - et {
                    Some(b)
                } else {
                    None
                };
                let end2 = if u <= eu {
                    Some(c)
                } else if u >= 1.0 - eu {
                    Some(d)
                } else {
                    None
                };
                match (end1, end2) {
                    (Some(v1), Some(v2)) => dsu.union(v1, v2),
                    (Some(v1), None) => inserts.push((s2, u, v1)),
                    (None, Some(v2)) => inserts.push((s1, t, v2)),
                    (None, None) => {
                        pts.push(p + r * t);
                        dsu.0.push(pts.len() - 1);
                        let v = pts.len() - 1;
                        inserts.push((s1, t, v));
                        inserts.push((s2, u, v));
                    }
                }
            }
        }
    }
    // 3. split segments at their crossings.
    let mut per_seg: Vec<Vec<(f64, usize)>> = vec![Vec::new(); segs.len()];
    for &(s, t, v) in &inserts {
        per_seg[s].push((t, v));
    }
    let mut edges: std::collections::BTreeSet<(usize, usize)> = Default::default();
    for (k, &(a, b)) in segs.iter().enumerate() {
        let list = &mut per_seg[k];
        list.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut prev = dsu.find(a);
        for &(_, v) in list.iter() {
            let v = dsu.find(v);
            if v != prev {
                edges.insert((prev.min(v), prev.max(v)));
                prev = v;
            }
        }
        let end = dsu.find(b);
        if end != prev {
            edges.insert((prev.min(end), prev.max(end)));
        }
    }
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); pts.len()];
    for &(a, b) in &edges {
        adj[a].push(b);
        adj[b].push(a);
    }
    // 4. walk the outer face, exterior on the right (counter-clockwise loop).
    let Some(start) = (0..pts.len())
        .filter(|&i| !adj[i].is_empty())
        .min_by(|&i, &j| {
            pts[i]
                .x
                .total_cmp(&pts[j].x)
                .then(pts[i].y.total_cmp(&pts[j].y))
        })
    else {
        return Ok(Vec::new());
    };
    let pick = |cur: usize, prev: Option<usize>, d_in: V2| -> usize {
        let mut best = adj[cur][0];
        let mut best_ang = f64::INFINITY;
        for &w in &adj[cur] {
            let d = pts[w] - pts[cur];
            let ang = if Some(w) == prev {
                std::f64::consts::PI * 1.5
            } else {
                cross(&d_in, &d).atan2(d_in.dot(&d))
            };
            if ang < best_ang {
                best_ang = ang;
                best = w;
            }
        }
        best
    };
    let first = pick(start, None, V2::new(0.0, -1.0));
    let mut loop_ids = vec![start];
    let (mut prev, mut cur) = (start, first);
    let limit = 4 * edges.len() + 8;
    for _ in 0..limit {
        let nxt = pick(cur, Some(prev), pts[cur] - pts[prev]);
        if cur == start && nxt == first {
            break;
        }
        loop_ids.push(cur);
        prev = cur;
        cur = nxt;
    }
    // 5. remove spikes (dangling edges walked out and back).
    let mut changed = true;
    while changed && loop_ids.len() > 2 {
        changed = false;
        let n = loop_ids.len();
        for i in 0..n {
            let (a, c) = (loop_ids[(i + n - 1) % n], loop_ids[(i + 1) % n]);
            if a == c {
                let (i1, i2) = (i, (i + 1) % n);
                let (hi_i, lo_i) = (i1.max(i2), i1.min(i2));
                loop_ids.remove(hi_i);
                loop_ids.remove(lo_i);
                changed = true;
                break;
            }
        }
    }
    let mut out: Vec<V2> = loop_ids.iter().map(|&i| pts[i]).collect();
    if signed_area(&out) < 0.0 {
        out.reverse();
    }
    Ok(out)
}

/// Bounding box `(lo, hi)` of a point set (m); `(+∞, −∞)` when empty.
pub fn bbox(points: &[V2]) -> (V2, V2) {
    let mut lo = V2::repeat(f64::INFINITY);
    let mut hi = V2::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// Whether segment `[a, b]` meets the closed box `(lo, hi)` (Liang–Barsky).
pub fn segment_meets_box(a: &V2, b: &V2, lo: &V2, hi: &V2) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for i in 0..2 {
        if d[i] == 0.0 {
            if a[i] < lo[i] || a[i] > hi[i] {
                return false;
            }
        } else {
            let (mut u, mut v) = ((lo[i] - a[i]) / d[i], (hi[i] - a[i]) / d[i]);
            if u > v {
                std::mem::swap(&mut u, &mut v);
            }
            t0 = t0.max(u);
            t1 = t1.min(v);
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// Whether the box `(lo, hi)` lies strictly inside the closed polygon: its
/// four corners inside and no polygon edge meeting it. False for an empty box.
pub fn box_inside(poly: &[V2], b: &(V2, V2)) -> bool {
    let (lo, hi) = b;
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return false;
    }
    let corners = [*lo, V2::new(hi.x, lo.y), *hi, V2::new(lo.x, hi.y)];
    if !corners.iter().all(|c| contains(poly, c)) {
        return false;
    }
    let n = poly.len();
    (0..n).all(|i| !segment_meets_box(&poly[i], &poly[(i + 1) % n], lo, hi))
}

/// Signed area (positive when counter-clockwise), in the points' unit squared.
pub fn signed_area(poly: &[V2]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| cross(&poly[i], &poly[(i + 1) % n]))
        .sum::<f64>()
        * 0.5
}

/// Whether `p` lies inside the closed polygon (even–odd rule; boundary points
/// may go either way).
pub fn contains(poly: &[V2], p: &V2) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Closest point of segment `[a, b]` to `p`.
#[inline]
pub fn closest_on_segment(a: &V2, b: &V2, p: &V2) -> V2 {
    let d = b - a;
    let l2 = d.norm_squared();
    if l2 == 0.0 {
        return *a;
    }
    let t = ((p - a).dot(&d) / l2).clamp(0.0, 1.0);
    a + d * t
}

/// Closest point of the polygon's boundary to `p`, and its distance; an empty polygon has no
/// boundary: `(p, ∞)`.
pub fn nearest_on_boundary(poly: &[V2], p: &V2) -> (V2, f64) {
    let n = poly.len();
    let Some(&first) = poly.first() else {
        return (*p, f64::INFINITY);
    };
    let mut best = (first, f64::INFINITY);
    for i in 0..n {
        let q = closest_on_segment(&poly[i], &poly[(i + 1) % n], p);
        let d = (q - p).norm();
        if d < best.1 {
            best = (q, d);
        }
    }
    best
}

/// Smallest `t` in `(0, 1]` at which the segment `a + t (b − a)` meets the
/// polygon boundary, if any.
pub fn first_crossing(poly: &[V2], a: &V2, b: &V2) -> Option<f64> {
    let r = b - a;
    let n = poly.len();
    let mut best: Option<f64> = None;
    for i in 0..n {
        let (q, q2) = (poly[i], poly[(i + 1) % n]);
        let s = q2 - q;
        let den = cross(&r, &s);
        if den == 0.0 {
            continue;
        }
        let t = cross(&(q - a), &s) / den;
        let u = cross(&(q - a), &r) / den;
        if t > 0.0 && t <= 1.0 && (0.0..=1.0).contains(&u) && best.is_none_or(|bt| t < bt) {
            best = Some(t);
        }
    }
    best
}

/// Largest distance from any point of `a`'s boundary (vertices and edges,
/// sampled every `step`) to the boundary of `b`: one side of the Hausdorff
/// distance between two closed polygons.
///
/// `b`'s edges are bucketed in a square grid and each sample searches rings of cells outward
/// until no unsearched edge can be nearer, so the result is exactly the brute-force minimum
/// over all edges (the same distances, the same minimum) in time about linear in the samples
/// (a 60-fold deeper trap's envelopes took 100 s to compare edge by edge).
pub fn directed_hausdorff(a: &[V2], b: &[V2], step: f64) -> f64 {
    let n = a.len();
    let nearest = EdgeGrid::new(b);
    let mut worst: f64 = 0.0;
    for i in 0..n {
        let (p, q) = (a[i], a[(i + 1) % n]);
        let k = (((q - p).norm() / step).ceil() as usize).max(1);
        for s in 0..k {
            let x = p + (q - p) * (s as f64 / k as f64);
            worst = worst.max(nearest.distance(&x));
        }
    }
    worst
}

/// A closed polygon's edges bucketed in a square grid, for the exact distance from many points
/// to its boundary.
struct EdgeGrid<'a> {
    poly: &'a [V2],
    lo: V2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Edge indices per cell, row-major.
    cells: Vec<Vec<usize>>,
}

impl<'a> EdgeGrid<'a> {
    fn new(poly: &'a [V2]) -> Self {
        let n = poly.len();
        let (mut lo, mut hi) = match poly.first() {
            Some(p) => (*p, *p),
            None => (V2::zeros(), V2::zeros()),
        };
        for p in poly {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let mean = (0..n)
            .map(|i| (poly[(i + 1) % n] - poly[i]).norm())
            .sum::<f64>()
            / n.max(1) as f64;
        let span = (hi - lo).max().max(f64::MIN_POSITIVE);
        let cell = (2.0 * mean).max(span / 256.0).max(f64::MIN_POSITIVE);
        let nx = (((hi.x - lo.x) / cell) as usize + 1).min(256);
        let ny = (((hi.y - lo.y) / cell) as usize + 1).min(256);
        let mut g = EdgeGrid {
            poly,
            lo,
            cell,
            nx,
            ny,
            cells: vec![Vec::new(); nx * ny],
        };
        for i in 0..n {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            let (x0, y0) = g.bucket(&p.inf(&q));
            let (x1, y1) = g.bucket(&p.sup(&q));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    g.cells[y * nx + x].push(i);
                }
            }
        }
        g
    }

    fn bucket(&self, p: &V2) -> (usize, usize) {
        let c = |v: f64, lo: f64, n: usize| {
            let k = ((v - lo) / self.cell).floor();
            if k.is_nan() || k < 0.0 {
                0
            } else {
                (k as usize).min(n - 1)
            }
        };
        (c(p.x, self.lo.x, self.nx), c(p.y, self.lo.y, self.ny))
    }

    /// Distance from `p` to the boundary (∞ for an empty polygon), exactly
    /// [`nearest_on_boundary`]'s.
    fn distance(&self, p: &V2) -> f64 {
        let n = self.poly.len();
        if n == 0 {
            return f64::INFINITY;
        }
        // Cells are clamped to the grid, so a point outside it searches from the nearest cell;
        // the rings' distance bound counts from the point itself.
        let (cx, cy) = self.bucket(p);
        let outside = {
            let hi = self.lo + V2::new(self.nx as f64, self.ny as f64) * self.cell;
            let dx = (self.lo.x - p.x).max(p.x - hi.x).max(0.0);
            let dy = (self.lo.y - p.y).max(p.y - hi.y).max(0.0);
            dx.max(dy)
        };
        let mut best = f64::INFINITY;
        let max_ring = self.nx.max(self.ny);
        for r in 0..=max_ring {
            let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(self.nx - 1));
            let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(self.ny - 1));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    // Only the ring's own cells (the inside was searched before).
                    if x.abs_diff(cx) != r && y.abs_diff(cy) != r {
                        continue;
                    }
                    for &i in &self.cells[y * self.nx + x] {
                        let q = closest_on_segment(&self.poly[i], &self.poly[(i + 1) % n], p);
                        best = best.min((q - p).norm());
                    }
                }
            }
            // Every edge not yet seen lies in cells of ring r + 1 or beyond: at least r cells
            // away along one axis, and never nearer than the grid itself.
            if best <= outside.max(r as f64 * self.cell) {
                break;
            }
        }
        best
    }
}

/// Symmetric Hausdorff distance between the boundaries of two closed polygons.
pub fn hausdorff(a: &[V2], b: &[V2], step: f64) -> f64 {
    directed_hausdorff(a, b, step).max(directed_hausdorff(b, a, step))
}

/// A polygon with its edges bucketed in horizontal strips, for fast
/// containment tests against many points.
#[derive(Debug, Clone)]
pub struct PolygonIndex {
    poly: Vec<V2>,
    y0: f64,
    dy: f64,
    strips: Vec<Vec<usize>>,
}

impl PolygonIndex {
    /// Index `poly` with `strips` horizontal strips.
    pub fn new(poly: &[V2], strips: usize) -> Self {
        let strips_n = strips.max(1);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in poly {
            lo = lo.min(p.y);
            hi = hi.max(p.y);
        }
        let dy = ((hi - lo) / strips_n as f64).max(f64::MIN_POSITIVE);
        let mut st = vec![Vec::new(); strips_n];
        let n = poly.len();
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let s0 = (((a.y.min(b.y) - lo) / dy) as usize).min(strips_n - 1);
            let s1 = (((a.y.max(b.y) - lo) / dy) as usize).min(strips_n - 1);
            for s in st.iter_mut().take(s1 + 1).skip(s0) {
                s.push(i);
            }
        }
        Self {
            poly: poly.to_vec(),
            y0: lo,
            dy,
            strips: st,
        }
    }

    /// Whether `p` lies inside (even–odd rule).
    pub fn contains(&self, p: &V2) -> bool {
        if p.y < self.y0 || self.strips.is_empty() {
            return false;
        }
        let s = ((p.y - self.y0) / self.dy) as usize;
        if s >= self.strips.len() {
            return false;
        }
        let n = self.poly.len();
        let mut inside = false;
        for &i in &self.strips[s] {
            let (a, b) = (self.poly[i], self.poly[(i + 1) % n]);
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if p.x < x {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty envelope (a degenerate map: a tick of 1e-15 s moves nothing) has no boundary:
    /// it is infinitely far from any point, and from any non-empty polygon (found by the
    /// `params` fuzz target, which panicked here).
    #[test]
    fn an_empty_polygon_is_infinitely_far() {
        let p = V2::new(1.0, 2.0);
        assert_eq!(nearest_on_boundary(&[], &p), (p, f64::INFINITY));
        let square = [
            V2::new(0.0, 0.0),
            V2::new(1.0, 0.0),
            V2::new(1.0, 1.0),
            V2::new(0.0, 1.0),
        ];
        assert_eq!(hausdorff(&square, &[], 0.1), f64::INFINITY);
        assert_eq!(hausdorff(&[], &[], 0.1), 0.0);
        assert_eq!(nearest_on_boundary(&square, &V2::new(0.5, 2.0)).1, 1.0);
    }

    /// The bucketed distance is the brute-force minimum over every edge, bit for bit, for
    /// points inside, on and far outside a long wiggly polygon.
    #[test]
    fn the_edge_grid_gives_the_brute_force_distance_exactly() {
        let poly: Vec<V2> = (0..2000)
            .map(|k| {
                let t = k as f64 / 2000.0 * std::f64::consts::TAU;
                let r = 1.0 + 0.3 * (7.0 * t).sin() + 0.05 * (91.0 * t).cos();
                V2::new(3e-7 * r * t.cos(), 1e-7 * r * t.sin())
            })
            .collect();
        let g = EdgeGrid::new(&poly);
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        for _ in 0..3000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            let v = (x & 0xFFFF) as f64 / 65535.0;
            let p = V2::new((u - 0.5) * 2e-6, (v - 0.5) * 8e-7);
            assert_eq!(g.distance(&p), nearest_on_boundary(&poly, &p).1);
        }
        for p in &poly[..50] {
            assert_eq!(g.distance(p), 0.0);
        }
        let other: Vec<V2> = poly.iter().map(|p| p * 1.01).collect();
        let brute = other
            .iter()
            .map(|p| nearest_on_boundary(&poly, p).1)
            .fold(0.0, f64::max);
        assert!(directed_hausdorff(&other, &poly, 1e9) == brute);
    }
}
