//! `nanohaptics-fuzz`: a mutation fuzzer on stable Rust for nanohaptics' input surfaces.
//!
//! ```text
//! nanohaptics-fuzz --target T [--inputs N] [--seconds S] [--seed N] [--batch B]
//!                  [--timeout-ms M] [--findings DIR] [--json]
//! nanohaptics-fuzz --target T --seed N --replay-index I     (one input, in this process)
//! nanohaptics-fuzz --target T --run-file FILE               (one input from a file)
//! nanohaptics-fuzz --ci [--seconds S]  (every target: a fixed input count each, or S seconds each)
//! nanohaptics-fuzz --all --inputs N [--seed N]  (every target, N inputs each: a campaign)
//! ```
//!
//! Targets: `scene`, `script` (the TOML parsers and what the parsed files drive), `recording`
//! (the MCAP reader, strict and salvage), `verify` (reader + bit-exact verifier, with changed
//! bytes and changed messages), `bridge` (device-bridge packets and the samples and device
//! specifications they carry, into the loop), `cli` (the `nanohaptics` program's options, one
//! process per input).
//!
//! Input `i` of a campaign is a seed input with 1–4 mutations (1–2 for `cli`) drawn from a
//! generator seeded by `(seed, i)`, so any input is regenerated alone. The inputs run in batches in child processes
//! (`--worker`): a panic is caught per input (`catch_unwind`); a hang (an input over the time
//! limit) is reported by the child's watchdog, which then exits; an abort kills the child, and
//! the batch is re-run one input per process to name the culprit. Every finding's input is
//! written to the findings folder. Exit status: 0 when there are no findings, 1 otherwise.

use nanohaptics_fuzz::targets;

use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Command, ExitCode, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use targets::{Outcome, TARGETS, Target};

#[derive(Clone, Debug)]
struct Args {
    target: Option<String>,
    inputs: u64,
    seconds: Option<f64>,
    seed: u64,
    batch: u64,
    timeout_ms: u64,
    findings: PathBuf,
    json: bool,
    worker: bool,
    start: u64,
    replay_index: Option<u64>,
    run_file: Option<PathBuf>,
    /// `--ci`: every target, a fixed input count each (seed 1 unless `--seed`).
    ci: bool,
    /// `--write-seeds DIR`: write the seed corpora and stop.
    write_seeds: Option<PathBuf>,
}

fn usage() -> String {
    format!(
        "usage: nanohaptics-fuzz --target T [--inputs N] [--seconds S] [--seed N] [--batch B] \
         [--timeout-ms M] [--findings DIR] [--json]\n       nanohaptics-fuzz --ci \
         [--seconds S]\n       nanohaptics-fuzz --all [--inputs N]\n       nanohaptics-fuzz \
         --write-seeds DIR\n       nanohaptics-fuzz --target T --seed N --replay-index I | \
         --run-file FILE\ntargets: {}",
        TARGETS.join(", ")
    )
}

fn parse_args() -> Result<Args, String> {
    parse_args_from(std::env::args().skip(1))
}

/// The arguments `args` (without the program's name) as [`Args`], with the defaults for what
/// they do not set.
fn parse_args_from(args: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        target: None,
        inputs: u64::MAX,
        seconds: None,
        seed: 1,
        batch: 500,
        timeout_ms: 10_000,
        findings: PathBuf::from("target/fuzz-findings"),
        json: false,
        worker: false,
        start: 0,
        replay_index: None,
        run_file: None,
        ci: false,
        write_seeds: None,
    };
    let mut it = args;
    while let Some(f) = it.next() {
        let mut val = |name: &str| {
            it.next()
                .ok_or_else(|| format!("{name} needs a value\n{}", usage()))
        };
        let num = |name: &str, v: String| {
            v.parse::<u64>()
                .map_err(|_| format!("{name} = `{v}`: expected a whole number ≥ 0"))
        };
        match f.as_str() {
            "--target" => a.target = Some(val("--target")?),
            "--inputs" => a.inputs = num("--inputs", val("--inputs")?)?,
            "--seconds" => {
                let v = val("--seconds")?;
                let s: f64 = v
                    .parse()
                    .ok()
                    .filter(|s: &f64| s.is_finite() && *s > 0.0)
                    .ok_or_else(|| format!("--seconds = `{v}`: expected a positive number"))?;
                a.seconds = Some(s);
            }
            "--seed" => a.seed = num("--seed", val("--seed")?)?,
            "--batch" => a.batch = num("--batch", val("--batch")?)?.max(1),
            "--timeout-ms" => a.timeout_ms = num("--timeout-ms", val("--timeout-ms")?)?.max(1),
            "--findings" => a.findings = PathBuf::from(val("--findings")?),
            "--start" => a.start = num("--start", val("--start")?)?,
            "--replay-index" => {
                a.replay_index = Some(num("--replay-index", val("--replay-index")?)?)
            }
            "--run-file" => a.run_file = Some(PathBuf::from(val("--run-file")?)),
            "--json" => a.json = true,
            "--worker" => a.worker = true,
            "--ci" => a.ci = true,
            // `--all`: every target, like `--ci` (a campaign gives --inputs or --seconds).
            "--all" => a.ci = true,
            "--write-seeds" => a.write_seeds = Some(PathBuf::from(val("--write-seeds")?)),
            "-h" | "--help" => return Err(usage()),
            other => return Err(format!("unknown option `{other}`\n{}", usage())),
        }
    }
    if !a.ci && a.target.is_none() && a.write_seeds.is_none() {
        return Err(format!("give --target or --ci\n{}", usage()));
    }
    if a.inputs == u64::MAX && a.seconds.is_none() && !a.ci {
        a.inputs = 10_000;
    }
    Ok(a)
}

/// The message of the last panic (the hook keeps it instead of printing it).
static PANIC: Mutex<String> = Mutex::new(String::new());

fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        if let Ok(mut p) = PANIC.lock() {
            *p = format!("{msg}{at}");
        }
    }));
}

/// Runs one input, a panic caught and turned into a finding.
fn run_one(t: &Target, input: &[u8], index: u64) -> Outcome {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| t.run(input, index))) {
        Ok(o) => o,
        Err(_) => Outcome::Finding("panic", PANIC.lock().map(|p| p.clone()).unwrap_or_default()),
    }
}

fn one_line(s: &str) -> String {
    s.replace(['\n', '\t', '\r'], " ")
}

/// Child process: runs inputs `start..start+inputs` (or until `seconds` pass), printing one
/// line per finding and a closing count line. A watchdog thread ends the process on a hang.
fn worker(a: &Args) -> Result<ExitCode, String> {
    let target = a.target.clone().unwrap_or_default();
    let t = Target::new(&target, Duration::from_millis(a.timeout_ms))?;
    println!("S");
    quiet_panics();
    let t0 = Instant::now();
    let current = std::sync::Arc::new(AtomicU64::new(u64::MAX));
    let started_ms = std::sync::Arc::new(AtomicU64::new(0));
    let counts = std::sync::Arc::new([AtomicU64::new(0), AtomicU64::new(0)]);
    {
        let (current, started_ms, counts) = (current.clone(), started_ms.clone(), counts.clone());
        let limit = a.timeout_ms;
        std::thread::spawn(move || {
            loop {
                std::thread::sleep(Duration::from_millis(20));
                let i = current.load(Ordering::Acquire);
                let now = t0.elapsed().as_millis() as u64;
                let since = now.saturating_sub(started_ms.load(Ordering::Acquire));
                if i != u64::MAX && since > limit {
                    println!(
                        "H\t{i}\t{}\t{}\t{since}",
                        counts[0].load(Ordering::Relaxed),
                        counts[1].load(Ordering::Relaxed)
                    );
                    let _ = std::io::stdout().flush();
                    std::process::exit(3);
                }
            }
        });
    }
    let deadline = a.seconds.map(|s| t0 + Duration::from_secs_f64(s));
    let mut done = 0u64;
    for i in a.start..a.start.saturating_add(a.inputs) {
        if deadline.is_some_and(|d| Instant::now() >= d) {
            break;
        }
        let input = t.input(a.seed, i);
        started_ms.store(t0.elapsed().as_millis() as u64, Ordering::Release);
        current.store(i, Ordering::Release);
        let o = run_one(&t, &input, i);
        current.store(u64::MAX, Ordering::Release);
        match o {
            Outcome::Accepted => counts[0].fetch_add(1, Ordering::Relaxed),
            Outcome::Refused => counts[1].fetch_add(1, Ordering::Relaxed),
            Outcome::Finding(kind, detail) => {
                println!("F\t{i}\t{kind}\t{}", one_line(&detail));
                0
            }
        };
        done += 1;
    }
    let _ = std::fs::remove_dir_all(targets::work_dir());
    println!(
        "D\t{done}\t{}\t{}",
        counts[0].load(Ordering::Relaxed),
        counts[1].load(Ordering::Relaxed)
    );
    Ok(ExitCode::SUCCESS)
}

#[derive(Default, Debug)]
struct Tally {
    inputs: u64,
    accepted: u64,
    refused: u64,
    /// `(kind, index, detail)`.
    findings: Vec<(String, u64, String)>,
}

impl Tally {
    fn count(&self, kind: &str) -> usize {
        self.findings.iter().filter(|f| f.0 == kind).count()
    }
}

enum BatchEnd {
    Done,
    Hang(u64),
    Crashed(String),
}

/// Runs a batch in a child process; returns how it ended and adds what it reported.
fn run_batch(
    a: &Args,
    target: &str,
    start: u64,
    count: u64,
    seconds: Option<f64>,
    tally: &mut Tally,
) -> Result<BatchEnd, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut cmd = Command::new(exe);
    cmd.args(["--worker", "--target", target])
        .args(["--seed", &a.seed.to_string()])
        .args(["--start", &start.to_string()])
        .args(["--inputs", &count.to_string()])
        .args(["--timeout-ms", &a.timeout_ms.to_string()]);
    if let Some(s) = seconds {
        cmd.args(["--seconds", &s.to_string()]);
    }
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start a worker: {e}"))?;
    let out = child.stdout.take().ok_or("no worker output")?;
    let mut end = None;
    let mut started = false;
    for line in BufReader::new(out).lines() {
        let line = line.map_err(|e| e.to_string())?;
        let f: Vec<&str> = line.splitn(5, '\t').collect();
        let n = |k: usize| f.get(k).and_then(|x| x.parse::<u64>().ok()).unwrap_or(0);
        match f.first().copied() {
            Some("S") => started = true,
            Some("F") => {
                tally.findings.push((
                    f.get(2).unwrap_or(&"").to_string(),
                    n(1),
                    f.get(3).unwrap_or(&"").to_string(),
                ));
            }
            Some("D") => {
                tally.inputs += n(1);
                tally.accepted += n(2);
                tally.refused += n(3);
                end = Some(BatchEnd::Done);
            }
            Some("H") => {
                let i = n(1);
                tally.inputs += i - start + 1;
                tally.accepted += n(2);
                tally.refused += n(3);
                tally.findings.push((
                    "hang".into(),
                    i,
                    format!("over the {} ms limit", a.timeout_ms),
                ));
                end = Some(BatchEnd::Hang(i));
            }
            _ => {}
        }
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = std::io::Read::read_to_string(&mut e, &mut err);
    }
    if !started {
        return Err(format!(
            "{target}: the worker did not start: {}",
            err.lines().last().unwrap_or("(no message)")
        ));
    }
    Ok(match end {
        Some(e) => e,
        None => {
            use std::os::unix::process::ExitStatusExt;
            let how = match status.signal() {
                Some(s) => format!("killed by signal {s}"),
                None => format!("exit status {:?}", status.code()),
            };
            let last = err.lines().last().unwrap_or("").to_string();
            BatchEnd::Crashed(format!("{how}: {last}"))
        }
    })
}

fn save_finding(a: &Args, t: &Target, kind: &str, index: u64) -> Option<PathBuf> {
    let dir = a.findings.clone();
    std::fs::create_dir_all(&dir).ok()?;
    let p = dir.join(format!("{}-seed{}-{index}-{kind}.bin", t.name, a.seed));
    std::fs::write(&p, t.input(a.seed, index)).ok()?;
    Some(p)
}

/// Runs one target's campaign: batches in child processes, crashes narrowed input by input.
fn campaign(
    a: &Args,
    target: &str,
    inputs: u64,
    seconds: Option<f64>,
) -> Result<(Tally, f64), String> {
    let t0 = Instant::now();
    let deadline = seconds.map(|s| t0 + Duration::from_secs_f64(s));
    let mut tally = Tally::default();
    let mut next = 0u64;
    while next < inputs {
        let left = deadline.map(|d| d.saturating_duration_since(Instant::now()).as_secs_f64());
        if left.is_some_and(|l| l <= 0.0) {
            break;
        }
        let count = a.batch.min(inputs - next);
        let mark = tally.findings.len();
        match run_batch(a, target, next, count, left, &mut tally)? {
            BatchEnd::Done => next += count,
            BatchEnd::Hang(i) => next = i + 1,
            BatchEnd::Crashed(why) => {
                // Re-run the batch one input per process to name the culprit(s) (what the
                // crashed batch reported is reported again by those runs).
                tally.findings.truncate(mark);
                let before = tally.findings.len();
                for i in next..next + count {
                    match run_batch(a, target, i, 1, None, &mut tally)? {
                        BatchEnd::Crashed(w) => {
                            tally.inputs += 1;
                            tally.findings.push(("abort".into(), i, w));
                        }
                        BatchEnd::Done | BatchEnd::Hang(_) => {}
                    }
                }
                if tally.findings.len() == before {
                    // Not reproducible input by input: say so rather than lose it.
                    tally.findings.push((
                        "abort".into(),
                        next,
                        format!("batch {next}+{count}: {why}"),
                    ));
                }
                next += count;
            }
        }
    }
    Ok((tally, t0.elapsed().as_secs_f64()))
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

fn report(a: &Args, target: &str, tally: &Tally, wall_s: f64) -> serde_json::Value {
    let t = Target::new(target, Duration::from_millis(a.timeout_ms)).ok();
    // The first five findings of each kind are listed (and their inputs saved); all are counted.
    let mut shown: std::collections::BTreeMap<&str, usize> = std::collections::BTreeMap::new();
    let findings: Vec<serde_json::Value> = tally
        .findings
        .iter()
        .filter(|(kind, _, _)| {
            let n = shown.entry(kind.as_str()).or_default();
            *n += 1;
            *n <= 5
        })
        .map(|(kind, i, detail)| {
            let file = t.as_ref().and_then(|t| save_finding(a, t, kind, *i));
            let shown = t.as_ref().map(|t| t.show(&t.input(a.seed, *i)));
            serde_json::json!({"kind": kind, "index": i, "detail": detail,
                "input_file": file.map(|p| p.display().to_string()), "input": shown,
                "replay": format!("nanohaptics-fuzz --target {target} --seed {} --replay-index {i}", a.seed)})
        })
        .collect();
    serde_json::json!({
        "target": target, "seed": a.seed, "inputs": tally.inputs,
        "accepted": tally.accepted, "refused": tally.refused,
        "panics": tally.count("panic"), "aborts": tally.count("abort"), "hangs": tally.count("hang"),
        "non_finite": tally.count("non-finite") + tally.count("over-limit"),
        "other_findings": tally.findings.len() - tally.count("panic") - tally.count("abort")
            - tally.count("hang") - tally.count("non-finite") - tally.count("over-limit"),
        "wall_s": wall_s, "inputs_per_s": tally.inputs as f64 / wall_s.max(1e-9),
        "load": load(), "findings": findings,
    })
}

fn print_report(j: &serde_json::Value, json: bool) {
    if json {
        println!("{j}");
        return;
    }
    println!(
        "{:<10} {:>9} inputs ({} accepted, {} refused) in {:.1} s = {:.0}/s; panics {}, aborts {}, \
         hangs {}, non-finite {}, other {}; load {}",
        j["target"].as_str().unwrap_or(""),
        j["inputs"],
        j["accepted"],
        j["refused"],
        j["wall_s"].as_f64().unwrap_or(0.0),
        j["inputs_per_s"].as_f64().unwrap_or(0.0),
        j["panics"],
        j["aborts"],
        j["hangs"],
        j["non_finite"],
        j["other_findings"],
        j["load"].as_str().unwrap_or("")
    );
    for f in j["findings"].as_array().into_iter().flatten().take(20) {
        println!(
            "  {} #{}: {}\n    replay: {}\n    input: {}",
            f["kind"].as_str().unwrap_or(""),
            f["index"],
            f["detail"].as_str().unwrap_or(""),
            f["replay"].as_str().unwrap_or(""),
            f["input_file"].as_str().unwrap_or("(not saved)")
        );
    }
}

/// Inputs per target in `--ci` mode: inputs 0..N of seed 1, the same on every machine. Sized
/// so that the eight targets take about 16 s together on an idle core (docs/fuzzing.md).
fn ci_inputs(target: &str) -> u64 {
    match target {
        "scene" | "script" => 12_000,
        "recording" | "verify" => 6000,
        "bridge" => 60_000,
        "params" => 20_000,
        "page" => 100_000,
        "cli" => 1000,
        _ => 300,
    }
}

fn real_main() -> Result<ExitCode, String> {
    let a = parse_args()?;
    if a.worker {
        return worker(&a);
    }
    if let (Some(target), Some(i)) = (&a.target, a.replay_index) {
        let t = Target::new(target, Duration::from_millis(a.timeout_ms))?;
        let input = t.input(a.seed, i);
        println!("input {i}: {}", t.show(&input));
        let o = t.run(&input, i);
        println!("outcome: {o:?}");
        return Ok(ExitCode::SUCCESS);
    }
    if let (Some(target), Some(f)) = (&a.target, &a.run_file) {
        let t = Target::new(target, Duration::from_millis(a.timeout_ms))?;
        let input = std::fs::read(f).map_err(|e| format!("{}: {e}", f.display()))?;
        let o = t.run(&input, 1);
        println!("outcome: {o:?}");
        return Ok(ExitCode::SUCCESS);
    }
    if let Some(dir) = &a.write_seeds {
        return write_seeds(dir);
    }
    // --ci and --all run every target (--ci: a fixed input set each); --target, one.
    let list: Vec<String> = match (&a.target, a.ci) {
        (Some(t), false) => vec![t.clone()],
        _ => TARGETS.iter().map(|t| t.to_string()).collect(),
    };
    let mut any = false;
    let mut ran = Vec::new();
    for target in &list {
        // CI: a fixed number of inputs per target (the same inputs on every machine, at most
        // about 4 s each on an idle core), unless --inputs or --seconds is given.
        let inputs = match (a.ci, a.inputs, a.seconds) {
            (true, u64::MAX, None) => ci_inputs(target),
            (_, n, _) => n,
        };
        let (tally, wall) = campaign(&a, target, inputs, a.seconds)?;
        any |= !tally.findings.is_empty();
        // A fixed input set that did not run whole is a failure too.
        if a.seconds.is_none() && tally.inputs < inputs {
            eprintln!("{target}: ran {} of its {inputs} inputs", tally.inputs);
            any = true;
        }
        ran.push(format!("{target} {}", tally.inputs));
        let j = report(&a, target, &tally, wall);
        print_report(&j, a.json);
    }
    if list.len() > 1 && !a.json {
        println!(
            "inputs run, seed {}: {}; {}",
            a.seed,
            ran.join(", "),
            if any { "FAILED" } else { "no findings" }
        );
    }
    let _ = std::fs::remove_dir_all(targets::work_dir());
    Ok(if any {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

/// Writes every in-process target's seeds into `dir/<target>/seed-<k>`: the starting corpus of
/// the libFuzzer targets (`fuzz/`). The `verify` seeds carry the libFuzzer target's mode byte.
fn write_seeds(dir: &std::path::Path) -> Result<ExitCode, String> {
    for name in TARGETS.iter().filter(|t| **t != "cli") {
        let t = Target::new(name, Duration::from_secs(10))?;
        let d = dir.join(name);
        std::fs::create_dir_all(&d).map_err(|e| format!("{}: {e}", d.display()))?;
        let mut seeds: Vec<Vec<u8>> = t.seeds().to_vec();
        if *name == "verify" {
            // Even first byte: a change to the seed recording's outputs; odd: raw bytes.
            let raw: Vec<Vec<u8>> = seeds.iter().map(|s| [&[1u8][..], s].concat()).collect();
            seeds = vec![
                vec![0u8; 10],
                vec![0, 7, 0, 0, 0, 2, 0, 0, 0, 0],
                vec![2, 3, 0, 0, 0, 3],
            ];
            seeds.extend(raw);
        }
        for (k, s) in seeds.iter().enumerate() {
            let p = d.join(format!("seed-{k}"));
            std::fs::write(&p, s).map_err(|e| format!("{}: {e}", p.display()))?;
        }
        println!("{name}: {} seeds in {}", seeds.len(), d.display());
    }
    let _ = std::fs::remove_dir_all(targets::work_dir());
    Ok(ExitCode::SUCCESS)
}

fn main() -> ExitCode {
    match real_main() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    /// docs/fuzzing.md's table of `--ci` inputs per target is `ci_inputs`, for every target.
    #[test]
    fn the_ci_input_counts_are_the_ones_docs_fuzzing_md_lists() {
        let doc = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../docs/fuzzing.md"
        ))
        .expect("docs/fuzzing.md");
        let mut listed = Vec::new();
        for line in doc.lines().filter(|l| l.starts_with("| `")) {
            let cells: Vec<&str> = line.split('|').map(str::trim).collect();
            for pair in [(1, 2), (4, 5)] {
                if let (Some(t), Some(n)) = (cells.get(pair.0), cells.get(pair.1)) {
                    if let Ok(n) = n.replace(' ', "").parse::<u64>() {
                        listed.push((t.trim_matches('`').to_string(), n));
                    }
                }
            }
        }
        let mut want: Vec<(String, u64)> = super::TARGETS
            .iter()
            .map(|t| (t.to_string(), super::ci_inputs(t)))
            .collect();
        listed.sort();
        want.sort();
        assert_eq!(listed, want);
    }

    /// docs/fuzzing.md, "How it runs": batches of 500 inputs, a 10 s time limit per input
    /// (`--timeout-ms`), the `cli` target's process killed at 80 % of it, and 1–4 mutations per
    /// input (1–2 for `cli`).
    #[test]
    fn the_defaults_docs_fuzzing_md_states_are_the_codes() {
        let args = |v: &[&str]| super::parse_args_from(v.iter().map(|s| s.to_string()));
        let a = args(&["--target", "scene"]).unwrap();
        assert_eq!((a.batch, a.timeout_ms, a.inputs), (500, 10_000, 10_000));
        let a = args(&["--ci", "--batch", "7", "--timeout-ms", "250"]).unwrap();
        assert_eq!((a.batch, a.timeout_ms), (7, 250));
        assert!(args(&[]).unwrap_err().starts_with("give --target or --ci"));
        assert_eq!(nanohaptics_fuzz::targets::KILL_AT, 0.8);
        let most = nanohaptics_fuzz::targets::max_mutations;
        assert_eq!(
            (most("cli"), most("scene"), most("bridge"), most("page")),
            (2, 4, 4, 4)
        );
    }
}
