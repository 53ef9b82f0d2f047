//! The working envelope of a 3D trap as a closed triangle mesh.
//!
//! Method: rays from the centre of the offset region (scaled by the waists)
//! through the vertices of a subdivided icosahedron; on each ray the fold
//! surface `det J = 0` is bracketed by marching outwards and refined by
//! bisection, then mapped. The mesh keeps the icosphere's triangles. This
//! holds when the fold surface is one star-shaped sheet whose image is the
//! envelope boundary — true for a single-well trap over a tick shorter than
//! about one axial period; otherwise [`working_envelope_3d`] returns
//! [`EnvelopeError::NotStarShaped`].

use crate::error::{EnvelopeError, Result, ValueError, finite_vec, positive};
use nalgebra::{Matrix3, Vector3};
use ot_physics::Propagator;
use std::collections::BTreeMap;

type V3 = Vector3<f64>;

/// A closed triangle mesh (m), outward-facing counter-clockwise triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Vertex positions (m).
    pub vertices: Vec<V3>,
    /// Triangles as vertex indices.
    pub triangles: Vec<[u32; 3]>,
}

/// A 3D working envelope.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope3 {
    /// Boundary of the reachable displacements (m).
    pub mesh: Mesh,
    /// Force evaluations spent.
    pub evals: u64,
}

impl Mesh {
    /// Generalised winding number of `p` (≈ 1 inside, ≈ 0 outside).
    pub fn winding(&self, p: &V3) -> f64 {
        let mut w = 0.0;
        for t in &self.triangles {
            let a = self.vertices[t[0] as usize] - p;
            let b = self.vertices[t[1] as usize] - p;
            let c = self.vertices[t[2] as usize] - p;
            let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
            let num = a.dot(&b.cross(&c));
            let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
            w += 2.0 * num.atan2(den);
        }
        w / (4.0 * std::f64::consts::PI)
    }
    /// Distance from `p` to the surface (m).
    pub fn distance(&self, p: &V3) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let q = closest_on_triangle(
                    p,
                    &self.vertices[t[0] as usize],
                    &self.vertices[t[1] as usize],
                    &self.vertices[t[2] as usize],
                );
                (q - p).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Enclosed volume (m³), positive for outward orientation.
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let (a, b, c) = (
                    self.vertices[t[0] as usize],
                    self.vertices[t[1] as usize],
                    self.vertices[t[2] as usize],
                );
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }
}

/// Closest point of triangle `abc` to `p` (Ericson, Real-Time Collision
/// Detection, §5.1.5).
fn closest_on_triangle(p: &V3, a: &V3, b: &V3, c: &V3) -> V3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let den = 1.0 / (va + vb + vc);
    a + ab * (vb * den) + ac * (vc * den)
}

/// Unit icosphere with `level` subdivisions (10·4^level + 2 vertices).
pub fn icosphere(level: u32) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<V3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| V3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: BTreeMap<(u32, u32), u32> = BTreeMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        let mut m = |a: u32, b: u32, v: &mut Vec<V3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push(((v[a as usize] + v[b as usize]) * 0.5).normalize());
                (v.len() - 1) as u32
            })
        };
        for [a, b, c] in f {
            let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
            nf.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
    }
    Mesh {
        vertices: v,
        triangles: f,
    }
}

/// The 3D working envelope of `prop`'s tick for velocity `v0` (m/s): rays on
/// an icosphere of `level` subdivisions, marched out to `reach` waists in
/// steps of `step` waists, fold points bisected to 1e-4 waist (a fold point off by δ maps O(δ²) inside).
pub fn working_envelope_3d(
    prop: &Propagator<3>,
    v0: &V3,
    level: u32,
    reach: f64,
    step: f64,
) -> Result<Envelope3> {
    finite_vec("velocity [m/s]", v0.as_slice())?;
    let reach = positive("reach [waists]", reach)?;
    let step = positive("step [waists]", step)?;
    if level > 6 {
        return Err(EnvelopeError::Value(ValueError::out_of_range(
            "level",
            f64::from(level),
            "0 ..= 6",
        )));
    }
    let w = prop.model().well.waists();
    let centre = v0 * (0.5 * prop.dt());
    let sphere = icosphere(level);
    let mut evals = 0;
    let det_at = |z: &V3, evals: &mut u64| -> Result<(f64, V3)> {
        let o = centre + z.component_mul(&w);
        let f = prop.flow_jacobian(&o, v0)?;
        *evals += f.evals;
        let j: Matrix3<f64> = f.d_offset;
        Ok((j.determinant(), f.displacement))
    };
    let mut vertices = Vec::with_capacity(sphere.vertices.len());
    let n = (reach / step).ceil() as usize;
    for u in &sphere.vertices {
        let (d0, _) = det_at(&V3::zeros(), &mut evals)?;
        let mut prev = (0.0, d0);
        let mut changes = Vec::new();
        for k in 1..=n {
            let s = reach * k as f64 / n as f64;
            let (d, _) = det_at(&(u * s), &mut evals)?;
            if (d >= 0.0) != (prev.1 >= 0.0) {
                changes.push((prev.0, s));
            }
            prev = (s, d);
        }
        if changes.len() != 1 {
            return Err(EnvelopeError::NotStarShaped(format!(
                "ray {:?} crosses det J = 0 {} times within {reach} waists",
                u.as_slice(),
                changes.len()
            )));
        }
        let (mut a, mut b) = changes[0];
        let (da, _) = det_at(&(u * a), &mut evals)?;
        let sa = da >= 0.0;
        while b - a > 1e-4 {
            let m = 0.5 * (a + b);
            let (dm, _) = det_at(&(u * m), &mut evals)?;
            if (dm >= 0.0) == sa { a = m } else { b = m }
        }
        let (_, disp) = det_at(&(u * (0.5 * (a + b))), &mut evals)?;
        vertices.push(disp);
    }
    let mut mesh = Mesh {
        vertices,
        triangles: sphere.triangles,
    };
    if mesh.volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    Ok(Envelope3 { mesh, evals })
}
