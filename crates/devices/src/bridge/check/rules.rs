//! The rules the simulator side can observe, each judged from what the check received: the
//! device's datagrams, their timing and the stylus positions they carry
//! (`docs/device-bridge.md`, "Checking your adapter before the first session", has the table).

use super::observed::{Observed, Received};
use super::stages::Stage;
use super::verdict::{RuleResult, Verdict};
use world_form::fmt_num;

/// Every rule, in the report's order: its name and the section of `docs/device-bridge.md`
/// that states it.
pub const RULES: [(&str, &str); 14] = [
    ("hello", "Protocol, version 1: hello"),
    (
        "hello.repeat",
        "Protocol, version 1: hello (repeat every 50 ms until welcomed)",
    ),
    (
        "packets",
        "Protocol, version 1: the version byte and size of each packet",
    ),
    (
        "sample.seq",
        "Protocol, version 1: sample (+1 per sample, from 0 after each hello)",
    ),
    (
        "sample.rate",
        "Protocol, version 1: welcome (send one sample per tick)",
    ),
    (
        "sample.buttons",
        "Protocol, version 1: hello (bit i of a sample is button i)",
    ),
    (
        "sample.two_port",
        "Protocol, version 2: sample (the two-port count since the hello)",
    ),
    (
        "render.planes",
        "What a device renders between answers, rule 3 (the planes)",
    ),
    (
        "render.body",
        "What a device renders between answers, rules 1–3 and the body",
    ),
    (
        "loss.samples",
        "The device's samples are the clock (one per tick, whatever is lost)",
    ),
    (
        "loss.body",
        "What a device renders between answers, rule 2 (answers whenever they arrive)",
    ),
    (
        "silence.samples",
        "The device's samples are the clock (one per tick, whatever is lost)",
    ),
    (
        "silence.resume",
        "What a device renders between answers, rule 2 and the hold time",
    ),
    ("bye", "Protocol, version 1: bye"),
];

/// The stages over which the device's own rate is measured, and their length, s.
const RATE_STAGES: [Stage; 3] = [Stage::Handshake, Stage::Wall, Stage::Brick];

/// Largest relative error of the sample rate against the welcome's.
pub const RATE_TOLERANCE: f64 = 0.05;

/// Largest relative change of the sample rate in the loss and silence stages against the
/// device's own rate before them.
pub const CONTINUE_TOLERANCE: f64 = 0.1;

/// Shortest and longest interval of the hello's repeat accepted, s (the document: 50 ms).
pub const HELLO_REPEAT_S: (f64, f64) = (0.02, 0.2);

/// Share of the samples that may be skipped in the numbering (lost in transit), of all.
pub const SKIP_TOLERANCE: f64 = 0.01;

/// Longest the device may go on sending after the check's bye, s.
pub const BYE_STOP_S: f64 = 0.5;

/// How long after the resume begins the brick is judged again, s (the engagement's ramp and
/// the hand's return).
pub const RESUME_SETTLE_S: f64 = 0.5;

/// How long after the brick stage begins the brick is judged, s: the stylus starts the stage
/// where the wall left it, so a device that failed the wall is not failed twice for it.
pub const BRICK_SETTLE_S: f64 = 0.25;

fn mm(x: f64) -> String {
    format!("{} mm", fmt_num((x * 1e5).round() / 100.0))
}

struct Judge<'a> {
    obs: &'a Observed,
    out: Vec<RuleResult>,
}

impl Judge<'_> {
    fn push(
        &mut self,
        rule: &'static str,
        pass: bool,
        figure: String,
        bound: String,
        value: Option<f64>,
    ) {
        self.push_verdict(
            rule,
            if pass { Verdict::Pass } else { Verdict::Fail },
            figure,
            bound,
            value,
        );
    }

    fn push_verdict(
        &mut self,
        rule: &'static str,
        verdict: Verdict,
        figure: String,
        bound: String,
        value: Option<f64>,
    ) {
        let section = RULES.iter().find(|r| r.0 == rule).map_or("", |r| r.1);
        self.out.push(RuleResult {
            rule,
            section,
            verdict,
            figure,
            bound,
            value,
        });
    }

    fn in_stage(&self, stage: Stage) -> impl Iterator<Item = &Received> {
        self.obs
            .samples
            .iter()
            .filter(move |s| s.stage == Some(stage))
    }

    /// Samples per second that arrived in `stages`, Hz.
    fn rate(&self, stages: &[Stage]) -> f64 {
        let n = self
            .obs
            .samples
            .iter()
            .filter(|s| s.stage.is_some_and(|x| stages.contains(&x)))
            .count();
        let d: f64 = stages.iter().map(|s| s.span_s().1 - s.span_s().0).sum();
        n as f64 / d
    }
}

/// Judges `obs` by every rule, in the order of [`RULES`].
pub fn judge(obs: &Observed) -> Vec<RuleResult> {
    let mut j = Judge {
        obs,
        out: Vec::with_capacity(RULES.len()),
    };
    let Some(hello) = &obs.hello else {
        let (figure, bound) = match &obs.refused {
            Some(r) => (r.message.clone(), r.allowed.clone()),
            None => ("no hello".into(), "a hello".into()),
        };
        j.push("hello", false, figure, bound, None);
        for (rule, _) in &RULES[1..] {
            j.push_verdict(
                rule,
                Verdict::NotApplicable,
                "not run: the hello was refused".into(),
                "a welcomed session".into(),
                None,
            );
        }
        return j.out;
    };
    let specs = &hello.specs;
    j.push(
        "hello",
        true,
        format!(
            "`{}`, version {} (session {}), {} N, {} N/m, {} m, {} buttons",
            specs.name,
            hello.version,
            obs.version,
            fmt_num(specs.limits.max_force_n),
            fmt_num(specs.limits.max_stiffness_n_per_m),
            fmt_num(specs.workspace_radius_m),
            specs.button_names.len()
        ),
        "every field in the document's range (the simulator's own checks)".into(),
        Some(f64::from(hello.version)),
    );
    hello_repeat(&mut j);
    packets(&mut j);
    numbering(&mut j);
    let base = rate(&mut j);
    buttons(&mut j, specs.button_names.len());
    two_port(&mut j);
    let f_max = specs.limits.max_force_n;
    let wall = f_max / obs.wall_n_per_m;
    let brick = f_max / obs.coupling_n_per_m;
    depth(
        &mut j,
        "render.planes",
        Stage::Wall,
        0.0,
        wall,
        "wall",
        obs.wall_n_per_m,
        true,
    );
    depth(
        &mut j,
        "render.body",
        Stage::Brick,
        BRICK_SETTLE_S,
        brick,
        "brick's floor",
        obs.coupling_n_per_m,
        true,
    );
    continues(&mut j, "loss.samples", Stage::Loss, base);
    depth(
        &mut j,
        "loss.body",
        Stage::Loss,
        0.0,
        brick,
        "brick's floor",
        obs.coupling_n_per_m,
        false,
    );
    continues(&mut j, "silence.samples", Stage::Silence, base);
    depth(
        &mut j,
        "silence.resume",
        Stage::Resume,
        RESUME_SETTLE_S,
        brick,
        "brick's floor",
        obs.coupling_n_per_m,
        false,
    );
    bye(&mut j);
    j.out
}

fn hello_repeat(j: &mut Judge) {
    let (lo, hi) = HELLO_REPEAT_S;
    let bound = format!(
        "repeated every {}–{} ms until welcomed (the document: 50 ms)",
        fmt_num(lo * 1e3),
        fmt_num(hi * 1e3)
    );
    match j.obs.hello_repeat_s {
        Some(i) => j.push(
            "hello.repeat",
            (lo..=hi).contains(&i),
            format!(
                "the unanswered hello repeated after {} ms",
                fmt_num((i * 1e4).round() / 10.0)
            ),
            bound,
            Some(i),
        ),
        None => j.push(
            "hello.repeat",
            false,
            format!(
                "the unanswered hello was not repeated within {} s",
                fmt_num(super::stages::HELLO_REPEAT_WAIT_S)
            ),
            bound,
            None,
        ),
    }
}

fn packets(j: &mut Judge) {
    let o = j.obs;
    let mut figure = format!("{} datagrams, {} malformed", o.datagrams, o.malformed);
    if let Some(m) = &o.first_malformed {
        figure.push_str(&format!(" (the first: {m})"));
    }
    if o.over_cap > 0 {
        figure.push_str(&format!(
            "; {} samples past the check's {} not kept",
            o.over_cap,
            super::observed::MAX_SAMPLES
        ));
    }
    j.push(
        "packets",
        o.malformed == 0 && o.over_cap == 0 && o.datagrams > 0,
        figure,
        format!(
            "none malformed (samples of 52 bytes with version byte 1 or 56 with 2, byes of 9), \
             at most {} samples",
            super::observed::MAX_SAMPLES
        ),
        Some(o.malformed as f64),
    );
}

fn numbering(j: &mut Judge) {
    let (mut first_bad, mut backwards, mut repeated, mut skipped) = (0u64, 0u64, 0u64, 0u64);
    let mut first_seen = Vec::new();
    let mut prev: Option<(u32, u64)> = None;
    for s in &j.obs.samples {
        match prev {
            Some((h, p)) if h == s.hellos => {
                if s.seq == p {
                    repeated += 1;
                } else if s.seq < p {
                    backwards += 1;
                } else {
                    skipped += s.seq - p - 1;
                }
            }
            _ => {
                first_seen.push(s.seq);
                first_bad += u64::from(s.seq != 0);
            }
        }
        if prev.is_none_or(|(h, p)| h != s.hellos || s.seq > p) {
            prev = Some((s.hellos, s.seq));
        }
    }
    let n = j.obs.samples.len();
    let firsts: Vec<String> = first_seen.iter().map(|f| f.to_string()).collect();
    let faults = first_bad + backwards + repeated;
    j.push(
        "sample.seq",
        n > 0 && faults == 0 && (skipped as f64) <= SKIP_TOLERANCE * n as f64,
        format!(
            "{n} samples, the first numbered {} after the hello; {skipped} skipped, {repeated} \
             repeated, {backwards} backwards",
            if firsts.is_empty() {
                "-".into()
            } else {
                firsts.join(", ")
            }
        ),
        format!(
            "from 0 after each hello, +1 per sample; none repeated or backwards, at most {} % \
             skipped (lost in transit)",
            fmt_num(SKIP_TOLERANCE * 100.0)
        ),
        Some(faults as f64),
    );
}

/// The sample rate over the first stages against the welcome's; returns the rate measured.
fn rate(j: &mut Judge) -> f64 {
    let r = j.rate(&RATE_STAGES);
    let want = f64::from(j.obs.rate_hz);
    j.push(
        "sample.rate",
        ((r / want) - 1.0).abs() <= RATE_TOLERANCE,
        format!(
            "{} samples/s over the handshake, wall and brick",
            fmt_num(r.round())
        ),
        format!(
            "the welcome's {} Hz ± {} %",
            j.obs.rate_hz,
            fmt_num(RATE_TOLERANCE * 100.0)
        ),
        Some(r),
    );
    r
}

fn buttons(j: &mut Judge, n: usize) {
    let mask = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    let seen = j.obs.samples.iter().fold(0u32, |a, s| a | s.buttons);
    let bad = j
        .obs
        .samples
        .iter()
        .filter(|s| s.buttons & !mask != 0)
        .count();
    j.push(
        "sample.buttons",
        bad == 0,
        format!("bits seen {seen:#x}; {bad} samples with a bit the hello did not declare"),
        format!("only the {n} declared bits ({mask:#x})"),
        Some(bad as f64),
    );
}

fn two_port(j: &mut Judge) {
    let v2: Vec<&Received> = j
        .obs
        .samples
        .iter()
        .filter(|s| s.two_port_periods.is_some())
        .collect();
    let bound = "never decreasing within a session (a count since the hello)".to_string();
    if v2.is_empty() {
        j.push_verdict(
            "sample.two_port",
            Verdict::NotApplicable,
            "no version-2 samples".into(),
            bound,
            None,
        );
        return;
    }
    let mut decreases = 0u64;
    for w in v2.windows(2) {
        if w[0].hellos == w[1].hellos
            && w[1].seq > w[0].seq
            && w[1].two_port_periods < w[0].two_port_periods
        {
            decreases += 1;
        }
    }
    let last = v2.last().and_then(|s| s.two_port_periods).unwrap_or(0);
    j.push(
        "sample.two_port",
        decreases == 0,
        format!(
            "{} version-2 samples, the count {last} at the end, {decreases} decreases",
            v2.len()
        ),
        bound,
        Some(f64::from(last)),
    );
}

/// The deepest the stylus went below the wall or floor in `stage` (from `settle_s` after its
/// start), against `bound_m`, the depth at which the device's maximum force meets the
/// stiffness `k`; `contact`: the stylus must have reached it.
#[allow(clippy::too_many_arguments)]
fn depth(
    j: &mut Judge,
    rule: &'static str,
    stage: Stage,
    settle_s: f64,
    bound_m: f64,
    what: &str,
    k: f64,
    contact: bool,
) {
    let from = stage.span_s().0 + settle_s;
    let Some(floor) = j.obs.floor_m else {
        j.push(
            rule,
            false,
            format!("the {} stage was not reached", stage.name()),
            String::new(),
            None,
        );
        return;
    };
    let depths: Vec<f64> = j
        .in_stage(stage)
        .filter(|s| s.t_s >= from)
        .map(|s| floor - s.position_m[2])
        .collect();
    let bound = format!(
        "{}≤ {} (the device's {} N against {} N/m)",
        if contact { "in contact, " } else { "" },
        mm(bound_m),
        fmt_num(
            j.obs
                .hello
                .as_ref()
                .map_or(0.0, |h| h.specs.limits.max_force_n)
        ),
        fmt_num(k)
    );
    let Some(deepest) = depths.iter().copied().reduce(f64::max) else {
        j.push(
            rule,
            false,
            format!("no samples in the {} stage", stage.name()),
            bound,
            None,
        );
        return;
    };
    let figure = if deepest > 0.0 {
        format!("deepest {} below the {what}", mm(deepest))
    } else {
        format!(
            "never reached the {what} (closest {} above it)",
            mm(-deepest)
        )
    };
    j.push(
        rule,
        deepest.is_finite() && deepest <= bound_m && (!contact || deepest > 0.0),
        figure,
        bound,
        Some(deepest),
    );
}

/// Samples go on in `stage` at the device's own rate `base` (Hz).
fn continues(j: &mut Judge, rule: &'static str, stage: Stage, base: f64) {
    let r = j.rate(&[stage]);
    let ratio = if base > 0.0 { r / base } else { 0.0 };
    j.push(
        rule,
        (ratio - 1.0).abs() <= CONTINUE_TOLERANCE,
        format!(
            "{} samples/s in the {} stage, {} % of the device's rate before it",
            fmt_num(r.round()),
            stage.name(),
            fmt_num((ratio * 1000.0).round() / 10.0)
        ),
        format!("100 ± {} %", fmt_num(CONTINUE_TOLERANCE * 100.0)),
        Some(ratio),
    );
}

fn bye(j: &mut Judge) {
    let o = j.obs;
    let last = o
        .samples
        .iter()
        .filter(|s| s.t_s > o.bye_s)
        .map(|s| s.t_s - o.bye_s)
        .reduce(f64::max);
    let own = match o.device_bye_s {
        Some(t) if t < o.bye_s => format!(
            "; the device said bye itself at {} s, before the end",
            fmt_num((t * 100.0).round() / 100.0)
        ),
        Some(_) => "; the device said bye too".into(),
        None => String::new(),
    };
    let early = o.device_bye_s.is_some_and(|t| t < o.bye_s);
    let figure = match last {
        Some(d) => format!(
            "the last sample {} ms after the check's bye{own}",
            fmt_num((d * 1e4).round() / 10.0)
        ),
        None => format!("no sample after the check's bye{own}"),
    };
    j.push(
        "bye",
        !early && last.unwrap_or(0.0) <= BYE_STOP_S,
        figure,
        format!(
            "samples stop within {} ms of the simulator's bye; no bye before the end",
            fmt_num(BYE_STOP_S * 1e3)
        ),
        Some(last.unwrap_or(0.0)),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bridge::check::observed::HelloSeen;

    /// What a welcomed Falcon that sent nothing but `over_cap` samples past the cap leaves.
    fn observed(over_cap: u64) -> Observed {
        Observed {
            bind: "127.0.0.1:9".parse().unwrap_or_else(|_| unreachable!()),
            hello: Some(HelloSeen {
                version: 2,
                rate_hz: 1000,
                specs: haptic_types::device::DeviceModel::Falcon.specs().clone(),
            }),
            refused: None,
            hello_repeat_s: Some(0.05),
            version: 2,
            rate_hz: 1000,
            samples: Vec::new(),
            datagrams: 10,
            malformed: 0,
            first_malformed: None,
            over_cap,
            answers_sent: 0,
            answers_dropped: 0,
            floor_m: None,
            wall_n_per_m: 3000.0,
            coupling_n_per_m: 1500.0,
            bye_s: 6.0,
            device_bye_s: None,
        }
    }

    #[test]
    fn a_flood_past_the_cap_fails_packets_and_says_so() {
        let packets = |o: &Observed| judge(o).into_iter().find(|r| r.rule == "packets");
        let ok = packets(&observed(0)).unwrap_or_else(|| unreachable!());
        assert_eq!(ok.verdict, Verdict::Pass);
        let r = packets(&observed(7)).unwrap_or_else(|| unreachable!());
        assert_eq!(r.verdict, Verdict::Fail);
        assert_eq!(
            r.figure,
            "10 datagrams, 0 malformed; 7 samples past the check's 150000 not kept"
        );
    }
}
