//! Back-to-front order of the solid primitives (painter's algorithm made exact for disjoint
//! convex bodies).
//!
//! Under an orthographic camera, two disjoint convex bodies whose images overlap are ordered
//! the same way along every viewing ray, and the one on the viewer's side of any separating
//! plane is in front. So for every pair whose screen rectangles overlap we find a separating
//! plane (sphere–sphere: the centre line; sphere–box: the closest point; box–box: the 15
//! separating-axis candidates) and add the edge "draw the far one first". A topological sort
//! of these edges, breaking ties by centre depth, gives the drawing order. Bodies that
//! interpenetrate have no separating plane and fall back to centre depth; cycles (possible
//! with three or more long bodies) are broken at the farthest remaining body.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use haptic_types::vec3::{Vec3, add, cross, dot, norm, scale, sub};

/// A solid as the sorter sees it.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Shape {
    /// Sphere: centre (m), radius (m).
    Sphere { c: Vec3, r: f64 },
    /// Oriented box: centre (m), unit axes, half extents (m). Flat shapes have a zero extent.
    Obb {
        c: Vec3,
        axes: [Vec3; 3],
        half: Vec3,
    },
}

/// One solid to order.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Item {
    pub shape: Shape,
    /// Depth of the centre along the viewing direction, m.
    pub depth: f64,
    /// Flat shapes (ellipses) sort before solids at equal depth.
    pub flat: bool,
    /// Screen rectangle, px: (x0, y0, x1, y1).
    pub rect: [f64; 4],
}

const EPS_REL: f64 = 1e-9;

/// Which of `a`, `b` is farther along `fwd` by a separating plane: `Some(true)` when `a` must be
/// drawn first, `Some(false)` when `b` must, `None` when no plane was found or the order does
/// not matter.
fn far_first(a: &Shape, b: &Shape, fwd: Vec3) -> Option<bool> {
    // axis n separates a (on its −side) from b (on its +side): b is farther iff n·fwd > 0.
    let decide = |n: Vec3| -> Option<bool> {
        let nf = dot(n, fwd);
        let nn = norm(n);
        if nf.abs() <= 1e-9 * nn {
            None
        } else {
            Some(nf > 0.0)
        }
    };
    match (a, b) {
        (Shape::Sphere { c: ca, r: ra }, Shape::Sphere { c: cb, r: rb }) => {
            let d = sub(*cb, *ca);
            let dn = norm(d);
            if dn >= (ra + rb) * (1.0 - EPS_REL) && dn > 0.0 {
                // b farther means a is in front: b first.
                decide(d).map(|b_farther| !b_farther)
            } else {
                None
            }
        }
        (Shape::Sphere { .. }, Shape::Obb { .. }) => far_first(b, a, fwd).map(|x| !x),
        (Shape::Obb { c, axes, half }, Shape::Sphere { c: cs, r }) => {
            // closest point of the box to the sphere centre
            let d = sub(*cs, *c);
            let mut q = *c;
            for i in 0..3 {
                let t = dot(d, axes[i]).clamp(-half[i], half[i]);
                q = add(q, scale(axes[i], t));
            }
            let n = sub(*cs, q);
            let nn = norm(n);
            if nn > 0.0 && nn >= r * (1.0 - EPS_REL) {
                decide(n).map(|sphere_farther| !sphere_farther)
            } else {
                None
            }
        }
        (
            Shape::Obb {
                c: ca,
                axes: aa,
                half: ha,
            },
            Shape::Obb {
                c: cb,
                axes: ab,
                half: hb,
            },
        ) => {
            let d = sub(*cb, *ca);
            let mut cands: [Vec3; 15] = [[0.0; 3]; 15];
            cands[..3].copy_from_slice(aa);
            cands[3..6].copy_from_slice(ab);
            for i in 0..3 {
                for j in 0..3 {
                    cands[6 + 3 * i + j] = cross(aa[i], ab[j]);
                }
            }
            let mut best: Option<(f64, Vec3)> = None;
            for n in cands {
                let nn = norm(n);
                if nn < 1e-9 {
                    continue;
                }
                let n = scale(n, 1.0 / nn);
                let ra: f64 = (0..3).map(|i| ha[i] * dot(aa[i], n).abs()).sum();
                let rb: f64 = (0..3).map(|i| hb[i] * dot(ab[i], n).abs()).sum();
                let dist = dot(d, n);
                let gap = dist.abs() - (ra + rb);
                if gap >= -EPS_REL * (ra + rb) {
                    let oriented = if dist >= 0.0 { n } else { scale(n, -1.0) };
                    // prefer the axis most aligned with the view: the robust witness
                    let w = dot(oriented, fwd).abs();
                    if best.is_none_or(|(bw, _)| w > bw) {
                        best = Some((w, oriented));
                    }
                }
            }
            best.and_then(|(_, n)| decide(n).map(|b_farther| !b_farther))
        }
    }
}

fn overlap(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Indices of `items` in drawing order (back to front).
pub(crate) fn back_to_front(items: &[Item], fwd: Vec3) -> Vec<usize> {
    let n = items.len();
    // initial rank: far first, flats before solids at equal depth, then insertion order
    let mut by_depth: Vec<usize> = (0..n).collect();
    by_depth.sort_by(|&i, &j| {
        items[j]
            .depth
            .total_cmp(&items[i].depth)
            .then(items[j].flat.cmp(&items[i].flat))
            .then(i.cmp(&j))
    });
    let mut rank = vec![0usize; n];
    for (r, &i) in by_depth.iter().enumerate() {
        rank[i] = r;
    }
    // edges between pairs whose screen rectangles overlap (sweep on x)
    let mut by_x: Vec<usize> = (0..n).collect();
    by_x.sort_by(|&i, &j| {
        items[i].rect[0]
            .total_cmp(&items[j].rect[0])
            .then(i.cmp(&j))
    });
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut indeg = vec![0usize; n];
    for (k, &i) in by_x.iter().enumerate() {
        for &j in &by_x[k + 1..] {
            if items[j].rect[0] >= items[i].rect[2] {
                break;
            }
            if !overlap(&items[i].rect, &items[j].rect) {
                continue;
            }
            let i_first =
                far_first(&items[i].shape, &items[j].shape, fwd).unwrap_or(rank[i] < rank[j]);
            let (from, to) = if i_first { (i, j) } else { (j, i) };
            succ[from].push(to);
            indeg[to] += 1;
        }
    }
    // Kahn's algorithm, lowest rank first; break cycles at the lowest remaining rank
    let mut heap: BinaryHeap<Reverse<(usize, usize)>> = BinaryHeap::new();
    for i in 0..n {
        if indeg[i] == 0 {
            heap.push(Reverse((rank[i], i)));
        }
    }
    let mut done = vec![false; n];
    let mut out = Vec::with_capacity(n);
    let mut next_rank = 0usize;
    while out.len() < n {
        let i = match heap.pop() {
            Some(Reverse((_, i))) => i,
            None => {
                while done[by_depth[next_rank]] {
                    next_rank += 1;
                }
                by_depth[next_rank]
            }
        };
        if done[i] {
            continue;
        }
        done[i] = true;
        out.push(i);
        for &j in &succ[i] {
            indeg[j] = indeg[j].saturating_sub(1);
            if indeg[j] == 0 && !done[j] {
                heap.push(Reverse((rank[j], j)));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: [Vec3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    fn obb(c: Vec3, half: Vec3) -> Shape {
        Shape::Obb { c, axes: ID, half }
    }

    #[test]
    fn long_slab_under_a_cube_is_drawn_first_from_above() {
        // A long thin slab whose centre is nearer to an oblique viewer than the cube standing
        // on its far end: centre depth alone would draw the slab last, over the cube.
        let slab = obb([0.0, 0.0, 0.0], [5.0, 0.5, 0.1]);
        let cube = obb([4.5, 0.0, 0.6], [0.5, 0.5, 0.5]);
        let fwd = crate::camera::View::Oblique {
            azimuth_rad: std::f64::consts::PI,
            elevation_rad: 0.4,
        }
        .basis()
        .2;
        // the cube's centre is farther than the slab's ...
        assert!(dot([4.5, 0.0, 0.6], fwd) > 0.0);
        // ... yet it stands on the slab, so the slab goes first
        assert_eq!(far_first(&slab, &cube, fwd), Some(true));
        assert_eq!(far_first(&cube, &slab, fwd), Some(false));
    }

    #[test]
    fn sphere_pairs_follow_centre_depth() {
        let a = Shape::Sphere {
            c: [0.0, 0.0, 0.0],
            r: 1.0,
        };
        let b = Shape::Sphere {
            c: [1.5, 0.0, 2.5],
            r: 1.0,
        };
        // looking down: b (higher z) is nearer, so a first
        assert_eq!(far_first(&a, &b, [0.0, 0.0, -1.0]), Some(true));
        assert_eq!(far_first(&b, &a, [0.0, 0.0, -1.0]), Some(false));
    }

    #[test]
    fn sphere_resting_on_box_is_drawn_after_it_from_above() {
        let b = obb([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
        let s = Shape::Sphere {
            c: [0.9, 0.0, 1.5],
            r: 0.5,
        };
        assert_eq!(far_first(&b, &s, [0.0, 0.0, -1.0]), Some(true));
    }
}
