//! The world's parameters, its refusals and its first-step reports.
#![allow(clippy::unwrap_used)]
use super::*;

fn limits() -> Limits {
    Limits::FALCON.in_world(1e6, 1e-3)
}

/// The error text of building a world from `p` with the Falcon's limits in the OT scene.
fn refused(p: Params) -> String {
    World::new(&p, &limits()).err().unwrap().to_string()
}

#[test]
fn the_paper_period_and_step_bound() {
    let p = Params::paper();
    // 2π / √(κ_max / m), κ_max = 2 ln2 · 1e-15 J / (300 nm)², m = 1e-15 kg: 1.6009 µs, the
    // period of the model the world builds (ot_envelope::tick_length, the one bound).
    assert!((p.small_oscillation_period_s() - 1.600_933_877e-6).abs() < 1e-15);
    let e = refused(Params {
        dt_s: 5e-6,
        ..Params::paper()
    });
    assert_eq!(
        e,
        "`dt_s` = 5e-6 is out of range: allowed ≤ 1.6009e-6 s, 1 period of the well's fastest \
         oscillation (ω = 3.9247e6 rad/s); a longer tick folds the map so often that the \
         envelope's boundary search grows without bound"
    );
}

#[test]
fn a_spring_stiffer_than_the_device_is_refused() {
    let e = refused(Params {
        stiffness_n_per_m: 5.0,
        ..Params::paper()
    });
    assert_eq!(
        e,
        "`stiffness_n_per_m` = 5 is out of range: allowed 0 < stiffness_n_per_m ≤ 3"
    );
    let e = refused(Params {
        depth_j: f64::NAN,
        ..Params::paper()
    });
    assert_eq!(
        e,
        "`depth_j` = NaN is out of range: allowed 0 < depth_j ≤ 1e-6"
    );
}

#[test]
fn an_unknown_method_names_the_allowed_ones() {
    let p = Params {
        tick_map: TickMap::Named {
            name: "euler".into(),
            substeps: None,
            rtol: None,
        },
        ..Params::paper()
    };
    let e = World::new(&p, &limits()).err().unwrap().to_string();
    assert!(
        e.starts_with("unknown method \"euler\": allowed \"paper-rk4\""),
        "{e}"
    );
}

#[test]
fn a_named_map_is_measured_and_reported_first() {
    let p = Params {
        tick_map: TickMap::Named {
            name: "rk4".into(),
            substeps: Some(8),
            rtol: None,
        },
        ..Params::paper()
    };
    let mut w = World::new(&p, &limits()).unwrap();
    let r = w.step(&Input {
        cursor_m: [5e-6, 0.0],
        grab: false,
    });
    match &r.events[0] {
        Event::TickMap {
            chosen_by,
            method,
            error_m,
            evals_per_flow,
            budget_m,
            ..
        } => {
            assert_eq!(*budget_m, None);
            assert_eq!((*chosen_by, method.as_str()), ("named", "rk4×8"));
            assert!(*error_m > 0.0 && *error_m < 1e-11, "{error_m}");
            assert_eq!(*evals_per_flow, 32);
        }
        e => panic!("first event {}", e.name()),
    }
    assert_eq!(r.events[1].name(), "envelope_grid");
    assert_eq!(r.events.len(), 2);
    // reported once
    let r = w.step(&Input {
        cursor_m: [5e-6, 0.0],
        grab: false,
    });
    assert!(r.events.is_empty());
}

#[test]
fn grab_steer_clip_and_release() {
    let mut w = World::new(&Params::paper(), &limits()).unwrap();
    let far = Input {
        cursor_m: [2e-6, 0.0],
        grab: true,
    };
    let r = w.step(&far);
    assert!(matches!(r.events[2], Event::GrabMissed { gap_m } if gap_m == 2e-6));
    assert!(!w.grabbed());
    w.step(&Input {
        cursor_m: [0.0, 0.0],
        grab: false,
    });
    let r = w.step(&Input {
        cursor_m: [0.0, 0.0],
        grab: true,
    });
    assert!(matches!(r.events[..], [Event::Grab { gap_m }] if gap_m == 0.0));
    // A command far outside the envelope (1 µm in one 0.2 µs step): clipped, and the hand
    // feels the spring on the excess, −k·excess, pointing back to the particle.
    let r = w.step(&Input {
        cursor_m: [1e-6, 0.0],
        grab: true,
    });
    let excess = w.excess_m();
    assert!(excess > 0.5e-6 && excess < 1e-6, "{excess}");
    assert!(matches!(r.events[..], [Event::Clipped { excess_m }] if excess_m == excess));
    assert!(
        (r.force_n[0] + 1e-6 * excess).abs() < 1e-18,
        "{:?}",
        r.force_n
    );
    assert_eq!(r.stiffness_n_per_m, 1e-6);
    // the particle moved towards the cursor, by the physics
    assert!(w.position_m()[0] > 0.0);
    let r = w.step(&Input {
        cursor_m: [1e-6, 0.0],
        grab: false,
    });
    assert_eq!(r.events, vec![Event::Release]);
    assert_eq!((r.force_n, r.stiffness_n_per_m), ([0.0, 0.0], 0.0));
}

#[test]
fn the_felt_force_never_exceeds_the_device() {
    // A device that renders at most 1e-13 N in this world: the spring force is scaled down
    // to it, its direction kept.
    let tiny = Limits {
        max_force_n: 1e-13,
        max_stiffness_n_per_m: 1e-3,
    };
    let mut w = World::new(&Params::paper(), &tiny).unwrap();
    w.step(&Input {
        cursor_m: [0.0, 0.0],
        grab: true,
    });
    let r = w.step(&Input {
        cursor_m: [0.0, 1e-6],
        grab: true,
    });
    let n = (r.force_n[0].powi(2) + r.force_n[1].powi(2)).sqrt();
    assert!((n - 1e-13).abs() < 1e-25, "{n}");
    assert!(r.force_n[1] < 0.0);
}

#[test]
fn events_serialize_with_a_tag_and_named_fields() {
    let json = |e: &Event| serde_json::to_string(e).unwrap();
    assert_eq!(
        json(&Event::Grab { gap_m: 1e-7 }),
        r#"{"type":"grab","gap_m":1e-7}"#
    );
    assert_eq!(json(&Event::Release), r#"{"type":"release"}"#);
    assert_eq!(
        json(&Event::EnvelopeGrid {
            chosen_by: "fixed",
            margin_waists: 3.0,
            cell_waists: 0.25,
            grid_error_m: None,
            region_bound_m: None,
            vertices: None,
        }),
        r#"{"type":"envelope_grid","chosen_by":"fixed","margin_waists":3.0,"cell_waists":0.25,"grid_error_m":null,"region_bound_m":null,"vertices":null}"#
    );
}
