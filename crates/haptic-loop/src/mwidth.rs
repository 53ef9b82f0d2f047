//! The M-width of a device (Colonnese and Okamura, RSS 2012): the range of virtual masses it
//! renders stably and faithfully, measured as a hand carries a brick of the brick world in
//! closed loop ([`crate::closed_loop::run_linked`]), the device side speaking bridge
//! protocol 2 (it integrates the carried body itself, behind its two-port passivity layer).
//!
//! A carry ([`carry_script`]): the built-in script's approach to the first brick, the grab,
//! a 14.3 mm lift, then a side-to-side sine along x at the carry frequency whose intended
//! acceleration is [`CARRY_ACCEL_M_PER_S2`] (its amplitude between [`MIN_AMPLITUDE_M`] and
//! [`MAX_AMPLITUDE_M`]), faded in over [`FADE_S`]. Measured over the last whole periods
//! spanning at least [`WINDOW_S`], after [`SETTLE_S`]: the phasor at the carry frequency of
//! the force the motors rendered along x and of the encoder's x reading ([`phasor`], Hann
//! window: the hand's own resonance, 2–3 Hz, rings on from the approach and must not leak
//! into a bin where the coupling's gain is a different one). The felt mass is `|F̂ / X̂| / ω²`, and
//! its ratio to the brick's mass at the device (`M · force_scale · workspace_scale`) is the
//! felt inertia's ratio: 1 is faithful. A passive coupling bounds it from below and above
//! ([`haptic_types::local::felt_mass_ratio`]).

use crate::closed_loop::{ClosedLoopError, Linked, Report, run_linked};
use crate::scene::load_scene_for;
use haptic_devices::modelled::preset_specs;
use haptic_devices::{Grip, Mechanics};

/// The carry frequencies of the table, Hz.
pub const FREQUENCIES_HZ: [f64; 4] = [0.5, 1.0, 2.0, 5.0];

/// The brick masses swept, kg (world units; the default brick is 0.5 kg).
pub const MASSES_KG: [f64; 8] = [0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0];

/// The carry's intended peak acceleration, m/s² (device frame).
pub const CARRY_ACCEL_M_PER_S2: f64 = 0.2;

/// Largest intended amplitude of the carry, m (device frame).
pub const MAX_AMPLITUDE_M: f64 = 0.01;

/// Smallest intended amplitude of the carry, m (device frame): at 5 Hz the acceleration is
/// then 1 m/s², so the encoder sees more than a count.
pub const MIN_AMPLITUDE_M: f64 = 0.001;

/// The carry's fade-in (its amplitude from 0 to full, smoothstep), s.
pub const FADE_S: f64 = 1.0;

/// Least span of the measured window (whole periods at its end), s.
pub const WINDOW_S: f64 = 4.0;

/// Settling between the fade-in's end and the measured window, s.
pub const SETTLE_S: f64 = 2.0;

/// Script time at which the sine starts (the brick grabbed and lifted), s.
pub const CARRY_START_S: f64 = 2.3;

/// Time between the sine's waypoints, s (one loop tick of the brick scene).
const WAYPOINT_S: f64 = 1e-3;

/// The lifted brick's grip position, mm (device frame; above the loading zone's first brick).
const LIFTED_MM: [f64; 3] = [-22.5, 2.5, 7.5];

/// The coupling's constants, as fractions of the device's rated stiffness and a damping
/// ratio (`[brickworld.params.coupling]`; [`Coupling::DEFAULT`] is the brick world's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coupling {
    /// The spring `k` over the rated stiffness.
    pub stiffness_fraction: f64,
    /// `k + k_s` over the rated stiffness.
    pub max_fraction: f64,
    /// `ζ` in `b = 2 ζ √(k M)`.
    pub damping_ratio: f64,
}

impl Coupling {
    /// The brick world's defaults (0.3, 0.6, 0.9).
    pub const DEFAULT: Coupling = Coupling {
        stiffness_fraction: 0.3,
        max_fraction: 0.6,
        damping_ratio: 0.9,
    };
    /// The stiffer coupling the bound points to: the spring at 0.6 of the rated stiffness and
    /// the high-frequency stiffness at all of it (a scene setting, not a default).
    pub const STIFF: Coupling = Coupling {
        stiffness_fraction: 0.6,
        max_fraction: 1.0,
        damping_ratio: 0.9,
    };
}

/// Periods measured and the carry's intended amplitude (m) at `hz`.
fn plan(hz: f64) -> (u32, f64) {
    let omega = 2.0 * std::f64::consts::PI * hz;
    let periods = (WINDOW_S * hz).ceil() as u32;
    (
        periods,
        (CARRY_ACCEL_M_PER_S2 / (omega * omega)).clamp(MIN_AMPLITUDE_M, MAX_AMPLITUDE_M),
    )
}

/// The carry's duration at `hz`, s.
pub fn carry_duration_s(hz: f64) -> f64 {
    let (periods, _) = plan(hz);
    CARRY_START_S + FADE_S + SETTLE_S + f64::from(periods) / hz
}

/// The script of a carry at `hz`: the approach and grab of the built-in brick script, the
/// lift, then `x = x₀ + A s(t) sin ω t` in waypoints one tick apart (`s` the fade-in), until
/// [`carry_duration_s`]. The grip is held to the end.
pub fn carry_script(hz: f64) -> String {
    let (_, amp) = plan(hz);
    let omega = 2.0 * std::f64::consts::PI * hz;
    let [x, y, z] = LIFTED_MM;
    let mut s = format!(
        "[script]\nname = \"carry at {hz} Hz\"\nduration_s = {:?}\n\n\
         [[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, 0.0]\n\n\
         [[waypoint]]\nt_s = 0.955\nposition_mm = [{x:?}, {y:?}, {z:?}]\n\n\
         [[waypoint]]\nt_s = 1.528\nposition_mm = [{x:?}, {y:?}, -6.8]\n\n\
         [[waypoint]]\nt_s = 1.531\nposition_mm = [{x:?}, {y:?}, -6.8]\n\n\
         [[waypoint]]\nt_s = 2.104\nposition_mm = [{x:?}, {y:?}, {z:?}]\n\n\
         [[button]]\nt_s = 1.529\nrole = \"grip\"\ndown = true\n",
        carry_duration_s(hz)
    );
    let n = ((carry_duration_s(hz) - CARRY_START_S) / WAYPOINT_S).round() as u32;
    for i in 0..=n {
        let t = f64::from(i) * WAYPOINT_S;
        let f = (t / FADE_S).min(1.0);
        let fade = f * f * (3.0 - 2.0 * f);
        let xi = x + 1e3 * amp * fade * (omega * t).sin();
        s.push_str(&format!(
            "\n[[waypoint]]\nt_s = {:?}\nposition_mm = [{xi:?}, {y:?}, {z:?}]\n",
            CARRY_START_S + t
        ));
    }
    s
}

/// The brick scene `base` (the shipped `brickworld.toml`) with its bricks of `mass_kg` and
/// the coupling `c`.
pub fn carry_scene(base: &str, mass_kg: f64, c: Coupling) -> String {
    base.replacen(
        "[brickworld.params]\n",
        &format!(
            "[brickworld.params]\nbrick_mass_kg = {mass_kg:?}\n\
             coupling = {{ stiffness_fraction = {:?}, max_fraction = {:?}, damping_ratio = {:?} }}\n",
            c.stiffness_fraction, c.max_fraction, c.damping_ratio
        ),
        1,
    )
}

/// The phasor of `series` (its `N` samples taken every `dt_s`) at `omega` (rad/s), through a
/// Hann window `wₙ = 1 − cos(2πn/N)`: `(2/N) Σ wₙ xₙ e^(−iωnΔt)`, as (real, imaginary). A
/// sine of amplitude `A` over whole periods gives `A`; a constant or a sine a whole number
/// of periods away by two or more gives nothing, and one between the bins little (the
/// window's side lobes fall as the cube of the distance).
pub fn phasor(series: &[f64], omega: f64, dt_s: f64) -> (f64, f64) {
    let n = series.len().max(1) as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for (i, x) in series.iter().enumerate() {
        let w = 1.0 - (2.0 * std::f64::consts::PI * i as f64 / n).cos();
        let ph = omega * i as f64 * dt_s;
        re += w * x * ph.cos();
        im -= w * x * ph.sin();
    }
    (re * 2.0 / n, im * 2.0 / n)
}

/// One carry: the run's report, what the hand felt, and the coupling's prediction.
#[derive(Clone, Debug, PartialEq)]
pub struct Carry {
    /// The closed-loop run's figures ([`Report::stable`] decides the M-width).
    pub report: Report,
    /// The brick's mass at the device, `M · force_scale · workspace_scale`, kg.
    pub device_mass_kg: f64,
    /// The felt mass over the brick's mass at the device: `|F̂ / X̂| / (ω² m)`.
    pub felt_ratio: f64,
    /// The coupling's `|K / (K − m ω²)|` ([`haptic_types::local::felt_mass_ratio`]).
    pub coupling_ratio: f64,
    /// The coupling's ratio with its dashpot locked (`|1 / (1 − m ω² / (k + k_s))|`, the
    /// least any damper gives below the locked resonance) and free (`|1 / (1 − m ω² / k)|`).
    pub limits: (f64, f64),
    /// The encoder's amplitude at the carry frequency, m.
    pub amplitude_m: f64,
}

impl Carry {
    /// The felt inertia's error, `felt_ratio − 1` (+0.10: felt 10 % heavy).
    pub fn error(&self) -> f64 {
        self.felt_ratio - 1.0
    }
}

/// Carries a brick of `mass_kg` (the brick scene `base`, coupling `c`) at `hz` on `mech` held
/// with `grip`, behind `linked`.
pub fn carry(
    base: &str,
    mass_kg: f64,
    c: Coupling,
    hz: f64,
    mech: Mechanics,
    grip: Grip,
    linked: &Linked,
) -> Result<Carry, ClosedLoopError> {
    let scene = carry_scene(base, mass_kg, c);
    let loaded = load_scene_for(&scene, preset_specs(&mech))?;
    let map = loaded.config.mapping;
    let dt = 1.0 / f64::from(loaded.config.rate_hz);
    let (report, trace) = run_linked(&scene, &carry_script(hz), mech, grip, linked, None)?;
    let omega = 2.0 * std::f64::consts::PI * hz;
    let (periods, _) = plan(hz);
    let n = (f64::from(periods) / hz / dt).round() as usize;
    let start = trace.felt.len().saturating_sub(n);
    let along_x = |s: &[[f64; 3]]| s[start..].iter().map(|v| v[0]).collect::<Vec<f64>>();
    let f = phasor(&along_x(&trace.felt), omega, dt);
    let x = phasor(&along_x(&trace.readings), omega, dt);
    let m = mass_kg * map.force_scale * map.workspace_scale;
    let felt_ratio = (f.0.hypot(f.1) / x.0.hypot(x.1)) / (omega * omega * m);
    // The coupling at the device: fractions of the rated stiffness, b = 2 ζ √(k m).
    let k_max = mech.limits.max_stiffness_n_per_m;
    let k = c.stiffness_fraction * k_max;
    let ks = (c.max_fraction - c.stiffness_fraction) * k_max;
    let b = 2.0 * c.damping_ratio * (k * m).sqrt();
    let mw2 = m * omega * omega;
    Ok(Carry {
        report,
        device_mass_kg: m,
        felt_ratio,
        coupling_ratio: haptic_types::local::felt_mass_ratio(k, ks, b, m, omega),
        limits: (
            (1.0 / (1.0 - mw2 / (k + ks))).abs(),
            (1.0 / (1.0 - mw2 / k)).abs(),
        ),
        amplitude_m: x.0.hypot(x.1),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_phasor_of_a_sine_over_whole_periods_is_its_amplitude() {
        let w = 2.0 * std::f64::consts::PI * 2.0;
        let s: Vec<f64> = (0..1000)
            .map(|i| 0.3 * (w * f64::from(i) * 1e-3 + 0.4).sin() + 5.0)
            .collect();
        let (re, im) = phasor(&s, w, 1e-3);
        assert!((re.hypot(im) - 0.3).abs() < 1e-12, "{re} {im}");
        // A sine three bins away contributes nothing; one 4.5 bins away (the hand's
        // resonance beside a 0.5 Hz carry) under 0.2 % of its amplitude.
        let s: Vec<f64> = (0..1000)
            .map(|i| (3.0 * w * f64::from(i) * 1e-3).sin())
            .collect();
        let (re, im) = phasor(&s, w, 1e-3);
        assert!(re.hypot(im) < 1e-12);
        let s: Vec<f64> = (0..1000)
            .map(|i| (5.5 * w * f64::from(i) * 1e-3).sin())
            .collect();
        let (re, im) = phasor(&s, w, 1e-3);
        assert!(re.hypot(im) < 2e-3, "{}", re.hypot(im));
    }

    #[test]
    fn a_carry_script_plays_its_sine_after_the_lift() {
        let s = carry_script(2.0);
        assert!(s.contains("name = \"carry at 2 Hz\""));
        // 2.3 s + 1 s fade + 2 s settle + 8 periods of 0.5 s.
        assert_eq!(carry_duration_s(2.0), 9.3);
        assert_eq!(s.matches("[[waypoint]]").count(), 5 + 7001);
        let (periods, amp) = plan(0.5);
        assert_eq!((periods, amp), (2, 0.01));
        let (periods, amp) = plan(2.0);
        assert_eq!(periods, 8);
        assert!((amp - 0.2 / (4.0 * std::f64::consts::PI).powi(2)).abs() < 1e-15);
        assert_eq!(plan(5.0), (20, 0.001));
    }
}
