//! The classroom without a browser: students join by name, each plays their own world through
//! their own page link, the teacher's link sees them and sets a switch for everyone, ends
//! every session and downloads the recordings as one zip; every recording replays bit for bit.
//! Forged `Origin`/`Host`, wrong codes and bad names are refused and counted.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::class::{
    Running, Ws, get, http, join, post_join, read_for, send, start, start_config, ws,
};
use haptic_loop::session::SceneSource;
use play::protocol::ServerMsg;
use recording::read_recording_file;
use serde_json::{Value, json};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

#[test]
fn a_class_of_three_plays_is_watched_switched_ended_and_collected() {
    let c = start("three", 3);
    let host = c.host.clone();
    assert_eq!(c.addr.join_code, None, "loopback: a name is enough");
    assert!(c.addr.teacher_url.ends_with("/teacher?code=TEACH123"));
    // The join page, and a student's page with its modules.
    let j = get(&host, "/");
    assert!(j.starts_with("HTTP/1.1 200 OK"), "{j}");
    assert!(j.contains(r#"<form method="post" action="/join">"#));
    assert!(!j.contains(r#"name="code""#));
    // Joining is no link another site can follow, and no form another site can send: each
    // forged join is refused with its reason and opens no session (the class of 3 still has
    // room for all three below).
    let link = http(
        &host,
        &format!(
            "GET /join?name=Eve HTTP/1.1\r\nHost: {host}\r\nSec-Fetch-Site: cross-site\r\n\r\n"
        ),
    );
    assert!(
        link.starts_with("HTTP/1.1 405 Method Not Allowed"),
        "{link}"
    );
    assert!(link.contains("Allow: POST\r\n"), "{link}");
    assert!(
        link.contains("GET /join changes state: send it as POST from this server&#39;s own page")
    );
    let cross = post_join(
        &host,
        "Eve",
        Some(&format!(
            "Origin: http://{host}\r\nSec-Fetch-Site: cross-site\r\n"
        )),
    );
    assert!(cross.starts_with("HTTP/1.1 403 Forbidden"), "{cross}");
    assert!(cross.contains("Sec-Fetch-Site `cross-site` is refused: allowed `same-origin`"));
    let other = post_join(&host, "Eve", Some("Origin: https://evil.example\r\n"));
    assert!(other.starts_with("HTTP/1.1 403 Forbidden"), "{other}");
    assert!(
        other.contains("Origin `https://evil.example` is not this page's own origin"),
        "{other}"
    );
    let bare = post_join(&host, "Eve", Some(""));
    assert!(bare.starts_with("HTTP/1.1 403 Forbidden"), "{bare}");
    assert!(bare.contains("a POST without an Origin header is refused"));
    let names = ["Ada", "Grace", "Zo%C3%AB"];
    let tokens: Vec<String> = names.iter().map(|n| join(&host, n)).collect();
    let page = get(&host, &format!("/play?s={}", tokens[0]));
    assert!(
        page.contains(r#"<script type="module" src="/main.js">"#),
        "{page}"
    );
    assert!(get(&host, "/main.js").starts_with("HTTP/1.1 200 OK"));
    // Refusals: the class is full, a taken name, a name that would be a path, no session.
    let full = post_join(&host, "Dan", None);
    assert!(full.starts_with("HTTP/1.1 503"), "{full}");
    assert!(full.contains("the class is full (3 students playing)"));
    let taken = post_join(&host, "Ada", None);
    assert!(taken.starts_with("HTTP/1.1 409"), "{taken}");
    let bad = post_join(&host, "..%2Fetc%2Fpasswd", None);
    assert!(bad.starts_with("HTTP/1.1 400"), "{bad}");
    assert!(bad.contains("name contains `/`: allowed letters, digits, spaces and - _ . &#39;"));
    assert!(get(&host, "/play?s=nope").starts_with("HTTP/1.1 404"));
    // The teacher page: its code, never without.
    assert!(get(&host, "/teacher?code=TEACH123").contains("<title>nanohaptics classroom: teacher"));
    assert!(get(&host, "/teacher?code=WRONG").starts_with("HTTP/1.1 403"));
    assert!(get(&host, "/recordings.zip").starts_with("HTTP/1.1 403"));
    // A forged origin may not drive a student's session or the teacher's link.
    let forged = http(
        &host,
        &format!(
            "GET /teacher/ws?code=TEACH123 HTTP/1.1\r\nHost: {host}\r\nOrigin: https://evil.example\r\n\
             Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
        ),
    );
    assert!(forged.starts_with("HTTP/1.1 403"), "{forged}");

    // Each student plays: Start, then a hand that moves down onto the floor.
    let mut pages: Vec<Ws> = tokens
        .iter()
        .map(|t| ws(&host, &format!("/ws?s={t}")))
        .collect();
    for p in pages.iter_mut() {
        let hello = read_for(p, 0.2);
        assert_eq!(hello[0]["type"], "hello", "{hello:?}");
        send(p, json!({"type": "start"}));
    }
    let mut teacher = ws(&host, "/teacher/ws?code=TEACH123");
    for k in 0..40u32 {
        for (i, p) in pages.iter_mut().enumerate() {
            let z = 0.2 - 0.02 * f64::from(k);
            let x = 0.1 * i as f64;
            send(
                p,
                json!({"type": "input", "seq": k + 1, "pos": [x, 0.0, z], "buttons": 0, "t_ms": f64::from(k)}),
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    // The teacher sees three students playing, and sets the friction for everyone.
    let seen = read_for(&mut teacher, 0.6);
    let class = seen.iter().rev().find(|m| m["type"] == "class").unwrap();
    let students = class["students"].as_array().unwrap();
    assert_eq!(students.len(), 3);
    for s in students {
        assert_eq!(s["status"]["phase"], "playing", "{s}");
        assert_eq!(s["pages"], 1);
        assert!(s["status"]["ticks"].as_u64().unwrap() > 0);
    }
    assert_eq!(students[2]["name"], "Zoë");
    send(
        &mut teacher,
        json!({"type": "switch", "name": "friction", "value": 0.25}),
    );
    send(
        &mut teacher,
        json!({"type": "switch", "name": "friction", "value": 11}),
    );
    let r = read_for(&mut teacher, 0.5);
    assert!(
        r.iter()
            .any(|m| m["type"] == "done" && m["message"] == "friction = 0.25 for 3 students"),
        "{r:?}"
    );
    assert!(r.iter().any(|m| m["type"] == "error"
        && m["message"] == "switch `friction` = 11 is out of range: allowed 0 ≤ value ≤ 10"));
    for p in pages.iter_mut() {
        let got = read_for(p, 0.3);
        let sw = got
            .iter()
            .find(|m| m["type"] == "switched")
            .expect("switched");
        assert_eq!(
            (sw["name"].as_str(), sw["value"].as_f64()),
            (Some("friction"), Some(0.25))
        );
        // Every message a student's page gets is a ServerMsg.
        for m in &got {
            serde_json::from_value::<ServerMsg>(m.clone()).unwrap();
        }
    }
    // A session still running is not replayed yet; the replay is the teacher's alone.
    let t0 = &tokens[0];
    let running = get(&host, &format!("/replay/index.json?s={t0}&code=TEACH123"));
    assert!(running.starts_with("HTTP/1.1 409 Conflict"), "{running}");
    assert!(running.contains("session is still running: it can be replayed once it has ended"));
    // The teacher ends every session; each page gets its end and its own recording.
    send(&mut teacher, json!({"type": "end_all"}));
    let r = read_for(&mut teacher, 0.5);
    assert!(
        r.iter().any(|m| m["message"] == "ended 3 sessions"),
        "{r:?}"
    );
    for (p, t) in pages.iter_mut().zip(&tokens) {
        let got = read_for(p, 1.0);
        let end = got.iter().find(|m| m["type"] == "end").expect("end");
        assert_eq!(end["end"], "stopped");
        assert_eq!(end["recording"], format!("/recording.mcap?s={t}"));
        let dl = get(&host, &format!("/recording.mcap?s={t}"));
        assert!(
            dl.starts_with("HTTP/1.1 200 OK"),
            "{}",
            &dl[..60.min(dl.len())]
        );
    }
    // The teacher watches an ended session again: the replay page and its data, made from the
    // student's recording (its ticks checked against the summary below); not without the code.
    let page = get(&host, &format!("/replay?s={t0}&code=TEACH123"));
    assert!(page.starts_with("HTTP/1.1 200 OK"), "{page}");
    assert!(page.contains(r#"<script type="module" src="/replay.js"></script>"#));
    let index = get(&host, &format!("/replay/index.json?s={t0}&code=TEACH123"));
    assert!(index.starts_with("HTTP/1.1 200 OK"), "{index}");
    let index: Value = serde_json::from_str(index.split("\r\n\r\n").nth(1).unwrap()).unwrap();
    for path in ["/replay", "/replay/index.json", "/replay/sound.f32"] {
        let r = get(&host, &format!("{path}?s={t0}&code=WRONG"));
        assert!(r.starts_with("HTTP/1.1 403 Forbidden"), "{path}: {r}");
    }
    let zip = get(&host, "/recordings.zip?code=TEACH123");
    assert!(zip.starts_with("HTTP/1.1 200 OK\r\nContent-Type: application/zip"));

    c.stop.store(true, Ordering::Relaxed);
    let summary = c.handle.join().unwrap().unwrap();
    assert_eq!(summary.students.len(), 3);
    assert!(
        summary.refused.join >= 2 && summary.refused.code >= 2,
        "{:?}",
        summary.refused
    );
    let first = summary
        .students
        .iter()
        .find(|s| {
            s.session
                .recording
                .to_string_lossy()
                .contains(index["file"].as_str().unwrap())
        })
        .expect("the replayed recording is a student's");
    assert_eq!(index["ticks"].as_u64(), Some(first.session.stats.ticks));
    // The forged teacher link, the cross-site form, the other site's and the bare POST.
    assert_eq!(summary.refused.origin, 4);
    assert_eq!(summary.refused.head, 1, "the GET link to /join");
    for s in &summary.students {
        assert_eq!(s.session.end, "stopped", "{}", s.line());
        assert!(s.session.stats.ticks > 100, "{}", s.line());
        assert!(s.session.error.is_none(), "{}", s.line());
        // Each recording is the student's own, named for them, and replays bit for bit.
        assert_eq!(s.session.recording.parent(), Some(c.dir.as_path()));
        let stem = s
            .session
            .recording
            .file_name()
            .unwrap()
            .to_string_lossy()
            .to_string();
        assert!(stem.starts_with(&format!("{}-", play::classroom::names::file_stem(&s.name))));
        let rec = read_recording_file(&s.session.recording, false).unwrap();
        let v = haptic_loop::replay::verify(&rec).unwrap();
        assert!(v.ok(), "{}: {:?}", s.name, v);
        assert_eq!(v.ticks, s.session.stats.ticks);
    }
    let _ = std::fs::remove_dir_all(&c.dir);
}

#[test]
fn a_bridged_device_joins_as_a_student_and_the_teacher_sees_and_ends_it() {
    use haptic_devices::bridge::BridgeConfig;
    use haptic_devices::bridge::fake::{FakeConfig, run_fake};
    use haptic_devices::script::Script;
    use haptic_types::DeviceModel;
    use haptic_types::device::FALCON;
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let Running {
        host,
        stop,
        handle,
        dir,
        ..
    } = start_config("device", |c| {
        c.scene = SceneSource::resolve("wall".as_ref()).unwrap();
        c.teacher_code = Some("T".into());
        let mut b = BridgeConfig::parse(&format!("udp:127.0.0.1:{port}")).unwrap();
        b.wait_s = 30.0;
        c.device = Some(b);
        c.device_name = "Falcon lab 2".into();
    });
    let text = SceneSource::builtin("wall").unwrap().scripts[0].1.clone();
    let fake = FakeConfig {
        target: format!("127.0.0.1:{port}").parse().unwrap(),
        model: DeviceModel::Falcon,
        script: Script::from_toml(&text, &FALCON).unwrap(),
        hand: None,
        physical: None,
        loss: 0.0,
        jitter_s: 0.0,
        latency_s: 0.0,
        seed: 1,
        seconds: Some(30.0),
        outage: None,
        wait_s: 20.0,
        bye: true,
        protocol: haptic_devices::local::Protocol::V2,
        fault: None,
    };
    let dev = std::thread::spawn(move || run_fake(&fake, None));
    // The teacher sees the device playing, and its page link lets a page watch it.
    let mut teacher = ws(&host, "/teacher/ws?code=T");
    let t0 = Instant::now();
    let device = loop {
        let seen = read_for(&mut teacher, 0.3);
        let playing = seen
            .iter()
            .rev()
            .find(|m| m["type"] == "class")
            .and_then(|c| {
                c["students"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|s| s["name"] == "Falcon lab 2" && s["status"]["phase"] == "playing")
                    .cloned()
            });
        if let Some(p) = playing {
            break p;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "the device never played"
        );
    };
    assert_eq!(device["pages"], 0);
    // The teacher ends it like any student's.
    send(
        &mut teacher,
        json!({"type": "end", "student": "Falcon lab 2"}),
    );
    let r = read_for(&mut teacher, 1.0);
    assert!(
        r.iter()
            .any(|m| m["message"] == "ended Falcon lab 2's session"),
        "{r:?}"
    );
    stop.store(true, Ordering::Relaxed);
    let summary = handle.join().unwrap().unwrap();
    let _ = dev.join();
    let s = summary
        .students
        .iter()
        .find(|s| s.name == "Falcon lab 2")
        .expect("the device's session");
    assert_eq!(s.session.end, "stopped", "{}", s.line());
    assert!(s.session.stats.ticks > 0, "{}", s.line());
    assert!(
        s.session
            .recording
            .file_name()
            .unwrap()
            .to_string_lossy()
            .starts_with("Falcon_lab_2-")
    );
    let rec = read_recording_file(&s.session.recording, false).unwrap();
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A session waits in the class's lobby until its page's Start and is begun there, off the tick
/// workers: a student who never starts never reaches a worker, so the workers' cycles hold the
/// started student alone; at the end the waiting one is still ended whole (an empty recording
/// that replays), and each worker reports its cycles.
#[test]
fn a_session_waits_in_the_lobby_until_its_start_and_the_workers_report_their_cycles() {
    let c = start_config("lobby", |c| {
        c.max_students = 2;
        c.workers = Some(1);
    });
    let host = c.host.clone();
    let (t_go, t_wait) = (join(&host, "Go"), join(&host, "Wait"));
    let mut go = ws(&host, &format!("/ws?s={t_go}"));
    let _wait = ws(&host, &format!("/ws?s={t_wait}"));
    send(&mut go, json!({"type": "start"}));
    for seq in 1..=3 {
        send(
            &mut go,
            json!({"type": "input", "seq": seq, "pos": [0.0, 0.0, 0.3], "buttons": 0, "t_ms": seq as f64}),
        );
    }
    let got = read_for(&mut go, 1.0);
    assert!(got.iter().any(|m| m["type"] == "frame"), "Go plays");
    c.stop.store(true, Ordering::Relaxed);
    let summary = c.handle.join().unwrap().unwrap();
    assert_eq!(summary.workers, 1);
    assert_eq!(summary.schedule.len(), 1);
    let w = &summary.schedule[0];
    let by = |n: &str| {
        summary
            .students
            .iter()
            .find(|s| s.name == n)
            .unwrap_or_else(|| panic!("{n} is in the summary"))
    };
    let (g, wt) = (by("Go"), by("Wait"));
    assert!(g.session.stats.ticks > 100, "{}", g.line());
    assert_eq!(wt.session.stats.ticks, 0, "{}", wt.line());
    assert_eq!(wt.session.end, "stopped");
    // Until the stop the worker held Go alone: every cycle but the last (the stop's, when the
    // lobby hands Wait over to be ended) ticked one session. Go's ticks ran one per cycle.
    assert!(w.most_sessions <= 2, "{}", w.describe());
    assert!(
        w.session_ticks >= g.session.stats.ticks && w.session_ticks <= w.cycles + 2,
        "{} ({} ticks)",
        w.describe(),
        g.session.stats.ticks
    );
    assert!(w.cycles >= g.session.stats.ticks, "{}", w.describe());
    for s in [g, wt] {
        let rec = read_recording_file(&s.session.recording, false).unwrap();
        let v = haptic_loop::replay::verify(&rec).unwrap();
        assert!(v.ok(), "{}: {:?}", s.name, v);
    }
}
