//! The workspace's 3-vector: `[f64; 3]` with small helpers, and quaternion helpers (f64). No
//! units of its own: the caller's vectors carry them (metres for points, newtons for forces).
//!
//! This is the one vector type at the seams between crates (scene primitives, device samples,
//! recorded messages), imported from here by every crate. Worlds use nalgebra (nanoworld,
//! ot-physics) or rapier's types (brickworld) inside and convert at their edge.

/// A point or vector, world frame (m for points).
pub type Vec3 = [f64; 3];

/// Component-wise sum `a + b`.
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Component-wise difference `a - b`.
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Scalar multiple `s * a`.
#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Dot product.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a × b`.
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm.
#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`; `a` itself when it is zero.
#[inline]
pub fn normalize(a: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 0.0 { scale(a, 1.0 / n) } else { a }
}

/// Rotates `v` by the unit quaternion `q = [x, y, z, w]`.
#[inline]
pub fn rotate(q: [f64; 4], v: Vec3) -> Vec3 {
    let u = [q[0], q[1], q[2]];
    let w = q[3];
    // v' = v + 2w (u × v) + 2 u × (u × v)
    let t = scale(cross(u, v), 2.0);
    add(add(v, scale(t, w)), cross(u, t))
}

/// The three local axes of a box rotated by `q`, as world unit vectors.
#[inline]
pub fn axes(q: [f64; 4]) -> [Vec3; 3] {
    [
        rotate(q, [1.0, 0.0, 0.0]),
        rotate(q, [0.0, 1.0, 0.0]),
        rotate(q, [0.0, 0.0, 1.0]),
    ]
}

/// `q / |q|` for a quaternion `[x, y, z, w]`.
pub fn normq(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    q.map(|v| v / n)
}

/// The 8 corners of a box with centre `c`, unit axes `ax` and half extents `h` (corner `k` has
/// `+h` along axis `i` when bit `i` of `k` is set).
pub fn box_corners(c: Vec3, ax: [Vec3; 3], h: Vec3) -> [Vec3; 8] {
    let mut out = [[0.0; 3]; 8];
    for (k, o) in out.iter_mut().enumerate() {
        let sx = if k & 1 == 0 { -h[0] } else { h[0] };
        let sy = if k & 2 == 0 { -h[1] } else { h[1] };
        let sz = if k & 4 == 0 { -h[2] } else { h[2] };
        *o = add(
            add(add(c, scale(ax[0], sx)), scale(ax[1], sy)),
            scale(ax[2], sz),
        );
    }
    out
}

/// True when every component is finite.
#[inline]
pub fn is_finite(a: Vec3) -> bool {
    a.iter().all(|c| c.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quarter_turn_about_z_maps_x_to_y() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let r = rotate([0.0, 0.0, h, h], [1.0, 0.0, 0.0]);
        assert!((r[0]).abs() < 1e-15 && (r[1] - 1.0).abs() < 1e-15 && r[2].abs() < 1e-15);
    }
}
