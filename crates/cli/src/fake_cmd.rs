//! `nanohaptics fake-device`: a device in another process, over the UDP bridge, played by a
//! script through a simulated hand or a modelled device, with loss, jitter and outages.

use crate::run_cmd::parse_operator;
use crate::status;
use haptic_devices::bridge::fake::{FakeConfig, FakeReport, Fault, run_fake_as};
use haptic_devices::local::Protocol;
use haptic_devices::source::DeviceSource;
use haptic_devices::source::OperatorChoice;
use haptic_devices::{Grip, Mechanics, Script};
use haptic_types::value::{ValueError, out_of_range};
use haptic_types::{DeviceModel, DeviceSpecs};
use std::path::PathBuf;
use world_form::fmt_num;

#[derive(clap::Args)]
pub(crate) struct FakeArgs {
    /// The simulator's bridge address, `udp:HOST:PORT` or `udp:PORT` (loopback).
    target: String,
    /// Script file (TOML) the stylus plays, or a built-in script by name (`optical_tweezers`,
    /// or a built-in scene's name for its default script; default: the built-in wall press).
    #[arg(long)]
    script: Option<PathBuf>,
    /// Play the hand `nanohaptics device-check` asks for instead of a script: still for
    /// 0.6 s, then 8 mm down and held (with --grip, a modelled device held by that hand).
    #[arg(long, conflicts_with = "script")]
    check_hand: bool,
    /// `hand` (default: a simulated hand pushed by the force), `rigid`, or
    /// `hand:mass_kg=0.3,stiffness_n_per_m=300,...` (also spelled `--hand`).
    #[arg(long, alias = "hand", default_value = "hand")]
    operator: String,
    /// Device model: falcon, touch, delta3 or inverse3 (delta3 and inverse3 are always
    /// modelled devices; see --grip).
    #[arg(long, default_value = "falcon")]
    model: String,
    /// Play a modelled device (moving mass, encoder counts, force held over each period) held
    /// by a hand: `loose` (300 N/m, 2 N·s/m), `firm` (1000 N/m, 8 N·s/m) or
    /// `k=N/m,b=N·s/m[,m=kg]` (docs/devices.md). Replaces --operator.
    #[arg(long)]
    grip: Option<String>,
    /// With --grip: an ideal device (no encoder counts, no force resolution).
    #[arg(long)]
    ideal: bool,
    /// The bridge protocol a modelled device asks for: 4 (the default: it renders the
    /// simulator's local model, with a bond that breaks where the world's contact lets go and
    /// the optical tweezers' held particle stepped through its working envelope, at its own
    /// servo rate, behind the two-port passivity layer), 3 (without the particle, as the
    /// Python reference client), 2 (without the bond either, as the Python adapters) or 1 (the
    /// answered force and stiffness only; docs/device-bridge.md).
    #[arg(long, default_value_t = 4)]
    protocol: u8,
    /// Probability that a sample is lost, 0–1.
    #[arg(long, default_value_t = 0.0)]
    loss: f64,
    /// Extra delay of each sample, uniform in 0–J ms (samples may overtake each other).
    #[arg(long, default_value_t = 0.0)]
    jitter_ms: f64,
    /// Fixed delay of each sample, ms.
    #[arg(long, default_value_t = 0.0)]
    latency_ms: f64,
    /// Seed of the loss and jitter draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// How long to play, s (default: the script's duration).
    #[arg(long)]
    seconds: Option<f64>,
    /// Go silent from START s for SECONDS s, then come back (`--outage 1.0:0.05`).
    #[arg(long)]
    outage: Option<String>,
    /// How long to wait for the simulator's welcome, s.
    #[arg(long, default_value_t = 30.0)]
    wait_s: f64,
    /// Announce these button names in the hello instead of the model's, comma-separated
    /// (`--button-names a,b,c`: a device the simulator maps by index; docs/devices.md).
    #[arg(long)]
    button_names: Option<String>,
    /// Break one rule of the bridge document on purpose, to see `nanohaptics device-check`
    /// fail by rule: numbers-from-1, ignores-planes, backs-off-in-silence or half-rate
    /// (docs/device-bridge.md, "Checking your adapter before the first session").
    #[arg(long)]
    fault: Option<String>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The default script of `fake-device`: press the wall scene's surface, as its own script does.
const FAKE_SCRIPT: &str = include_str!("../../../scenes/wall.script.toml");

pub(crate) fn cmd(a: FakeArgs) -> Result<u8, String> {
    let (cfg, physical, names) = config(&a)?;
    if !a.json {
        eprintln!("fake-device: saying hello to {} ...", cfg.target);
    }
    let r = run_fake_as(&cfg, names.as_deref(), None).map_err(|e| e.to_string())?;
    if a.json {
        println!("{}", serde_json::json!(r));
    } else {
        print_report(&r, physical, a.ideal);
    }
    Ok(status::SUCCESS)
}

/// A flag's value checked against its range `lo`–`hi` in `unit` (empty for a plain number).
fn check(flag: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<f64, String> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        let allowed = format!("{}–{}{unit}", fmt_num(lo), fmt_num(hi));
        Err(ValueError::out_of_range(format!("--{flag}"), v, allowed).to_string())
    }
}

/// `--outage START:SECONDS`, each part checked.
fn outage(o: &str) -> Result<(f64, f64), String> {
    let bad = || format!("--outage `{o}`: expected START:SECONDS, e.g. 1.0:0.05");
    let (s, d) = o.split_once(':').ok_or_else(bad)?;
    let s: f64 = s.parse().map_err(|_| bad())?;
    let d: f64 = d.parse().map_err(|_| bad())?;
    Ok((
        check("outage start", s, 0.0, 86400.0, "s")?,
        check("outage seconds", d, 0.0, 86400.0, "s")?,
    ))
}

/// The modelled device and its grip (`--grip`, or a loose grip for a device that is only
/// ever modelled), `None` for an ideal stylus.
fn physical(a: &FakeArgs) -> Result<Option<(Mechanics, Grip)>, String> {
    let mech = Mechanics::preset(&a.model).map_err(|e| format!("--model: {e}"))?;
    let grip = match (&a.grip, DeviceModel::from_name(&a.model).is_ok()) {
        (Some(g), _) => Some(Grip::parse(g).map_err(|e| format!("--grip: {e}"))?),
        (None, false) => Some(Grip::LOOSE),
        (None, true) => None,
    };
    if a.ideal && grip.is_none() {
        return Err("--ideal needs --grip (it removes a modelled device's encoder counts)".into());
    }
    Ok(grip.map(|g| {
        let m = if a.ideal {
            mech.without_quantization()
        } else {
            mech
        };
        (m, g)
    }))
}

/// The script the stylus plays (`--script`, or the built-in wall press) on a device with
/// `specs` (its button events by role or by that device's button names), errors located.
fn script(a: &FakeArgs, specs: &DeviceSpecs) -> Result<Script, String> {
    let (text, origin) = match &a.script {
        _ if a.check_hand => (
            haptic_devices::bridge::check::stages::hand_script(),
            "device-check's hand".into(),
        ),
        // A file that is not there may name a built-in script, as `run` takes built-in scenes.
        Some(p) => match (
            p.exists(),
            haptic_loop::builtin::script(&p.to_string_lossy()),
        ) {
            (false, Some((file, text))) => (text.to_string(), format!("built-in {file}")),
            _ => (
                haptic_loop::session::read_toml_text(p).map_err(|e| format!("--script: {e}"))?,
                p.display().to_string(),
            ),
        },
        None => (
            FAKE_SCRIPT.to_string(),
            "built-in fake-device script".into(),
        ),
    };
    Script::from_toml(&text, specs).map_err(|e| {
        let at = haptic_types::textpos::Location {
            file: origin,
            at: e.position(&text),
        };
        format!("--script: {at}: {e}")
    })
}

/// The button names of `--button-names`, each checked as a hello checks them.
fn button_names(a: &FakeArgs) -> Result<Option<Vec<String>>, String> {
    let Some(list) = &a.button_names else {
        return Ok(None);
    };
    let names: Vec<String> = list
        .split(',')
        .map(|b| b.trim().to_string())
        .filter(|b| !b.is_empty())
        .collect();
    haptic_devices::bridge::fake::with_button_names(haptic_types::device::FALCON, &names)
        .validate()
        .map_err(|e| format!("--button-names: {e}"))?;
    Ok(Some(names))
}

/// The fake device's configuration from its flags, every value checked, with the button names
/// it announces instead of its model's (`--button-names`).
type Config = (FakeConfig, Option<(Mechanics, Grip)>, Option<Vec<String>>);

/// The fake device's configuration from its flags, every value checked.
fn config(a: &FakeArgs) -> Result<Config, String> {
    let target = match DeviceSource::parse(&a.target) {
        Ok(DeviceSource::Udp(b)) => b.bind,
        Ok(DeviceSource::Model(m)) => {
            return Err(format!(
                "`{}` is a device model: fake-device plays against the simulator's address, \
                 udp:HOST:PORT or udp:PORT (the model is --model {})",
                a.target,
                m.name()
            ));
        }
        Err(e) => return Err(e.to_string()),
    };
    let protocol = match Protocol::of_version(a.protocol) {
        Some(p) => p,
        None => return Err(out_of_range("--protocol", a.protocol, "1, 2, 3 or 4")),
    };
    let physical = physical(a)?;
    // Every device announces its own buttons (a modelled preset its preset's); the built-in
    // scripts bind their events by role, so each plays on every preset.
    let model = DeviceModel::from_name(&a.model).unwrap_or(DeviceModel::Falcon);
    let names = button_names(a)?;
    let base = match &physical {
        Some((mech, _)) => haptic_devices::modelled::preset_specs(mech),
        None => model.specs().clone(),
    };
    let specs = match &names {
        Some(n) => haptic_devices::bridge::fake::with_button_names(base, n),
        None => base,
    };
    let script = script(a, &specs)?;
    let hand = match parse_operator(&a.operator)? {
        OperatorChoice::Rigid => None,
        OperatorChoice::Hand(p) => Some(p),
        OperatorChoice::ScriptHand => Some(script.operator.unwrap_or_default()),
    };
    let loss = check("loss", a.loss, 0.0, 1.0, "(a probability)")?;
    let jitter = check("jitter-ms", a.jitter_ms, 0.0, 1000.0, "ms")?;
    let latency = check("latency-ms", a.latency_ms, 0.0, 1000.0, "ms")?;
    let outage = a.outage.as_deref().map(outage).transpose()?;
    if let Some(s) = a.seconds {
        // Up to a day: a soak plays for hours.
        check("seconds", s, 1e-3, 86400.0, "s")?;
    }
    let fault = a.fault.as_deref().map(Fault::parse).transpose()?;
    haptic_devices::bridge::fault::applies(fault, physical.is_some(), protocol)?;
    let cfg = FakeConfig {
        target,
        model,
        script,
        hand,
        physical,
        loss,
        jitter_s: jitter * 1e-3,
        latency_s: latency * 1e-3,
        seed: a.seed,
        seconds: a.seconds,
        outage,
        wait_s: check("wait-s", a.wait_s, 0.0, 86400.0, "s")?,
        bye: true,
        protocol,
        fault,
    };
    Ok((cfg, physical, names))
}

/// The report as text: periods, samples, round trips, forces and the work done on the hand.
fn print_report(r: &FakeReport, physical: Option<(Mechanics, Grip)>, ideal: bool) {
    println!(
        "fake-device: {} periods, {} samples sent, {} dropped (loss), {} silent (outage), {} replies",
        r.ticks, r.sent, r.dropped, r.silent, r.replies
    );
    if r.held_back > 0 {
        println!(
            "  {} periods sent no sample (the fault backs-off-in-silence)",
            r.held_back
        );
    }
    println!(
        "  round trip p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs; peak force {:.3} N (within limits: {})",
        r.round_trip.p50_ns as f64 / 1e3,
        r.round_trip.p99_ns as f64 / 1e3,
        r.round_trip.max_ns as f64 / 1e3,
        r.max_force_n,
        if r.forces_within_limits { "yes" } else { "NO" }
    );
    println!(
        "  force changes above 1 N between periods: {} (largest {:.3} N)",
        r.jumps_over_1n, r.max_jump_n
    );
    if let Some((m, g)) = physical {
        println!(
            "  modelled {} held {} ({} N/m, {} N·s/m){}: the motors did {:+.4} J of work on the hand, \
             the largest force they put on it {:.3} N",
            m.name,
            g.label(),
            g.stiffness_n_per_m,
            g.damping_n_s_per_m,
            if ideal { ", ideal sensing" } else { "" },
            r.energy_to_hand_j,
            r.max_felt_n
        );
        println!(
            "  protocol {}{}",
            r.protocol,
            if r.protocol >= 2 {
                format!(
                    ": the local model rendered at the device's servo rate; the two-port layer held the force back on {} servo periods",
                    r.two_port_interventions
                )
            } else {
                ": the answered force and stiffness".to_string()
            }
        );
    }
}
