//! The outer boundary of a set of polylines: their planar arrangement (vertices merged,
//! crossings found through a bucket grid, segments split at them) walked with the right-hand
//! rule around its unbounded face.

use super::{Buckets, V2, bbox, cross, signed_area};
use std::collections::{BTreeMap, BTreeSet};

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

/// [`outer_boundary`] that stops with [`ot_physics::PhysicsError::Value`] when the
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
    let (mut pts, segs) = vertices_and_segments(polylines);
    if segs.is_empty() {
        return Ok(Vec::new());
    }
    // 2. all crossings, found through a bucket grid.
    let grid = Grid::new(&pts, &segs);
    grid.check_pairs(max_pairs)?;
    let (mut dsu, inserts) = grid.crossings(&mut pts, &segs, snap)?;
    // 3. split segments at their crossings.
    let edges = split_at_crossings(&segs, &inserts, &mut dsu);
    // 4. walk the outer face, exterior on the right (counter-clockwise loop).
    let Some(mut loop_ids) = walk_outer_face(&pts, &edges) else {
        return Ok(Vec::new());
    };
    // 5. remove spikes (dangling edges walked out and back).
    remove_spikes(&mut loop_ids);
    let mut out: Vec<V2> = loop_ids.iter().map(|&i| pts[i]).collect();
    if signed_area(&out) < 0.0 {
        out.reverse();
    }
    Ok(out)
}

/// The arrangement's vertices (bit-identical points are one vertex) and segments (vertex
/// pairs; a closed polyline's closing segment included, zero-length ones left out).
fn vertices_and_segments(polylines: &[(Vec<V2>, bool)]) -> (Vec<V2>, Vec<(usize, usize)>) {
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
    (pts, segs)
}

/// A bucket grid over the arrangement: each cell lists the segments whose box meets it.
struct Grid(Buckets);

impl Grid {
    /// Cells of about twice the mean segment length (at most 1024 × 1024).
    fn new(pts: &[V2], segs: &[(usize, usize)]) -> Grid {
        let (lo, hi) = bbox(pts);
        let mean_len = segs
            .iter()
            .map(|&(a, b)| (pts[b] - pts[a]).norm())
            .sum::<f64>()
            / segs.len() as f64;
        let ends = segs.iter().map(|&(a, b)| (pts[a], pts[b]));
        Grid(Buckets::new(lo, hi, mean_len, 512.0, 1024, ends))
    }

    /// The crossing search tests every pair of segments sharing a bucket: bound it before
    /// it starts (a tangle of fold images costs minutes, and its boundary is no envelope one
    /// can use).
    fn check_pairs(&self, max_pairs: u64) -> Result<(), ot_physics::PhysicsError> {
        let pairs: u64 = self
            .0
            .cells
            .iter()
            .map(|l| (l.len() as u64) * (l.len() as u64).saturating_sub(1) / 2)
            .sum();
        if pairs > max_pairs {
            return Err(ot_physics::PhysicsError::Value(
                ot_physics::ValueError::out_of_range(
                    "envelope boundary: segment pairs to test",
                    pairs as f64,
                    "≤ 2e6 (the images of the map's folds are tangled: take a shorter tick, \
                          a slower particle or a tick map with more substeps)",
                ),
            ));
        }
        Ok(())
    }

    /// Every crossing of two segments: endpoints within `snap` of each other merged (the
    /// union–find), a crossing near one segment's end inserted into the other, an interior
    /// crossing added as a new vertex of both. Returns the merges and the (segment,
    /// parameter, vertex) insertions.
    #[allow(clippy::type_complexity)]
    fn crossings(
        &self,
        pts: &mut Vec<V2>,
        segs: &[(usize, usize)],
        snap: f64,
    ) -> Result<(Dsu, Vec<(usize, f64, usize)>), ot_physics::PhysicsError> {
        let mut dsu = Dsu((0..pts.len()).collect());
        let mut inserts: Vec<(usize, f64, usize)> = Vec::new();
        for (cell_idx, list) in self.0.cells.iter().enumerate() {
            let (ci, cj) = (cell_idx / self.0.ny, cell_idx % self.0.ny);
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
                    if self.0.bucket(&olo) != (ci, cj) {
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
                    let end = |t: f64, e: f64, a: usize, b: usize| {
                        if t <= e {
                            Some(a)
                        } else if t >= 1.0 - e {
                            Some(b)
                        } else {
                            None
                        }
                    };
                    match (end(t, et, a, b), end(u, eu, c, d)) {
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
        Ok((dsu, inserts))
    }
}

/// The arrangement's edges: each segment split at its crossings, in order along it, between
/// merged vertices (each edge once, low id first).
fn split_at_crossings(
    segs: &[(usize, usize)],
    inserts: &[(usize, f64, usize)],
    dsu: &mut Dsu,
) -> BTreeSet<(usize, usize)> {
    let mut per_seg: Vec<Vec<(f64, usize)>> = vec![Vec::new(); segs.len()];
    for &(s, t, v) in inserts {
        per_seg[s].push((t, v));
    }
    let mut edges: BTreeSet<(usize, usize)> = Default::default();
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
    edges
}

/// The outer face's vertex loop, walked from the leftmost-lowest vertex with the exterior on
/// the right (at each vertex the sharpest right turn); `None` without edges.
fn walk_outer_face(pts: &[V2], edges: &BTreeSet<(usize, usize)>) -> Option<Vec<usize>> {
    let mut adj: Vec<Vec<usize>> = vec![Vec::new(); pts.len()];
    for &(a, b) in edges {
        adj[a].push(b);
        adj[b].push(a);
    }
    let start = (0..pts.len())
        .filter(|&i| !adj[i].is_empty())
        .min_by(|&i, &j| {
            pts[i]
                .x
                .total_cmp(&pts[j].x)
                .then(pts[i].y.total_cmp(&pts[j].y))
        })?;
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
    Some(loop_ids)
}

/// Removes spikes from a vertex loop: dangling edges walked out and back (`a, b, a`).
fn remove_spikes(loop_ids: &mut Vec<usize>) {
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
}
