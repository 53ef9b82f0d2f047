//! Measures the nano world's speed and accuracy and writes `docs/bench/nanoworld.md` plus
//! `docs/figures/nanoworld-*.png`, through the shared `bench-harness`.
//!
//! Run: `cargo run --release -p nanoworld --example nanoworld-report` (about a minute).

use std::error::Error;
use std::fmt::Write as _;

use bench_harness::chart::{Chart, Legend, Level, PALETTE, Scale, Series, Style};
use bench_harness::{Align, Report, Summary, Table, Timings, Verdict, span};
use nalgebra::Vector3;
use nanoworld::{
    CurveSpec, ForceCurve, GAME_FALCON_LIMITS, Interaction, PairKind, Params, TipInput, World,
    force_distance_curve, house_script,
};

type Res<T> = Result<T, Box<dyn Error>>;

fn bare(mut p: Params, n: usize) -> Params {
    p.substrate.nx = n;
    p.substrate.ny = n;
    p.loading_zone = None;
    p.initial_atoms_xy_m.clear();
    p.house = None;
    p
}

/// Circle of radius 1 nm at a 0.25 nm tip–surface gap (inside the 0.6 nm activation gap,
/// outside the 0.15 nm snap gap) over the substrate centre.
fn hover(p: &Params, ticks: usize) -> Vec<TipInput> {
    let c = p.substrate.nx as f64 * p.substrate.spacing_m / 2.0;
    let z = p.substrate.atom_radius_m + p.tip.radius_m + 0.25e-9;
    (0..ticks)
        .map(|k| {
            let t = k as f64 / 997.0 * std::f64::consts::TAU;
            TipInput {
                position_m: Vector3::new(c + 1e-9 * t.cos(), c + 1e-9 * t.sin(), z),
            }
        })
        .collect()
}

struct Timing {
    atoms: usize,
    /// Wall-clock tick times, µs.
    tick: Summary,
    brute_us: f64,
    max_cell_err: f64,
    cutoff_err: f64,
    in_range: usize,
}

/// Wall-clock µs of every tick (the harness's percentiles); `None` only for zero ticks.
fn tick_us(t: &Timings) -> Res<Summary> {
    Ok(t.wall_us().ok_or("no ticks timed")?)
}

fn time_world(n: usize, ticks: usize) -> Res<Timing> {
    let p = bare(Params::game_default(), n);
    let path = hover(&p, ticks);
    let mut w = World::new(&p, &p.default_limits(), path[0].position_m)?;
    for i in path.iter().take(2000) {
        w.step(i, 1e-3)?;
    }
    let mut t = Timings::with_capacity(ticks);
    let mut sink = 0.0;
    for i in &path {
        sink += t.time(|| w.step(i, 1e-3))?.force_n.z;
    }
    assert!(sink.is_finite());
    // Accuracy: cell list vs the exact sum of the same law, and the activation cutoff vs
    // the untruncated 1/z² law, at 50 points of the path.
    let (mut max_cell_err, mut cutoff_err, mut in_range) = (0.0f64, 0.0f64, 0);
    let mut brute = Timings::with_capacity(50);
    for i in path.iter().step_by(ticks / 50) {
        let c = brute
            .time(|| w.substrate_force_check(i.position_m))
            .ok_or("game mode has a check")?;
        let e = (c.cell_list_n - c.brute_force_n).norm() / c.brute_force_n.norm();
        max_cell_err = max_cell_err.max(e);
        cutoff_err =
            cutoff_err.max((c.cell_list_n - c.untruncated_n).norm() / c.untruncated_n.norm());
        in_range = in_range.max(c.atoms_in_range);
    }
    Ok(Timing {
        atoms: n * n,
        tick: tick_us(&t)?,
        brute_us: tick_us(&brute)?.mean(),
        max_cell_err,
        cutoff_err,
        in_range,
    })
}

fn curve_plot(r: &Report, file: &str, title: &str, c: &ForceCurve, gap_label: &str) -> Res<()> {
    let nm = |(g, f): (&f64, &f64)| [g / 1e-9, f / 1e-9];
    let approach = c.approach_gap_m.iter().zip(&c.approach_force_n).map(nm);
    let retract = c.retract_gap_m.iter().zip(&c.retract_force_n).map(nm);
    let mut ch = Chart::new(title, gap_label, "force z (nN)");
    ch.series = vec![
        Series::new("approach", approach.collect(), PALETTE[0], Style::Line),
        Series::new("retract", retract.collect(), PALETTE[3], Style::Line),
    ];
    ch.write_png(&r.figure(file), 900, 560)?;
    Ok(())
}

fn cost_plot(r: &Report, rows: &[Timing]) -> Res<()> {
    let ymax = rows
        .iter()
        .map(|r| r.tick.p99().max(r.brute_us))
        .fold(0.0, f64::max)
        * 2.0;
    let line = |label: &str, f: &dyn Fn(&Timing) -> f64, color| {
        let pts = rows.iter().map(|r| [r.atoms as f64, f(r)]).collect();
        let pen = Style::Pen {
            line_px: 2.0,
            dot_px: 4.0,
        };
        Series::new(label, pts, color, pen)
    };
    let mut c = Chart::new(
        "nanoworld: tick cost vs substrate size (game mode, tip hovering in range)",
        "substrate atoms",
        "time per tick (µs)",
    );
    (c.x_scale, c.y_scale) = (Scale::Log10, Scale::Log10);
    (c.x_range, c.y_range) = (Some([5e2, 2e6]), Some([0.1, ymax]));
    c.series = vec![
        line("tick p50 (cell list)", &|r| r.tick.median(), PALETTE[0]),
        line("tick p99 (cell list)", &|r| r.tick.p99(), PALETTE[3]),
        line("exact all-atom sum, one force", &|r| r.brute_us, [0, 0, 0]),
    ];
    c.levels.push(Level {
        y: 250.0,
        label: "target: p99 ≤ 250 µs at 10⁵".into(),
        color: PALETTE[2],
    });
    c.legend = Legend::UpperLeft;
    c.write_png(&r.figure("nanoworld-tick-cost.png"), 900, 560)?;
    Ok(())
}

fn main() -> Res<()> {
    let mut md = Report::start("nanoworld", "nanoworld")?;
    md.para(
        "`cargo run --release -p nanoworld --example nanoworld-report` (one run on a machine shared with other jobs; quote ratios, not absolute times). Tick times are wall clock; percentiles are nearest rank (`bench-harness`).",
    );

    // ---- tick cost against substrate size --------------------------------------------------
    let ticks = 20_000;
    let mut rows = Vec::new();
    for n in [32usize, 100, 317, 1000] {
        let t = time_world(n, ticks)?;
        eprintln!(
            "{} atoms: p50 {:.2} µs p99 {:.2} µs",
            t.atoms,
            t.tick.median(),
            t.tick.p99()
        );
        rows.push(t);
    }
    md.heading("Tick cost against substrate size");
    md.para(&format!(
        "Game mode, bare tip circling 0.25 nm above the surface (inside the 0.6 nm activation gap, every tick sums the pair law over the atoms in range through the cell list), {ticks} timed ticks after 2000 warm-up ticks. \"Exact sum\" is one force evaluated by scanning every substrate atom, the reference the cell list replaces."
    ));
    let mut t = Table::new([
        "substrate atoms",
        "atoms in range",
        "tick p50 (µs)",
        "tick p99 (µs)",
        "tick max (µs)",
        "tick mean (µs)",
        "exact all-atom sum (µs)",
        "cell list vs exact sum, max rel. error",
        "activation cutoff vs untruncated 1/z², max rel. difference",
    ])
    .align_from(0, Align::Right);
    for r in &rows {
        t.row([
            r.atoms.to_string(),
            r.in_range.to_string(),
            format!("{:.2}", r.tick.median()),
            format!("{:.2}", r.tick.p99()),
            format!("{:.1}", r.tick.max()),
            format!("{:.2}", r.tick.mean()),
            format!("{:.1}", r.brute_us),
            format!("{:.1e}", r.max_cell_err),
            format!("{:.3}", r.cutoff_err),
        ])?;
    }
    md.table(&t);
    let r5 = rows.iter().find(|r| r.atoms == 100_489).ok_or("10^5 row")?;
    let r3 = &rows[0];
    let r6 = &rows[rows.len() - 1];
    writeln!(
        md,
        "- Target tick p99 ≤ 250 µs at 10⁵ substrate atoms: **{}** ({:.2} µs at {} atoms).",
        Verdict::at_most(r5.tick.p99(), 250.0).word(),
        r5.tick.p99(),
        r5.atoms
    )?;
    writeln!(
        md,
        "- Flatness: p50 at 10⁶ / p50 at 10³ = {:.2} (same run); the exact all-atom sum grows {:.0}× over the same range.",
        r6.tick.median() / r3.tick.median(),
        r6.brute_us / r3.brute_us
    )?;
    writeln!(
        md,
        "- Accuracy: the cell list visits exactly the atoms within reach, in index order, so its sum equals the exact sum of the same law bit for bit (error 0, also a property test). The activation cutoff is part of the game's law (the paper's w₁); the last column says how far that law is from an untruncated A/z² sum over all atoms, for information."
    )?;
    // Physical mode at 10^5: the substrate is a Hamaker half-space, no sum over atoms.
    let pp = bare(Params::physical_default(), 317);
    let mut pw = World::new(&pp, &pp.default_limits(), Vector3::new(47e-9, 47e-9, 30e-9))?;
    let zc = pp.substrate.atom_radius_m + pp.tip.radius_m + 2e-9;
    let mut pt = Timings::with_capacity(ticks);
    for k in 0..ticks {
        let a = k as f64 / 997.0 * std::f64::consts::TAU;
        let i = TipInput {
            position_m: Vector3::new(47e-9 + 5e-9 * a.cos(), 47e-9 + 5e-9 * a.sin(), zc),
        };
        pt.time(|| pw.step(&i, 1e-3))?;
    }
    let pt = tick_us(&pt)?;
    writeln!(
        md,
        "- Physical mode at {} substrate atoms (continuum sphere–plane, no atom sum; Newton solve of the cantilever equilibrium to 1e-9·z0), tip 2 nm above the plane: p50 {:.2} µs, p99 {:.2} µs per tick.\n",
        pp.substrate.nx * pp.substrate.ny,
        pt.median(),
        pt.p99()
    )?;
    cost_plot(&md, &rows)?;
    md.image("tick cost", "nanoworld-tick-cost.png");

    // ---- physics checks against analytic values ------------------------------------------
    md.heading("Force–distance curves against the analytic values");
    let g = bare(Params::game_default(), 1);
    let g_limits = world_form::Limits {
        max_force_n: 1e-8,
        ..GAME_FALCON_LIMITS
    };
    let steps = 100_000;
    let gspec = CurveSpec {
        xy_m: [0.0, 0.0],
        far_gap_m: 2e-9,
        near_gap_m: 0.0,
        steps,
        dt_s: 1e-3,
    };
    let (gc, gs) = span(|| force_distance_curve(&g, &g_limits, &gspec));
    let gc = gc?;
    let g_us = gs.wall_s * 1e6 / (2.0 * steps as f64 + 2.0);
    let gw = World::new(&g, &g_limits, Vector3::new(0.0, 0.0, 5e-9))?;
    let gl = *gw.laws().get(PairKind::TipSubstrate);
    let h = 2e-9 / steps as f64;
    let gi = gc.snap_index.ok_or("game snap")?;
    let gj = gc.pull_off_index.ok_or("game pull-off")?;
    let g_snap_f = -gc.approach_force_n[gi - 1];
    let g_pull = gc.retract_force_n[..gj]
        .iter()
        .fold(0.0f64, |m, f| m.max(-f));
    let (a, wg, zs, k) = (
        gl.coef_n_m2,
        gl.cutoff_gap_m,
        gl.snap_gap_m,
        gl.stiffness_n_per_m,
    );
    let zpo = gl.pull_off_n / k;
    let g_area =
        0.5 * k * (zpo * zpo - zs * zs) - (a * (1.0 / zs - 1.0 / wg) - a * (wg - zs) / (wg * wg));

    let mut ph = bare(Params::physical_default(), 1);
    let Interaction::Physical(pp) = &mut ph.interaction else {
        return Err("physical".into());
    };
    let (ah, r, z0) = (
        pp.hamaker_j.tip_substrate,
        ph.tip.radius_m,
        pp.contact_gap_m,
    );
    let kc = pp.cantilever_stiffness_n_per_m;
    let far = 3e-9;
    let psteps = 300_000;
    let pspec = CurveSpec {
        xy_m: [0.0, 0.0],
        far_gap_m: far,
        near_gap_m: 0.0,
        steps: psteps,
        dt_s: 1e-3,
    };
    let (pc, ps) = span(|| force_distance_curve(&ph, &ph.default_limits(), &pspec));
    let pc = pc?;
    let p_us = ps.wall_s * 1e6 / (2.0 * psteps as f64 + 2.0);
    let ph_h = far / psteps as f64;
    let pi = pc.snap_index.ok_or("physical snap")?;
    let pj = pc.pull_off_index.ok_or("physical pull-off")?;
    let z_jtc = (ah * r / (3.0 * kc)).cbrt();
    let f_jtc = ah * r / (6.0 * z_jtc * z_jtc);
    let w_adh = ah / (12.0 * std::f64::consts::PI * z0 * z0);
    let f_po = 2.0 * std::f64::consts::PI * r * w_adh;
    let p_snap_f = -pc.approach_force_n[pi - 1];
    let p_pull = pc.retract_force_n[..pj]
        .iter()
        .fold(0.0f64, |m, f| m.max(-f));
    // Loop area, quasi-static cantilever: the free branch is the same on both legs between
    // the pull-off base gap and far; the loop is the area between the contact line
    // k_c·(h − z0) and the free branch from the jump to the pull-off gap.
    md.para(&format!(
        "Single substrate atom (game) / sphere–plane (physical), tip on the axis; gaps are cursor gaps (tip surface held by the cursor to the substrate top). Game: {steps} ticks per leg (step {:.0e} m), {:.2} µs per tick. Physical: {psteps} ticks per leg (step {:.0e} m), {:.2} µs per tick (Newton solve of the cantilever equilibrium).",
        h, g_us, ph_h, p_us
    ));
    let mut t = Table::new([
        "quantity",
        "measured",
        "analytic",
        "rel. error",
        "bound from the step",
    ])
    .align_from(1, Align::Right);
    let mut row = |name: &str, m: f64, a: f64, bound: String| {
        t.row([
            name.to_string(),
            format!("{m:.5e}"),
            format!("{a:.5e}"),
            format!("{:.1e}", ((m - a) / a).abs()),
            bound,
        ])
        .map(|_| ())
    };
    row(
        "game: snap gap (m)",
        gc.approach_gap_m[gi - 1],
        zs,
        format!("< h/z_s = {:.1e}", h / zs),
    )?;
    row(
        "game: snap force A(1/z_s²−1/w²) (N)",
        g_snap_f,
        gl.snap_force_n,
        format!(
            "≤ 2A h/z_s³/F = {:.1e}",
            2.0 * a * h / zs.powi(3) / gl.snap_force_n
        ),
    )?;
    row(
        "game: largest pull before release (N)",
        g_pull,
        gl.pull_off_n,
        format!("≤ k h/F = {:.1e}", k * h / gl.pull_off_n),
    )?;
    row(
        "game: pull-off / snap",
        g_pull / g_snap_f,
        10.0,
        "sum of the two above".into(),
    )?;
    row(
        "game: hysteresis loop area (J)",
        gc.hysteresis_j,
        g_area,
        "O(h), first order (test)".into(),
    )?;
    row(
        "physical: jump base gap 1.5·z_jtc (m)",
        pc.approach_gap_m[pi],
        1.5 * z_jtc,
        format!("≤ h/z = {:.1e}", ph_h / (1.5 * z_jtc)),
    )?;
    row(
        "physical: jump force A·R/(6 z_jtc²) (N)",
        p_snap_f,
        f_jtc,
        format!(
            "≤ 2√(2h/3z_jtc) = {:.1e}",
            2.0 * (2.0 * ph_h / (3.0 * z_jtc)).sqrt()
        ),
    )?;
    row(
        "physical: pull-off 2πRW, W = A/(12π z0²) (N)",
        p_pull,
        f_po,
        format!("≤ k_c h/F = {:.1e}", kc * ph_h / f_po),
    )?;
    let cc = ah * r / 6.0;
    let hpo = z0 + f_po / kc;
    let mut dpo = hpo;
    for _ in 0..100 {
        dpo -= (kc * (hpo - dpo) - cc / (dpo * dpo)) / (-kc + 2.0 * cc / dpo.powi(3));
    }
    let prim = |x: f64| -cc / x + cc * cc / (2.0 * kc * x.powi(4));
    let p_area =
        0.5 * kc * ((hpo - z0).powi(2) - (1.5 * z_jtc - z0).powi(2)) - (prim(dpo) - prim(z_jtc));
    row(
        "physical: hysteresis loop area (J)",
        pc.hysteresis_j,
        p_area,
        "O(h) (test)".into(),
    )?;
    row(
        "physical: pull-off / jump force, k_c = A·R/(95 z0³)",
        p_pull / p_snap_f,
        (95.0f64 / 3.0).powf(2.0 / 3.0),
        "sum of the two above".into(),
    )?;
    md.table(&t);
    md.para(&format!(
        "k_c = A·R/(95·z0³) = {kc:.3} N/m for A = {ah:.0e} J, R = {:.0} nm, z0 = {:.3} nm: z_jtc = (95/3)^{{1/3}}·z0 = {:.3} nm and pull-off/jump = (z_jtc/z0)² = (95/3)^{{2/3}} = {:.4}; the exact tenfold stiffness is A·R/(3·10^{{3/2}}·z0³) = A·R/(94.87·z0³).",
        r * 1e9,
        z0 * 1e9,
        z_jtc * 1e9,
        (95.0f64 / 3.0).powf(2.0 / 3.0)
    ));
    curve_plot(
        &md,
        "nanoworld-curve-game.png",
        "game mode: approach–retract, tip over one substrate atom",
        &gc,
        "cursor gap (nm)",
    )?;
    curve_plot(
        &md,
        "nanoworld-curve-physical.png",
        "physical mode: 20 nm tip, A = 1e-19 J, k_c = A·R/(95 z0³)",
        &pc,
        "cantilever base gap (nm)",
    )?;
    md.image("game curve", "nanoworld-curve-game.png");
    md.image("physical curve", "nanoworld-curve-physical.png");

    // ---- the scripted house session ------------------------------------------------------
    let mut w = World::new(
        &Params::game_default(),
        &GAME_FALCON_LIMITS,
        Vector3::new(4e-9, 4e-9, 4e-9),
    )?;
    let script = house_script(&w, 2e-12)?;
    let mut t = Timings::with_capacity(script.len());
    let mut events = 0;
    for i in &script {
        events += t.time(|| w.step(i, 1e-3))?.events.len();
    }
    let t = tick_us(&t)?;
    md.heading("Scripted house session (game default scene)");
    let mut tab = Table::new([
        "ticks",
        "events",
        "slots filled",
        "house complete",
        "tick p50 (µs)",
        "tick p99 (µs)",
        "tick max (µs)",
    ])
    .align_from(0, Align::Right)
    .align(3, Align::Center);
    tab.row([
        script.len().to_string(),
        events.to_string(),
        format!("{}/{}", w.house().score(), w.house().slots_m().len()),
        (if w.house().is_complete() { "yes" } else { "no" }).to_string(),
        format!("{:.2}", t.median()),
        format!("{:.2}", t.p99()),
        format!("{:.1}", t.max()),
    ])?;
    md.table(&tab);
    md.finish()?;
    Ok(())
}
