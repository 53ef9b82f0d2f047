//! The paper's method (§2.2–2.3, Fig. 8), kept as the benchmark baseline and
//! implemented honestly: a grid of target displacements; for each target,
//! marching-squares segments of `Δx = tx` and `Δy = ty` in every element of an
//! offset grid, their intersections as seeds, Newton from each, elements
//! subdivided (2×2, twice at most) when Newton fails; the envelope is the
//! contour of the solvable targets (marching squares on the solvable
//! indicator, outer loop kept — Feldman's loop extraction).
//!
//! The one liberty taken in its favour: the offset grid is sampled once and
//! shared by all targets (the paper's text recomputes nothing per target
//! either way).

use crate::error::{Result, positive};
use crate::geometry::outer_boundary;
use crate::region::OffsetRegion;
use crate::sample::SampledMap;
use nalgebra::Vector2;
use ot_physics::Propagator;

type V2 = Vector2<f64>;

/// The baseline's envelope and its counters.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperEnvelope {
    /// Contour of the solvable targets (m), counter-clockwise.
    pub polygon: Vec<V2>,
    /// Targets tried.
    pub targets: usize,
    /// Targets found solvable.
    pub solvable: usize,
    /// Target grid shape (points per axis).
    pub shape: [usize; 2],
    /// Solvable flag per target, index `a * shape[1] + b` for the target
    /// `t_lo + spacing · (a, b)`.
    pub solved: Vec<bool>,
    /// Newton runs.
    pub newton_runs: u64,
    /// Force evaluations (offset grid included).
    pub evals: u64,
}

/// Plain Newton (the paper's), ≤ 20 iterations, residual ≤ 1e-12 m.
fn newton(
    prop: &Propagator<2>,
    v0: &V2,
    start: V2,
    target: &V2,
    evals: &mut u64,
) -> Result<Option<V2>> {
    let mut o = start;
    for _ in 0..20 {
        let f = prop.flow_offset_jacobian(&o, v0)?;
        *evals += f.evals;
        let r = f.displacement - target;
        if r.norm() <= 1e-12 {
            return Ok(Some(o));
        }
        match f.d_offset.try_inverse() {
            Some(inv) => o -= inv * r,
            None => return Ok(None),
        }
        if !o.iter().all(|x| x.is_finite()) {
            return Ok(None);
        }
    }
    Ok(None)
}

/// Zero crossings of `g` (values at corners 00, 10, 11, 01 of a unit square)
/// on the square's edges, in unit coordinates.
fn square_crossings(g: [f64; 4]) -> Vec<V2> {
    let c = [
        V2::new(0.0, 0.0),
        V2::new(1.0, 0.0),
        V2::new(1.0, 1.0),
        V2::new(0.0, 1.0),
    ];
    let mut out = Vec::new();
    for k in 0..4 {
        let (a, b) = (g[k], g[(k + 1) % 4]);
        if (a >= 0.0) != (b >= 0.0) {
            let t = a / (a - b);
            out.push(c[k] + (c[(k + 1) % 4] - c[k]) * t);
        }
    }
    out
}

/// Intersection of segments `p0p1` and `q0q1`, if any.
fn seg_intersect(p0: V2, p1: V2, q0: V2, q1: V2) -> Option<V2> {
    let (r, s) = (p1 - p0, q1 - q0);
    let den = r.x * s.y - r.y * s.x;
    if den == 0.0 {
        return None;
    }
    let d = q0 - p0;
    let t = (d.x * s.y - d.y * s.x) / den;
    let u = (d.x * r.y - d.y * r.x) / den;
    ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then(|| p0 + r * t)
}

/// Seeds in one element (unit coordinates) from the two contour sets.
fn element_seeds(dx: [f64; 4], dy: [f64; 4]) -> Vec<V2> {
    let (a, b) = (square_crossings(dx), square_crossings(dy));
    let mut s = Vec::new();
    for pa in a.chunks(2).filter(|c| c.len() == 2) {
        for pb in b.chunks(2).filter(|c| c.len() == 2) {
            if let Some(x) = seg_intersect(pa[0], pa[1], pb[0], pb[1]) {
                s.push(x);
            }
        }
    }
    s
}

/// Whether `target` is solvable, searching element `(lo, size)` with corner
/// displacements `d`, subdividing on Newton failure down to `depth` levels.
#[allow(clippy::too_many_arguments)]
fn solve_element(
    prop: &Propagator<2>,
    v0: &V2,
    lo: V2,
    size: V2,
    d: [V2; 4],
    target: &V2,
    depth: u32,
    runs: &mut u64,
    evals: &mut u64,
) -> Result<bool> {
    let dx = [
        d[0].x - target.x,
        d[1].x - target.x,
        d[2].x - target.x,
        d[3].x - target.x,
    ];
    let dy = [
        d[0].y - target.y,
        d[1].y - target.y,
        d[2].y - target.y,
        d[3].y - target.y,
    ];
    let seeds = element_seeds(dx, dy);
    if seeds.is_empty() {
        return Ok(false);
    }
    for s in &seeds {
        *runs += 1;
        if newton(prop, v0, lo + s.component_mul(&size), target, evals)?.is_some() {
            return Ok(true);
        }
    }
    if depth == 0 {
        return Ok(false);
    }
    // subdivide 2×2: displacements at the 5 new points
    let half = size * 0.5;
    let mut g = [[V2::zeros(); 3]; 3];
    for (i, row) in g.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = match (i, j) {
                (0, 0) => d[0],
                (2, 0) => d[1],
                (2, 2) => d[2],
                (0, 2) => d[3],
                _ => {
                    let o = lo + V2::new(half.x * i as f64, half.y * j as f64);
                    let (disp, _, e) = prop.flow(&o, v0)?;
                    *evals += e;
                    disp
                }
            };
        }
    }
    for i in 0..2 {
        for j in 0..2 {
            let l = lo + V2::new(half.x * i as f64, half.y * j as f64);
            let dd = [g[i][j], g[i + 1][j], g[i + 1][j + 1], g[i][j + 1]];
            if solve_element(prop, v0, l, half, dd, target, depth - 1, runs, evals)? {
                return Ok(true);
            }
        }
    }
    Ok(false)
}

/// The paper's working envelope: targets on a grid of `spacing` (m) over
/// the box `[t_lo, t_hi]` (m), seeds from an offset grid of `cell_waists`
/// waists over `region`.
pub fn paper_envelope(
    prop: &Propagator<2>,
    v0: &V2,
    region: &OffsetRegion,
    cell_waists: f64,
    t_lo: V2,
    t_hi: V2,
    spacing: f64,
) -> Result<PaperEnvelope> {
    let spacing = positive("spacing [m]", spacing)?;
    let map = SampledMap::build(prop, v0, region, Some(cell_waists))?;
    let mut evals = map.evals;
    let mut runs = 0;
    let nt = [
        ((t_hi.x - t_lo.x) / spacing).ceil() as usize + 1,
        ((t_hi.y - t_lo.y) / spacing).ceil() as usize + 1,
    ];
    let [nx, ny] = map.n;
    let mut solvable = vec![false; nt[0] * nt[1]];
    for a in 0..nt[0] {
        for b in 0..nt[1] {
            let target = t_lo + V2::new(spacing * a as f64, spacing * b as f64);
            'cells: for i in 0..nx - 1 {
                for j in 0..ny - 1 {
                    let d = [
                        map.disp[map.idx(i, j)],
                        map.disp[map.idx(i + 1, j)],
                        map.disp[map.idx(i + 1, j + 1)],
                        map.disp[map.idx(i, j + 1)],
                    ];
                    if solve_element(
                        prop,
                        v0,
                        map.offset(i, j),
                        map.h,
                        d,
                        &target,
                        2,
                        &mut runs,
                        &mut evals,
                    )? {
                        solvable[a * nt[1] + b] = true;
                        break 'cells;
                    }
                }
            }
        }
    }
    // contour of the solvable set: marching squares at level ½
    let val = |a: usize, b: usize| if solvable[a * nt[1] + b] { 1.0 } else { 0.0 };
    let mut segs: Vec<(Vec<V2>, bool)> = Vec::new();
    for a in 0..nt[0] - 1 {
        for b in 0..nt[1] - 1 {
            let c = [(a, b), (a + 1, b), (a + 1, b + 1), (a, b + 1)];
            let g = [
                val(c[0].0, c[0].1) - 0.5,
                val(c[1].0, c[1].1) - 0.5,
                val(c[2].0, c[2].1) - 0.5,
                val(c[3].0, c[3].1) - 0.5,
            ];
            let xs = square_crossings(g);
            // from integer indices so that a crossing shared by two cells is
            // bit-identical in both (the contour's segments then connect)
            let to = |u: &V2| t_lo + V2::new(a as f64 + u.x, b as f64 + u.y) * spacing;
            if xs.len() == 2 {
                segs.push((vec![to(&xs[0]), to(&xs[1])], false));
            } else if xs.len() == 4 {
                segs.push((vec![to(&xs[0]), to(&xs[1])], false));
                segs.push((vec![to(&xs[2]), to(&xs[3])], false));
            }
        }
    }
    let polygon = outer_boundary(&segs, 1e-6 * spacing);
    Ok(PaperEnvelope {
        polygon,
        targets: nt[0] * nt[1],
        solvable: solvable.iter().filter(|x| **x).count(),
        shape: nt,
        solved: solvable.clone(),
        newton_runs: runs,
        evals,
    })
}
