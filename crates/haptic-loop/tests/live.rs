//! The live view: a Foxglove WebSocket client (the `foxglove.sdk.v1` subprotocol) connects to a
//! running session and receives the 3D scene (one entity per body, real timestamps), the cursor
//! frame and the plotted state.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use foxglove::Decode;
use foxglove::schemas::SceneUpdate;
use haptic_loop::live::LiveConfig;
use haptic_loop::session::{SceneSource, SessionOptions, run_session};
use std::collections::BTreeMap;
use std::net::TcpListener;
use std::path::Path;
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, connect};

type Client = tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<std::net::TcpStream>>;

/// A Foxglove client (`foxglove.sdk.v1`) connected to the live view on loopback `port`, trying
/// every 20 ms for at most `within`; panics when the server refused it that long.
fn foxglove_client(port: u16, within: Duration) -> Client {
    let t0 = Instant::now();
    loop {
        let mut req = format!("ws://127.0.0.1:{port}")
            .into_client_request()
            .unwrap();
        req.headers_mut()
            .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
        match connect(req) {
            Ok((ws, _)) => return ws,
            Err(_) if t0.elapsed() < within => std::thread::sleep(Duration::from_millis(20)),
            Err(e) => panic!("the live view refused a viewer for {within:?}: {e}"),
        }
    }
}

#[test]
fn a_foxglove_client_receives_the_scene_while_the_session_runs() {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root.join("scenes/wall.toml")).unwrap());
    o.realtime = true;
    o.seconds = Some(3.0);
    o.live = Some(LiveConfig::parse(&format!("ws:127.0.0.1:{port}")).unwrap());
    let session = std::thread::spawn(move || run_session(&o, &mut |_, _| {}).unwrap());

    // Connect (the server starts before the first tick).
    let mut ws = foxglove_client(port, Duration::from_secs(10));
    // Channel advertisements (JSON text), then subscribe by topic.
    let mut channels: BTreeMap<String, u64> = BTreeMap::new();
    while channels.len() < 4 {
        if let Message::Text(t) = ws.read().unwrap() {
            let j: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
            if j["op"] == "advertise" {
                for c in j["channels"].as_array().unwrap() {
                    channels.insert(
                        c["topic"].as_str().unwrap().to_string(),
                        c["id"].as_u64().unwrap(),
                    );
                }
            }
        }
    }
    for t in [
        "/foxglove/scene",
        "/foxglove/tf",
        "/foxglove/log",
        "/live/state",
    ] {
        assert!(channels.contains_key(t), "{t} not advertised: {channels:?}");
    }
    let subs: Vec<_> = ["/foxglove/scene", "/live/state"]
        .iter()
        .enumerate()
        .map(|(i, t)| serde_json::json!({"id": i as u32 + 1, "channelId": channels[*t]}))
        .collect();
    ws.send(Message::text(
        serde_json::json!({"op": "subscribe", "subscriptions": subs}).to_string(),
    ))
    .unwrap();
    let (mut scene, mut state) = (None, None);
    while scene.is_none() || state.is_none() {
        if let Message::Binary(b) = ws.read().unwrap() {
            // opcode 1: message data = subscription u32, log time u64, payload
            assert_eq!(b[0], 1);
            let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
            let log_time = u64::from_le_bytes(b[5..13].try_into().unwrap());
            let payload = b[13..].to_vec();
            match sub {
                1 => scene = Some((log_time, SceneUpdate::decode(payload.as_slice()).unwrap())),
                _ => state = Some(serde_json::from_slice::<serde_json::Value>(&payload).unwrap()),
            }
        }
    }
    let (log_time, scene) = scene.unwrap();
    // Timestamps are the session's real start plus tick time (after 2024-01-01), not 1970.
    assert!(log_time > 1_704_067_200_000_000_000, "{log_time}");
    let ts = scene.entities[0].timestamp.unwrap();
    assert_eq!(
        u64::from(ts.sec()) * 1_000_000_000 + u64::from(ts.nsec()),
        log_time
    );
    // One entity per body: the wall (a box), the cursor (a sphere) and its label apart.
    let ids: Vec<&str> = scene.entities.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(ids, ["box_0", "sphere_0", "label_0"]);
    assert_eq!(scene.entities[1].spheres.len(), 1);
    let state = state.unwrap();
    assert!(state["device_force_norm_n"].as_f64().unwrap() >= 0.0);
    assert!(state["tick"].as_u64().is_some());
    drop(ws);
    let r = session.join().unwrap();
    let live = r.live.unwrap();
    assert!(live.scenes >= 100, "{live:?}");
    assert_eq!(live.dropped, 0);
}

/// The live view serves from the start of a bridged session, before the device's hello: a
/// viewer that connects first is served (and told the channels), not refused.
#[test]
fn a_viewer_connects_before_the_device_says_hello() {
    let free = || {
        TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port()
    };
    let (ws_port, udp_port) = (free(), free());
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root.join("scenes/wall.toml")).unwrap());
    let mut bridge =
        haptic_devices::BridgeConfig::parse(&format!("udp:127.0.0.1:{udp_port}")).unwrap();
    // No device will come: the session gives up after 3 s of waiting for the hello.
    bridge.wait_s = 3.0;
    o.device = Some(haptic_devices::source::DeviceSource::Udp(bridge));
    o.live = Some(LiveConfig::parse(&format!("ws:127.0.0.1:{ws_port}")).unwrap());
    let session = std::thread::spawn(move || run_session(&o, &mut |_, _| {}));
    let mut ws = foxglove_client(ws_port, Duration::from_secs(2));
    // The server greets the viewer (serverInfo) while the session still waits for the device.
    let first = ws.read().unwrap();
    let Message::Text(t) = first else {
        panic!("expected the serverInfo text message")
    };
    let j: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
    assert_eq!(j["op"], "serverInfo");
    assert!(
        !session.is_finished(),
        "the session ended before the viewer was served"
    );
    let err = session.join().unwrap().unwrap_err().to_string();
    assert!(err.contains("hello"), "{err}");
}

/// The teaching game's menu in Foxglove's Parameters panel: the brick scene's switches are
/// offered at their values, a set is applied before a tick's step and recorded as that tick's
/// switch (so the recording replays bit for bit), and a value out of range is refused.
#[test]
fn foxglove_parameters_set_a_switch_that_is_recorded() {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let out = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-live-menu-{}.mcap", std::process::id()));
    let mut o = SessionOptions::new(SceneSource::resolve(Path::new("brickworld")).unwrap());
    o.realtime = true;
    o.seconds = Some(2.0);
    o.out = Some(out.clone());
    o.live = Some(LiveConfig::parse(&format!("ws:127.0.0.1:{port}")).unwrap());
    let session = std::thread::spawn(move || run_session(&o, &mut |_, _| {}).unwrap());
    let mut ws = foxglove_client(port, Duration::from_secs(10));
    let reply = |ws: &mut tungstenite::WebSocket<_>, id: &str| loop {
        if let Message::Text(t) = ws.read().unwrap() {
            let j: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
            if j["op"] == "serverInfo" {
                let caps = j["capabilities"].as_array().unwrap();
                assert!(caps.iter().any(|c| c == "parameters"), "{j}");
            }
            if j["op"] == "parameterValues" && j["id"] == id {
                return j["parameters"].as_array().unwrap().clone();
            }
        }
    };
    // The menu is offered once the session has started (its scene is known).
    let params = loop {
        ws.send(Message::text(
            serde_json::json!({"op": "getParameters", "parameterNames": [], "id": "get"})
                .to_string(),
        ))
        .unwrap();
        let p = reply(&mut ws, "get");
        if !p.is_empty() {
            break p;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let value = |ps: &[serde_json::Value], name: &str| {
        ps.iter()
            .find(|p| p["name"] == name)
            .map(|p| p["value"].clone())
    };
    assert_eq!(
        value(&params, "gravity_m_per_s2"),
        Some(serde_json::json!(9.81))
    );
    assert_eq!(value(&params, "inertia"), Some(serde_json::json!(true)));
    ws.send(Message::text(
        serde_json::json!({"op": "setParameters", "id": "set", "parameters": [
            {"name": "gravity_m_per_s2", "value": 2.5},
            {"name": "restitution", "value": 7.0}]})
        .to_string(),
    ))
    .unwrap();
    let set = reply(&mut ws, "set");
    assert_eq!(
        value(&set, "gravity_m_per_s2"),
        Some(serde_json::json!(2.5))
    );
    // Out of range (0–1): refused, the value in force kept.
    assert_ne!(value(&set, "restitution"), Some(serde_json::json!(7.0)));
    drop(ws);
    session.join().unwrap();
    let rec = recording::read_recording_file(&out, false).unwrap();
    let sched = recording::switch_schedule(&rec, 1_000_000).unwrap();
    assert_eq!(sched.len(), 1, "{sched:?}");
    assert_eq!(
        (sched[0].1.name.as_str(), sched[0].1.value),
        ("gravity_m_per_s2", 2.5)
    );
    assert!(haptic_loop::replay::verify(&rec).unwrap().ok());
    std::fs::remove_file(&out).ok();
}

/// The shipped Foxglove layout names only topics and fields the live view publishes.
#[test]
fn the_shipped_foxglove_layout_uses_only_published_topics_and_fields() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("docs/foxglove/nanohaptics-live.json")).unwrap();
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let topics = [
        "/foxglove/scene",
        "/foxglove/tf",
        "/foxglove/log",
        "/live/state",
    ];
    let fields = [
        "tick",
        "time_s",
        "cursor_m",
        "world_force_n",
        "device_force_n",
        "device_force_norm_n",
        "engagement",
        "watchdog",
        "status",
        "sample_age_ticks",
        "dropped",
    ];
    let mut checked = 0;
    for (id, panel) in j["configById"].as_object().unwrap() {
        if let Some(t) = panel["topics"].as_object() {
            for k in t.keys() {
                assert!(topics.contains(&k.as_str()), "{id}: {k}");
                checked += 1;
            }
        }
        if let Some(t) = panel["topicToRender"].as_str() {
            assert_eq!(t, "/foxglove/log", "{id}");
            checked += 1;
        }
        for p in panel["paths"].as_array().into_iter().flatten() {
            let v = p["value"].as_str().unwrap();
            let rest = v
                .strip_prefix("/live/state.")
                .unwrap_or_else(|| panic!("{id}: {v}"));
            let field = rest.split('.').next().unwrap();
            assert!(fields.contains(&field), "{id}: {v}");
            checked += 1;
        }
    }
    assert!(checked >= 11, "{checked}");
    // Every panel of the configuration is placed in the layout tree.
    let layout = j["layout"].to_string();
    for id in j["configById"].as_object().unwrap().keys() {
        assert!(layout.contains(id.as_str()), "{id} not in the layout");
    }
}

/// A WebSocket upgrade to the live view on `port` with `host` and `origin` (none: `None`), as
/// a browser page would send it: the answer's status line.
fn upgrade_status(port: u16, host: &str, origin: Option<&str>) -> String {
    use std::io::{Read, Write};
    let mut s = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let o = origin
        .map(|o| format!("Origin: {o}\r\n"))
        .unwrap_or_default();
    s.write_all(
        format!(
            "GET / HTTP/1.1\r\nHost: {host}\r\n{o}Upgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.sdk.v1\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"
        )
        .as_bytes(),
    )
    .unwrap();
    let mut line = Vec::new();
    let mut b = [0u8; 1];
    while let Ok(1) = s.read(&mut b) {
        if b[0] == b'\n' {
            break;
        }
        line.push(b[0]);
    }
    String::from_utf8(line).unwrap().trim_end().to_string()
}

#[test]
fn another_sites_page_and_a_rebinding_host_cannot_reach_the_live_view() {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root.join("scenes/wall.toml")).unwrap());
    o.realtime = true;
    o.seconds = Some(2.0);
    o.live = Some(LiveConfig::parse(&format!("ws:127.0.0.1:{port}")).unwrap());
    let session = std::thread::spawn(move || run_session(&o, &mut |_, _| {}).unwrap());
    let _first = foxglove_client(port, Duration::from_secs(10));
    let host = format!("127.0.0.1:{port}");
    // Another site's page (cross-site WebSocket hijacking could set switches).
    assert_eq!(
        upgrade_status(port, &host, Some("https://evil.example")),
        "HTTP/1.1 403 Forbidden"
    );
    // A DNS-rebinding page: its own name as Host.
    assert_eq!(
        upgrade_status(port, &format!("rebind.evil.example:{port}"), None),
        "HTTP/1.1 403 Forbidden"
    );
    // Foxglove's web app, the desktop app (no Origin) and localhost are let through.
    for (h, origin) in [
        (host.clone(), Some("https://app.foxglove.dev")),
        (host.clone(), None),
        (format!("localhost:{port}"), None),
    ] {
        assert_eq!(
            upgrade_status(port, &h, origin),
            "HTTP/1.1 101 Switching Protocols",
            "{h} {origin:?}"
        );
    }
    let report = session.join().unwrap();
    let live = report.live.expect("the live view's summary");
    assert_eq!((live.refused_origin, live.refused_host), (1, 1));
}
