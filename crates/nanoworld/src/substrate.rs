//! The fixed substrate layer and its cell list.
//!
//! Atoms sit on a square lattice at z = 0. A uniform grid of square cells in the x–y
//! plane (cell edge ≥ the largest interaction reach) holds the atom indices cell by cell
//! (compressed rows), so a query visits at most a 3 × 3 block of cells and costs the same
//! for 10³ or 10⁶ atoms. Queries return every atom within the given radius, in ascending
//! index order, so sums over them are bit-reproducible and equal to the brute-force sum
//! over the same atoms in the same order.

use nalgebra::Vector3;

use crate::params::SubstrateParams;

/// The fixed substrate atoms with a cell list over them.
#[derive(Debug, Clone)]
pub struct Substrate {
    positions: Vec<Vector3<f64>>,
    radius_m: f64,
    cell_m: f64,
    ncx: usize,
    ncy: usize,
    cell_start: Vec<u32>,
    cell_atoms: Vec<u32>,
}

impl Substrate {
    /// Build the lattice of `p` with cells at least `reach_m` wide (m).
    pub fn new(p: &SubstrateParams, reach_m: f64) -> Self {
        let mut positions = Vec::with_capacity(p.nx * p.ny);
        for j in 0..p.ny {
            for i in 0..p.nx {
                positions.push(Vector3::new(
                    i as f64 * p.spacing_m,
                    j as f64 * p.spacing_m,
                    0.0,
                ));
            }
        }
        Self::from_positions(positions, p.atom_radius_m, reach_m.max(p.spacing_m))
    }

    fn from_positions(positions: Vec<Vector3<f64>>, radius_m: f64, cell_m: f64) -> Self {
        let (mut xmax, mut ymax) = (0.0f64, 0.0f64);
        for q in &positions {
            xmax = xmax.max(q.x);
            ymax = ymax.max(q.y);
        }
        let ncx = (xmax / cell_m).floor() as usize + 1;
        let ncy = (ymax / cell_m).floor() as usize + 1;
        let cell_of = |q: &Vector3<f64>| {
            let cx = ((q.x / cell_m).floor() as usize).min(ncx - 1);
            let cy = ((q.y / cell_m).floor() as usize).min(ncy - 1);
            cy * ncx + cx
        };
        let mut counts = vec![0u32; ncx * ncy + 1];
        for q in &positions {
            counts[cell_of(q) + 1] += 1;
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let cell_start = counts.clone();
        let mut fill = counts;
        let mut cell_atoms = vec![0u32; positions.len()];
        // Index order within each cell is ascending because atoms are visited in order.
        for (i, q) in positions.iter().enumerate() {
            let c = cell_of(q);
            cell_atoms[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        Substrate {
            positions,
            radius_m,
            cell_m,
            ncx,
            ncy,
            cell_start,
            cell_atoms,
        }
    }

    /// Atom centres (m), in index order.
    pub fn positions(&self) -> &[Vector3<f64>] {
        &self.positions
    }

    /// Radius of every substrate atom (m).
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Number of atoms.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// Whether the substrate has no atoms (never true for a valid world).
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Edge of a grid cell (m).
    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// Call `f(index, centre)` for every atom whose centre lies within `radius_m` of `p`,
    /// in ascending index order (radius ≤ cell edge; larger radii are searched fully).
    pub fn for_each_within(
        &self,
        p: &Vector3<f64>,
        radius_m: f64,
        mut f: impl FnMut(usize, &Vector3<f64>),
    ) {
        if radius_m > self.cell_m {
            self.for_each_within_brute_force(p, radius_m, f);
            return;
        }
        let r2 = radius_m * radius_m;
        if p.z.abs() >= radius_m {
            return;
        }
        let lo = |v: f64, n: usize| -> Option<usize> {
            let c = ((v - radius_m) / self.cell_m).floor();
            if c >= n as f64 {
                None
            } else {
                Some(c.max(0.0) as usize)
            }
        };
        let hi = |v: f64, n: usize| -> Option<usize> {
            let c = ((v + radius_m) / self.cell_m).floor();
            if c < 0.0 {
                None
            } else {
                Some((c as usize).min(n - 1))
            }
        };
        let (Some(x0), Some(x1), Some(y0), Some(y1)) = (
            lo(p.x, self.ncx),
            hi(p.x, self.ncx),
            lo(p.y, self.ncy),
            hi(p.y, self.ncy),
        ) else {
            return;
        };
        // Cells are visited row by row; atoms are stored row-major by lattice index, and a
        // 3 × 3 block can interleave rows, so collect and sort the (few) hits for a stable order.
        let mut buf: smallvec_lite::Buf = smallvec_lite::Buf::new();
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                let c = cy * self.ncx + cx;
                let (s, e) = (self.cell_start[c] as usize, self.cell_start[c + 1] as usize);
                for &i in &self.cell_atoms[s..e] {
                    let q = &self.positions[i as usize];
                    if (q - p).norm_squared() < r2 {
                        buf.push(i);
                    }
                }
            }
        }
        buf.sort();
        for &i in buf.as_slice() {
            f(i as usize, &self.positions[i as usize]);
        }
    }

    /// Call `f` for every atom within `radius_m` of `p` by scanning all atoms (the exact
    /// reference for the cell list), in ascending index order.
    pub fn for_each_within_brute_force(
        &self,
        p: &Vector3<f64>,
        radius_m: f64,
        mut f: impl FnMut(usize, &Vector3<f64>),
    ) {
        let r2 = radius_m * radius_m;
        for (i, q) in self.positions.iter().enumerate() {
            if (q - p).norm_squared() < r2 {
                f(i, q);
            }
        }
    }
}

/// A tiny growable index buffer that lives on the stack for the usual few dozen hits.
mod smallvec_lite {
    const INLINE: usize = 256;

    pub struct Buf {
        inline: [u32; INLINE],
        len: usize,
        spill: Vec<u32>,
    }

    impl Buf {
        pub fn new() -> Self {
            Buf {
                inline: [0; INLINE],
                len: 0,
                spill: Vec::new(),
            }
        }

        pub fn push(&mut self, v: u32) {
            if self.len < INLINE {
                self.inline[self.len] = v;
                self.len += 1;
            } else {
                if self.spill.is_empty() {
                    self.spill.extend_from_slice(&self.inline);
                }
                self.spill.push(v);
                self.len += 1;
            }
        }

        pub fn sort(&mut self) {
            if self.len <= INLINE {
                self.inline[..self.len].sort_unstable();
            } else {
                self.spill.sort_unstable();
            }
        }

        pub fn as_slice(&self) -> &[u32] {
            if self.len <= INLINE {
                &self.inline[..self.len]
            } else {
                &self.spill
            }
        }
    }
}
