//! `device-check` against the fake device: a modelled Falcon and delta.3 held by the check's
//! hand pass every rule; each deliberate fault fails the rule it breaks, and only the rules
//! that follow from it.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::bridge::check::{CheckConfig, Report, Verdict, run_check_on, stages};
use haptic_devices::bridge::fake::{FakeConfig, Fault, run_fake};
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics, Script};
use haptic_types::DeviceModel;
use std::net::UdpSocket;

/// Starts the check on a free loopback port, waiting `wait_s` (s) for the hello: its address
/// and the thread that returns its outcome.
fn start_check(
    wait_s: f64,
) -> (
    std::net::SocketAddr,
    std::thread::JoinHandle<Result<Report, haptic_devices::bridge::check::CheckError>>,
) {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = socket.local_addr().unwrap();
    let cfg = CheckConfig {
        wait_s,
        ..CheckConfig::parse(&format!("udp:{addr}")).unwrap()
    };
    (
        addr,
        std::thread::spawn(move || run_check_on(&socket, &cfg, &mut |_| {})),
    )
}

/// Runs the check on a loopback port against a modelled `mech` held by the check's hand with
/// `grip`, with `fault`; the report and the fake device's outcome.
fn check(mech: Mechanics, grip: Grip, fault: Option<Fault>) -> Report {
    let (addr, checker) = start_check(20.0);
    let specs = haptic_devices::modelled::preset_specs(&mech);
    let fake = FakeConfig {
        target: addr,
        model: DeviceModel::Falcon,
        script: Script::from_toml(&stages::hand_script(), &specs).unwrap(),
        hand: None,
        physical: Some((mech, grip)),
        loss: 0.0,
        jitter_s: 0.0,
        latency_s: 0.0,
        seed: 1,
        seconds: None,
        outage: None,
        wait_s: 20.0,
        bye: true,
        protocol: Protocol::V2,
        fault,
    };
    let device = run_fake(&fake, None).unwrap();
    let report = checker.join().unwrap().unwrap();
    // The check's bye ends the device long before its script's minute.
    assert!(
        (device.ticks as f64) < 10.0 * f64::from(device.welcome.rate_hz),
        "{} periods",
        device.ticks
    );
    report
}

fn failed(r: &Report) -> Vec<&'static str> {
    r.failed()
}

fn show(r: &Report) -> String {
    r.text()
}

#[test]
fn a_modelled_falcon_and_delta3_pass_every_rule_and_each_fault_fails_its_own() {
    // A device that follows the document.
    for (mech, grip) in [
        (Mechanics::FALCON, Grip::LOOSE),
        (Mechanics::DELTA3, Grip::FIRM),
    ] {
        let r = check(mech, grip, None);
        assert!(r.passed(), "{}", show(&r));
        assert_eq!(r.version, 2);
        assert_eq!(r.rules.len(), 14);
        assert!(
            r.rules.iter().all(|x| x.verdict == Verdict::Pass),
            "{}",
            show(&r)
        );
        // The wall held: in contact, and no deeper than the device's force against the wall's
        // stiffness (a hand of k pushing 6 mm through a wall of K sits 6 mm·k/(k+K) deep).
        let planes = r.rule("render.planes").unwrap().value.unwrap();
        let k = grip.stiffness_n_per_m;
        let wall = mech.limits.max_stiffness_n_per_m;
        let statics = 0.006 * k / (k + wall);
        assert!(
            planes > 0.5 * statics && planes < 2.0 * statics,
            "{}: {planes} m against the static {statics} m",
            mech.name
        );
        // About a fifth of the answers in the loss stage were dropped (1 s at 1 kHz).
        assert!(
            (150..=250).contains(&r.answers_dropped),
            "{}",
            r.answers_dropped
        );
    }

    // Each fault fails the rule it breaks.
    let r = check(Mechanics::FALCON, Grip::LOOSE, Some(Fault::NumbersFrom1));
    assert_eq!(failed(&r), ["sample.seq"], "{}", show(&r));
    let fig = &r.rule("sample.seq").unwrap().figure;
    assert!(
        fig.contains("the first numbered 1 after the hello"),
        "{fig}"
    );

    let r = check(Mechanics::FALCON, Grip::LOOSE, Some(Fault::HalfRate));
    assert_eq!(failed(&r), ["sample.rate"], "{}", show(&r));
    let rate = r.rule("sample.rate").unwrap().value.unwrap();
    assert!((480.0..=520.0).contains(&rate), "{rate}");

    let r = check(
        Mechanics::FALCON,
        Grip::LOOSE,
        Some(Fault::BacksOffInSilence),
    );
    assert_eq!(failed(&r), ["silence.samples"], "{}", show(&r));
    // It sent about a tenth of its samples once 100 ms had passed without an answer.
    let ratio = r.rule("silence.samples").unwrap().value.unwrap();
    assert!((0.2..=0.4).contains(&ratio), "{ratio}");

    // A device that ignores the planes goes through the wall to where the hand pushes it.
    let r = check(Mechanics::FALCON, Grip::LOOSE, Some(Fault::IgnoresPlanes));
    assert_eq!(failed(&r), ["render.planes"], "{}", show(&r));
    let depth = r.rule("render.planes").unwrap().value.unwrap();
    assert!((0.005..=0.0065).contains(&depth), "{depth}");
}

/// A hello the simulator cannot accept is answered with the refusal, and the report fails
/// `hello` with the simulator's words; no other rule is judged.
#[test]
fn a_refused_hello_fails_the_hello_rule_with_the_simulators_words() {
    use haptic_devices::bridge::protocol::Packet;
    let (addr, checker) = start_check(20.0);
    let mut specs = DeviceModel::Falcon.specs().clone();
    specs.limits.max_force_n = -1.0;
    let hello = Packet::Hello {
        version: 2,
        rate_hz: 1000,
        specs,
    }
    .encode();
    let device = UdpSocket::bind("127.0.0.1:0").unwrap();
    device
        .set_read_timeout(Some(std::time::Duration::from_secs(5)))
        .unwrap();
    device.send_to(&hello, addr).unwrap();
    let mut buf = [0u8; 2048];
    let (n, _) = device.recv_from(&mut buf).unwrap();
    let Ok(Packet::Refusal(refusal)) = Packet::decode(&buf[..n]) else {
        panic!("not a refusal: {:?}", &buf[..n]);
    };
    assert_eq!(refusal.field, "max_force_n");
    let r = checker.join().unwrap().unwrap();
    assert!(!r.passed());
    assert_eq!(r.failed(), ["hello"]);
    let hello = r.rule("hello").unwrap();
    assert_eq!(hello.figure, refusal.message);
    assert_eq!(hello.bound, refusal.allowed);
    assert!(
        r.rules[1..]
            .iter()
            .all(|x| x.verdict == Verdict::NotApplicable),
        "{}",
        r.text()
    );
}

/// No hello within the wait: the check says so, with what arrived instead.
#[test]
fn no_hello_within_the_wait_names_what_arrived_instead() {
    let (addr, checker) = start_check(0.5);
    let device = UdpSocket::bind("127.0.0.1:0").unwrap();
    device.send_to(b"not a packet", addr).unwrap();
    let e = checker.join().unwrap().unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "no device said hello on udp:{addr} within 0.5 s; 1 datagram malformed, the last: "
        )),
        "{e}"
    );
}

/// The document's section lists every rule in the report's order and the bounds and stage
/// times the check uses.
#[test]
fn the_documents_tables_are_the_checks_rules_bounds_and_stages() {
    use haptic_devices::bridge::check::{rules, world};
    let doc = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/device-bridge.md"),
    )
    .unwrap();
    let start = doc
        .find("## Checking your adapter before the first session")
        .unwrap();
    let sec = &doc[start..];
    let sec = &sec[..sec[3..].find("\n## ").unwrap()];
    // Every rule, in order.
    let mut at = 0;
    for (rule, _) in rules::RULES {
        let row = format!("\n| `{rule}` |");
        let i = sec[at..].find(&row).unwrap_or_else(|| panic!("{rule}"));
        at += i + row.len();
    }
    // The stages, with their spans.
    for (stage, _) in stages::STAGES {
        let (a, b) = stage.span_s();
        let row = format!(
            "\n| {} | {}–{} |",
            stage.name(),
            world_form::fmt_num(a),
            world_form::fmt_num(b)
        );
        assert!(sec.contains(&row), "{row}");
    }
    let (lo, hi) = rules::HELLO_REPEAT_S;
    for (text, ok) in [
        (
            format!("every {}–{} ms", lo * 1e3, hi * 1e3),
            (lo, hi) == (0.02, 0.2),
        ),
        ("the rate ± 5 %".into(), rules::RATE_TOLERANCE == 0.05),
        (
            "its own rate ± 10 %".into(),
            rules::CONTINUE_TOLERANCE == 0.1,
        ),
        ("at most 1 % skipped".into(), rules::SKIP_TOLERANCE == 0.01),
        ("no sample 500 ms after it".into(), rules::BYE_STOP_S == 0.5),
        (
            "from 0.25 s into the stage".into(),
            rules::BRICK_SETTLE_S == 0.25,
        ),
        (
            "from 0.5 s into the stage".into(),
            rules::RESUME_SETTLE_S == 0.5,
        ),
        ("one answer in five dropped".into(), stages::LOSS == 0.2),
        ("20 ms late".into(), stages::LATENCY_S == 0.02),
        ("a 0.1 kg brick".into(), world::BRICK_MASS_KG == 0.1),
        ("over 0.25 s".into(), stages::ENGAGE_S == 0.25),
        ("a wall 2 mm below".into(), stages::WALL_GAP_M == 0.002),
        ("100 ms pass without an answer".into(), {
            haptic_devices::bridge::fake::BACK_OFF_AFTER_S == 0.1
        }),
        ("1 s after the bye".into(), stages::AFTER_BYE_S == 1.0),
        (
            "at most 150 000 samples".into(),
            haptic_devices::bridge::check::observed::MAX_SAMPLES == 150_000,
        ),
    ] {
        assert!(sec.contains(&text), "the document lacks `{text}`");
        assert!(ok, "`{text}` is not the check's value");
    }
}
