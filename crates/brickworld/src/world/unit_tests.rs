//! rapier's length unit in the brick world (`crate::bricks::LENGTH_UNIT`).

use rapier3d_f64::prelude::IntegrationParameters;
use world_form::Limits;

use crate::bricks::BrickSet;
use crate::params::Params;

/// The unit changes no physical value: each is rapier's default in metres, to the bit.
#[test]
fn the_length_unit_keeps_every_physical_value() {
    let set = BrickSet::new(&Params::default());
    let (p, d) = (
        &set.phys.integration_parameters,
        IntegrationParameters::default(),
    );
    assert_eq!(p.length_unit, crate::bricks::LENGTH_UNIT);
    assert_eq!(p.allowed_linear_error(), d.allowed_linear_error());
    assert_eq!(p.max_corrective_velocity(), d.max_corrective_velocity());
    assert_eq!(p.prediction_distance(), d.prediction_distance());
    assert_eq!(p.max_linear_velocity(), d.max_linear_velocity());
    assert_eq!(
        p.contact_recycle_distance(),
        crate::rest::RECYCLE_DISTANCE_M
    );
}

/// 20 bricks laid 3 cm apart on the ground, 100 steps: rapier pairs each only with the
/// ground (20 pairs); with its default unit the broad phase's 4 cm padding paired every
/// neighbour too, once the settling bricks had left their first, unpadded boxes (75 pairs).
#[test]
fn bricks_3_cm_apart_are_not_paired() {
    let p = super::tests::floor_with_gaps(0.03);
    let mut w = crate::World::new(&p, &Limits::FALCON).unwrap();
    let input = w.input([1.5, 1.5, 1.5], crate::Grip::default()).unwrap();
    for _ in 0..100 {
        w.step(&input);
    }
    assert_eq!(w.bricks.phys.narrow_phase.contact_pairs().count(), 20);
}
