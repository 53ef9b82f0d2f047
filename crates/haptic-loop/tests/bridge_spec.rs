//! docs/device-bridge.md as the spec (issue 41, item 2): the last packet, the link counters
//! the document lists, and the first tick's sample, each as the document says.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::bridge::protocol::{FORCE_LEN, Packet, Sample};
use haptic_devices::bridge::{BridgeConfig, UdpDevice};
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use haptic_types::HapticDevice;
use haptic_types::device::FALCON;
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The counters the document's table lists, in its order.
fn documented_counters() -> Vec<String> {
    let doc = std::fs::read_to_string(root().join("docs/device-bridge.md")).unwrap();
    let start = doc.find("| counter | what it counts |").unwrap();
    doc[start..]
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.split('`').nth(1).unwrap().to_string())
        .collect()
}

#[test]
fn the_document_lists_every_link_counter() {
    let dev = UdpDevice::new(BridgeConfig::parse("udp:127.0.0.1:9").unwrap());
    let names: Vec<String> = dev
        .link_counters()
        .iter()
        .map(|c| c.0.to_string())
        .collect();
    assert_eq!(names, documented_counters());
}

/// A version-2 session on the wall scene, driven by hand: the welcome is 21 + len(scene) + 4
/// bytes; tick n answers sample first + n with `first` the first tick's sample; when the
/// device says bye the simulator's last force packet is 121 bytes, version byte 1, tick
/// 2⁶⁴ − 1, zero force and stiffness, status 0, answering the newest sample a tick read, and
/// a bye follows it.
#[test]
fn the_last_packet_is_a_version_1_zero_force_with_the_largest_tick() {
    let sock = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = {
        let s = UdpSocket::bind("127.0.0.1:0").unwrap();
        s.local_addr().unwrap()
    };
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes/wall.toml")).unwrap());
    let mut b = BridgeConfig::parse(&format!("udp:{addr}")).unwrap();
    b.wait_s = 20.0;
    o.device = Some(haptic_devices::source::DeviceSource::Udp(b));
    let sim = std::thread::spawn(move || run_session(&o, &mut |_, _| {}));
    sock.set_read_timeout(Some(Duration::from_millis(50)))
        .unwrap();
    let hello = Packet::Hello {
        version: 2,
        rate_hz: 1000,
        specs: FALCON,
    }
    .encode();
    let mut buf = [0u8; 2048];
    let (n, scene) = loop {
        sock.send_to(&hello, addr).unwrap();
        if let Ok((n, _)) = sock.recv_from(&mut buf) {
            if let Ok(Packet::Welcome { scene, .. }) = Packet::decode(&buf[..n]) {
                break (n, scene);
            }
        }
    };
    assert_eq!(n, 21 + scene.len() + 4);
    // 300 samples, 1 ms apart, answers drained as they come.
    let mut answers = Vec::new();
    let t0 = Instant::now();
    for seq in 0..300u64 {
        let s = Packet::Sample(Sample {
            seq,
            device_time_ns: 0,
            position_m: [0.0, 0.0, 0.01],
            buttons: 0,
            two_port_periods: Some(0),
        });
        sock.send_to(&s.encode(), addr).unwrap();
        let due = t0 + Duration::from_millis(seq + 1);
        sock.set_read_timeout(Some(Duration::from_micros(200)))
            .unwrap();
        while Instant::now() < due {
            if let Ok((n, _)) = sock.recv_from(&mut buf) {
                answers.push(buf[..n].to_vec());
            }
        }
    }
    sock.send_to(&Packet::Bye { reason: 0 }.encode(), addr)
        .unwrap();
    sock.set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let end = Instant::now() + Duration::from_secs(10);
    while Instant::now() < end {
        if let Ok((n, _)) = sock.recv_from(&mut buf) {
            answers.push(buf[..n].to_vec());
            if matches!(Packet::decode(&buf[..n]), Ok(Packet::Bye { .. })) {
                break;
            }
        }
    }
    let r = sim.join().unwrap().unwrap();
    let forces: Vec<(usize, u8, haptic_devices::bridge::protocol::ForceReply)> = answers
        .iter()
        .filter_map(|a| match Packet::decode(a) {
            Ok(Packet::Force(f)) => Some((a.len(), a[4], f)),
            _ => None,
        })
        .collect();
    assert!(matches!(
        Packet::decode(answers.last().unwrap()),
        Ok(Packet::Bye { reason: 0 })
    ));
    let (len, version, last) = forces.last().unwrap();
    assert_eq!((*len, *version, last.tick), (FORCE_LEN, 1, u64::MAX));
    assert_eq!(
        (last.force_n, last.stiffness_n_per_m, last.status),
        ([0.0; 3], [0.0; 9], 0)
    );
    assert!(last.local.is_none());
    // Every other answer is a version-2 packet; tick n answers sample first + n − age, with
    // `first` the first tick's sample (the recorded arrays).
    let a = &r.arrays;
    let first = a.device_seq[0];
    assert_eq!(last.seq, *a.device_seq.last().unwrap());
    for (_, v, f) in &forces[..forces.len() - 1] {
        assert_eq!(*v, 2);
        let n = f.tick as usize;
        assert_eq!(f.seq + u64::from(a.device_age_ticks[n]), first + f.tick);
    }
}
