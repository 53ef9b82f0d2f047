//! `nanohaptics device-check`: a lab's device adapter checked against the bridge document
//! before its first session, rule by rule, with the figures.

use crate::status;
use haptic_devices::bridge::check::{CheckConfig, Report, run_check, stages};
use haptic_types::value::ValueError;
use world_form::fmt_num;

/// Arguments of `nanohaptics device-check`.
#[derive(clap::Args, Debug)]
pub(crate) struct DeviceCheckArgs {
    /// Where to listen for the device, as `run --device`: `udp:HOST:PORT` or `udp:PORT`
    /// (loopback). Point the device's adapter here, as for a session.
    address: String,
    /// The tick rate the welcome asks the device for, Hz (100–10000).
    #[arg(long, default_value_t = 1000)]
    rate: u32,
    /// How long to wait for the device's hello, s (0–86400, not 0).
    #[arg(long, default_value_t = 60.0)]
    wait_s: f64,
    /// Print the report as JSON (the progress lines are not printed).
    #[arg(long)]
    json: bool,
}

/// Runs the check; exits 0 when every rule holds, [`status::DIVERGED`] when one fails.
pub(crate) fn cmd(a: &DeviceCheckArgs) -> Result<u8, String> {
    let mut cfg = CheckConfig::parse(&a.address).map_err(|e| e.to_string())?;
    if !(100..=10_000).contains(&a.rate) {
        return Err(
            ValueError::out_of_range("--rate", f64::from(a.rate), "100–10000 Hz").to_string(),
        );
    }
    if !(a.wait_s.is_finite() && a.wait_s > 0.0 && a.wait_s <= 86_400.0) {
        return Err(ValueError::out_of_range("--wait-s", a.wait_s, "0 < s ≤ 86400").to_string());
    }
    cfg.rate_hz = a.rate;
    cfg.wait_s = a.wait_s;
    let json = a.json;
    if !json {
        eprintln!(
            "device-check: the sequence takes {} s after the welcome; follow the prompts",
            fmt_num(stages::total_s())
        );
    }
    let report: Report = run_check(&cfg, &mut |line| {
        if !json {
            eprintln!("device-check: {line}");
        }
    })
    .map_err(|e| e.to_string())?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).map_err(|e| e.to_string())?
        );
    } else {
        print!("{}", report.text());
    }
    Ok(if report.passed() {
        status::SUCCESS
    } else {
        status::DIVERGED
    })
}
