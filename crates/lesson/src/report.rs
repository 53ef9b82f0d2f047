//! The lesson's report: `lesson.md` and its PNG figures, every number from the runs.

use crate::measure::{self, events, times};
use crate::{LessonError, LessonSummary, Run, Runs, write_file};
use chart::{Band, Bar, BarChart, Chart, Figure, Marker, Scale, Series, Style};
use std::fmt::Write;
use std::path::Path;
use world_form::numbers::{SiStyle, fmt_num, fmt_si, fmt_sig};

const BLUE: [u8; 3] = [31, 119, 180];
const ORANGE: [u8; 3] = [255, 127, 14];
const GREEN: [u8; 3] = [44, 160, 44];
const RED: [u8; 3] = [214, 39, 40];
const PURPLE: [u8; 3] = [148, 103, 189];
const GREY: [u8; 3] = [110, 110, 110];
const TEAL: [u8; 3] = [0, 140, 140];

fn series(label: &str, points: Vec<[f64; 2]>, color: [u8; 3], style: Style) -> Series {
    Series {
        label: label.to_string(),
        points,
        color,
        style,
    }
}

/// Component `k` of the world force over time, × `unit`.
fn force_curve(r: &Run, k: usize, unit: f64) -> Vec<[f64; 2]> {
    times(&r.arrays)
        .into_iter()
        .zip(&r.arrays.world_force_n)
        .map(|(t, f)| [t, f[k] * unit])
        .collect()
}

/// |world force| over time, × `unit`.
fn force_norm(r: &Run, unit: f64) -> Vec<[f64; 2]> {
    times(&r.arrays)
        .into_iter()
        .zip(&r.arrays.world_force_n)
        .map(|(t, f)| [t, (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt() * unit])
        .collect()
}

fn markers(r: &Run, names: &[(&str, &str, [u8; 3])]) -> Vec<Marker> {
    let mut out = Vec::new();
    for (name, label, color) in names {
        for (t, _) in events(&r.arrays, name) {
            out.push(Marker {
                x: t,
                label: label.to_string(),
                color: *color,
            });
        }
    }
    out.sort_by(|a, b| a.x.total_cmp(&b.x));
    out
}

/// Draws `figure` into `dir/name` (`w` × `w/2` px) and lists the file.
fn save(
    dir: &Path,
    name: &str,
    w: u32,
    figure: &dyn Figure,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    figure
        .write_png(&dir.join(name), w, w / 2)
        .map_err(|e| LessonError::Figure {
            figure: name.to_string(),
            message: e.to_string(),
        })?;
    files.push(name.to_string());
    Ok(())
}

/// Approach (until the deepest point) and retract branches of force z (nN) vs cursor height
/// (nm) of an approach–retract run.
fn branches(r: &Run) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let a = &r.arrays;
    let low = a
        .cursor_m
        .iter()
        .enumerate()
        .min_by(|x, y| x.1[2].total_cmp(&y.1[2]))
        .map_or(0, |(i, _)| i);
    let pts: Vec<[f64; 2]> = a
        .cursor_m
        .iter()
        .zip(&a.world_force_n)
        .map(|(c, f)| [c[2] * 1e9, f[2] * 1e9])
        .collect();
    (
        pts[..=low.min(pts.len().saturating_sub(1))].to_vec(),
        pts[low..].to_vec(),
    )
}

/// Short form of a number with its unit: `4.91 N`, `3.00 nN`, `1.00e-24 N` ([`fmt_si`] in
/// the [`SiStyle::QUANTITY`] style).
pub fn si(v: f64, unit: &str) -> String {
    fmt_si(v, unit, SiStyle::QUANTITY)
}

/// Draws the figures and writes `lesson.md`; returns the files written.
pub fn write(
    dir: &Path,
    w: u32,
    s: &LessonSummary,
    runs: &Runs,
) -> Result<Vec<String>, LessonError> {
    let mut files = Vec::new();
    house_figures(dir, w, runs, &mut files)?;
    lift_figures(dir, w, runs, &mut files)?;
    hysteresis_figure(dir, w, s, runs, &mut files)?;
    throw_figure(dir, w, s, &mut files)?;
    scale_figures(dir, w, s, &mut files)?;
    let md = markdown(s);
    write_file(&dir.join("lesson.md"), md.as_bytes())?;
    files.insert(0, "lesson.md".to_string());
    Ok(files)
}

/// The events a house chart marks: event name, its label on the chart, its colour (RGB).
type EventMarks<'a> = &'a [(&'a str, &'a str, [u8; 3])];

/// The house tasks: force over time with their events.
fn house_figures(
    dir: &Path,
    w: u32,
    runs: &Runs,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    let worlds: [(&str, &str, &Run, f64, EventMarks, &str); 2] = [
        (
            "Macro world: building the wall (force on the hand, world frame)",
            "force (N)",
            &runs.macro_house,
            1.0,
            &[
                ("brick.grabbed", "grab", GREEN),
                ("brick.released", "release", RED),
                ("brick.slot_filled", "slot", PURPLE),
            ],
            "macro_forces.png",
        ),
        (
            "Nano world: building the house (force on the tip, world frame)",
            "force (nN)",
            &runs.nano_house,
            1e9,
            &[
                ("nano.snap", "snap", GREEN),
                ("nano.pull_off", "pull-off", RED),
                ("nano.slot_filled", "slot", PURPLE),
            ],
            "nano_forces.png",
        ),
    ];
    for (title, y_label, run, scale, events, file) in worlds {
        save(
            dir,
            file,
            w,
            &house_chart(title, y_label, run, scale, events),
            files,
        )?;
    }
    Ok(())
}

/// Lifting a brick: weight and inertia, and the same motion with the switches.
fn lift_figures(
    dir: &Path,
    w: u32,
    runs: &Runs,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    let labels = ["normal", "gravity off", "inertia off"];
    let colors = [BLUE, GREEN, ORANGE];
    for (title, y_label, axis, file) in [
        (
            "Lift and carry a brick: vertical force (weight)",
            "Fz (N)",
            2,
            "lift_weight.png",
        ),
        (
            "Lift and carry a brick: sideways force (inertia −M a)",
            "Fx (N)",
            0,
            "lift_inertia.png",
        ),
    ] {
        let mut c = Chart::new(title, "time (s)", y_label);
        c.series = runs
            .lifts
            .iter()
            .zip(labels.iter().zip(colors))
            .map(|(r, (l, col))| series(l, force_curve(r, axis, 1.0), col, Style::Line))
            .collect();
        c.markers = lift_markers();
        save(dir, file, w, &c, files)?;
    }
    Ok(())
}

/// Approach and retract over one atom: snap-in and pull-off, adhesion full and halved.
fn hysteresis_figure(
    dir: &Path,
    w: u32,
    s: &LessonSummary,
    runs: &Runs,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    let (a1, r1) = branches(&runs.cycles[0]);
    let (a2, r2) = branches(&runs.cycles[1]);
    let mut c = Chart::new(
        "Approach and retract over one atom: the tip snaps in and pulls off at ten times the snap force",
        "cursor height (nm)",
        "Fz on the tip (nN)",
    );
    c.series = vec![
        series("approach", a1, BLUE, Style::Line),
        series("retract", r1, RED, Style::Line),
        series("approach, adhesion halved", a2, TEAL, Style::Line),
        series("retract, adhesion halved", r2, ORANGE, Style::Line),
    ];
    c.markers = vec![
        Marker {
            x: s.hysteresis.snap_height_m * 1e9,
            label: "snap".into(),
            color: GREEN,
        },
        Marker {
            x: s.hysteresis.pull_off_height_m * 1e9,
            label: "pull-off".into(),
            color: RED,
        },
    ];
    save(dir, "hysteresis.png", w, &c, files)?;
    Ok(())
}

/// Throwing: the heavy-atom sweep against the predicted threshold.
fn throw_figure(
    dir: &Path,
    w: u32,
    s: &LessonSummary,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    let sw = &s.sweep;
    let ratio = |a_hand: f64| sw.mass_kg * a_hand * 1.5e-7 / sw.hold_n;
    let kept: Vec<[f64; 2]> = sw
        .runs
        .iter()
        .filter(|r| !r.2)
        .map(|r| [r.1, ratio(r.1)])
        .collect();
    let off: Vec<[f64; 2]> = sw
        .runs
        .iter()
        .filter(|r| r.2)
        .map(|r| [r.1, ratio(r.1)])
        .collect();
    let mut c = Chart::new(
        "Throwing a (3 g, gravity off) atom: it leaves the tip when m·a exceeds the tip's hold",
        "peak hand acceleration (m/s²)",
        "load / hold",
    );
    c.series = vec![
        series("stayed on the tip", kept, BLUE, Style::Dots),
        series("thrown off", off, RED, Style::Dots),
    ];
    c.markers = vec![Marker {
        x: sw.predicted_hand_m_per_s2,
        label: "predicted threshold".into(),
        color: GREY,
    }];
    c.bands = vec![Band {
        y_min: 1.0,
        y_max: ratio(sw.runs.iter().map(|r| r.1).fold(0.0, f64::max)).max(1.5),
        label: "load above the hold".into(),
        color: RED,
    }];
    save(dir, "throw_threshold.png", w, &c, files)?;
    Ok(())
}

/// Scales (the paper's Fig. 2): forces and sizes of the two worlds.
fn scale_figures(
    dir: &Path,
    w: u32,
    s: &LessonSummary,
    files: &mut Vec<String>,
) -> Result<(), LessonError> {
    let bar = |group: &str, label: &str, value: f64, color: [u8; 3]| Bar {
        group: group.to_string(),
        label: label.to_string(),
        value,
        color,
    };
    let atom_weight = s.atom_mass_kg * 9.81;
    let forces = BarChart {
        title: "Forces in the two worlds (log scale): newtons against nanonewtons".into(),
        y_label: "force (N)".into(),
        y_scale: Scale::Log10,
        bars: vec![
            bar("macro", "brick weight", s.lift_weight_n[0].abs(), BLUE),
            bar("macro", "carry inertia", s.lift_inertia_n[0], BLUE),
            bar(
                "macro",
                "peak (house task)",
                s.macro_house.peak_world_force_n,
                BLUE,
            ),
            bar("nano", "snap", s.hysteresis.snap_force_n, ORANGE),
            bar("nano", "pull-off", s.hysteresis.pull_off_n, ORANGE),
            bar("nano", "atom weight", atom_weight, ORANGE),
            bar("nano", "atom inertia (throw)", s.atom_inertia_n, ORANGE),
        ],
    };
    save(dir, "scale_forces.png", w, &forces, files)?;
    let sizes = BarChart {
        title: "Sizes in the two worlds (log scale): metres against nanometres".into(),
        y_label: "size (m)".into(),
        y_scale: Scale::Log10,
        bars: s
            .sizes_m
            .iter()
            .enumerate()
            .map(|(i, (l, v))| {
                bar(
                    if i < 2 { "macro" } else { "nano" },
                    l,
                    *v,
                    if i < 2 { BLUE } else { ORANGE },
                )
            })
            .collect(),
    };
    save(dir, "scale_sizes.png", w, &sizes, files)?;
    Ok(())
}

/// Force over time of a house task (vertical and magnitude, × `unit`) with its events marked.
fn house_chart(title: &str, y_label: &str, r: &Run, unit: f64, events: EventMarks) -> Chart {
    let mut c = Chart::new(title, "time (s)", y_label);
    c.series = vec![
        series(
            "vertical force Fz",
            force_curve(r, 2, unit),
            BLUE,
            Style::Line,
        ),
        series("|F|", force_norm(r, unit), ORANGE, Style::Line),
    ];
    c.markers = markers(r, events);
    c
}

fn lift_markers() -> Vec<Marker> {
    let (_, t) = crate::scripts::brick_lift(&[]);
    [
        (t[0], "grab", GREEN),
        (t[1], "lifted", GREY),
        (t[2], "carry", GREY),
        (t[3], "stop", GREY),
    ]
    .into_iter()
    .map(|(x, l, c)| Marker {
        x,
        label: l.to_string(),
        color: c,
    })
    .collect()
}

fn house_row(name: &str, h: &measure::HouseOutcome, slots: &str, unit: f64, u: &str) -> String {
    format!(
        "| {name} | {} {slots} | {:.1} | {} | {:.2} s | {} | {} ({}) |\n",
        h.filled,
        h.score,
        h.dropped,
        h.comfort_exceeded_s,
        if h.complete_s >= 0.0 {
            format!("{:.2} s", h.complete_s)
        } else {
            "not complete".into()
        },
        si(h.peak_world_force_n * unit, u),
        si(h.peak_device_force_n, "N at the hand"),
    )
}

/// The report's text.
pub fn markdown(s: &LessonSummary) -> String {
    let mut m = String::new();
    md_house(&mut m, s);
    md_lift(&mut m, s);
    md_touch(&mut m, s);
    md_throw(&mut m, s);
    md_scale(&mut m);
    m
}

/// The title and the house task in both worlds.
fn md_house(m: &mut String, s: &LessonSummary) {
    let _ = writeln!(
        *m,
        "# Building a house twice: bricks and atoms\n\n\
         A lesson from the haptic teaching game. The same operator (a rigid stylus playing each \
         world's house script) builds a small wall of bricks in the macro world and a house of \
         atoms with an AFM tip in the nano world; then a few short experiments show what the \
         hand feels in each. Every number below was measured from these runs \
         (`nanohaptics lesson`); `lesson.json` holds them all, and the two house sessions are \
         recordings (`macro_house.mcap`, `nano_house.mcap`) that Foxglove opens and \
         `nanohaptics replay --verify` recomputes bit for bit.\n"
    );
    let _ = writeln!(
        *m,
        "## The house task in both worlds\n\n\
         | world | slots filled | score | dropped | force above comfort | complete at | peak force |\n\
         |---|---|---|---|---|---|---|"
    );
    m.push_str(&house_row("bricks", &s.macro_house, "of 4", 1.0, "N"));
    m.push_str(&house_row("atoms", &s.nano_house, "of 7", 1e9, "nN"));
    let _ = writeln!(
        *m,
        "\nScore = 100 × filled / slots − 10 per dropped brick or atom − 5 per second the hand \
         felt more than half the device's largest force (4 N on a Falcon); never below 0.\n\n\
         Listen: [bricks](macro_house.wav), [atoms](nano_house.wav) — a thud or a clack per \
         collision (louder for a larger impulse), a click at each snap and a pop at each \
         pull-off, and a tone that rises as the cursor nears the nearest object (the aid the \
         paper gave blind students).\n\n\
         ![force over time, macro world](macro_forces.png)\n\n\
         ![force over time, nano world](nano_forces.png)\n\n\
         In the macro world the hand feels the brick's **weight** while carrying it and a push \
         when the brick meets the ground; in the nano world it feels the **attraction** before \
         contact, the **snap** into contact, and the much larger **pull-off** when it leaves: \
         atoms stick, and the tip has to tear itself away.\n"
    );
}

/// Lifting a brick: weight and inertia.
fn md_lift(m: &mut String, s: &LessonSummary) {
    let _ = writeln!(
        *m,
        "## Lifting a brick: weight and inertia\n\n\
         Holding the {} kg brick still, the hand feels {} downwards (M g = {}). Carrying it \
         0.45 m sideways in 0.9 s, it feels up to {} sideways: the brick's inertia −M a \
         (predicted for this minimum-jerk move of the hand: {}). The brick hangs in the hand on \
         a spring the device can hold (the virtual coupling), so it lags the hand and swings \
         a little past it: its peak is {:.0} % above the hand's.\n\n\
         The same hand motion with the paper's menu switches:\n\n\
         | run | weight felt | peak inertial force |\n|---|---|---|\n\
         | normal | {} | {} |\n| gravity off | {} | {} |\n| inertia off | {} | {} |\n\n\
         ![vertical force while lifting](lift_weight.png)\n\n![sideways force while carrying](lift_inertia.png)\n",
        s.brick_mass_kg,
        si(-s.lift_weight_n[0], "N"),
        si(s.brick_mass_kg * s.gravity_m_per_s2, "N"),
        si(s.lift_inertia_n[0], "N"),
        si(s.lift_inertia_predicted_n, "N"),
        100.0 * (s.lift_inertia_n[0] / s.lift_inertia_predicted_n - 1.0),
        si(-s.lift_weight_n[0], "N"),
        si(s.lift_inertia_n[0], "N"),
        si(-s.lift_weight_n[1], "N"),
        si(s.lift_inertia_n[1], "N"),
        si(-s.lift_weight_n[2], "N"),
        si(s.lift_inertia_n[2], "N"),
    );
}

/// Touching an atom: snap-to-contact and the tenfold pull-off.
fn md_touch(m: &mut String, s: &LessonSummary) {
    let h = &s.hysteresis;
    let hh = &s.hysteresis_half;
    let _ = writeln!(
        *m,
        "## Touching an atom: snap-to-contact and the tenfold pull-off\n\n\
         The tip comes down over one substrate atom and goes back up. It is pulled in before it \
         touches, **snaps** into contact at a cursor height of {} with a force of {}, and \
         stays stuck on the way up until the pull reaches **{}** at a cursor height of {}: \
         {:.2} times the snap force. Going down and coming up do not follow the same curve \
         (hysteresis).\n\n\
         With the adhesion halved (menu switch `adhesion_scale = 0.5`), the snap force is {} \
         and the pull-off {} — both half.\n\n![approach–retract hysteresis](hysteresis.png)\n",
        si(h.snap_height_m, "m"),
        si(h.snap_force_n, "N"),
        si(h.pull_off_n, "N"),
        si(h.pull_off_height_m, "m"),
        h.ratio,
        si(hh.snap_force_n, "N"),
        si(hh.pull_off_n, "N"),
    );
}

/// Throwing a brick and an atom, and the threshold.
fn md_throw(m: &mut String, s: &LessonSummary) {
    let t = &s.brick_throw;
    let sw = &s.sweep;
    let _ = writeln!(
        *m,
        "## Throwing\n\n\
         **A brick flies.** Swinging the hand 30 mm in 0.3 s (a peak hand acceleration of {}) \
         and letting go at the fastest point, the brick leaves at {} and lands {} away after \
         {:.2} s{}.\n\n\
         **An atom stays.** The same hand motion in the nano world with an atom on the tip: the \
         atom {}. Its inertia is {} and its weight {}, while the tip holds it with {} \
         (the tip–atom pull-off force): {} times more than both. To throw it off, the hand \
         would have to accelerate at {} — adhesion beats inertia at this scale.\n\n\
         **The threshold, shown.** Make the atom {} kg ({} times heavier) and switch gravity \
         off, and the threshold comes within reach: predicted {} of hand acceleration \
         (hold / mass / workspace scale). In {} throws, the atom stayed on up to {} and left \
         the tip from {}.\n\n![throw threshold](throw_threshold.png)\n",
        si(s.throw_hand_m_per_s2, "m/s²"),
        si(t.release_speed_m_per_s, "m/s"),
        si(t.distance_m, "m"),
        t.flight_s,
        if t.thrown {
            " (a throw, in the world's terms)"
        } else {
            ""
        },
        if s.atom_stayed {
            "stayed on the tip"
        } else {
            "left the tip"
        },
        si(s.atom_inertia_n, "N"),
        si(s.atom_mass_kg * 9.81, "N"),
        si(s.atom_hold_n, "N"),
        fmt_sig(s.atom_hold_n / s.atom_load_n, 2),
        si(s.atom_threshold_hand_m_per_s2, "m/s²"),
        fmt_num(sw.mass_kg),
        fmt_sig(sw.mass_kg / s.atom_mass_kg, 1),
        si(sw.predicted_hand_m_per_s2, "m/s²"),
        sw.runs.len(),
        si(sw.kept_below_m_per_s2, "m/s²"),
        si(sw.thrown_from_m_per_s2, "m/s²"),
    );
}

/// The two worlds' scales.
fn md_scale(m: &mut String) {
    let _ = writeln!(
        *m,
        "## Scale\n\nThe forces of the two worlds are nine to ten orders of magnitude apart, and \
         so are their sizes; the device maps both onto the same few newtons and centimetres of \
         the hand.\n\n![forces](scale_forces.png)\n\n![sizes](scale_sizes.png)\n"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn si_prefixes() {
        assert_eq!(si(4.905, "N"), "4.91 N");
        assert_eq!(si(3e-9, "N"), "3.00 nN");
        assert_eq!(si(2.5e-10, "N"), "0.25 nN");
        assert_eq!(si(1e-24, "N"), "1.00e-24 N");
        assert_eq!(si(-0.45, "m"), "-450 mN".replace("mN", "mm"));
        assert_eq!(si(0.0, "N"), "0 N");
    }
}
