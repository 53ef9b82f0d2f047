//! Benchmark report of the haptic loop: tick times with MCAP logging on and off (batch and real
//! time), replay speed, MCAP bytes per minute, and the accuracy of what the loop renders
//! (stiffness cap, force clamp, bit-exact replay). Writes `docs/bench/haptic-loop.md` and
//! `docs/figures/haptic-loop-*.png` through the shared `bench-harness`.
//!
//! `cargo run --release -p haptic-loop --example haptic-loop-report` (about 1 minute: it includes a
//! 20 s real-time session).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bench_harness::chart::{Chart, Legend, PALETTE, Scale, Series, Style};
use bench_harness::{Report, Summary, Table, Verdict, span};
use haptic_devices::OperatorParams;
use haptic_devices::source::OperatorChoice;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use recording::read_recording_file;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

mod bench_figures;
use bench_figures::workload_script;

fn us(ns: u64) -> f64 {
    ns as f64 / 1e3
}

/// Nearest-rank percentiles of a session's per-tick work, µs.
fn tick_us(compute_ns: &[u64]) -> Summary {
    Summary::of(compute_ns.iter().map(|&n| us(n))).expect("a session has ticks")
}

/// The tick-time table, one row per session: p50, p99, p99.9, max, ticks over 250 µs and 1 ms.
fn tick_table() -> Table {
    Table::new([
        "session",
        "p50 (µs)",
        "p99 (µs)",
        "p99.9 (µs)",
        "max (µs)",
        "ticks > 250 µs",
        "ticks > 1 ms",
    ])
}

fn tick_row(t: &mut Table, name: &str, compute_ns: &[u64]) {
    let s = tick_us(compute_ns);
    t.row([
        name.to_string(),
        format!("{:.2}", s.median()),
        format!("{:.2}", s.p99()),
        format!("{:.2}", s.p999()),
        format!("{:.1}", s.max()),
        s.count_above(250.0).to_string(),
        s.count_above(1000.0).to_string(),
    ])
    .unwrap();
}

fn main() {
    let mut md = Report::start(
        "haptic-loop",
        "haptic-loop: tick times, recording size, replay",
    )
    .unwrap();
    let root = md.root().to_path_buf();
    let scene = SceneSource::from_path(&root.join("scenes/wall.toml")).unwrap();
    let tmp = std::env::temp_dir().join(format!("haptic-loop-bench-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();

    // 1. Batch, 60 s, logging on and off.
    let run = |seconds: f64, out: Option<PathBuf>, realtime: bool| {
        let mut o = SessionOptions::new(scene.clone());
        o.script = Some(workload_script(seconds));
        o.operator = OperatorChoice::ScriptHand;
        o.out = out;
        o.realtime = realtime;
        run_session(&o, &mut |_, _| {}).unwrap()
    };
    let rec60 = tmp.join("bench60.mcap");
    let on = run(60.0, Some(rec60.clone()), false);
    let off = run(60.0, None, false);
    let w = on.written.clone().unwrap();
    let bytes_per_min = w.bytes as f64; // a 60 s session
    eprintln!(
        "batch done: p99 on {} ns, off {} ns",
        on.stats.compute.p99_ns, off.stats.compute.p99_ns
    );

    // 2. Real time, 20 s, logging on.
    let rt_rec = tmp.join("rt20.mcap");
    let rt = run(20.0, Some(rt_rec.clone()), true);
    eprintln!("realtime done: missed {}", rt.stats.missed);

    // 3. Replay speed and exactness.
    let rec = read_recording_file(&rec60, false).unwrap();
    let (v, replay) = span(|| verify(&rec).unwrap());
    let replay_s = replay.wall_s;
    let rt_v = verify(&read_recording_file(&rt_rec, false).unwrap()).unwrap();

    // 4. Accuracy of the rendering: a rigid stylus pushed slowly 21 mm into the wall.
    let ramp_run = bench_figures::ramp_session(&scene);
    let a = &ramp_run.arrays;
    let pen = a.state_column("penetration_m").unwrap();
    let (stiff_err, clamp_err, clamp_dir) = bench_figures::rendering_errors(a);

    // Figures.
    plot_ticks(
        &md.figure("haptic-loop-tick-times.png"),
        &[
            ("batch, logging on", &on.arrays.compute_ns, RED),
            ("batch, logging off", &off.arrays.compute_ns, BLUE),
            ("real time, logging on", &rt.arrays.compute_ns, GREEN),
        ],
    );
    plot_wall(&md.figure("haptic-loop-wall.png"), &pen, a);

    // 5. Every world scene with its default script, logging on.
    let mut worlds = Vec::new();
    for name in ["nanoworld", "brickworld"] {
        let src = SceneSource::from_path(&root.join(format!("scenes/{name}.toml"))).unwrap();
        let mut o = SessionOptions::new(src);
        o.out = Some(tmp.join(format!("{name}.mcap")));
        let r = run_session(&o, &mut |_, _| {}).unwrap();
        let rec = read_recording_file(o.out.as_ref().unwrap(), false).unwrap();
        let ok = verify(&rec).unwrap().ok();
        worlds.push((name, r, ok));
    }
    // 6. Optical tweezers: a 60 s session (envelope every tick, logging on) and the paper's
    //    experiment (§4): drag faster than the trap can follow, feedback off / on.
    let ot_src = SceneSource::from_path(&root.join("scenes/optical_tweezers.toml")).unwrap();
    let mut sq = String::from(
        "[script]\nname = \"bench: 60 s of steering around a square\"\nduration_s = 60.0\n\
         [[button]]\nt_s = 0.3\nname = \"centre\"\ndown = true\n\
         [[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, 0.0]\n\
         [[waypoint]]\nt_s = 0.5\nposition_mm = [0.0, 0.0, 0.0]\n",
    );
    let corners = [[4.0, 0.0], [4.0, 4.0], [0.0, 4.0], [0.0, 0.0]];
    for k in 1..60 {
        let c = corners[k % 4];
        let _ = write!(
            sq,
            "[[waypoint]]\nt_s = {k}.5\nposition_mm = [{:?}, {:?}, 0.0]\n",
            c[0], c[1]
        );
    }
    let mut o = SessionOptions::new(ot_src.clone());
    o.script = Some(sq);
    o.out = Some(tmp.join("ot60.mcap"));
    let ot60 = run_session(&o, &mut |_, _| {}).unwrap();
    let ot60_ok = verify(&read_recording_file(o.out.as_ref().unwrap(), false).unwrap())
        .unwrap()
        .ok();
    let grabbed_ticks = ot60
        .arrays
        .state_column("grabbed")
        .unwrap()
        .iter()
        .filter(|g| **g == 1.0)
        .count();
    assert!(
        grabbed_ticks > 55_000,
        "the particle was grabbed for {grabbed_ticks} ticks only"
    );
    eprintln!("ot 60 s done: p99 {} ns", ot60.stats.compute.p99_ns);
    let drag = "[script]\nname = \"drag too fast\"\nduration_s = 2.5\n\
                [[button]]\nt_s = 0.3\nname = \"centre\"\ndown = true\n\
                [[button]]\nt_s = 2.2\nname = \"centre\"\ndown = false\n\
                [[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, 0.0]\n\
                [[waypoint]]\nt_s = 0.5\nposition_mm = [0.0, 0.0, 0.0]\n\
                [[waypoint]]\nt_s = 0.75\nposition_mm = [10.0, 0.0, 0.0]\n";
    let experiment = |feedback: bool, op: OperatorParams| {
        let mut src = ot_src.clone();
        if !feedback {
            src.text = src.text.replace("feedback = true", "feedback = false");
        }
        let mut o = SessionOptions::new(src);
        o.script = Some(drag.to_string());
        o.operator = OperatorChoice::Hand(op);
        let r = run_session(&o, &mut |_, _| {}).unwrap();
        let lag = r.arrays.state_column("lag_m").unwrap();
        let grabbed = r.arrays.state_column("grabbed").unwrap();
        let max = lag
            .iter()
            .zip(&grabbed)
            .filter(|(_, g)| **g == 1.0)
            .map(|(l, _)| *l)
            .fold(0.0, f64::max);
        (lag, max)
    };
    let passive = OperatorParams::default();
    let yielding = OperatorParams {
        yield_force_n: 0.5,
        ..passive
    };
    let (lag_off, max_off) = experiment(false, passive);
    let (lag_on, max_on) = experiment(true, passive);
    let (lag_on_y, max_on_y) = experiment(true, yielding);
    plot_lag(
        &md.figure("haptic-loop-ot-drag.png"),
        &[
            ("feedback off", &lag_off, RED),
            ("feedback on, passive hand", &lag_on, BLUE),
            (
                "feedback on, hand that yields (0.5 N halves its speed)",
                &lag_on_y,
                GREEN,
            ),
        ],
    );
    // Report.
    md.para(
        "Scene `scenes/wall.toml` (stiff wall, Falcon, 1 kHz), 60 s script of repeated presses \
         through the simulated hand (`bench_report` example). Tick work = the runner's \
         `compute_ns`: device read, world step, force mapping and sending the force. The sinks \
         (the recorder's encoding of every channel and its hand-off to the MCAP writer thread, \
         the per-tick arrays) run after it, each timed on its own (second table). One run, 2 \
         shared cores: the largest ticks are scheduler preemptions (they appear with logging \
         off too). Percentiles are nearest rank over every tick's work.",
    );
    let mut t = tick_table();
    tick_row(&mut t, "batch 60 s, logging on", &on.arrays.compute_ns);
    tick_row(&mut t, "batch 60 s, logging off", &off.arrays.compute_ns);
    tick_row(&mut t, "real time 20 s, logging on", &rt.arrays.compute_ns);
    for (name, r, _) in &worlds {
        let name = format!(
            "{name}, default script ({:.1} s), batch, logging on",
            r.stats.ticks as f64 / 1e3
        );
        tick_row(&mut t, &name, &r.arrays.compute_ns);
    }
    md.table(&t);
    let mut t = Table::new([
        "session",
        "sink",
        "per tick p50 (µs)",
        "p99 (µs)",
        "max (µs)",
    ]);
    for (name, r) in [
        ("batch 60 s, logging on", &on),
        ("batch 60 s, logging off", &off),
        ("real time 20 s, logging on", &rt),
    ] {
        for s in &r.sinks {
            t.row([
                name.to_string(),
                s.sink.to_string(),
                format!("{:.2}", us(s.tick.p50_ns)),
                format!("{:.2}", us(s.tick.p99_ns)),
                format!("{:.1}", us(s.tick.max_ns)),
            ])
            .unwrap();
        }
    }
    md.table(&t);
    let (on_t, off_t) = (
        tick_us(&on.arrays.compute_ns),
        tick_us(&off.arrays.compute_ns),
    );
    writeln!(
        md,
        "Real-time pacing (20 s): start jitter p99 {:.1} µs, max {:.1} µs; {} missed deadlines \
         of {} ticks (zero force sent on each, logged).",
        us(rt.stats.jitter.p99_ns),
        us(rt.stats.jitter.max_ns),
        rt.stats.missed,
        rt.stats.ticks
    )
    .unwrap();
    writeln!(
        md,
        "Logging on/off p99 ratio, same run: {:.2}.\n",
        on_t.p99() / off_t.p99().max(1e-3)
    )
    .unwrap();
    let met = |v: Verdict| v.word();
    let mut t = Table::new(["target", "measured", "status"]);
    t.row([
        "tick p99 ≤ 250 µs, logging on (wall scene)".to_string(),
        format!("{:.2} µs", on_t.p99()),
        met(Verdict::at_most(on_t.p99(), 250.0)).to_string(),
    ])
    .unwrap();
    t.row([
        "tick max ≤ 1 ms, logging on (wall scene)".to_string(),
        format!("{:.1} µs", on_t.max()),
        met(Verdict::at_most(on_t.max(), 1000.0)).to_string(),
    ])
    .unwrap();
    t.row([
        "replay bit-exact".to_string(),
        format!(
            "{} (60 s batch), {} (20 s real time)",
            replay_word(&v),
            match &rt_v.divergence {
                None => "identical".to_string(),
                Some(d) => format!("diverged at tick {}", d.tick),
            }
        ),
        met(Verdict::all([
            Verdict::from_bool(v.ok()),
            Verdict::from_bool(rt_v.ok()),
        ]))
        .to_string(),
    ])
    .unwrap();
    md.table(&t);
    md.para(&format!(
        "MCAP size: {:.0} kB per minute of session ({} messages; zstd chunks flushed every \
         session second; the writer queue peaked at {} ticks). Replay with verification: \
         {:.0} ticks/s ({:.2} s for 60 s).",
        bytes_per_min / 1e3,
        w.messages,
        w.max_queue_ticks,
        v.ticks as f64 / replay_s,
        replay_s
    ));
    let mut t = Table::new(["scene", "MCAP kB per minute", "replay bit-exact"]);
    t.row([
        "wall (60 s)".to_string(),
        format!("{:.0}", bytes_per_min / 1e3),
        v.ok().to_string(),
    ])
    .unwrap();
    for (name, r, ok) in &worlds {
        let w = r.written.as_ref().unwrap();
        t.row([
            format!("{name} ({:.1} s)", r.stats.ticks as f64 / 1e3),
            format!(
                "{:.0}",
                w.bytes as f64 / 1e3 * 60.0 / (r.stats.ticks as f64 / 1e3)
            ),
            ok.to_string(),
        ])
        .unwrap();
    }
    md.table(&t);
    md.para("Accuracy of the rendered force (rigid stylus pushed 21 mm into a 5000 N/m wall):");
    let mut t = Table::new(["quantity", "expected", "worst error"]);
    t.row([
        "force in the unclamped range vs k·d − b·v_n, k capped at 3000 N/m".to_string(),
        "exact".to_string(),
        format!("{stiff_err:.1e} relative"),
    ])
    .unwrap();
    t.row([
        "clamped force norm".to_string(),
        "8 N".to_string(),
        format!("{clamp_err:.1e} N"),
    ])
    .unwrap();
    t.row([
        "direction of the sent force vs the world force".to_string(),
        "same".to_string(),
        format!("{clamp_dir:.1e} rad"),
    ])
    .unwrap();
    md.table(&t);
    md.heading("Optical tweezers: steering with the working envelope every tick");
    md.para(
        "Scene `scenes/optical_tweezers.toml` (paper constants; the scene's tick map, \
         `tick_map_tol_nm = 0.01`: the cheapest RK4/RK8 within 0.01 nm of converged dynamics; \
         `ot-envelope` controller with the warm-started envelope: envelope, clip, inverse solve \
         while grabbed), 60 s of steering around a 4 µm square, logging on.",
    );
    let mut t = tick_table();
    tick_row(
        &mut t,
        "optical tweezers 60 s, batch, logging on",
        &ot60.arrays.compute_ns,
    );
    md.table(&t);
    let ot_t = tick_us(&ot60.arrays.compute_ns);
    let ow = ot60.written.as_ref().unwrap();
    let mut t = Table::new(["target", "measured", "status"]);
    t.row([
        "OT tick p99 ≤ 250 µs (envelope + logging on)".to_string(),
        format!("{:.1} µs", ot_t.p99()),
        met(Verdict::at_most(ot_t.p99(), 250.0)).to_string(),
    ])
    .unwrap();
    t.row([
        "OT tick max ≤ 1 ms".to_string(),
        format!("{:.1} µs", ot_t.max()),
        met(Verdict::at_most(ot_t.max(), 1000.0)).to_string(),
    ])
    .unwrap();
    t.row([
        "replay bit-exact (60 s)",
        if ot60_ok { "identical" } else { "DIVERGED" },
        met(Verdict::from_bool(ot60_ok)),
    ])
    .unwrap();
    md.table(&t);
    md.para(&format!(
        "MCAP size: {:.0} kB per minute (the envelope is drawn in `/foxglove/scene` at 50 Hz).",
        ow.bytes as f64 / 1e3
    ));
    md.para(
        "The paper's experiment, headless: grab the particle, then the simulated operator drags \
         the cursor 10 µm in 0.25 s (peak 75 nm per tick, beyond what the trap can move the \
         particle in one cycle), holds, releases. Largest cursor–particle distance while grabbed:",
    );
    let mut t = Table::new(["run", "largest cursor–particle distance", "paper"]);
    t.row([
        "feedback off".to_string(),
        format!("{:.2} µm", max_off * 1e6),
        "up to 3 µm".to_string(),
    ])
    .unwrap();
    t.row([
        "feedback on, passive hand (0.3 kg, 300 N/m, 12 N·s/m)".to_string(),
        format!("{:.2} µm", max_on * 1e6),
        "under 0.3 µm".to_string(),
    ])
    .unwrap();
    t.row([
        "feedback on, hand that slows down under force (0.5 N halves its speed)".to_string(),
        format!("{:.2} µm", max_on_y * 1e6),
        "under 0.3 µm".to_string(),
    ])
    .unwrap();
    md.table(&t);
    md.para(&format!(
        "A passive hand is held back only by the spring (800 N/m on the device against its own \
         300 N/m pull); the paper's operators also slowed down because they felt the wall, which \
         the yielding hand models. Feedback on/off ratio (passive): {:.2}; (yielding): {:.2}.",
        max_on / max_off,
        max_on_y / max_off
    ));
    md.image("OT drag experiment", "haptic-loop-ot-drag.png");
    md.image("tick times", "haptic-loop-tick-times.png");
    md.image("wall", "haptic-loop-wall.png");
    let (_, text) = md.finish().unwrap();
    print!("{text}");
    let _ = std::fs::remove_dir_all(&tmp);
}

const BLUE: [u8; 3] = PALETTE[0];
const GREEN: [u8; 3] = PALETTE[2];
const RED: [u8; 3] = PALETTE[3];

fn plot_ticks(path: &Path, series: &[(&str, &Vec<u64>, [u8; 3])]) {
    let max = series
        .iter()
        .flat_map(|s| s.1.iter())
        .copied()
        .max()
        .unwrap_or(1) as f64
        / 1e3;
    let mut c = Chart::new(
        "tick work (up to the writer hand-off): fraction of ticks above a time",
        "tick work (µs)",
        "fraction of ticks ≥ x",
    );
    (c.x_scale, c.y_scale) = (Scale::Log10, Scale::Log10);
    (c.x_range, c.y_range) = (Some([0.1, max * 1.5]), Some([1e-5, 1.0]));
    for (name, data, color) in series {
        let v = tick_us(data);
        let n = v.len() as f64;
        let pts = v
            .sorted()
            .iter()
            .enumerate()
            .map(|(i, &x)| [x.max(0.1), ((n - i as f64) / n).max(1e-5)])
            .collect();
        c.series.push(Series::new(name, pts, *color, Style::Line));
    }
    c.write_png(path, 900, 500).unwrap();
}

fn plot_lag(path: &Path, series: &[(&str, &Vec<f64>, [u8; 3])]) {
    let ymax = series
        .iter()
        .flat_map(|s| s.1.iter())
        .copied()
        .fold(0.0, f64::max)
        * 1e6
        * 1.1;
    let mut c = Chart::new(
        "optical tweezers: cursor–particle distance while dragging too fast",
        "time (s)",
        "cursor–particle distance (µm)",
    );
    (c.x_range, c.y_range) = (Some([0.0, 2.5]), Some([0.0, ymax.max(1.0)]));
    for (name, lag, color) in series {
        let pts = lag
            .iter()
            .enumerate()
            .map(|(i, l)| [i as f64 / 1000.0, l * 1e6])
            .collect();
        c.series.push(Series::new(name, pts, *color, Style::Line));
    }
    c.write_png(path, 900, 500).unwrap();
}

fn plot_wall(path: &Path, pen: &[f64], a: &haptic_loop::SessionArrays) {
    let engaged = || (0..pen.len()).filter(|&i| a.engagement[i] == 1.0);
    let world = engaged()
        .map(|i| [pen[i] * 1e3, a.world_force_n[i][2].min(12.0)])
        .collect();
    let sent = engaged()
        .map(|i| [pen[i] * 1e3, a.device_force_n[i][2]])
        .collect();
    let pen = |line_px| Style::Pen {
        line_px,
        dot_px: 0.0,
    };
    let mut c = Chart::new(
        "stiff wall: force sent vs penetration (Falcon, rigid stylus)",
        "penetration (mm)",
        "force (N)",
    );
    (c.x_range, c.y_range) = (Some([0.0, 21.0]), Some([0.0, 12.0]));
    c.series = vec![
        Series::new(
            "requested 5000 N/m",
            vec![[0.0, 0.0], [2.4, 12.0]],
            [180, 180, 180],
            pen(1.0),
        ),
        Series::new("scene force (capped at 3000 N/m)", world, BLUE, pen(2.0)),
        Series::new("force sent (clamped at 8 N)", sent, RED, pen(3.0)),
    ];
    c.legend = Legend::LowerRight;
    c.write_png(path, 900, 500).unwrap();
}

/// A replay's outcome in the targets table: every message compared identical, or where it
/// first diverged (verification stops there).
fn replay_word(v: &haptic_loop::replay::VerifyReport) -> String {
    match &v.divergence {
        None => format!("all {} output messages identical", v.messages_compared),
        Some(d) => format!(
            "diverged at tick {} on {} ({} messages compared)",
            d.tick, d.channel, v.messages_compared
        ),
    }
}
