//! A real device on a real link (issue 31): stability against delay and transparency, in
//! closed loop with a modelled device held by a hand behind a modelled link
//! ([`haptic_loop::closed_loop::run_linked`]). Writes `docs/bench/link.md` (or `--out FILE`)
//! and `docs/figures/link-zwidth-<device>.png`.
//!
//! 1. **Stability against delay**: the `wall` world's virtual wall `F = −K x` (B = 0, safety
//!    layer off), swept over K (100–100 000 N/m, a quarter decade apart) on each preset held
//!    loosely, with encoder counts, at each one-way latency, with the device side speaking
//!    protocol 1 (`F0 − K (p − p0)` from the answer) and protocol 2 (the wall's plane rendered
//!    locally): the largest stable K, beside Colgate's bound `K ≤ b / (T/2 + t_d)` with `b` the
//!    hand's and the device's damping, `T` the device's servo period and `t_d` the round trip.
//! 2. **Every world at its defaults**: each built-in scene on each preset, loose grip, the
//!    safety layer on: the largest one-way latency (of 0–50 ms) up to which every run is
//!    stable, protocol 1 against protocol 2.
//! 3. **Transparency**: the wall at half the device's rated stiffness pressed 2 mm by a firm
//!    hand: the stiffness the hand feels (the slope of the rendered force against the
//!    reading) divided by the wall's; and the drag in free space at 0.1 m/s, at each latency.
//! 4. **The atoms' pull-off**: the nano world on each preset, loose and firm, behind 2, 5 and
//!    10 ms: the peak force the hand feels over the ideal link's, protocol 2 (the adhesion as
//!    the residual's linear spring) against protocol 3 (the bond, a spring that breaks).
//! 5. **The 10 kHz trap**: the optical tweezers at 10 kHz on each preset, loose and firm,
//!    behind 2, 5 and 10 ms: the peak force the hand feels over the largest force the world
//!    answered in the same run, protocol 3 (the excess spring as the residual's linear spring)
//!    against protocol 4 (the follower: the held particle stepped through its envelope).
#![allow(clippy::unwrap_used)]

use bench_harness::chart::{Chart, Scale, Series, Style};
use bench_harness::report::out_arg;
use bench_harness::{Report, Table};
use haptic_devices::link::LinkParams;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop::{Linked, run_linked};

mod probe;
use probe::{PRESS, wall};

const LATENCIES_MS: [f64; 8] = [0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
const KS: usize = 13;
const COLORS: [[u8; 3]; 3] = [[210, 50, 40], [40, 150, 60], [120, 120, 120]];

fn k_of(i: usize) -> f64 {
    100.0 * 10f64.powf(i as f64 / 4.0)
}

fn linked(ms: f64, protocol: Protocol) -> Linked {
    Linked {
        link: LinkParams::latency_ms(ms),
        protocol,
    }
}

/// The largest stable wall stiffness (N/m) of the grid, or 0.
fn largest_stable(mech: Mechanics, l: &Linked) -> f64 {
    let mut dev = mech;
    dev.limits.max_stiffness_n_per_m *= 1e4;
    let mut best = 0.0;
    for i in 0..KS {
        let k = k_of(i);
        let (r, _) = run_linked(&wall(k), PRESS, dev, Grip::LOOSE, l, None).unwrap();
        if !r.stable() {
            break;
        }
        best = k;
    }
    best
}

/// Colgate's bound for a loose hand on `mech` with a round trip of `rt_s`, N/m.
fn colgate(mech: Mechanics, rt_s: f64) -> f64 {
    let b = Grip::LOOSE.damping_n_s_per_m + mech.viscous_n_s_per_m;
    b / (0.5 / mech.servo_rate_hz + rt_s)
}

fn main() {
    let mut md = Report::start("link", "haptic-loop — a real device on a real link")
        .unwrap()
        .output(out_arg());
    let root = md.root().to_path_buf();
    let read = |n: &str| std::fs::read_to_string(root.join("scenes").join(n)).unwrap();
    md.para(
        "Closed loop behind a modelled link (`haptic_loop::closed_loop::run_linked`): the \
         device's samples reach the loop, and its answers reach the device, after the one-way \
         latency (both directions; the round trip is twice it); the loop follows the bridge's \
         rule for late samples; the device renders each answer from its arrival with the \
         device-side library (`haptic_devices::local`). Protocol 1 renders `F0 − K (p − p0)`; \
         protocol 2 renders the world's local model (contact planes, the carried brick) at the \
         device's servo rate, behind the two-port passivity layer; protocol 3 adds the bond, \
         a spring that breaks at the nano world's pull-off; protocol 4 the follower, the \
         optical tweezers' held particle stepped through its working envelope. Loose hand: 300 N/m, \
         2 N·s/m; firm: 1000 N/m, 8 N·s/m. Stable: no undeclared force jump above 1 N, at most \
         10 % of the power above 50 Hz, the observer within its reserve.",
    );

    // 1. Stability against delay.
    md.heading("Stability against delay: the stiffest stable wall");
    let mut st = Table::new([
        "device",
        "one-way latency (ms)",
        "protocol 1 (N/m)",
        "protocol 2 (N/m)",
        "Colgate's bound b / (T/2 + t_d) (N/m)",
    ]);
    for mech in PRESETS {
        let mut series = [Vec::new(), Vec::new(), Vec::new()];
        for ms in LATENCIES_MS {
            let k1 = largest_stable(mech, &linked(ms, Protocol::V1));
            let k2 = largest_stable(mech, &linked(ms, Protocol::V2));
            let bound = colgate(mech, 2.0 * ms * 1e-3);
            let x = ms.max(0.1);
            series[0].push([x, k1.max(50.0)]);
            series[1].push([x, k2.max(50.0)]);
            series[2].push([x, bound]);
            st.row([
                mech.name.to_string(),
                format!("{ms}"),
                format!("{k1:.0}"),
                format!("{k2:.0}"),
                format!("{bound:.0}"),
            ])
            .unwrap();
        }
        let mut chart = Chart::new(
            &format!(
                "Stiffest stable wall on the {} against one-way latency (loose hand)",
                mech.name
            ),
            "one-way latency (ms; 0 drawn at 0.1)",
            "stiffest stable wall K (N/m)",
        );
        chart.x_scale = Scale::Log10;
        chart.y_scale = Scale::Log10;
        let pen = Style::Pen {
            line_px: 2.0,
            dot_px: 5.0,
        };
        let [s1, s2, sb] = series;
        chart.series = vec![
            Series::new("protocol 1", s1, COLORS[0], pen),
            Series::new("protocol 2", s2, COLORS[1], pen),
            Series::new("Colgate's bound", sb, COLORS[2], pen),
        ];
        let file = format!("link-zwidth-{}.png", mech.name);
        chart.write_png(&md.figure(&file), 900, 560).unwrap();
        md.image(&format!("stiffest stable wall on the {}", mech.name), &file);
    }
    md.table(&st);

    // 2. Every world at its defaults.
    md.heading("Every world at its defaults: stable up to which latency");
    let worlds = [
        ("wall", "wall.toml", "wall.script.toml"),
        ("bricks", "brickworld.toml", "brickworld.script.toml"),
        ("atoms", "nanoworld.toml", "nanoworld.script.toml"),
        (
            "optical tweezers",
            "optical_tweezers.toml",
            "optical_tweezers.script.toml",
        ),
    ];
    let mut wt = Table::new([
        "world",
        "device",
        "protocol 1: stable to (ms)",
        "protocol 2: stable to (ms)",
        "protocol 2: motors' work on the hand at 10 ms (J)",
    ]);
    for (world, scene, script) in worlds {
        let (text, stext) = (read(scene), read(script));
        for mech in PRESETS {
            let mut up_to = [None, None];
            let mut at10 = 0.0;
            for (pi, protocol) in [Protocol::V1, Protocol::V2].into_iter().enumerate() {
                for ms in LATENCIES_MS {
                    let (r, _) = run_linked(
                        &text,
                        &stext,
                        mech,
                        Grip::LOOSE,
                        &linked(ms, protocol),
                        None,
                    )
                    .unwrap();
                    if protocol == Protocol::V2 && ms == 10.0 {
                        at10 = r.energy_to_hand_j;
                    }
                    if !r.stable() {
                        break;
                    }
                    up_to[pi] = Some(ms);
                }
            }
            let show = |v: Option<f64>| v.map_or("unstable at 0".to_string(), |m| format!("{m}"));
            wt.row([
                world.to_string(),
                mech.name.to_string(),
                show(up_to[0]),
                show(up_to[1]),
                format!("{at10:+.4}"),
            ])
            .unwrap();
        }
    }
    md.table(&wt);

    // 3. Transparency.
    md.heading("Transparency: the stiffness the hand feels, and the drag in free space");
    let mut tt = Table::new([
        "device",
        "one-way latency (ms)",
        "felt / wall stiffness, protocol 1",
        "protocol 2",
        "free-space drag at 0.1 m/s, protocol 2 (N)",
    ]);
    for mech in PRESETS {
        let k = 0.5 * mech.limits.max_stiffness_n_per_m;
        for ms in [0.0, 0.5, 1.0, 2.0, 5.0, 10.0] {
            let felt = |protocol| probe::felt_over_wall(mech, k, &linked(ms, protocol));
            let drag = probe::drag_n(mech, k, &linked(ms, Protocol::V2));
            tt.row([
                mech.name.to_string(),
                format!("{ms}"),
                format!("{:.3}", felt(Protocol::V1)),
                format!("{:.3}", felt(Protocol::V2)),
                format!("{drag:.4}"),
            ])
            .unwrap();
        }
    }
    md.table(&tt);
    md.para(
        "How to read: protocol 1 renders the answer's local stiffness around the reading it \
         answered, so a wall's spring is felt at once, but its contact onset and everything \
         the answer's force carries arrive a round trip late, and the largest stable wall falls \
         with the delay as Colgate's bound does. Protocol 2 renders the wall's plane at the \
         device's own servo rate from the position read now: the loop that can go unstable \
         no longer contains the link, and the stiffest stable wall stays where the device's \
         own Z-width puts it, whatever the latency. Transparency is the felt slope over the \
         wall's; the drag is the mean force magnitude gliding at 0.1 m/s in free space.",
    );
    pull_off(&mut md, &read);
    trap(&mut md, &read);
    let (path, _) = md.finish().unwrap();
    println!("wrote {}", path.display());
}

/// 4. The atoms' pull-off behind the link, protocols 2 and 3.
fn pull_off(md: &mut Report, read: &dyn Fn(&str) -> String) {
    md.heading("The atoms' pull-off: the peak the hand feels, protocol 2 against 3");
    let (text, stext) = (read("nanoworld.toml"), read("nanoworld.script.toml"));
    let mut t = Table::new([
        "device",
        "grip",
        "one-way latency (ms)",
        "ideal link's peak (N)",
        "protocol 2 / ideal",
        "protocol 3 / ideal",
    ]);
    for mech in PRESETS {
        for (grip, held) in [(Grip::LOOSE, "loose"), (Grip::FIRM, "firm")] {
            let peak = |l: &Linked| {
                run_linked(&text, &stext, mech, grip, l, None)
                    .unwrap()
                    .0
                    .peak_force_n
            };
            let ideal = peak(&Linked::IDEAL);
            for ms in [2.0, 5.0, 10.0] {
                t.row([
                    mech.name.to_string(),
                    held.to_string(),
                    format!("{ms}"),
                    format!("{ideal:.4}"),
                    format!("{:.3}", peak(&linked(ms, Protocol::V2)) / ideal),
                    format!("{:.3}", peak(&linked(ms, Protocol::V3)) / ideal),
                ])
                .unwrap();
            }
        }
    }
    md.table(&t);
    md.para(
        "How to read: the anchored tip's adhesion is a spring until the pull reaches the \
         pull-off, where the world's force drops to zero. Protocol 2 sends it as the residual's \
         linear spring, which the device goes on rendering for a round trip past the pull-off: \
         the hand is pulled harder than the world ever pulls, more with the delay. Protocol 3 \
         sends a bond, a spring that breaks at the world's pull-off, evaluated at the position \
         read now: the peak is the world's at every latency (docs/device-bridge.md).",
    );
}

/// 5. The 10 kHz trap behind the link: the felt peak over the world's own, protocols 3 and 4.
fn trap(md: &mut Report, read: &dyn Fn(&str) -> String) {
    md.heading(
        "The 10 kHz trap: the peak the hand feels over the world's own, protocol 3 against 4",
    );
    let (text, stext) = (
        read("optical_tweezers_10khz.toml"),
        read("optical_tweezers.script.toml"),
    );
    let mut t = Table::new([
        "device",
        "grip",
        "one-way latency (ms)",
        "protocol 3: felt / world peak (N)",
        "protocol 3 ratio",
        "protocol 4: felt / world peak (N)",
        "protocol 4 ratio",
    ]);
    for mech in PRESETS {
        for (grip, held) in [(Grip::LOOSE, "loose"), (Grip::FIRM, "firm")] {
            let peaks = |l: &Linked| {
                let (r, tr) = run_linked(&text, &stext, mech, grip, l, None).unwrap();
                let world = tr
                    .world
                    .iter()
                    .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
                    .fold(0.0, f64::max);
                (r.peak_force_n, world)
            };
            for ms in [2.0, 5.0, 10.0] {
                let (f3, w3) = peaks(&linked(ms, Protocol::V3));
                let (f4, w4) = peaks(&linked(ms, Protocol::V4));
                t.row([
                    mech.name.to_string(),
                    held.to_string(),
                    format!("{ms}"),
                    format!("{f3:.3} / {w3:.3}"),
                    format!("{:.3}", f3 / w3),
                    format!("{f4:.3} / {w4:.3}"),
                    format!("{:.3}", f4 / w4),
                ])
                .unwrap();
            }
        }
    }
    md.table(&t);
    md.para(
        "How to read: the held particle follows the hand at up to its working envelope a tick, \
         and the world pushes back only on the command beyond the envelope. Protocol 3 sends \
         that spring as the residual's linear `F0 − K (p − p0)` about a reading a round trip \
         old: inside the envelope, where the world answers nothing, the hand feels a drag of K \
         times its travel over the round trip, many times the world's force. Protocol 4 sends \
         the particle, its free drift and its envelope, and the device steps the particle with \
         its own readings as the world does: the hand feels the world's force \
         (docs/device-bridge.md).",
    );
}
