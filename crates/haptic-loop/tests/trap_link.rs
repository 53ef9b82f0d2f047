//! Protocol 4's follower on a real link: the optical tweezers at 10 kHz bridged over loopback
//! UDP to the fake device's modelled hand (`run_fake` with a preset and a grip: moving mass,
//! encoder counts, the force held over each servo period), its samples delayed 10 ms with
//! 1 ms of jitter and 5 % loss (the fake device delays its samples, not the answers: a round
//! trip of about 10 ms), on every preset, loose and firm, over the whole script (grab, steer,
//! the drag past the envelope, release).
//!
//! Asserted: the peak force the motors put on the hand is within 20 % of the largest force the
//! world answered in the same session (read from its recording; 0.975–0.993 measured), no
//! buzz (force steps over 1 N only in the fast drag, a few at most), at most 0.01 J into
//! the hand, every force within the device's limit, and the session replays bit for bit. And
//! the contrast that is the reason for protocol 4: on a loosely held Delta.3, protocol 3's
//! device drags the hand inside the envelope, where the world answers nothing (simulated at
//! 5 ms each way, the same round trip: 2.87 × the world's peak; measured on the real link
//! 2.42–3.70 ×).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::bridge::fake::FakeReport;
use haptic_devices::local::Protocol;
use haptic_devices::{Grip, Mechanics, PRESETS};
use haptic_loop::session::SessionReport;
use std::path::{Path, PathBuf};

mod fake_link;

/// The script: grab at 0.3 s, the square, the drag to 20 mm at 4.5 s, release at 5.3 s.
const SECONDS: f64 = 5.5;

fn out(name: &str) -> PathBuf {
    fake_link::out("trap", name)
}

/// One bridged session of the 10 kHz trap against the modelled `mech` held with `grip`,
/// speaking `protocol`, its samples 10 ms late with jitter and loss.
fn bridged(
    mech: Mechanics,
    grip: Grip,
    protocol: Protocol,
    rec: &Path,
) -> (SessionReport, FakeReport) {
    fake_link::bridged(
        "optical_tweezers_10khz.toml",
        "optical_tweezers.script.toml",
        SECONDS,
        (mech, grip),
        protocol,
        rec,
    )
}

/// The largest force the loop answered in the session, N.
fn world_peak_n(r: &SessionReport) -> f64 {
    r.arrays
        .device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max)
}

#[test]
fn the_10_khz_trap_behind_10_ms_of_real_link_feels_the_worlds_force_on_every_preset() {
    let mut lines = Vec::new();
    for mech in PRESETS {
        for (grip, held) in [(Grip::LOOSE, "loose"), (Grip::FIRM, "firm")] {
            let rec = out(&format!("{}-{held}.mcap", mech.name));
            let (r, dev) = bridged(mech, grip, Protocol::V4, &rec);
            let world = world_peak_n(&r);
            let q = dev.max_felt_n / world;
            lines.push(format!(
                "{} {}: felt {:.4} N against the world's {world:.4} N ({q:.3}), {} changes \
                 over 1 N (largest {:.3} N) at {:?} s, {:+.4} J into the hand, {} two-port \
                 periods",
                mech.name,
                held,
                dev.max_felt_n,
                dev.jumps_over_1n,
                dev.max_jump_n,
                dev.jump_times_s,
                dev.energy_to_hand_j,
                dev.two_port_interventions
            ));
            let c = |k: &str| r.link.iter().find(|(n, _)| *n == k).map_or(0, |x| x.1);
            println!(
                "{} [ticks stale {}, samples superseded {}, resyncs {}, ticks {}]",
                lines.last().unwrap(),
                c("stale_ticks"),
                c("superseded"),
                c("resync"),
                r.stats.ticks
            );
            assert_eq!(dev.protocol, 4);
            // The drag past the envelope pushes back: the world answers at least 1 N.
            assert!(world > 1.0, "{}", lines.last().unwrap());
            assert!((0.8..=1.2).contains(&q), "{}", lines.last().unwrap());
            // No buzz. The force changes by over 1 N between two servo periods only in the
            // fast drag (4.5–4.55 s, the hand at 0.32 m/s): measured on a firm Falcon, 0 to 6
            // in 12 runs (largest 2.15 N), all within 4.53–4.56 s; every other preset and
            // grip 0 in 3 runs. The residual there carries the loop's own safety layer (its
            // passivity damping and rate limit) acting on the real link's bursty readings (90 %
            // of the ticks stale, 3,000–6,500 samples superseded): it changed by up to 0.59 N
            // from one answer to the next, where the simulated link's changes stay below 0.5 N.
            assert!(dev.jumps_over_1n <= 8, "{}", lines.last().unwrap());
            assert!(
                dev.jump_times_s.iter().all(|t| (4.5..4.6).contains(t)),
                "{}: jumps at {:?} s",
                lines.last().unwrap(),
                dev.jump_times_s
            );
            fake_link::assert_sound_and_replayed(&dev, &rec, lines.last().unwrap());
        }
    }
    // The contrast on the real link: protocol 3 drags the hand (the round trip's length varies
    // with the machine's scheduling: a lower bound only).
    let rec = out("delta3-loose-v3.mcap");
    let (r, v3) = bridged(Mechanics::DELTA3, Grip::LOOSE, Protocol::V3, &rec);
    let q3 = v3.max_felt_n / world_peak_n(&r);
    println!(
        "protocol 3, delta3 loose: felt {:.4} N, {q3:.3} of the world's peak",
        v3.max_felt_n
    );
    assert!(q3 > 1.5, "{q3}");
}
