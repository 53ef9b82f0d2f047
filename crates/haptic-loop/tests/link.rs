//! Every built-in scene on every device preset, loose grip and firm, behind a link (issue 31):
//! one-way latency {0, 0.5, 1, 2, 5, 10, 20, 50} ms, each also with 1 ms of jitter and 5 % loss
//! in both directions, the device side speaking bridge protocol 4 (the local model with its
//! bond and its follower, the two-port passivity layer). The criteria are issue 22's
//! ([`haptic_loop::closed_loop::Report::stable`]), measured on the force the device's motors
//! rendered: no undeclared jump above 1 N, at most 10 % of the power above 50 Hz, the observer
//! within its reserve.
//!
//! Asserted: every run up to 10 ms one way is stable (the target); the 20 and 50 ms runs (the
//! goal) are printed with their figures and must keep the energy the motors put into the hand
//! below 0.1 J. And the contrasts that are the reasons for protocols 2 to 4: the carried
//! brick on a loosely held Falcon buzzes behind 2 ms with protocol 1 and not with protocol 2;
//! the atoms' pull-off behind 10 ms pulls a quarter harder than the world with protocol 2 and
//! as the world with protocol 3; the 10 kHz trap behind 10 ms drags the hand at 31 times the
//! world's force with protocol 3 and renders the world's with protocol 4.
#![allow(clippy::unwrap_used)]

use haptic_devices::link::LinkParams;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop::{Linked, Report, Trace, run_linked};

#[path = "../examples/probe/mod.rs"]
mod probe;

fn read(name: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    std::fs::read_to_string(root.join(name)).unwrap()
}

const SCENES: [(&str, &str); 5] = [
    ("wall.toml", "wall.script.toml"),
    ("brickworld.toml", "brickworld.script.toml"),
    ("nanoworld.toml", "nanoworld.script.toml"),
    ("optical_tweezers.toml", "optical_tweezers.script.toml"),
    (
        "optical_tweezers_10khz.toml",
        "optical_tweezers.script.toml",
    ),
];

const LATENCIES_MS: [f64; 8] = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];

fn link(ms: f64, bad: bool) -> LinkParams {
    LinkParams {
        latency_s: ms * 1e-3,
        jitter_s: if bad { 1e-3 } else { 0.0 },
        loss: if bad { 0.05 } else { 0.0 },
        seed: 7,
    }
}

fn line(label: &str, r: &Report) -> String {
    format!(
        "{label:<58} {} jumps {:>3}, max jump {:>6.3} N, above 50 Hz {:.4}, observer min {:+.4} J, \
         motors' work on the hand {:+.4} J, two-port {:>5}",
        if r.stable() { "stable  " } else { "UNSTABLE" },
        r.undeclared_jumps,
        r.max_jump_n,
        r.hf_fraction,
        r.min_observer_j,
        r.energy_to_hand_j,
        r.device_interventions
    )
}

/// One run of the grid: `ms` `None` is the ideal link (no delay, no loss, protocol 1: the
/// closed loop of issue 22), the reference the linked runs are held to.
#[derive(Clone, Copy)]
struct Case {
    scene: &'static str,
    script: &'static str,
    mech: Mechanics,
    grip: Grip,
    ms: Option<f64>,
    bad: bool,
}

/// What the grid keeps of a run: its report, the largest force the loop answered (the
/// world's own peak, N) and, for the wall, the felt stiffness.
struct Run {
    case: Case,
    label: String,
    r: Report,
    world_peak_n: f64,
    wall_n_per_m: Option<f64>,
}

/// The stiffness the hand feels pressing into `wall.toml`'s plane (z = −5 mm): the slope of
/// the felt F_z against the depth, over the readings 0.5–2.5 mm deep on the way down (before
/// the deepest reading; below the force clamp of every preset), N/m.
fn wall_stiffness(t: &Trace) -> f64 {
    let deepest = (0..t.readings.len())
        .min_by(|&a, &b| t.readings[a][2].total_cmp(&t.readings[b][2]))
        .unwrap_or(0);
    let pts: Vec<(f64, f64)> = (t.readings[..deepest].iter().zip(&t.felt))
        .map(|(p, f)| (-0.005 - p[2], f[2]))
        .filter(|(d, _)| (0.0005..0.0025).contains(d))
        .collect();
    assert!(pts.len() > 50, "{} readings in the wall", pts.len());
    probe::slope(&pts)
}

fn norm(f: [f64; 3]) -> f64 {
    (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()
}

/// Runs every case on two threads, in the order of `cases`.
fn run_all(cases: &[Case]) -> Vec<Run> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&c) = cases.get(i) else {
                        break;
                    };
                    let l = match c.ms {
                        None => Linked::IDEAL,
                        Some(ms) => Linked {
                            link: link(ms, c.bad),
                            protocol: Protocol::V4,
                        },
                    };
                    let (r, t) =
                        run_linked(&read(c.scene), &read(c.script), c.mech, c.grip, &l, None)
                            .unwrap_or_else(|e| panic!("{} on {}: {e}", c.scene, c.mech.name));
                    let wall_n_per_m = (c.scene == "wall.toml").then(|| wall_stiffness(&t));
                    let world_peak_n = t.world.iter().map(|f| norm(*f)).fold(0.0, f64::max);
                    let link = if c.ms.is_some() {
                        l.link.label()
                    } else {
                        "ideal link".into()
                    };
                    let label = format!("{} {} {} {link}", c.scene, c.mech.name, c.grip.label());
                    results.lock().unwrap().push((
                        i,
                        Run {
                            case: c,
                            label,
                            r,
                            world_peak_n,
                            wall_n_per_m,
                        },
                    ));
                }
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    results.into_iter().map(|r| r.1).collect()
}

#[test]
fn every_scene_on_every_device_is_stable_and_transparent_behind_a_link_of_up_to_10_ms() {
    // Every (scene, device, grip) on the ideal link, then behind every (latency, link).
    let mut cases = Vec::new();
    for (scene, script) in SCENES {
        for mech in PRESETS {
            for grip in [Grip::LOOSE, Grip::FIRM] {
                let case = Case {
                    scene,
                    script,
                    mech,
                    grip,
                    ms: None,
                    bad: false,
                };
                cases.push(case);
                for ms in LATENCIES_MS {
                    for bad in [false, true] {
                        cases.push(Case {
                            ms: Some(ms),
                            bad,
                            ..case
                        });
                    }
                }
            }
        }
    }
    assert_eq!(cases.len(), 5 * 4 * 2 * (1 + 8 * 2));
    let runs = run_all(&cases);
    let mut unstable = Vec::new();
    let mut untransparent = Vec::new();
    let mut unbuilt = Vec::new();
    let mut over_peak = Vec::new();
    // The nano world's peak felt force against the ideal link's, 0–10 ms (the bond's scene).
    let (mut nano_lo, mut nano_hi) = (f64::MAX, 0.0f64);
    let (mut goal_unstable, mut goal_runs) = (0, 0);
    let mut worst_goal_energy: f64 = f64::NEG_INFINITY;
    let mut worst_target_energy: f64 = f64::NEG_INFINITY;
    let (mut peak_lo, mut peak_hi, mut wall_lo, mut wall_hi) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
    let mut ideal = None;
    // The felt peak against the world's own peak in the same run (0–10 ms), and the runs
    // whose hand felt more than 1.2 × anything the world answered.
    let (mut own_lo, mut own_hi) = (f64::MAX, 0.0f64);
    let mut over_own = Vec::new();
    for Run {
        case,
        label,
        r,
        world_peak_n,
        wall_n_per_m,
    } in &runs
    {
        println!("{}", line(label, r));
        let Some(ms) = case.ms else {
            // The reference: stable, and both houses built on the ideal link.
            assert!(r.stable(), "{label}");
            assert!(
                r.house_complete_s.is_none_or(|t| t > 0.0),
                "{label}: house not built"
            );
            ideal = Some((r.peak_force_n, *wall_n_per_m));
            continue;
        };
        let (ideal_peak, ideal_wall) = ideal.unwrap();
        if ms > 10.0 {
            goal_runs += 1;
            goal_unstable += u32::from(!r.stable());
            worst_goal_energy = worst_goal_energy.max(r.energy_to_hand_j);
            continue;
        }
        // The target, 0–10 ms: stable, the energy into the hand within 0.01 J, the house
        // built in both worlds, and transparent: the peak force the hand feels within 20 % of
        // the ideal link's, the wall's felt stiffness within 10 % of it.
        if !r.stable() {
            unstable.push(label.clone());
        }
        worst_target_energy = worst_target_energy.max(r.energy_to_hand_j);
        if r.house_complete_s.is_some_and(|t| t <= 0.0) {
            unbuilt.push(label.clone());
        }
        let peak = r.peak_force_n / ideal_peak;
        (peak_lo, peak_hi) = (peak_lo.min(peak), peak_hi.max(peak));
        let own = r.peak_force_n / world_peak_n;
        (own_lo, own_hi) = (own_lo.min(own), own_hi.max(own));
        if own > 1.2 {
            over_own.push(format!("{label}: {own:.3}"));
        }
        if peak > 1.2 {
            over_peak.push(format!("{label}: {peak:.3}"));
        }
        if case.scene == "nanoworld.toml" {
            (nano_lo, nano_hi) = (nano_lo.min(peak), nano_hi.max(peak));
        }
        if !(0.8..=1.2).contains(&peak) {
            untransparent.push(format!("{label}: peak {peak:.3} of the ideal link's"));
        }
        if let (Some(k), Some(k0)) = (wall_n_per_m, ideal_wall) {
            let q = k / k0;
            (wall_lo, wall_hi) = (wall_lo.min(q), wall_hi.max(q));
            if (q - 1.0).abs() > 0.1 {
                untransparent.push(format!("{label}: wall felt {q:.3} of the ideal link's"));
            }
        }
    }
    println!(
        "{goal_unstable} of {goal_runs} runs unstable at 20 and 50 ms (the goal); the most energy \
         the motors put into a hand there: {worst_goal_energy:+.4} J; at 0–10 ms: \
         {worst_target_energy:+.4} J; peak felt force {peak_lo:.3}–{peak_hi:.3} of the ideal \
         link's; the wall's felt stiffness {wall_lo:.4}–{wall_hi:.4} of the ideal link's"
    );
    println!("peak above 1.2 × the ideal link's (5 and 10 ms): {over_peak:#?}");
    println!(
        "peak felt force at 0–10 ms: {own_lo:.3}–{own_hi:.3} of the world's own peak in the same \
         run; above 1.2 ×: {over_own:#?}"
    );
    println!(
        "the atoms' peak felt force at 0–10 ms: {nano_lo:.3}–{nano_hi:.3} of the ideal link's"
    );
    assert!(unstable.is_empty(), "unstable up to 10 ms: {unstable:#?}");
    assert!(worst_target_energy <= 0.01, "{worst_target_energy} J");
    assert!(
        untransparent.is_empty(),
        "not transparent: {untransparent:#?}"
    );
    // docs/devices.md: "at 20 and 50 ms, 156 of 160 are [stable], and the most the motors put
    // into a hand there is 0.07 J". The link is simulated and seeded: the count is exact. (152
    // before the brick's edge planes went, 147 with protocol 3: protocol 4's follower steadied all four unstable 10 kHz trap runs; of
    // the 1 kHz trap's, a loose Falcon and a loose Delta.3 at 50 ms turned stable and a firm
    // Delta.3 at 20 ms unstable, on one jump of 1.006 N against the 1 N rule. 148 before the
    // observer counted late samples.)
    assert_eq!((goal_runs - goal_unstable, goal_runs), (156, 160));
    assert!(
        (0.065..0.075).contains(&worst_goal_energy),
        "{worst_goal_energy} J"
    );
    // The atoms behind 0–10 ms: within 20 % of the ideal link's peak both ways in all 64
    // runs, 0.990–1.000 measured (docs/devices.md). With protocol 2 the device extrapolated the
    // adhesion's `F0 − K (p − p0)` past the pull-off for a round trip, where the world's force
    // drops to 0: 14 of them pulled 1.21–1.29 × (Touch, firm, 10 ms: 0.50 N against 0.40 N);
    // protocol 3's bond breaks where the world lets go.
    assert!(
        nano_lo >= 0.985 && nano_hi <= 1.005,
        "the atoms' peak {nano_lo:.3}–{nano_hi:.3}"
    );
    // Issue 40's target, 20 % of the ideal link's peak both ways at every latency to 10 ms, is
    // held above in every run; the range measured (docs/devices.md) is 0.822–1.105. Before the
    // brick world stopped sending a neighbour's edge as a plane (`Hand::carried_contacts`), 3
    // runs exceeded +20 %, all the brick on a Delta.3 at 10 ms (loose, jitter and loss: 2.67 N
    // against 1.81 N, now 1.49 N): the carried brick, lowered past a neighbour's edge into
    // the house, saw that edge across the gap first below it, then at every angle to the
    // side; each angle arrived as a plane a round trip late and stopped the device's body
    // where the world's brick went on down. 17 exceeded it with protocol 3, 31 with protocol
    // 2; the 10 kHz trap's 14 went with protocol 4 (below). Tried and not kept for the trap,
    // each measured on this grid: the envelope's edge as a plane moving at the particle's
    // velocity (13 runs unstable: chatter as the hand left the edge); the residual's spring
    // drifting at the particle's velocity (6 unstable to 10 ms); the world's stiffness
    // reported only beyond the envelope (21 over +20 %, 16 unstable); a follower whose
    // envelope did not move with the particle's velocity (11 of 128 trap runs unstable: its
    // replay fell a round trip's worth of drift behind the world's, 0.85–1.9 mm on a firm
    // Falcon, felt as a jump at each answer).
    assert!(over_peak.is_empty(), "{over_peak:#?}");
    assert!(
        (0.815..0.83).contains(&peak_lo) && (1.10..1.11).contains(&peak_hi),
        "peak {peak_lo:.3}–{peak_hi:.3} of the ideal link's"
    );
    // The hand against the world itself (docs/devices.md): in every scene the peak felt force
    // is 0.952–1.143 of the largest force the loop answered in the same run (0.879 before the
    // brick's edge planes went), so what the hand
    // feels is the world's. With protocol 3 the 10 kHz trap was not: 37 of its 64 runs
    // exceeded 1.2 ×, up to 31.3 × (the drag of `K (p − p0)` inside the envelope, where the
    // world answers zero; see the test below).
    assert!(
        (0.945..0.96).contains(&own_lo) && (1.135..1.15).contains(&own_hi),
        "felt / world peak {own_lo:.3}–{own_hi:.3}"
    );
    assert!(over_own.is_empty(), "{over_own:#?}");
    // Every house is built in both worlds at 0–10 ms (the last exception, a Falcon at 1 ms
    // with jitter and loss, was a one-count flicker thrown as a release velocity).
    assert!(
        unbuilt.is_empty(),
        "houses not built at 0–10 ms: {unbuilt:#?}"
    );
}

/// Why protocol 2: the carried brick on a loosely held Falcon behind 2 ms each way. With
/// protocol 1 the device renders the answered force and stiffness (`F0 − K (p − p0)`), and the
/// brick's coupling reaches the hand a round trip late: it buzzes and pumps joules into the
/// hand. With protocol 2 the device integrates the brick itself: stable.
#[test]
fn the_carried_brick_buzzes_behind_2_ms_with_protocol_1_and_not_with_protocol_2() {
    let (scene, script) = (read("brickworld.toml"), read("brickworld.script.toml"));
    let run = |protocol| {
        let l = Linked {
            link: LinkParams::latency_ms(2.0),
            protocol,
        };
        run_linked(&scene, &script, Mechanics::FALCON, Grip::LOOSE, &l, None)
            .unwrap()
            .0
    };
    let (v1, v2) = (run(Protocol::V1), run(Protocol::V2));
    println!("{}", line("protocol 1, 2 ms", &v1));
    println!("{}", line("protocol 2, 2 ms", &v2));
    assert!(!v1.stable() && v2.stable());
    // docs/devices.md: "buzzes with protocol 1 (2167 changes, +4.03 J)" (simulated: exact).
    assert_eq!(v1.undeclared_jumps, 2167);
    assert!(
        (4.025..4.035).contains(&v1.energy_to_hand_j),
        "{} J",
        v1.energy_to_hand_j
    );
    assert!(v2.stable() && v2.energy_to_hand_j < 0.0);
    // The house still gets built through the link.
    assert!(v2.house_complete_s.is_some_and(|t| t > 0.0));
}

/// Why protocol 3: the atoms on a firmly held Touch behind 10 ms each way. With protocol 2 the
/// anchored tip's adhesion is the residual's linear spring, which the device extrapolates for
/// a round trip past the pull-off, where the world's force has dropped to 0: the hand feels a
/// pull the world never gave. Protocol 3's bond breaks at the world's pull-off.
#[test]
fn the_atoms_pull_off_behind_10_ms_overshoots_with_protocol_2_and_not_with_protocol_3() {
    let (scene, script) = (read("nanoworld.toml"), read("nanoworld.script.toml"));
    let run = |l: &Linked| {
        run_linked(&scene, &script, Mechanics::TOUCH, Grip::FIRM, l, None)
            .unwrap()
            .0
    };
    let behind = |protocol| Linked {
        link: LinkParams::latency_ms(10.0),
        protocol,
    };
    let ideal = run(&Linked::IDEAL);
    let (v2, v3) = (run(&behind(Protocol::V2)), run(&behind(Protocol::V3)));
    let (p2, p3) = (
        v2.peak_force_n / ideal.peak_force_n,
        v3.peak_force_n / ideal.peak_force_n,
    );
    println!(
        "ideal link peak {:.4} N; 10 ms: protocol 2 {:.4} N ({p2:.3}), protocol 3 {:.4} N ({p3:.3})",
        ideal.peak_force_n, v2.peak_force_n, v3.peak_force_n
    );
    // docs/devices.md: "0.50 N against the world's 0.40 N (1.254 ×) with protocol 2, the
    // world's 0.40 N (1.000 ×) with protocol 3" (simulated: exact).
    assert!((1.25..1.26).contains(&p2), "{p2}");
    assert!((0.999..1.001).contains(&p3), "{p3}");
    assert!(v2.stable() && v3.stable());
    assert!(v3.energy_to_hand_j <= 0.01, "{} J", v3.energy_to_hand_j);
    assert!(v3.house_complete_s.is_none_or(|t| t > 0.0));
}

/// Why protocol 4: the 10 kHz trap on a loosely held Delta.3 behind 10 ms each way. With
/// protocol 3 the device extrapolates the excess spring `K (p − p0)` from a reading a round
/// trip old while the world's particle follows the hand: inside the envelope, where the world
/// answers nothing, the hand feels a drag of `K` times its travel over the round trip.
/// Protocol 4's follower steps the particle with the device's own readings as the world does.
#[test]
fn the_10_khz_trap_drags_behind_10_ms_with_protocol_3_and_not_with_protocol_4() {
    let (scene, script) = (
        read("optical_tweezers_10khz.toml"),
        read("optical_tweezers.script.toml"),
    );
    let run = |protocol| {
        let l = Linked {
            link: LinkParams::latency_ms(10.0),
            protocol,
        };
        run_linked(&scene, &script, Mechanics::DELTA3, Grip::LOOSE, &l, None).unwrap()
    };
    let own = |(r, t): &(Report, Trace)| {
        let world = t.world.iter().map(|f| norm(*f)).fold(0.0, f64::max);
        (r.peak_force_n, world, r.peak_force_n / world)
    };
    let (v3, v4) = (run(Protocol::V3), run(Protocol::V4));
    let ((f3, w3, q3), (f4, w4, q4)) = (own(&v3), own(&v4));
    println!(
        "felt / world peak: protocol 3 {f3:.3} / {w3:.3} N ({q3:.1} ×), protocol 4 {f4:.3} / \
         {w4:.3} N ({q4:.3} ×)"
    );
    // docs/devices.md: "4.53 N against the world's 0.145 N (31.3 ×) with protocol 3; 3.78 N
    // against the world's 3.97 N (0.952 ×) with protocol 4" (simulated: exact). Undragged,
    // the hand reaches the envelope's edge, as on the ideal link (3.80 N).
    assert!((31.2..31.4).contains(&q3), "{q3}");
    assert!((0.950..0.955).contains(&q4), "{q4}");
    assert!((3.77..3.79).contains(&f4), "{f4} N");
    assert!(v3.0.stable() && v4.0.stable());
    assert!(v4.0.energy_to_hand_j <= 0.01, "{} J", v4.0.energy_to_hand_j);
}

/// A linked run is simulated in whole nanoseconds with seeded draws: every scene repeats to
/// the bit behind a lossy, jittery link, every reading and every force the hand felt as well
/// as the summary.
#[test]
fn a_run_behind_a_lossy_jittery_link_repeats_to_the_bit() {
    let l = Linked {
        link: link(5.0, true),
        protocol: Protocol::V4,
    };
    let bits = |t: &Trace| -> Vec<u64> {
        (t.readings.iter().chain(&t.felt))
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    };
    for (scene, script) in SCENES {
        let (scene, script) = (read(scene), read(script));
        let run = || run_linked(&scene, &script, Mechanics::TOUCH, Grip::LOOSE, &l, None).unwrap();
        let (a, b) = (run(), run());
        assert_eq!(a.0, b.0);
        assert!(!a.1.felt.is_empty() && a.1.felt.len() == a.1.readings.len());
        assert_eq!(a.1.felt.len() as u64, a.0.ticks);
        assert_eq!(bits(&a.1), bits(&b.1));
    }
    // And an ideal link with protocol 1 is the closed loop of issue 22.
    let ideal = run_linked(
        &read("wall.toml"),
        &read("wall.script.toml"),
        Mechanics::TOUCH,
        Grip::LOOSE,
        &Linked::IDEAL,
        None,
    )
    .unwrap()
    .0;
    assert!(ideal.stable());
}

/// docs/devices.md and BENCHMARKS.md ("Transparency"): with protocol 2 the hand feels
/// 0.94–1.00 of the wall's stiffness at every latency to 10 ms on every preset, and 0 N of
/// drag gliding at 0.1 m/s in free space. The link report's probe
/// (`examples/link_report.rs`): the wall at half the preset's rated stiffness, B = 0, the
/// safety layer off, pressed 2 mm by a firm hand; the slope of F_z against the reading over
/// the samples 0.5–2 mm deep.
#[test]
fn the_hand_feels_0_94_to_1_00_of_the_walls_stiffness_and_no_drag_to_10_ms() {
    let (mut lo, mut hi, mut drag) = (f64::MAX, 0.0f64, 0.0f64);
    for mech in PRESETS {
        let k = 0.5 * mech.limits.max_stiffness_n_per_m;
        for ms in [0.0, 0.5, 1.0, 2.0, 5.0, 10.0] {
            let l = Linked {
                link: LinkParams::latency_ms(ms),
                protocol: Protocol::V2,
            };
            let q = probe::felt_over_wall(mech, k, &l);
            println!("{} {ms} ms: felt / wall stiffness {q:.3}", mech.name);
            (lo, hi) = (lo.min(q), hi.max(q));
            drag = drag.max(probe::drag_n(mech, k, &l));
        }
    }
    println!("felt / wall stiffness {lo:.3}–{hi:.3}, drag at most {drag:.4} N");
    // Two-sided, to the quoted figures' rounding: the softest 0.94 (a Falcon), the stiffest 1.00.
    assert!((0.935..0.945).contains(&lo), "{lo}");
    assert!((0.995..1.005).contains(&hi), "{hi}");
    assert!(drag < 5e-5, "{drag} N");
}

#[test]
fn a_bad_link_is_refused_by_name() {
    let l = Linked {
        link: LinkParams {
            jitter_s: -1e-3,
            ..LinkParams::IDEAL
        },
        protocol: Protocol::V2,
    };
    let e = run_linked(
        &read("wall.toml"),
        &read("wall.script.toml"),
        Mechanics::FALCON,
        Grip::LOOSE,
        &l,
        None,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "link `jitter_s` = -0.001 is out of range: allowed 0 ≤ jitter_s ≤ 1 s"
    );
}
