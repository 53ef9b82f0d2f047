//! The range-limited inverse solve: the laser can only place the trap inside
//! a disc. Exact roots in range are returned as they are; otherwise the
//! offset in range whose displacement is closest to the target, by
//! trust-region Gauss–Newton whose convex subproblem (a quadratic with the
//! disc as a second-order cone and the trust region as bounds) is solved by
//! clarabel.

use crate::error::{EnvelopeError, Result, finite_vec, positive};
use crate::inverse::TrapSolver;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Matrix2, Vector2};

type V2 = Vector2<f64>;

/// Result of the range-limited solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounded {
    /// Chosen trap offset (m), inside the steering range.
    pub offset: V2,
    /// Displacement it produces (m).
    pub displacement: V2,
    /// Distance from the target (m); ≤ the residual tolerance when reachable.
    pub miss: f64,
    /// Whether the target itself is reachable within the range.
    pub reachable: bool,
}

/// The laser's steering range: a disc of trap positions (world frame, m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteeringRange {
    /// Centre of the disc (m).
    pub centre: V2,
    /// Radius (m, > 0).
    pub radius: f64,
}

impl SteeringRange {
    /// A validated steering disc.
    pub fn new(centre: V2, radius: f64) -> Result<Self> {
        finite_vec("steering.centre [m]", centre.as_slice())?;
        Ok(Self {
            centre,
            radius: positive("steering.radius [m]", radius)?,
        })
    }
}

impl TrapSolver<'_> {
    /// Range-limited solve: the trap position `particle + offset` must stay in
    /// `range`. Returns the exact solution when one lies in range (chosen as in
    /// [`TrapSolver::steer`]), else the offset in range whose displacement is
    /// closest to `target`, by trust-region Gauss–Newton whose subproblem —
    /// a quadratic with the steering disc as a second-order cone and the trust
    /// region as bounds — is solved by clarabel.
    pub fn solve_bounded(
        &self,
        target: &V2,
        particle: &V2,
        range: &SteeringRange,
        prev: Option<&V2>,
    ) -> Result<Bounded> {
        finite_vec("target [m]", target.as_slice())?;
        finite_vec("particle [m]", particle.as_slice())?;
        let c = range.centre - particle; // disc centre in offset coordinates
        let inside = |o: &V2| (o - c).norm() <= range.radius * (1.0 + 1e-12);
        let (sol, _) = self.solve(target)?;
        let anchor = prev.copied().unwrap_or_else(V2::zeros);
        if let Some(o) = sol
            .offsets()
            .iter()
            .filter(|o| inside(o))
            .min_by(|a, b| (*a - anchor).norm().total_cmp(&(*b - anchor).norm()))
        {
            let (d, _, _) = self.prop.flow(o, &self.map.v0)?;
            return Ok(Bounded {
                offset: *o,
                displacement: d,
                miss: (d - target).norm(),
                reachable: true,
            });
        }
        // Seeds: projections of the unconstrained solutions onto the disc,
        // and the three in-range grid vertices whose images are closest.
        let project = |o: &V2| {
            let d = o - c;
            let n = d.norm();
            if n > range.radius {
                c + d * (range.radius / n)
            } else {
                *o
            }
        };
        let mut seeds: Vec<V2> = sol.offsets().iter().map(project).collect();
        let mut verts: Vec<(f64, V2)> = Vec::new();
        for i in 0..self.map.n[0] {
            for j in 0..self.map.n[1] {
                let o = self.map.offset(i, j);
                if inside(&o) {
                    verts.push(((self.map.disp[self.map.idx(i, j)] - target).norm(), o));
                }
            }
        }
        verts.sort_by(|a, b| a.0.total_cmp(&b.0));
        seeds.extend(verts.iter().take(3).map(|v| v.1));
        if seeds.is_empty() {
            seeds.push(project(&self.map.region.centre()));
        }
        let mut best: Option<Bounded> = None;
        for s in seeds {
            let b = self.gauss_newton_in_disc(&s, target, &c, range.radius)?;
            if best.is_none_or(|x| b.miss < x.miss) {
                best = Some(b);
            }
        }
        best.ok_or_else(|| EnvelopeError::Subproblem("no seed in the steering range".into()))
    }

    fn gauss_newton_in_disc(
        &self,
        start: &V2,
        target: &V2,
        c: &V2,
        radius: f64,
    ) -> Result<Bounded> {
        let l = self.w.min();
        let mut o = *start;
        let f = self.prop.flow_offset_jacobian(&o, &self.map.v0)?;
        let (mut r, mut j) = ((f.displacement - target) / l, f.d_offset);
        let mut trust = 0.25; // waists (of the smallest axis)
        for _ in 0..40 {
            let delta = disc_step(&j, &r, &((o - c) / l), radius / l, trust)?;
            let pred = (r + j * delta).norm_squared();
            let cand = o + delta * l;
            let fc = self.prop.flow_offset_jacobian(&cand, &self.map.v0)?;
            let rc = (fc.displacement - target) / l;
            let actual = r.norm_squared() - rc.norm_squared();
            let predicted = r.norm_squared() - pred;
            if actual > 0.0 && actual >= 0.1 * predicted {
                (o, r, j) = (cand, rc, fc.d_offset);
                if actual > 0.75 * predicted {
                    trust = (trust * 2.0).min(2.0);
                }
            } else {
                trust *= 0.25;
            }
            if trust < 1e-9 || delta.norm() < 1e-10 || r.norm() * l <= self.residual {
                break;
            }
        }
        let d = r * l + target;
        Ok(Bounded {
            offset: o,
            displacement: d,
            miss: r.norm() * l,
            reachable: r.norm() * l <= self.residual,
        })
    }
}

/// The trust-region Gauss–Newton subproblem, scaled (offsets in waists):
/// `min |r + J δ|²` subject to `|o + δ − c| ≤ R` (second-order cone) and
/// `|δ_i| ≤ trust` (bounds), solved by clarabel.
fn disc_step(j: &Matrix2<f64>, r: &V2, o_minus_c: &V2, radius: f64, trust: f64) -> Result<V2> {
    let jtj = j.transpose() * j;
    let g = j.transpose() * r;
    let reg = 1e-9 * (1.0 + jtj.norm());
    // ½ δᵀ P δ + qᵀ δ with P = 2(JᵀJ + εI) (upper triangle), q = 2 Jᵀ r.
    let p = CscMatrix::from(&[
        [2.0 * (jtj[(0, 0)] + reg), 2.0 * jtj[(0, 1)]],
        [0.0, 2.0 * (jtj[(1, 1)] + reg)],
    ]);
    let q = vec![2.0 * g.x, 2.0 * g.y];
    // s = b − A δ: bounds (4 rows, s ≥ 0), then the cone (R, o − c + δ).
    let a = CscMatrix::from(&[
        [1.0, 0.0],
        [-1.0, 0.0],
        [0.0, 1.0],
        [0.0, -1.0],
        [0.0, 0.0],
        [-1.0, 0.0],
        [0.0, -1.0],
    ]);
    let b = vec![trust, trust, trust, trust, radius, o_minus_c.x, o_minus_c.y];
    let cones = [
        SupportedConeT::NonnegativeConeT(4),
        SupportedConeT::SecondOrderConeT(3),
    ];
    let settings = DefaultSettings::<f64> {
        verbose: false,
        ..Default::default()
    };
    let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings)
        .map_err(|e| EnvelopeError::Subproblem(format!("{e:?}")))?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Ok(V2::new(solver.solution.x[0], solver.solution.x[1]))
        }
        s => Err(EnvelopeError::Subproblem(format!("clarabel status {s:?}"))),
    }
}
