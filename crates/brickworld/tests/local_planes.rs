//! What the world tells a device's local model of the carried brick's surroundings (bridge
//! protocol 2's body planes, `World::local_primitives`): the planes the device's copy of the
//! brick meets before the next answer arrives.
//!
//! - A plane never stops the device's body where the world's brick goes on: every plane
//!   announced while a brick is lowered into a slot between two bricks (2 mm to spare each
//!   side) holds the brick's grip point through the next 40 ticks the world steps (a round
//!   trip of 20 ms each way), to 0.1 mm. Before the neighbours' edges stopped being sent as
//!   planes this failed: the edge seen across the gap, first below the brick and then at
//!   every angle to the side, was a plane the world's brick went through by 26 mm.
//! - The floor the brick lands on is announced before it lands (the lookahead).
//! - A neighbour's edge the brick is heading for is announced as the face it strikes: a brick
//!   5 mm beside a neighbour's top edge and 10 mm above it, moving down and towards it at
//!   45°, is told of the top face 10 mm below its grip point (to 0.5 mm); moving up and away,
//!   of nothing there.
#![allow(clippy::unwrap_used)]

mod common;

use brickworld::{Inertia, Params, World};
use common::{at, hold};
use haptic_types::local::WorldPrimitives;

/// The carried brick's half extents (the default brick), m.
const HALF: [f64; 3] = [0.1, 0.05, 0.03];
/// The cursor 2 mm above a brick resting on the ground, centred: its grip point, m.
const ABOVE_Z: f64 = 2.0 * HALF[2] + 0.005 + 0.002;

fn world(neighbours: &[[f64; 3]]) -> World {
    let mut bricks = vec![at([0.0, 0.0, HALF[2]])];
    bricks.extend(neighbours.iter().map(|c| at(*c)));
    let p = Params {
        inertia: Inertia::Coupling,
        sleeping: false,
        bricks,
        ..common::bare()
    };
    common::world(p)
}

/// Grabs the first brick and moves the hand along `path` (one position a tick); returns what
/// the world announced at each tick.
fn carry(w: &mut World, path: &[[f64; 3]]) -> Vec<WorldPrimitives> {
    for _ in 0..50 {
        hold(w, [0.0, 0.0, ABOVE_Z], false);
    }
    path.iter()
        .map(|p| {
            hold(w, *p, true);
            w.local_primitives()
        })
        .collect()
}

/// A path from `a` to `b` at `speed` m/s (1 ms ticks), then `rest` ticks at `b`.
fn path(a: [f64; 3], b: [f64; 3], speed: f64, rest: usize) -> Vec<[f64; 3]> {
    let d = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
    let n = (d / (speed * 1e-3)).ceil() as usize;
    let mut out: Vec<[f64; 3]> = (0..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            [0, 1, 2].map(|k| a[k] + s * (b[k] - a[k]))
        })
        .collect();
    out.extend(std::iter::repeat_n(b, rest));
    out
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn no_plane_stops_the_devices_body_where_the_worlds_brick_goes_on() {
    // Two neighbours leave a slot 4 mm wider than the brick; the brick is lifted 8 cm out of
    // it and lowered back at 0.5 m/s, 1 mm to the side.
    let gap = 0.002;
    let x = 2.0 * HALF[0] + gap;
    let mut w = world(&[[-x, 0.0, HALF[2]], [x, 0.0, HALF[2]]]);
    let top = [0.0, 0.0, ABOVE_Z + 0.08];
    let mut hand = path([0.0, 0.0, ABOVE_Z], top, 0.2, 200);
    let descent = hand.len();
    hand.extend(path(top, [0.001, 0.0, ABOVE_Z], 0.5, 300));
    let seen = carry(&mut w, &hand);
    let (mut planes, mut worst, mut floor_ahead) = (0, 0.0f64, None);
    for (t, prims) in seen.iter().enumerate() {
        let Some(body) = &prims.body else { continue };
        for plane in &prims.body_planes {
            planes += 1;
            for later in seen[t..].iter().take(40) {
                if let Some(b) = &later.body {
                    let behind = plane.offset_m - dot(plane.normal, b.position_m);
                    worst = worst.max(behind);
                }
            }
            // The floor under the slot (the ground, z = 0) before the brick is 1 cm above it
            // (the body's position is the grip point, `ABOVE_Z` above the brick's bottom).
            let bottom = body.position_m[2] - ABOVE_Z;
            if plane.normal[2] > 1.0 - 1e-9 && t >= descent {
                floor_ahead = Some(bottom.max(floor_ahead.unwrap_or(0.0)));
            }
        }
    }
    assert!(planes > 100, "{planes} planes announced");
    assert!(
        worst <= 1e-4,
        "a plane stopped the device's body {:.2} mm short of where the world's brick went",
        worst * 1e3
    );
    let ahead = floor_ahead.expect("the floor announced before the landing");
    assert!(
        ahead > 0.02,
        "the floor announced {:.1} mm ahead",
        ahead * 1e3
    );
}

#[test]
fn a_neighbours_edge_the_brick_heads_for_is_announced_as_the_face_it_strikes() {
    // The neighbour's top edge 5 mm to the side of the brick and 10 mm below it: a
    // neighbour stacked on another, its top at 0.12 m.
    let lift = 4.0 * HALF[2] + 0.016;
    let x = 2.0 * HALF[0] + 0.012;
    let run = |dir: f64| {
        let mut w = world(&[[x, 0.0, HALF[2]], [x, 0.0, 3.0 * HALF[2]]]);
        let hold_at = [0.0, 0.0, ABOVE_Z + lift];
        let mut hand = path([0.0, 0.0, ABOVE_Z], hold_at, 0.2, 300);
        // 45° down and towards it (or up and away), 5 mm each way at 0.14 m/s.
        let to = [dir * 0.005, 0.0, ABOVE_Z + lift - dir * 0.005];
        hand.extend(path(hold_at, to, 0.1414, 0));
        let seen = carry(&mut w, &hand);
        let bottom = w.bricks().next().unwrap().position_m[2] - HALF[2];
        (seen.last().unwrap().clone(), bottom - 4.0 * HALF[2])
    };
    let (towards, height) = run(1.0);
    let body = towards.body.as_ref().unwrap();
    let top: Vec<_> = towards
        .body_planes
        .iter()
        .filter(|p| p.normal[2] > 1.0 - 1e-6)
        .collect();
    assert_eq!(top.len(), 1, "{:?}", towards.body_planes);
    let gap = dot(top[0].normal, body.position_m) - top[0].offset_m;
    assert!(
        (0.008..0.012).contains(&height) && (gap - height).abs() < 5e-4,
        "the top face announced {:.2} mm below, the brick {:.2} mm above it",
        gap * 1e3,
        height * 1e3
    );
    let (away, _) = run(-1.0);
    assert!(
        away.body_planes.is_empty(),
        "moving away: {:?}",
        away.body_planes
    );
}
