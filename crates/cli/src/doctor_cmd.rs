//! `nanohaptics doctor`: what this machine allows a tick thread — its real-time permissions,
//! its wake-up latency with and without real-time priority, the tick rates it can hold, and
//! what to change when it cannot.

use crate::status;
use haptic_engine::realtime::{self, Permissions, RtRequest};
use haptic_engine::wakeup::{self, Measurement, RATES_HZ, Verdict};
use haptic_types::value::ValueError;
use std::time::Duration;

/// Arguments of `nanohaptics doctor`.
#[derive(clap::Args, Debug)]
pub(crate) struct DoctorArgs {
    /// How long to measure, s (half at normal priority, half in real time), 0.1–3600.
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Time between wake-ups, µs (10–100000).
    #[arg(long, default_value_t = 500)]
    interval_us: u64,
    /// SCHED_FIFO priority of the real-time half, 1–99.
    #[arg(long, default_value_t = i64::from(realtime::DEFAULT_PRIORITY))]
    rt_priority: i64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

fn us(ns: u64) -> String {
    format!("{:.1} µs", ns as f64 / 1e3)
}

fn verdict_text(v: Verdict) -> String {
    match v {
        Verdict::Holds => "holds".into(),
        Verdict::Misses { per_minute } => format!("no: ~{per_minute:.1} late ticks a minute"),
    }
}

/// What to change, from what was measured and permitted.
fn advice(p: &Permissions, normal: &Measurement, rt: &Measurement) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(a) = rt.realtime.advice() {
        out.push(a);
    }
    let rt_holds = |hz| rt.verdict(hz) == Verdict::Holds;
    if RATES_HZ.iter().all(|&hz| rt_holds(hz)) {
        if rt.realtime.priority.is_some() {
            out.push(
                "every rate holds in real time: keep the default (sessions ask for it), and \
                 use --no-rt only to compare"
                    .into(),
            );
        }
    } else {
        if p.preemption != "PREEMPT_RT" {
            out.push(format!(
                "the kernel's preemption model is {}: a PREEMPT_RT kernel (or booting with \
                 preempt=full) removes the rare millisecond wake-ups a stock kernel has",
                p.preemption
            ));
        }
        if p.cores > 1 {
            out.push(
                "give the tick thread a core of its own: boot with isolcpus=N nohz_full=N \
                 rcu_nocbs=N for the last core (the tick thread pins itself to it)"
                    .into(),
            );
        }
        out.push(
            "turn off deep CPU idle states and frequency scaling (cpupower idle-set -D 10; \
             cpupower frequency-set -g performance); in a virtual machine, the host's \
             scheduling adds latency no guest setting removes"
                .into(),
        );
    }
    if normal.latency.max_ns > 0 && rt.realtime.priority.is_some() {
        let gain = normal.latency.p999_ns as f64 / rt.latency.p999_ns.max(1) as f64;
        if gain > 1.5 {
            out.push(format!(
                "real time cuts the p99.9 wake-up {gain:.1}-fold here: do not run sessions with \
                 --no-rt"
            ));
        }
    }
    out
}

/// Runs `nanohaptics doctor`.
pub(crate) fn cmd(a: &DoctorArgs) -> Result<u8, String> {
    check_args(a)?;
    let req = RtRequest {
        pin: true,
        ..RtRequest::with_priority(a.rt_priority).map_err(|e| format!("--{e}"))?
    };
    let p = realtime::permissions();
    let half = Duration::from_secs_f64(a.seconds / 2.0);
    let interval = Duration::from_micros(a.interval_us);
    if !a.json {
        println!(
            "nanohaptics doctor: wake-up latency for {:.1} s (half at normal priority, half in \
             real time), a wake-up every {} µs",
            a.seconds, a.interval_us
        );
    }
    let normal = wakeup::measure(interval, half, None).map_err(|e| e.to_string())?;
    let rt = wakeup::measure(interval, half, Some(req)).map_err(|e| e.to_string())?;
    let tips = advice(&p, &normal, &rt);
    if a.json {
        print_json(&p, &normal, &rt, &tips)?;
        return Ok(status::SUCCESS);
    }
    print_permissions(&p);
    println!();
    print_latency(&normal, &rt);
    println!();
    print_rates(&normal, &rt);
    if !tips.is_empty() {
        println!();
        for t in &tips {
            println!("  - {t}");
        }
    }
    Ok(status::SUCCESS)
}

/// The measuring time and the wake-up interval within their ranges.
fn check_args(a: &DoctorArgs) -> Result<(), String> {
    if !(a.seconds.is_finite() && (0.1..=3600.0).contains(&a.seconds)) {
        return Err(ValueError::out_of_range("--seconds", a.seconds, "0.1–3600 s").to_string());
    }
    if !(10..=100_000).contains(&a.interval_us) {
        return Err(ValueError::out_of_range(
            "--interval-us",
            a.interval_us as f64,
            "10–100000 µs",
        )
        .to_string());
    }
    Ok(())
}

/// The report as JSON: permissions, both measurements, the verdict per rate and the advice.
fn print_json(
    p: &Permissions,
    normal: &Measurement,
    rt: &Measurement,
    tips: &[String],
) -> Result<(), String> {
    let rates: Vec<serde_json::Value> = RATES_HZ
        .iter()
        .map(|&hz| {
            serde_json::json!({
                "rate_hz": hz,
                "normal": normal.verdict(hz),
                "realtime": rt.verdict(hz),
            })
        })
        .collect();
    let j = serde_json::json!({
        "permissions": p,
        "normal": normal,
        "realtime": rt,
        "rates": rates,
        "advice": tips,
    });
    println!(
        "{}",
        serde_json::to_string_pretty(&j).map_err(|e| e.to_string())?
    );
    Ok(())
}

/// The kernel and the real-time permissions.
fn print_permissions(p: &Permissions) {
    let opt = |v: Option<u64>| v.map_or("unlimited".to_string(), |x| x.to_string());
    println!(
        "  kernel {}, {} cores, real-time throttling {} µs of each second",
        p.preemption,
        p.cores,
        p.rt_runtime_us.map_or("unknown".into(), |v| v.to_string())
    );
    println!(
        "  CAP_SYS_NICE {}, RLIMIT_RTPRIO {}, CAP_IPC_LOCK {}, RLIMIT_MEMLOCK {} bytes",
        if p.cap_sys_nice { "yes" } else { "no" },
        opt(p.rlimit_rtprio),
        if p.cap_ipc_lock { "yes" } else { "no" },
        opt(p.rlimit_memlock_bytes)
    );
}

/// The wake-up latency table, at normal priority and in real time.
fn print_latency(normal: &Measurement, rt: &Measurement) {
    println!(
        "  {:<44} {:>8} {:>10} {:>10} {:>10} {:>10}",
        "scheduling", "wake-ups", "p50", "p99", "p99.9", "max"
    );
    for m in [normal, rt] {
        let l = &m.latency;
        println!(
            "  {:<44} {:>8} {:>10} {:>10} {:>10} {:>10}",
            m.realtime.describe(),
            m.samples,
            us(l.p50_ns),
            us(l.p99_ns),
            us(l.p999_ns),
            us(l.max_ns)
        );
    }
}

/// Which tick rates hold, at normal priority and in real time.
fn print_rates(normal: &Measurement, rt: &Measurement) {
    println!(
        "  {:<8} {:<10} {:<40} real time",
        "rate", "period", "normal priority"
    );
    for &hz in &RATES_HZ {
        println!(
            "  {:<8} {:<10} {:<40} {}",
            format!("{} kHz", hz / 1000),
            format!("{} µs", 1_000_000 / hz),
            verdict_text(normal.verdict(hz)),
            verdict_text(rt.verdict(hz))
        );
    }
    println!(
        "  (a rate holds when no wake-up took more than half its period; the other half is the \
         tick's work)"
    );
}
