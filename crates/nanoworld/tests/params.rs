//! Bad input gives typed errors naming the field and its allowed range; run-time changes
//! are validated and take effect.

use nalgebra::Vector3;
use nanoworld::{
    CurveSpec, GAME_FALCON_LIMITS, Interaction, ParamError, Params, StepError, TipInput, World,
    force_distance_curve,
};

fn start() -> Vector3<f64> {
    Vector3::new(2e-9, 2e-9, 2e-9)
}

fn game(p: &mut Params) -> &mut nanoworld::GameParams {
    match &mut p.interaction {
        Interaction::Game(g) => g,
        Interaction::Physical(_) => unreachable!("game params"),
    }
}

#[test]
fn defaults_are_valid() {
    Params::game_default().validate().expect("game default");
    Params::physical_default()
        .validate()
        .expect("physical default");
}

#[test]
fn snap_gap_beyond_activation_gap_is_rejected_by_name() {
    let mut p = Params::game_default();
    game(&mut p).pairs.tip_atom.snap_gap_m = 0.7e-9;
    let e = World::new(&p, &p.default_limits(), start()).expect_err("invalid");
    assert_eq!(
        e.to_string(),
        "interaction.game.pairs.tip_atom.snap_gap_m = 7e-10 is out of range: allowed 0 < value < activation_gap_m = 6e-10"
    );
}

#[test]
fn nan_and_negative_values_are_rejected_not_clamped() {
    let mut p = Params::game_default();
    p.substrate.spacing_m = f64::NAN;
    let e = p.validate().expect_err("NaN");
    assert!(matches!(&e, ParamError::Value(v) if v.field() == "substrate.spacing_m"));
    let p = Params::game_default();
    let bad = world_form::Limits {
        max_force_n: -1.0,
        ..GAME_FALCON_LIMITS
    };
    assert_eq!(
        World::new(&p, &bad, start())
            .expect_err("negative")
            .to_string(),
        "device.max_force_n = -1 is out of range: allowed 0 < max_force_n ≤ 100000 N"
    );
    let mut p = Params::game_default();
    game(&mut p).pull_off_ratio = 0.5;
    assert_eq!(
        p.validate().expect_err("ratio").to_string(),
        "interaction.game.pull_off_ratio = 0.5 is out of range: allowed 1 <= value <= 1000"
    );
    let mut p = Params::game_default();
    p.initial_atoms_xy_m.push([5.0e-9, 6.15e-9]);
    let e = p.validate().expect_err("overlap");
    assert!(e.to_string().starts_with("initial_atoms_xy_m[5] = "), "{e}");
    assert!(
        e.to_string()
            .contains("distance to initial_atoms_xy_m[0] >= 2*atoms.radius_m")
    );
}

#[test]
fn scene_table_parses_and_unknown_fields_are_rejected() {
    let toml_text = r#"
        gravity_m_per_s2 = 9.81
        [substrate]
        nx = 10
        ny = 10
        spacing_m = 3e-10
        atom_radius_m = 1.5e-10
        [tip]
        radius_m = 3e-10
        [atoms]
        radius_m = 1.5e-10
        mass_kg = 1e-25
        max_count = 10
        [interaction.physical]
        contact_gap_m = 1.65e-10
        cantilever_stiffness_n_per_m = 4.7
        [interaction.physical.hamaker_j]
        tip_substrate = 1e-19
        tip_atom = 2e-19
        atom_atom = 4e-19
        atom_substrate = 1e-19
    "#;
    let p: Params = toml::from_str(toml_text).expect("parses");
    p.validate().expect("valid");
    assert!(matches!(p.interaction, Interaction::Physical(_)));
    let bad = toml_text.replace("radius_m = 3e-10", "radius_m = 3e-10\nradius_nm = 0.3");
    let e = toml::from_str::<Params>(&bad).expect_err("unknown field");
    assert!(e.to_string().contains("unknown field `radius_nm`"), "{e}");
    // The force limit moved to the device: an old table that still sets it is refused, by name.
    let old = toml_text.replace(
        "gravity_m_per_s2 = 9.81",
        "gravity_m_per_s2 = 9.81\nmax_force_n = 1e-8",
    );
    let e = toml::from_str::<Params>(&old).expect_err("removed field");
    assert!(
        e.to_string().contains(
            "`max_force_n` is no longer a nanoworld parameter: the limit now comes from the \
             device (world_form::Limits given to World::new; in a scene file, the [device] model \
             mapped by mapping.force_scale); remove it"
        ),
        "{e}"
    );
    assert_eq!(
        ParamError::MovedToDevice {
            field: "max_force_n"
        }
        .field(),
        "max_force_n"
    );
}

#[test]
fn bad_tick_input_is_a_typed_error() {
    let mut w = World::new(&Params::game_default(), &GAME_FALCON_LIMITS, start()).expect("valid");
    let e = w
        .step(
            &TipInput {
                position_m: Vector3::new(0.0, f64::NAN, 0.0),
            },
            1e-3,
        )
        .expect_err("NaN");
    assert!(matches!(e, StepError::NonFinitePosition { axis: 'y', .. }));
    assert_eq!(
        e.to_string(),
        "tip position y = NaN is out of range: allowed a finite number of metres"
    );
    let e = w
        .step(
            &TipInput {
                position_m: start(),
            },
            0.0,
        )
        .expect_err("dt");
    assert_eq!(
        e.to_string(),
        "dt_s = 0 is out of range: allowed 1e-9 <= dt_s <= 1 s"
    );
    // A rejected tick leaves the world untouched.
    assert_eq!(w.tick(), 0);
}

#[test]
fn bad_curve_spec_is_a_typed_error() {
    let spec = CurveSpec {
        xy_m: [0.0, 0.0],
        far_gap_m: 1e-9,
        near_gap_m: 2e-9,
        steps: 100,
        dt_s: 1e-3,
    };
    let e = force_distance_curve(&Params::game_default(), &GAME_FALCON_LIMITS, &spec)
        .expect_err("near > far");
    assert_eq!(
        e.to_string(),
        "near_gap_m = 2e-9 is out of range: allowed finite and < far_gap_m = 1e-9 m"
    );
}

#[test]
fn run_time_changes_are_validated_and_take_effect() {
    let p = Params::game_default();
    let mut w = World::new(&p, &p.default_limits(), start()).expect("valid");
    let mut geometry = p.clone();
    geometry.substrate.nx = 41;
    assert_eq!(
        w.set_params(geometry).expect_err("geometry"),
        ParamError::NotChangeableAtRunTime { field: "substrate" }
    );
    let mut mode = p.clone();
    mode.interaction = Params::physical_default().interaction;
    assert_eq!(
        w.set_params(mode).expect_err("mode").to_string(),
        "interaction (game/physical mode) cannot change at run time (it fixes the geometry); build a new World instead"
    );
    let mut bad = p.clone();
    game(&mut bad).pairs.tip_substrate.stiffness_n_per_m = 0.0;
    assert!(w.set_params(bad).is_err());
    // Doubling the tip–substrate strength doubles its snap and pull-off forces.
    let before = *w.laws().get(nanoworld::PairKind::TipSubstrate);
    let mut stronger = p.clone();
    game(&mut stronger).pairs.tip_substrate.strength_n_m2 *= 2.0;
    w.set_params(stronger).expect("valid change");
    let after = *w.laws().get(nanoworld::PairKind::TipSubstrate);
    assert_eq!(after.snap_force_n, 2.0 * before.snap_force_n);
    assert_eq!(after.pull_off_n, 2.0 * before.pull_off_n);
}

#[test]
fn mass_is_felt_only_through_weight_and_inertia() {
    // A carried atom's weight adds m·g to the device force; at atomic mass it is ~1e-24 N,
    // fourteen orders below the 0.3 nN van der Waals snap force (the game's lesson).
    let mut p = Params::game_default();
    p.inertia = false;
    let spawn = p.loading_zone.as_ref().expect("zone").spawn_xy_m;
    let mut w = World::new(
        &p,
        &p.default_limits(),
        Vector3::new(spawn[0], spawn[1], 3e-9),
    )
    .expect("valid");
    let rest = w.rest_position(spawn);
    let mut last = None;
    let n = 3000;
    for k in 0..=n {
        let z = 3e-9 + (rest.z + 0.42e-9 - 3e-9) * k as f64 / n as f64;
        last = Some(
            w.step(
                &TipInput {
                    position_m: Vector3::new(spawn[0], spawn[1], z),
                },
                1e-3,
            )
            .expect("ok"),
        );
    }
    assert_eq!(w.carried().len(), 1);
    let up = Vector3::new(spawn[0], spawn[1], 5e-9);
    let f_light = w
        .step(&TipInput { position_m: up }, 1e-3)
        .expect("ok")
        .force_n;
    assert!(last.is_some());
    let mut heavy = p.clone();
    heavy.atoms.mass_kg = 1e-12;
    w.set_params(heavy).expect("valid");
    let f_heavy = w
        .step(&TipInput { position_m: up }, 1e-3)
        .expect("ok")
        .force_n;
    let dw = f_heavy.z - f_light.z;
    let expect = -(1e-12 - 1e-25) * 9.81;
    assert!(
        (dw - expect).abs() < 1e-9 * expect.abs(),
        "{dw:e} vs {expect:e}"
    );
}

/// Params are serde both ways (the world form): both presets written as TOML read back to the
/// same bits, and the written text uses the one unit spelling.
#[test]
fn params_round_trip_through_toml() {
    for p in [Params::game_default(), Params::physical_default()] {
        let text = toml::to_string(&p).expect("serializes");
        assert!(text.contains("gravity_m_per_s2"), "{text}");
        assert!(!text.contains("max_force_n"), "{text}");
        let back: Params = toml::from_str(&text).expect("reads back");
        assert_eq!(back, p);
    }
}
