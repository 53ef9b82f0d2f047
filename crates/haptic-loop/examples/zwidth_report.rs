//! Z-width of every device preset, and the stiffness margin of every world on it, measured
//! in closed loop with a modelled device held by a hand (issue 22). Writes
//! `docs/bench/zwidth.md` (or `--out FILE`) and `docs/figures/zwidth-<device>.png`.
//!
//! 1. **Z-width** (Colgate and Brown 1994): the virtual wall `F = −K x − B ẋ` of the `wall`
//!    world, swept over K (100–100 000 N/m, a quarter decade apart) and B (0–16 N·s/m), safety
//!    layer off (the rendering's own region), on each preset held loosely (300 N/m, 2 N·s/m)
//!    and firmly (1000 N/m, 8 N·s/m), with encoder counts. The hand approaches, means to go
//!    2 mm into the wall (about 0.6 N), holds 1.5 s and lets go. A run is stable by
//!    [`haptic_loop::closed_loop::Report::stable`].
//! 2. **Margins**: each world's default scene and script, its device-side impedance scaled by
//!    `s` (the mapping's force scale and the device's stiffness cap both × s, so the world
//!    renders the same springs, `s` times stiffer at the hand), safety layer off, loose grip
//!    with counts: the largest `s` still stable is the world's stiffness margin on that device.
#![allow(clippy::unwrap_used)]

use bench_harness::chart::{Chart, Marker, Scale, Series, Style};
use bench_harness::report::out_arg;
use bench_harness::{Report, Table};
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::closed_loop::{run, scale_impedance};

/// Dot and line colours of the figures.
const GREEN: [u8; 3] = [40, 150, 60];
const RED: [u8; 3] = [210, 50, 40];
const BLUE: [u8; 3] = [40, 80, 200];

/// Down 8 mm into the wall in 0.5 s, held 1.5 s, back up by 2.5 s.
const SCRIPT: &str = include_str!("press_and_hold.script.toml");

fn wall(k: f64, b: f64) -> String {
    format!(
        "[scene]\nname = \"z-width wall\"\nkind = \"wall\"\n[device]\nmodel = \"falcon\"\n\
         [loop]\nengage_s = 0.0\npassivity = false\nforce_rate_limit = false\n\
         [wall]\nnormal = [0.0, 0.0, 1.0]\npoint_m = [0.0, 0.0, 0.0]\n\
         stiffness_n_per_m = {k:?}\ndamping_n_s_per_m = {b:?}\ncursor_radius_m = 0.001\n"
    )
}

/// The device with its stiffness cap raised out of the way (the plant's physics does not
/// read it; the loop and the worlds would refuse or cap stiffer springs).
fn uncapped(m: Mechanics, factor: f64) -> Mechanics {
    let mut u = m;
    u.limits.max_stiffness_n_per_m = m.limits.max_stiffness_n_per_m * factor;
    u
}

const KS: usize = 13;
const BS: [f64; 6] = [0.0, 1.0, 2.0, 4.0, 8.0, 16.0];
const SCALES: [f64; 8] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0];

fn k_of(i: usize) -> f64 {
    100.0 * 10f64.powf(i as f64 / 4.0)
}

fn main() {
    let mut md = Report::start(
        "zwidth",
        "haptic-loop — Z-width and stiffness margins in closed loop",
    )
    .unwrap()
    .output(out_arg());
    let root = md.root().to_path_buf();
    let scenes = root.join("scenes");
    let read = |n: &str| std::fs::read_to_string(scenes.join(n)).unwrap();
    md.para(
        "Closed loop: the script is the operator's intent; a hand (loose 300 N/m, 2 N·s/m; firm \
         1000 N/m, 8 N·s/m) holds a modelled device (moving mass, viscous friction, encoder \
         counts, force resolution, the force held over each 1 ms tick and rendered at the \
         device's servo rate; `haptic_devices`, presets and sources in `docs/devices.md`). \
         Stable: no force change above 1 N in one tick outside declared events, at most 10 % of \
         the force's power above 50 Hz, and the passivity observer above minus its 20 mJ \
         reserve. Safety layer off: these are the renderings' own regions.",
    );

    // 1. Z-width per device and grip.
    let mut zt = Table::new([
        "device",
        "grip",
        "largest stable K at B = 0 (N/m)",
        "at B = 2",
        "at B = 8",
        "rated k_max (N/m)",
        "margin at B = 0",
    ]);
    for mech in PRESETS {
        let dev = uncapped(mech, 1e4);
        let mut charts_pts = (Vec::new(), Vec::new(), Vec::new());
        for grip in [Grip::LOOSE, Grip::FIRM] {
            let mut largest = [0.0f64; BS.len()];
            for (bi, b) in BS.iter().enumerate() {
                for ki in 0..KS {
                    let k = k_of(ki);
                    let r = run(&wall(k, *b), SCRIPT, dev, grip, None).unwrap();
                    let ok = r.stable();
                    if grip == Grip::LOOSE {
                        if ok {
                            charts_pts.0.push([k, *b]);
                        } else {
                            charts_pts.1.push([k, *b]);
                        }
                    }
                    if ok {
                        largest[bi] = k;
                    }
                }
            }
            if grip == Grip::FIRM {
                charts_pts.2 = BS
                    .iter()
                    .zip(largest)
                    .filter(|(_, k)| *k > 0.0)
                    .map(|(b, k)| [k, *b])
                    .collect();
            }
            let rated = mech.limits.max_stiffness_n_per_m;
            zt.row([
                mech.name.to_string(),
                grip.label(),
                format!("{:.0}", largest[0]),
                format!("{:.0}", largest[2]),
                format!("{:.0}", largest[4]),
                format!("{rated:.0}"),
                format!("{:.2}×", largest[0] / rated),
            ])
            .unwrap();
        }
        let (stable, unstable, firm) = charts_pts;
        let mut chart = Chart::new(
            &format!(
                "Z-width of the {} (wall K, B; hand loose; counts)",
                mech.name
            ),
            "K, wall stiffness (N/m)",
            "B, wall damping (N·s/m)",
        );
        chart.x_scale = Scale::Log10;
        (chart.x_range, chart.y_range) = (Some([70.0, 1.5e5]), Some([-1.0, 17.0]));
        let dots = Style::Pen {
            line_px: 0.0,
            dot_px: 5.0,
        };
        let line = Style::Pen {
            line_px: 2.0,
            dot_px: 0.0,
        };
        chart.series = vec![
            Series::new("stable, loose grip", stable, GREEN, dots),
            Series::new("unstable, loose grip", unstable, RED, dots),
            Series::new("stability edge, firm grip", firm, BLUE, line),
        ];
        let rated = mech.limits.max_stiffness_n_per_m;
        chart.markers.push(Marker {
            x: rated,
            label: format!("rated k_max {rated:.0} N/m"),
            color: [120, 120, 120],
        });
        let file = format!("zwidth-{}.png", mech.name);
        chart.write_png(&md.figure(&file), 900, 560).unwrap();
        md.image(&format!("Z-width of the {}", mech.name), &file);
    }
    md.para(
        "How to read the plots: each dot is one closed-loop run of the virtual wall at that \
         stiffness K and damping B, green when stable with a loose hand. The region of green \
         dots is the device's Z-width (Colgate and Brown 1994): the impedances it renders \
         without buzzing. Its right edge is the stiffest wall; it moves right with a firmer \
         hand (blue line: the firm grip's largest stable K at each B), because the hand's \
         damping is what absorbs the energy a sampled spring returns (Colgate: b > K T / 2 + B). \
         Virtual damping B computed from encoder differences eats into the region from above. \
         A world's defaults are safe when its stiffest spring (table below) sits well inside.",
    );
    md.heading("Z-width: largest stable wall stiffness");
    md.table(&zt);

    // 2. Each world's stiffness margin on each device.
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
    let mut mt = Table::new([
        "world",
        "device",
        "stiffest spring at the hand, default (N/m)",
        "stable up to s =",
        "stiffness margin",
    ]);
    let mut world_figs = Vec::new();
    for (world, scene, script) in worlds {
        let text = read(scene);
        let stext = read(script);
        let edit = |s: f64, mech: Mechanics| {
            let (t, m) = scale_impedance(&text, mech, s);
            (
                t.replace(
                    "[loop]\n",
                    "[loop]\npassivity = false\nforce_rate_limit = false\n",
                ),
                m,
            )
        };
        let (mut ok_pts, mut bad_pts) = (Vec::new(), Vec::new());
        for (di, mech) in PRESETS.into_iter().enumerate() {
            let row = (di + 1) as f64;
            let mut k0 = None;
            let mut margin = None;
            for s in SCALES {
                let (t, m) = edit(s, mech);
                let r = match run(&t, &stext, m, Grip::LOOSE, None) {
                    Ok(r) => r,
                    Err(_) => break,
                };
                if s == 1.0 {
                    k0 = Some(r.max_stiffness_n_per_m);
                }
                if std::env::var_os("ZWIDTH_VERBOSE").is_some() {
                    eprintln!("{world} {} s = {s}: {r:?}", mech.name);
                }
                let k = k0.unwrap_or(0.0) * s;
                if !r.stable() {
                    bad_pts.push([k, row]);
                    break;
                }
                ok_pts.push([k, row]);
                margin = Some(s);
            }
            let Some(k0) = k0 else {
                mt.row([
                    world.to_string(),
                    mech.name.to_string(),
                    "refused (spring above the device's cap)".into(),
                    "–".into(),
                    "–".into(),
                ])
                .unwrap();
                continue;
            };
            mt.row([
                world.to_string(),
                mech.name.to_string(),
                format!("{k0:.0}"),
                margin.map_or("unstable at 1".into(), |m| format!("{m}")),
                margin.map_or("none".into(), |m| {
                    if m == SCALES[SCALES.len() - 1] {
                        format!("≥ {m}×")
                    } else {
                        format!("{m}×")
                    }
                }),
            ])
            .unwrap();
        }
        let file = format!("zwidth-world-{}.png", world.replace(' ', "-"));
        let mut c = Chart::new(
            &format!("The {world} on each device: its stiffest spring × s (loose grip, counts)"),
            "stiffest spring at the hand, N/m",
            "device: 1 falcon, 2 touch, 3 delta3, 4 inverse3",
        );
        c.x_scale = Scale::Log10;
        (c.x_range, c.y_range) = (Some([100.0, 2e5]), Some([0.5, 4.5]));
        let dots = Style::Pen {
            line_px: 0.0,
            dot_px: 6.0,
        };
        c.series = vec![
            Series::new("stable", ok_pts, GREEN, dots),
            Series::new("unstable", bad_pts, RED, dots),
        ];
        c.write_png(&md.figure(&file), 900, 360).unwrap();
        world_figs.push((world, file));
    }
    md.heading("Each world's stiffness margin (loose grip, counts, safety layer off)");
    for (world, file) in &world_figs {
        md.image(
            &format!("stiffness margin of the {world} on every device"),
            file,
        );
    }
    md.para(
        "The world's device-side impedance scaled by s until the closed loop is no longer \
         stable; the defaults sit at s = 1. The stiffest spring column is the largest local \
         stiffness the world sent with its force in the default run.",
    );
    md.table(&mt);

    // 3. The paper's inertia (F = −M a from sampled positions): its measured stability limit.
    let masses = [0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5];
    let mut pt = Table::new([
        "device",
        "largest stable brick, counts, safety off (kg)",
        "the same, safety on (kg)",
        "ideal sensing, safety off (kg)",
        "displayed at the device (kg)",
        "the coupling at 0.5 kg, counts",
    ]);
    let brick = read("brickworld.toml");
    let bscript = read("brickworld.script.toml");
    for mech in PRESETS {
        let mut largest = [None, None, None];
        for (si, (safety, counts)) in [(false, true), (true, true), (false, false)]
            .into_iter()
            .enumerate()
        {
            let dev = if counts {
                mech
            } else {
                mech.without_quantization()
            };
            for m in masses {
                let mut t = brick.replace(
                    "[brickworld.params]\n",
                    &format!("[brickworld.params]\ninertia = \"paper\"\nbrick_mass_kg = {m:?}\n"),
                );
                if !safety {
                    t = t.replace(
                        "[loop]\n",
                        "[loop]\npassivity = false\nforce_rate_limit = false\n",
                    );
                }
                let ok = run(&t, &bscript, dev, Grip::LOOSE, None)
                    .map(|r| r.stable())
                    .unwrap_or(false);
                if !ok {
                    break;
                }
                largest[si] = Some(m);
            }
        }
        let coupled = run(&brick, &bscript, mech, Grip::LOOSE, None)
            .map(|r| if r.stable() { "stable" } else { "unstable" })
            .unwrap_or("refused");
        let kg = |m: Option<f64>| m.map_or("< 0.005".to_string(), |m| format!("{m}"));
        pt.row([
            mech.name.to_string(),
            kg(largest[0]),
            kg(largest[1]),
            kg(largest[2]),
            largest[2].map_or("–".into(), |m| format!("{:.3}", m * 0.125 * 20.0)),
            coupled.to_string(),
        ])
        .unwrap();
    }
    md.heading("The paper's inertia: how heavy a brick it can carry (loose grip)");
    md.para(
        "The brick world with `inertia = \"paper\"` (F = −M a from a five-sample stencil of \
         encoder readings) and the brick's mass swept 0.005–0.5 kg; at the default mapping a \
         brick of M kg is displayed as 2.5 M kg at the device. The default (0.5 kg) through the \
         coupling for comparison.",
    );
    md.table(&pt);
    md.finish().unwrap();
}
