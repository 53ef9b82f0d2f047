//! The haptic-loop report's sessions whose figures do not depend on the clock, shared by the
//! report (`bench_report.rs`) and the test that holds BENCHMARKS.md's figures
//! (`tests/bench_figures.rs`): the 60 s workload on the wall, and the rigid stylus pushed into
//! it with the errors of what the loop rendered.
#![allow(dead_code)]

use haptic_devices::source::OperatorChoice;
use haptic_loop::SessionArrays;
use haptic_loop::session::{SceneSource, SessionOptions, SessionReport, run_session};
use std::fmt::Write as _;

/// A workload of `seconds`: press into the wall and slide, every 1.5 s, the centre button
/// held while pressing (so contact, clamp and button events keep happening).
pub fn workload_script(seconds: f64) -> String {
    let mut s = format!("[script]\nname = \"bench: repeated presses\"\nduration_s = {seconds}\n");
    let mut t = 0.0;
    let mut k = 0;
    while t <= seconds {
        let (x, z) = match k % 3 {
            0 => (0.0, 8.0),
            1 => (-10.0, -12.0),
            _ => (10.0, -30.0),
        };
        let _ = write!(
            s,
            "[[waypoint]]\nt_s = {t}\nposition_mm = [{x}, 0.0, {z}]\n"
        );
        if k % 3 == 1 {
            let _ = write!(s, "[[button]]\nt_s = {t}\nname = \"centre\"\ndown = true\n");
        }
        if k % 3 == 0 && k > 0 {
            let _ = write!(
                s,
                "[[button]]\nt_s = {t}\nname = \"centre\"\ndown = false\n"
            );
        }
        t += 0.5;
        k += 1;
    }
    s
}

/// A rigid stylus pushed slowly from 4 mm above the wall's plane to 25 mm (21 mm) in 4 s.
pub fn ramp_session(scene: &SceneSource) -> SessionReport {
    let ramp = "[script]\nname = \"ramp\"\n[[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, -4.0]\n\
                [[waypoint]]\nt_s = 4.0\nposition_mm = [0.0, 0.0, -25.0]\n";
    let mut o = SessionOptions::new(scene.clone());
    o.script = Some(ramp.to_string());
    o.operator = OperatorChoice::Rigid;
    run_session(&o, &mut |_, _| {}).expect("the ramp session runs")
}

/// The errors of what the loop rendered in the ramp session: (the force in the unclamped
/// range against `k·d − b·v_n` with the capped 3000 N/m and the scene's 1 N·s/m, relative;
/// the clamped force's norm against 8 N, N; the sent force's direction against the world's,
/// rad).
pub fn rendering_errors(a: &SessionArrays) -> (f64, f64, f64) {
    let pen = a
        .state_column("penetration_m")
        .expect("the wall's penetration");
    let engaged: Vec<usize> = (0..a.tick.len())
        .filter(|&i| a.engagement[i] == 1.0 && a.status[i] == 0 && pen[i] > 1e-4)
        .collect();
    let stiff_err = engaged
        .iter()
        .map(|&i| {
            let v_n = (a.cursor_m[i][2] - a.cursor_m[i - 1][2]) * 1000.0;
            let expected = 3000.0 * pen[i] - 1.0 * v_n;
            (a.device_force_n[i][2] - expected).abs() / expected
        })
        .fold(0.0, f64::max);
    let clamp_err = a
        .device_force_n
        .iter()
        .zip(&a.status)
        .filter(|(_, s)| **s & 1 != 0)
        .map(|(f, _)| ((f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() - 8.0).abs())
        .fold(0.0, f64::max);
    let clamp_dir = a
        .device_force_n
        .iter()
        .zip(&a.world_force_n)
        .filter(|(f, _)| f[2] > 0.0)
        .map(|(f, g)| {
            let nf = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            let ng = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            let c = (f[0] * g[0] + f[1] * g[1] + f[2] * g[2]) / (nf * ng);
            c.clamp(-1.0, 1.0).acos()
        })
        .fold(0.0, f64::max);
    (stiff_err, clamp_err, clamp_dir)
}
