//! Fold curves of the tick map and their images: marching squares on
//! `det J` over a [`SampledMap`], crossings placed by regula falsi, image
//! tangents from the rank-1 Jacobian, refinement where the image turns, and
//! cubic Hermite polylines of the images (with the region's edge image).

use crate::error::Result;
use crate::sample::{SampledMap, Slice};
use nalgebra::{Matrix2, Vector2};
use ot_physics::Propagator;
use std::collections::BTreeSet;

type V2 = Vector2<f64>;

/// Bit pattern of a point, to recognise shared vertices exactly.
pub(crate) type Key = (u64, u64);

/// The traced image curves of one sampled map.
#[derive(Clone)]
pub(crate) struct Traced {
    /// Fold-curve images first, the region edge's image last.
    pub curves: Vec<Curve>,
    /// Number of fold curves.
    pub fold_curves: usize,
    /// Keys of image points that belong to the region edge only.
    pub edge_only: BTreeSet<Key>,
    /// Force evaluations spent (the map's included).
    pub evals: u64,
}

/// A point of an image curve: offset (m), displacement (m), Jacobian.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CurvePoint {
    pub(crate) o: V2,
    pub(crate) d: V2,
    j: Matrix2<f64>,
}

/// Unit direction of the column space of a (near) rank-1 Jacobian: the
/// tangent of the fold image.
fn fold_tangent(j: &Matrix2<f64>) -> V2 {
    let m = j * j.transpose();
    let (a, b, c) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
    let l = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let v1 = V2::new(b, l - a);
    let v2 = V2::new(l - c, b);
    let v = if v1.norm_squared() >= v2.norm_squared() {
        v1
    } else {
        v2
    };
    let n = v.norm();
    if n > 0.0 { v / n } else { V2::new(1.0, 0.0) }
}

struct Ctx<'a> {
    prop: &'a Propagator<2>,
    v0: V2,
    w: V2,
    evals: u64,
    iters: usize,
}

impl Ctx<'_> {
    fn eval(&mut self, o: &V2) -> Result<CurvePoint> {
        let f = self.prop.flow_offset_jacobian(o, &self.v0)?;
        self.evals += f.evals;
        Ok(CurvePoint {
            o: *o,
            d: f.displacement,
            j: f.d_offset,
        })
    }

    /// Fold point on the segment `a → b` (det of opposite signs at the ends):
    /// Illinois regula falsi from the linear interpolation, `iters` steps.
    fn crossing(&mut self, a: &V2, da: f64, b: &V2, db: f64) -> Result<CurvePoint> {
        let (mut ta, mut fa, mut tb, mut fb) = (0.0, da, 1.0, db);
        let mut side = 0i8;
        let mut best: Option<(f64, CurvePoint)> = None;
        for _ in 0..self.iters {
            let t = (ta * fb - tb * fa) / (fb - fa);
            let p = self.eval(&(a + (b - a) * t))?;
            let ft = p.j.determinant();
            if best.as_ref().is_none_or(|(f, _)| ft.abs() < *f) {
                best = Some((ft.abs(), p));
            }
            if ft == 0.0 || (tb - ta) < 1e-9 {
                break;
            }
            if (ft >= 0.0) == (fa >= 0.0) {
                (ta, fa) = (t, ft);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                (tb, fb) = (t, ft);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
        }
        Ok(best.expect("at least one regula-falsi step").1)
    }

    /// A fold point between two fold points: bisect in scaled offsets, then
    /// secant along the normal to the chord.
    fn fold_between(&mut self, a: &CurvePoint, b: &CurvePoint) -> Result<CurvePoint> {
        let (za, zb) = (a.o.component_div(&self.w), b.o.component_div(&self.w));
        let dz = zb - za;
        let len = dz.norm();
        let nz = V2::new(-dz.y, dz.x) / len;
        let zm = (za + zb) * 0.5;
        let w = self.w;
        let at = |s: f64| (zm + nz * s).component_mul(&w);
        let (mut s0, mut p0) = (0.0, self.eval(&at(0.0))?);
        let mut g0 = p0.j.determinant();
        let mut best = p0;
        let mut s1 = 0.25 * len;
        for _ in 0..4 {
            let p1 = self.eval(&at(s1))?;
            let g1 = p1.j.determinant();
            if g1.abs() < best.j.determinant().abs() {
                best = p1;
            }
            if g1 == g0 {
                break;
            }
            let s2 = (s1 - g1 * (s1 - s0) / (g1 - g0)).clamp(-len, len);
            if (s2 - s1).abs() < 1e-4 * len {
                break;
            }
            (s0, g0, p0) = (s1, g1, p1);
            s1 = s2;
        }
        let _ = p0;
        Ok(best)
    }
}

/// One image curve under construction.
#[derive(Clone)]
pub(crate) struct Curve {
    pub(crate) pts: Vec<CurvePoint>,
    closed: bool,
    /// `Some(dir)` for a region edge walked along `dir` (tangent = J·dir at
    /// every point); `None` for a fold curve.
    pub(crate) edge_dir: Option<Vec<V2>>,
}

fn tangents(c: &Curve, k: usize, chord: &V2) -> (V2, V2) {
    let n = c.pts.len();
    let (a, b) = (&c.pts[k], &c.pts[(k + 1) % n]);
    let (mut ta, mut tb) = match &c.edge_dir {
        Some(dirs) => {
            let d = dirs[k];
            let (x, y) = (a.j * d, b.j * d);
            (
                x / x.norm().max(f64::MIN_POSITIVE),
                y / y.norm().max(f64::MIN_POSITIVE),
            )
        }
        None => (fold_tangent(&a.j), fold_tangent(&b.j)),
    };
    if ta.dot(chord) < 0.0 {
        ta = -ta;
    }
    if tb.dot(chord) < 0.0 {
        tb = -tb;
    }
    (ta, tb)
}

const COS_MAX_TURN: f64 = 0.906_307_787_036_649_9; // cos 25°
const MAX_REFINE: usize = 4096;

/// Trace every fold curve of `map` and the region edge, refined so that
/// consecutive image tangents turn by at most 25° (`tol` in m).
pub(crate) fn trace(prop: &Propagator<2>, map: &SampledMap, tol: f64) -> Result<Traced> {
    let mut job = TraceJob::new(prop, map);
    job.run(prop, map, tol, &mut Slice::unlimited())?;
    Ok(job.finish())
}

/// Where a [`TraceJob`] stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TraceStage {
    /// Placing the crossings of the grid edges leaving vertex `next`.
    Crossings { next: usize },
    /// Refining fold curve `curve` from its point `k`.
    Refine { curve: usize, k: usize },
    /// Complete.
    Done,
}

/// The tracing of [`trace`] as a resumable job. Work items: the crossings of
/// one grid vertex's two edges (≤ 2 regula-falsi steps each), then one fold
/// point inserted by refinement (≤ 5 evaluations); the marching-squares
/// linking between the two stages evaluates nothing. Items run in the
/// one-shot order, so the finished trace is the one-shot trace bit for bit.
#[derive(Clone)]
pub(crate) struct TraceJob {
    v0: V2,
    w: V2,
    evals: u64,
    det: Vec<f64>,
    cross_of: Vec<Option<usize>>,
    pts: Vec<CurvePoint>,
    curves: Vec<Curve>,
    fold_curves: usize,
    edge_only: BTreeSet<Key>,
    refinements: usize,
    stage: TraceStage,
}

impl std::fmt::Debug for TraceJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TraceJob")
            .field("stage", &self.stage)
            .field("evals", &self.evals)
            .finish_non_exhaustive()
    }
}

impl TraceJob {
    /// A job over the complete `map`; traces nothing yet.
    pub(crate) fn new(prop: &Propagator<2>, map: &SampledMap) -> Self {
        let [nx, ny] = map.n;
        let nh = (nx - 1) * ny;
        let n_edges = nh + nx * (ny - 1);
        Self {
            v0: map.v0,
            w: prop.model().well.waists(),
            evals: map.evals,
            det: map.jac.iter().map(|j| j.determinant()).collect(),
            cross_of: vec![None; n_edges],
            pts: Vec::new(),
            curves: Vec::new(),
            fold_curves: 0,
            edge_only: BTreeSet::new(),
            refinements: 0,
            stage: TraceStage::Crossings { next: 0 },
        }
    }

    /// The traced curves (once [`TraceJob::run`] has returned true).
    pub(crate) fn finish(self) -> Traced {
        Traced {
            curves: self.curves,
            fold_curves: self.fold_curves,
            edge_only: self.edge_only,
            evals: self.evals,
        }
    }

    /// Runs work items while `slice` is open; true once the trace is complete.
    pub(crate) fn run(
        &mut self,
        prop: &Propagator<2>,
        map: &SampledMap,
        tol: f64,
        slice: &mut Slice,
    ) -> Result<bool> {
        let mut ctx = Ctx {
            prop,
            v0: self.v0,
            w: self.w,
            evals: self.evals,
            iters: 2,
        };
        let r = self.run_with(&mut ctx, map, tol, slice);
        self.evals = ctx.evals;
        r
    }

    fn run_with(
        &mut self,
        ctx: &mut Ctx<'_>,
        map: &SampledMap,
        tol: f64,
        slice: &mut Slice,
    ) -> Result<bool> {
        let [nx, ny] = map.n;
        let ids = EdgeIds::of(map);
        if let TraceStage::Crossings { mut next } = self.stage {
            let det = &self.det;
            let pos = |i: usize, j: usize| det[i * ny + j] >= 0.0;
            while next < nx * ny {
                let (i, j) = (next / ny, next % ny);
                let cx = i + 1 < nx && pos(i, j) != pos(i + 1, j);
                let cy = j + 1 < ny && pos(i, j) != pos(i, j + 1);
                if (cx || cy) && !slice.open() {
                    self.stage = TraceStage::Crossings { next };
                    return Ok(false);
                }
                let before = ctx.evals;
                let d0 = det[i * ny + j];
                if cx {
                    let p = ctx.crossing(
                        &map.offset(i, j),
                        d0,
                        &map.offset(i + 1, j),
                        det[(i + 1) * ny + j],
                    )?;
                    self.cross_of[ids.h(i, j)] = Some(self.pts.len());
                    self.pts.push(p);
                }
                if cy {
                    let p = ctx.crossing(
                        &map.offset(i, j),
                        d0,
                        &map.offset(i, j + 1),
                        det[i * ny + j + 1],
                    )?;
                    self.cross_of[ids.v(i, j)] = Some(self.pts.len());
                    self.pts.push(p);
                }
                slice.spend(ctx.evals - before);
                next += 1;
            }
            self.link(map);
            self.stage = TraceStage::Refine { curve: 0, k: 0 };
        }
        // Refine fold curves where the image tangent turns too fast.
        if let TraceStage::Refine { mut curve, mut k } = self.stage {
            while curve < self.curves.len() {
                let c = &mut self.curves[curve];
                if c.edge_dir.is_some() {
                    curve += 1;
                    k = 0;
                    continue;
                }
                if !(k + 1 < c.pts.len() + usize::from(c.closed) && self.refinements < MAX_REFINE) {
                    curve += 1;
                    k = 0;
                    continue;
                }
                let n = c.pts.len();
                let (a, b) = (c.pts[k], c.pts[(k + 1) % n]);
                let chord = b.d - a.d;
                let l = chord.norm();
                let scaled = (b.o - a.o).component_div(&ctx.w).norm();
                if l > tol && scaled > 1e-6 {
                    let (ta, tb) = tangents(c, k, &chord);
                    if ta.dot(&chord) < COS_MAX_TURN * l || tb.dot(&chord) < COS_MAX_TURN * l {
                        if !slice.open() {
                            self.stage = TraceStage::Refine { curve, k };
                            return Ok(false);
                        }
                        let before = ctx.evals;
                        let m = ctx.fold_between(&a, &b)?;
                        slice.spend(ctx.evals - before);
                        c.pts.insert(k + 1, m);
                        self.refinements += 1;
                        continue;
                    }
                }
                k += 1;
            }
            // Crossing points on the region edge are fold points too.
            for c in self.curves.iter().filter(|c| c.edge_dir.is_none()) {
                for p in [c.pts.first(), c.pts.last()].into_iter().flatten() {
                    self.edge_only.remove(&(p.d.x.to_bits(), p.d.y.to_bits()));
                }
            }
            self.stage = TraceStage::Done;
        }
        Ok(true)
    }

    /// Marching squares: links the crossings through the cells into fold
    /// curves and appends the region edge's curve (no evaluations).
    fn link(&mut self, map: &SampledMap) {
        let ids = EdgeIds::of(map);
        let links = cell_links(ids, map.n, &self.det, &self.cross_of, self.pts.len());
        for (chain, closed) in chains(&links) {
            self.curves.push(Curve {
                pts: chain.iter().map(|&k| self.pts[k]).collect(),
                closed,
                edge_dir: None,
            });
        }
        self.fold_curves = self.curves.len();
        let edge = edge_curve(ids, map, &self.cross_of, &self.pts, &mut self.edge_only);
        self.curves.push(edge);
    }
}

/// Where the grid edges stand in `cross_of`: first the edges `(i, j) → (i + 1, j)`, then the
/// edges `(i, j) → (i, j + 1)`.
#[derive(Clone, Copy)]
struct EdgeIds {
    /// Grid vertices along the second axis.
    ny: usize,
    /// Number of edges along the first axis.
    nh: usize,
}

impl EdgeIds {
    fn of(map: &SampledMap) -> Self {
        let [nx, ny] = map.n;
        Self {
            ny,
            nh: (nx - 1) * ny,
        }
    }

    /// The edge `(i, j) → (i + 1, j)`.
    fn h(self, i: usize, j: usize) -> usize {
        i * self.ny + j
    }

    /// The edge `(i, j) → (i, j + 1)`.
    fn v(self, i: usize, j: usize) -> usize {
        self.nh + i * (self.ny - 1) + j
    }
}

/// Marching squares on the signs of `det` over the `n` grid: for each crossing (of `n_pts`),
/// the crossings it is linked to through the cells it bounds. A cell with four crossings (a
/// saddle) is split by the sign of its centre (the mean of its corners).
fn cell_links(
    ids: EdgeIds,
    n: [usize; 2],
    det: &[f64],
    cross_of: &[Option<usize>],
    n_pts: usize,
) -> Vec<Vec<usize>> {
    let [nx, ny] = n;
    let pos = |i: usize, j: usize| det[i * ny + j] >= 0.0;
    let mut links: Vec<Vec<usize>> = vec![Vec::new(); n_pts];
    let link = |a: Option<usize>, b: Option<usize>, links: &mut Vec<Vec<usize>>| {
        if let (Some(a), Some(b)) = (a, b) {
            links[a].push(b);
            links[b].push(a);
        }
    };
    for i in 0..nx - 1 {
        for j in 0..ny - 1 {
            let (bo, to, le, ri) = (
                cross_of[ids.h(i, j)],
                cross_of[ids.h(i, j + 1)],
                cross_of[ids.v(i, j)],
                cross_of[ids.v(i + 1, j)],
            );
            let es: Vec<Option<usize>> = [bo, ri, to, le]
                .into_iter()
                .filter(|e| e.is_some())
                .collect();
            match es.len() {
                2 => link(es[0], es[1], &mut links),
                4 => {
                    let centre = det[i * ny + j]
                        + det[(i + 1) * ny + j]
                        + det[i * ny + j + 1]
                        + det[(i + 1) * ny + j + 1];
                    if (centre >= 0.0) == pos(i, j) {
                        link(bo, ri, &mut links);
                        link(le, to, &mut links);
                    } else {
                        link(bo, le, &mut links);
                        link(ri, to, &mut links);
                    }
                }
                _ => {}
            }
        }
    }
    links
}

/// The chains of linked crossings, each with whether it closes on itself: open ones walked
/// from their ends first, then the closed loops.
fn chains(links: &[Vec<usize>]) -> Vec<(Vec<usize>, bool)> {
    let n = links.len();
    let mut used = vec![false; n];
    let walk = |s: usize, used: &mut Vec<bool>| -> (Vec<usize>, bool) {
        let mut chain = vec![s];
        used[s] = true;
        let mut cur = s;
        loop {
            let next = links[cur].iter().copied().find(|&x| !used[x]);
            match next {
                Some(x) => {
                    used[x] = true;
                    chain.push(x);
                    cur = x;
                }
                None => break,
            }
        }
        let closed = chain.len() > 2 && links[cur].contains(&s);
        (chain, closed)
    };
    let order: Vec<usize> = (0..n)
        .filter(|&k| links[k].len() <= 1)
        .chain((0..n).filter(|&k| links[k].len() > 1))
        .collect();
    let mut out = Vec::new();
    for s in order {
        if used[s] {
            continue;
        }
        out.push(walk(s, &mut used));
    }
    out
}

/// The region edge, counter-clockwise, with its fold crossings (`pts` by `cross_of`)
/// inserted; its grid points are added to `edge_only`.
fn edge_curve(
    ids: EdgeIds,
    map: &SampledMap,
    cross_of: &[Option<usize>],
    pts: &[CurvePoint],
    edge_only: &mut BTreeSet<Key>,
) -> Curve {
    let [nx, ny] = map.n;
    let mut ring: Vec<(usize, usize)> = Vec::new();
    ring.extend((0..nx - 1).map(|i| (i, 0)));
    ring.extend((0..ny - 1).map(|j| (nx - 1, j)));
    ring.extend((1..nx).rev().map(|i| (i, ny - 1)));
    ring.extend((1..ny).rev().map(|j| (0, j)));
    let m = ring.len();
    let mut points = Vec::new();
    let mut dirs = Vec::new();
    for k in 0..m {
        let (i, j) = ring[k];
        let (i2, j2) = ring[(k + 1) % m];
        let dir = V2::new(i2 as f64 - i as f64, j2 as f64 - j as f64);
        let d = map.disp[map.idx(i, j)];
        points.push(CurvePoint {
            o: map.offset(i, j),
            d,
            j: map.jac[map.idx(i, j)],
        });
        dirs.push(dir);
        edge_only.insert((d.x.to_bits(), d.y.to_bits()));
        let e = if j2 == j {
            ids.h(i.min(i2), j)
        } else {
            ids.v(i, j.min(j2))
        };
        if let Some(c) = cross_of[e] {
            points.push(pts[c]);
            dirs.push(dir);
        }
    }
    Curve {
        pts: points,
        closed: true,
        edge_dir: Some(dirs),
    }
}

/// Cubic Hermite polylines of the image curves, subdivided until each piece
/// deviates from its chord by at most `tol / 16` (m). New points of the
/// region edge are added to `edge_only`.
pub(crate) fn hermite_polylines(
    curves: &[Curve],
    tol: f64,
    edge_only: &mut BTreeSet<Key>,
) -> Vec<(Vec<V2>, bool)> {
    let mut lines: Vec<(Vec<V2>, bool)> = Vec::new();
    for c in curves {
        let n = c.pts.len();
        if n == 0 {
            continue;
        }
        let segs = if c.closed { n } else { n - 1 };
        let mut out = vec![c.pts[0].d];
        for k in 0..segs {
            let (a, b) = (c.pts[k].d, c.pts[(k + 1) % n].d);
            let chord = b - a;
            let l = chord.norm();
            if l > 0.0 {
                let (ta, tb) = tangents(c, k, &chord);
                let sin = ((ta.x * chord.y - ta.y * chord.x).abs())
                    .max((tb.x * chord.y - tb.y * chord.x).abs())
                    / l;
                let dev = 0.25 * l * sin;
                let pieces = ((dev / (0.0625 * tol)).sqrt().ceil() as usize).clamp(1, 128);
                for s in 1..pieces {
                    let t = s as f64 / pieces as f64;
                    let (t2, t3) = (t * t, t * t * t);
                    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
                    let h10 = t3 - 2.0 * t2 + t;
                    let h01 = -2.0 * t3 + 3.0 * t2;
                    let h11 = t3 - t2;
                    let p = a * h00 + ta * (l * h10) + b * h01 + tb * (l * h11);
                    if c.edge_dir.is_some() {
                        edge_only.insert((p.x.to_bits(), p.y.to_bits()));
                    }
                    out.push(p);
                }
            }
            if k + 1 < n {
                out.push(b);
            }
        }
        lines.push((out, c.closed));
    }
    lines
}
