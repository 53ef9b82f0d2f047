//! The scene file's table, the tick map's choice and its report.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use super::*;
use crate::scene::SceneFile;

fn params(extra: &str) -> OtParams {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/optical_tweezers.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let text = text.replace("tick_map_tol_nm = 0.01", extra);
    SceneFile::parse(&text)
        .unwrap()
        .world::<OtParams>()
        .unwrap()
        .expect("optical scene")
}

fn limits() -> Limits {
    Limits::FALCON.in_world(1e6, 1e-3)
}

fn first_events(p: OtParams) -> Vec<Event> {
    let mut s = OpticalScene::new(p, &limits()).unwrap();
    let mut out = SceneOutput::default();
    let input = SceneInput {
        tick: 0,
        dt_s: 1e-3,
        cursor_m: [0.0; 3],
        buttons: haptic_types::Buttons(0),
        input_valid: true,
    };
    s.step(&input, &mut out);
    out.events
}

fn build_error(extra: &str) -> String {
    match OpticalScene::new(params(extra), &limits()) {
        Ok(_) => panic!("accepted {extra}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_tick_map_choice_is_reported_once() {
    let ev = first_events(params("tick_map_tol_nm = 0.01"));
    assert_eq!(ev.len(), 2);
    assert_eq!(ev[0].name, "ot.tick_map");
    assert_eq!(ev[1].name, "ot.envelope_grid");
    assert!(
        ev[1]
            .detail
            .starts_with(r#"{"type":"envelope_grid","chosen_by":"budget","margin_waists":"#),
        "{}",
        ev[1].detail
    );
    assert!(
        ev[0]
            .detail
            .starts_with(r#"{"type":"tick_map","chosen_by":"budget","method":"rk4×2","error_m":"#),
        "{}",
        ev[0].detail
    );
    // the older form, and the same map by name: one choice, one report
    for form in [
        "rk4_substeps = 8",
        "tick_map = \"rk4\"\ntick_map_substeps = 8",
    ] {
        let fixed = first_events(params(form));
        assert!(
            fixed[0].detail.starts_with(
                r#"{"type":"tick_map","chosen_by":"named","method":"rk4×8","error_m":"#
            ),
            "{form}: {}",
            fixed[0].detail
        );
    }
    let adaptive = first_events(params("tick_map = \"dopri5\"\ntick_map_rtol = 1e-9"));
    assert!(
        adaptive[0]
            .detail
            .contains(r#""chosen_by":"named","method":"dopri5×1""#),
        "{}",
        adaptive[0].detail
    );
}

/// The tick map is chosen by name, and each bad field of the scene's `[optical_tweezers]`
/// table is refused with its exact message: the field, the value, the allowed range or forms.
#[test]
fn bad_fields_are_refused_with_their_exact_message() {
    for (extra, want) in [
        (
            "tick_map = \"euler\"",
            "scene: optical_tweezers: `tick_map` = \"euler\" is not a tick map (allowed: \"budget\", \
         \"paper-rk4\", \"rk4\", \"rk8\", \"dopri5\", \"adaptive\", \"symplectic\", \
         \"yoshida4\", \"yoshida6\")",
        ),
        (
            "rk4_substeps = 4\ntick_map = \"rk8\"",
            "scene: optical_tweezers: `rk4_substeps` is the older form of \
         `tick_map = \"rk4\"` with `tick_map_substeps`: give one of them, not both",
        ),
        (
            "tick_map = \"rk8\"\ntick_map_tol_nm = 0.1",
            "scene: optical_tweezers: `tick_map_tol_nm` is the budget of \
         `tick_map = \"budget\"`; the named map `rk8` is set by `tick_map_substeps` or \
         `tick_map_rtol`",
        ),
        (
            "tick_map = \"rk4\"\ntick_map_substeps = 0",
            "scene: `optical_tweezers.tick_map_substeps` = 0 is out of range: allowed 1 ≤ \
         optical_tweezers.tick_map_substeps ≤ 1000",
        ),
        (
            "envelope_build_evals_per_tick = 0",
            "scene: `optical_tweezers.envelope_build_evals_per_tick` = 0 is out of range: \
         allowed 1 ≤ optical_tweezers.envelope_build_evals_per_tick ≤ 1e6",
        ),
        (
            "spread_build = false\nenvelope_build_evals_per_tick = 64",
            "scene: optical_tweezers: `envelope_build_evals_per_tick` sets the spread rebuild \
         that `spread_build = false` switches off: give one of them, not both",
        ),
        (
            "tick_map_tol_nm = 0.0",
            "scene: `optical_tweezers.tick_map_tol_nm` = 0 is out of range: allowed 1e-4 ≤ \
         optical_tweezers.tick_map_tol_nm ≤ 100",
        ),
        (
            "tick_map_speed_m_per_s = -1.0",
            "scene: `optical_tweezers.tick_map_speed_m_per_s` = -1 is out of range: allowed 0 ≤ \
         optical_tweezers.tick_map_speed_m_per_s ≤ 1000",
        ),
        (
            "rk4_substeps = 0",
            "scene: `optical_tweezers.rk4_substeps` = 0 is out of range: allowed 1 ≤ \
         optical_tweezers.rk4_substeps ≤ 1000",
        ),
    ] {
        assert_eq!(build_error(extra), want, "{extra}");
    }
}

#[test]
fn the_10_khz_scene_loads_with_an_exact_period() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/optical_tweezers_10khz.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let loaded = crate::scene::load_scene(&text, None).unwrap();
    assert_eq!(loaded.config.rate_hz, 10_000);
    assert_eq!(loaded.config.period_ns(), 100_000);
    assert_eq!(loaded.scene.kind(), "optical_tweezers");
}

#[test]
fn the_spread_build_fields_reach_the_world() {
    let l = limits();
    let world = |extra: &str| params(extra).world_params(&l).unwrap();
    assert_eq!(
        world("tick_map_tol_nm = 0.01").envelope_build_evals_per_tick,
        Some(ot_envelope::tick::DEFAULT_BUILD_EVALS_PER_TICK)
    );
    assert_eq!(
        world("envelope_build_evals_per_tick = 64").envelope_build_evals_per_tick,
        Some(64)
    );
    assert_eq!(
        world("spread_build = false").envelope_build_evals_per_tick,
        None
    );
    // the first envelope is built when the scene loads
    let s = OpticalScene::new(params("tick_map_tol_nm = 0.01"), &l).unwrap();
    assert_eq!((s.tick_stats().rebuilds, s.tick_stats().ticks), (1, 0));
}

#[test]
fn a_tick_longer_than_one_period_of_the_fastest_oscillation_is_refused() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/optical_tweezers.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let with = |from: &str, to: &str| {
        let t = text.replace(from, to);
        let p = SceneFile::parse(&t)
            .unwrap()
            .world::<OtParams>()
            .unwrap()
            .unwrap();
        OpticalScene::new(p, &limits()).err().map(|e| e.to_string())
    };
    // Paper constants: κ = 2·ln2·1e-15 J / (300 nm)², period 2π·√(1e-15 kg / κ) = 1.6009 µs.
    assert_eq!(
        with("dt_us = 0.2", "dt_us = 5.0").as_deref(),
        Some(
            "scene: `optical_tweezers.dt_us` = 5 is out of range: allowed 0 < dt_us ≤ 1.6 µs, \
             1 period of the particle's fastest oscillation in this trap (2π·√(mass/κ), κ = \
             2·ln2·depth/waist², narrower waist); a longer tick makes the envelope too costly \
             for a haptic loop"
        )
    );
    // The fuzz finding: a particle 1000× lighter at the default 0.2 µs tick.
    let light = with("mass_g = 1.0e-12", "mass_g = 1e-15").unwrap_or_default();
    assert!(light.contains("≤ 0.0506 µs"), "{light}");
    assert_eq!(with("dt_us = 0.2", "dt_us = 1.0"), None);
    assert_eq!(three_digits_down(1.8849), "1.88");
    assert_eq!(three_digits_down(0.059605), "0.0596");
    assert_eq!(three_digits_down(1.6009), "1.6");
    assert_eq!(three_digits_down(123456.0), "123000");
}
