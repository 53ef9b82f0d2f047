//! The lesson's numbers, measured from the per-tick arrays of its runs.

use haptic_loop::session::SessionArrays;
use serde::Serialize;

/// A run's event of one name: (time s, its JSON detail).
pub fn events<'a>(
    a: &'a SessionArrays,
    name: &'a str,
) -> impl Iterator<Item = (f64, serde_json::Value)> + 'a {
    let dt = 1.0 / f64::from(a.rate_hz);
    a.events.iter().filter(move |e| e.1 == name).map(move |e| {
        (
            e.0 as f64 * dt,
            serde_json::from_str(&e.2).unwrap_or(serde_json::Value::Null),
        )
    })
}

/// A number field of a JSON event detail.
pub fn num(v: &serde_json::Value, key: &str) -> Option<f64> {
    v.get(key).and_then(serde_json::Value::as_f64)
}

/// Time of each tick, s.
pub fn times(a: &SessionArrays) -> Vec<f64> {
    let dt = 1.0 / f64::from(a.rate_hz);
    a.tick.iter().map(|t| *t as f64 * dt).collect()
}

/// The last value of a state column.
pub fn last(a: &SessionArrays, field: &str) -> Option<f64> {
    a.state_column(field).and_then(|c| c.last().copied())
}

/// Index range of the ticks with time in `[t0, t1)`.
pub fn window(a: &SessionArrays, t0: f64, t1: f64) -> std::ops::Range<usize> {
    let r = f64::from(a.rate_hz);
    let lo = ((t0 * r).ceil().max(0.0) as usize).min(a.tick.len());
    let hi = ((t1 * r).ceil().max(0.0) as usize).min(a.tick.len());
    lo..hi.max(lo)
}

/// Mean of component `k` of the world force over `range`, N.
pub fn mean_force(a: &SessionArrays, range: std::ops::Range<usize>, k: usize) -> f64 {
    let n = range.len().max(1) as f64;
    a.world_force_n[range].iter().map(|f| f[k]).sum::<f64>() / n
}

/// Largest |component `k`| of the world force over `range`, N.
pub fn peak_force(a: &SessionArrays, range: std::ops::Range<usize>, k: usize) -> f64 {
    a.world_force_n[range]
        .iter()
        .map(|f| f[k].abs())
        .fold(0.0, f64::max)
}

/// Largest |acceleration| of the device position (second difference at the tick rate), m/s².
pub fn peak_hand_acceleration(a: &SessionArrays) -> f64 {
    let dt = 1.0 / f64::from(a.rate_hz);
    a.device_position_m
        .windows(3)
        .map(|w| {
            let d: Vec<f64> = (0..3).map(|k| w[2][k] - 2.0 * w[1][k] + w[0][k]).collect();
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / (dt * dt)
        })
        .fold(0.0, f64::max)
}

/// Largest |device force| over the run, N.
pub fn peak_device_force(a: &SessionArrays) -> f64 {
    a.device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max)
}

/// Largest |world force| over the run, N.
pub fn peak_world_force(a: &SessionArrays) -> f64 {
    a.world_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max)
}

/// A house task's outcome (the score's parts, from the last tick's state).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HouseOutcome {
    /// Slots filled at the end.
    pub filled: f64,
    /// Score by the stated rule.
    pub score: f64,
    /// Bricks or atoms dropped.
    pub dropped: f64,
    /// Seconds of force above the comfort limit.
    pub comfort_exceeded_s: f64,
    /// When the house was complete, s (−1: not complete).
    pub complete_s: f64,
    /// Largest force sent to the device, N.
    pub peak_device_force_n: f64,
    /// Largest force in the world, N.
    pub peak_world_force_n: f64,
    /// Session length, s.
    pub duration_s: f64,
}

/// The outcome of a house run; `filled_field` is the scene's slot count column.
pub fn house_outcome(a: &SessionArrays, filled_field: &str) -> HouseOutcome {
    let get = |f: &str| last(a, f).unwrap_or(f64::NAN);
    HouseOutcome {
        filled: get(filled_field),
        score: get("score"),
        dropped: get("dropped"),
        comfort_exceeded_s: get("comfort_exceeded_s"),
        complete_s: get("complete_s"),
        peak_device_force_n: peak_device_force(a),
        peak_world_force_n: peak_world_force(a),
        duration_s: a.tick.len() as f64 / f64::from(a.rate_hz),
    }
}

/// The approach–retract cycle measured: snap and pull-off.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Hysteresis {
    /// The snap force the contact jumped in with, N (from the `nano.snap` event).
    pub snap_force_n: f64,
    /// Cursor height at the snap, m.
    pub snap_height_m: f64,
    /// The pull the bond resisted at release, N (from the `nano.pull_off` event).
    pub pull_off_n: f64,
    /// Cursor height at the pull-off, m.
    pub pull_off_height_m: f64,
    /// Pull-off over snap force.
    pub ratio: f64,
}

/// Snap and pull-off of an approach–retract run (the first of each).
pub fn hysteresis(a: &SessionArrays) -> Option<Hysteresis> {
    let (ts, snap) = events(a, "nano.snap").next()?;
    let (tp, pull) = events(a, "nano.pull_off").next()?;
    let r = f64::from(a.rate_hz);
    let z = |t: f64| a.cursor_m.get((t * r).round() as usize).map(|c| c[2]);
    let snap_force_n = num(&snap, "snap_force_n")?;
    let pull_off_n = num(&pull, "pull_off_n")?;
    Some(Hysteresis {
        snap_force_n,
        snap_height_m: z(ts)?,
        pull_off_n,
        pull_off_height_m: z(tp)?,
        ratio: pull_off_n / snap_force_n,
    })
}

/// A brick throw measured: release velocity and where the brick first landed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BrickThrow {
    /// Horizontal speed at release, m/s (the brick's own velocity through the coupling; the
    /// range is this speed times the flight time).
    pub release_speed_m_per_s: f64,
    /// Horizontal distance from the release point to the first impact, m.
    pub distance_m: f64,
    /// Flight time to the first impact, s.
    pub flight_s: f64,
    /// Whether the world called it a throw (`brick.thrown`).
    pub thrown: bool,
}

/// The first release of a run and the thrown brick's first impact after it.
pub fn brick_throw(a: &SessionArrays) -> Option<BrickThrow> {
    let (tr, rel) = events(a, "brick.released").next()?;
    let v = rel.get("velocity_m_per_s")?.as_array()?;
    let v: Vec<f64> = v.iter().filter_map(serde_json::Value::as_f64).collect();
    let speed = v.iter().take(2).map(|x| x * x).sum::<f64>().sqrt();
    let brick = rel.get("brick")?.clone();
    let r = f64::from(a.rate_hz);
    let i = (tr * r).round() as usize;
    let px = a.state_column("proxy_x_m")?;
    let py = a.state_column("proxy_y_m")?;
    let (x0, y0) = (*px.get(i)?, *py.get(i)?);
    let (ti, hit) = events(a, "brick.impact").find(|(t, e)| {
        *t > tr
            && (e.get("a") == Some(&json_brick(&brick)) || e.get("b") == Some(&json_brick(&brick)))
    })?;
    let p = hit.get("point_m")?.as_array()?;
    let (x1, y1) = (p.first()?.as_f64()?, p.get(1)?.as_f64()?);
    Some(BrickThrow {
        release_speed_m_per_s: speed,
        distance_m: (x1 - x0).hypot(y1 - y0),
        flight_s: ti - tr,
        thrown: events(a, "brick.thrown").next().is_some(),
    })
}

fn json_brick(id: &serde_json::Value) -> serde_json::Value {
    serde_json::json!({ "brick": id })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arrays() -> SessionArrays {
        let mut a = SessionArrays::new(1000, vec!["score".into()]);
        for t in 0..10u64 {
            a.tick.push(t);
            let x = 0.5 * 2.0 * (t as f64 * 1e-3).powi(2);
            a.device_position_m.push([x, 0.0, 0.0]);
            a.world_force_n.push([t as f64, 0.0, -1.0]);
            a.device_force_n.push([3.0, 4.0, 0.0]);
            a.state.push(t as f64);
        }
        a.events
            .push((4, "nano.snap".into(), r#"{"snap_force_n":2.5}"#.into()));
        a
    }

    #[test]
    fn measurements_read_what_the_arrays_hold() {
        let a = arrays();
        // x = ½ a t² with a = 2 m/s².
        assert!((peak_hand_acceleration(&a) - 2.0).abs() < 1e-6);
        assert_eq!(peak_device_force(&a), 5.0);
        assert_eq!(window(&a, 0.002, 0.005), 2..5);
        assert_eq!(mean_force(&a, 2..5, 0), 3.0);
        assert_eq!(peak_force(&a, 0..10, 0), 9.0);
        assert_eq!(last(&a, "score"), Some(9.0));
        let (t, e) = events(&a, "nano.snap").next().unwrap();
        assert_eq!(t, 0.004);
        assert_eq!(num(&e, "snap_force_n"), Some(2.5));
    }
}
