//! The transparency probe of the link report, shared by `examples/link_report.rs` (which
//! tabulates it in BENCHMARKS.md) and `tests/link.rs` (which asserts the quoted figures): the
//! `wall` world at a given stiffness (B = 0, the safety layer off, no engagement ramp) pressed
//! 8 mm by a hand, and a glide through free space 20 mm above it.

use haptic_devices::{Grip, Mechanics};
use haptic_loop::closed_loop::{Linked, run_linked};

/// Down 8 mm into the wall in 0.5 s, held 1.5 s, back up by 2.5 s.
pub const PRESS: &str = include_str!("../press_and_hold.script.toml");

/// 0.1 m/s along x, 20 mm above the wall (free space), after a 0.2 s start.
pub const GLIDE: &str = r#"
[script]
name = "glide at 0.1 m/s"
duration_s = 0.8
[[waypoint]]
t_s = 0.0
position_mm = [-30.0, 0.0, 20.0]
[[waypoint]]
t_s = 0.2
position_mm = [-30.0, 0.0, 20.0]
[[waypoint]]
t_s = 0.8
position_mm = [30.0, 0.0, 20.0]
"#;

/// The probe's scene: a wall of stiffness `k` (N/m) through the origin, facing +z.
pub fn wall(k: f64) -> String {
    format!(
        "[scene]\nname = \"link wall\"\nkind = \"wall\"\n[device]\nmodel = \"falcon\"\n\
         [mapping]\nfit_device = false\n\
         [loop]\nengage_s = 0.0\npassivity = false\nforce_rate_limit = false\n\
         [wall]\nnormal = [0.0, 0.0, 1.0]\npoint_m = [0.0, 0.0, 0.0]\n\
         stiffness_n_per_m = {k:?}\ndamping_n_s_per_m = 0.0\ncursor_radius_m = 0.001\n"
    )
}

/// Least-squares slope of `y` against `x` over the points `(x, y)`.
pub fn slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |a, p| {
        (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2))
    });
    sxy / sxx
}

/// The stiffness a firm hand feels pressing the wall of stiffness `k` on `mech` behind `l`,
/// over `k`: the least-squares slope of the felt F_z against the depth over the samples
/// 0.5–2 mm deep.
pub fn felt_over_wall(mech: Mechanics, k: f64, l: &Linked) -> f64 {
    let (_, t) = run_linked(&wall(k), PRESS, mech, Grip::FIRM, l, None).unwrap();
    let pts: Vec<(f64, f64)> = (t.readings.iter().zip(&t.felt))
        .map(|(p, f)| (-p[2], f[2]))
        .filter(|(d, _)| (0.0005..0.002).contains(d))
        .collect();
    slope(&pts) / k
}

/// The mean force a firm hand feels gliding at 0.1 m/s in free space above the wall of
/// stiffness `k` (samples 300–700, the steady glide), N: nothing is rendered there.
pub fn drag_n(mech: Mechanics, k: f64, l: &Linked) -> f64 {
    let (_, g) = run_linked(&wall(k), GLIDE, mech, Grip::FIRM, l, None).unwrap();
    let glide: Vec<f64> = (g.felt.iter().skip(300).take(400))
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .collect();
    glide.iter().sum::<f64>() / glide.len().max(1) as f64
}
