//! The classroom in a real browser (Debian's headless `chromium`, through the DevTools
//! Protocol): a student joins on the join page and starts playing; two more play through page
//! links; the teacher page shows all three, sets a switch for everyone, ends every session and
//! downloads the zip. Screenshots of the join and teacher pages go to the target folder's
//! `tmp/figures/play/` (`scripts/figures.sh` writes them to docs/figures/play/).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::class::{Running, start_config};
use common::figures;
use recording::read_recording_file;
use serde_json::json;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::sleep;
use std::time::Duration;
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

type Ws = WebSocket<MaybeTlsStream<TcpStream>>;

/// A student playing through a page link (no browser): joins, starts, and moves the hand
/// down and back up until `stop`.
fn link_student(
    host: String,
    name: &'static str,
    stop: Arc<AtomicBool>,
) -> std::thread::JoinHandle<u64> {
    std::thread::spawn(move || {
        let mut s = TcpStream::connect(&host).unwrap();
        use std::io::{Read, Write};
        s.write_all(
            format!(
                "POST /join HTTP/1.1\r\nHost: {host}\r\nOrigin: http://{host}\r\n\
                 Content-Type: application/x-www-form-urlencoded\r\n\
                 Content-Length: {}\r\n\r\nname={name}",
                name.len() + 5
            )
            .as_bytes(),
        )
        .unwrap();
        let mut r = String::new();
        s.read_to_string(&mut r).unwrap();
        let token = r
            .lines()
            .find_map(|l| l.strip_prefix("Location: /play?s="))
            .unwrap()
            .trim()
            .to_string();
        let (mut ws, _): (Ws, _) =
            tungstenite::connect(format!("ws://{host}/ws?s={token}").as_str()).unwrap();
        if let MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_read_timeout(Some(Duration::from_millis(5))).unwrap();
        }
        ws.send(Message::text(json!({"type": "start"}).to_string()))
            .unwrap();
        let mut k = 0u64;
        let mut switched = 0;
        while !stop.load(Ordering::Relaxed) {
            k += 1;
            let z = 0.3 * ((k as f64) * 0.05).sin() - 0.3;
            let m = json!({"type": "input", "seq": k, "pos": [0.1, 0.0, z], "buttons": 0, "t_ms": k as f64});
            if ws.send(Message::text(m.to_string())).is_err() {
                break;
            }
            // Everything waiting (frames, sound ticks, switches), until the socket is empty.
            loop {
                match ws.read() {
                    Ok(Message::Text(t)) => {
                        if t.as_str().contains(r#""type":"switched""#) {
                            switched += 1;
                        }
                    }
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
            sleep(Duration::from_millis(16));
        }
        switched
    })
}

#[test]
fn the_teacher_page_watches_switches_ends_and_collects_the_class() {
    let Running {
        addr,
        host,
        stop,
        handle: class,
        dir,
    } = start_config("browser", |_| {});
    let mut b = Browser::launch(1100, 640).unwrap();

    // A student joins in the browser: the join page, a name, Start.
    b.open(&addr.student_url).unwrap();
    b.eval("document.querySelector('input[name=name]').value = 'Ada Lovelace'")
        .unwrap();
    b.screenshot(&figures().join("class-join.png")).unwrap();
    b.eval("document.querySelector('form').submit()").unwrap();
    b.wait_for(
        "location.pathname === '/play' && window.__play && window.__play.hello !== null && !document.getElementById('go').disabled",
        20.0,
    )
    .unwrap();
    b.eval("document.getElementById('go').click()").unwrap();
    b.wait_for(
        "window.__play.role === 'hand' && window.__play.frames > 5",
        20.0,
    )
    .unwrap();
    let ws_url = b.websockets.last().cloned().unwrap();
    assert!(
        ws_url.starts_with(&format!("ws://{host}/ws?s=")),
        "{ws_url}"
    );
    b.check().unwrap();

    // Two more students play through page links.
    let links_stop = Arc::new(AtomicBool::new(false));
    let grace = link_student(host.clone(), "Grace", links_stop.clone());
    let lin = link_student(host.clone(), "Lin", links_stop.clone());

    // The teacher page: all three, Ada no longer connected (her tab is now the teacher's).
    b.open(&addr.teacher_url).unwrap();
    b.wait_for(
        "document.querySelectorAll('#students tbody tr').length === 3 && [...document.querySelectorAll('#students tbody tr')].every(r => r.children[1].textContent === 'playing')",
        20.0,
    )
    .unwrap();
    let rows = b
        // The two page links join at once, in either order: compare by name.
        .eval("[...document.querySelectorAll('#students tbody tr')].map(r => [r.children[0].textContent, r.children[2].textContent]).sort()")
        .unwrap();
    assert_eq!(
        rows,
        json!([
            ["Ada Lovelace", "no"],
            ["Grace", "yes (1)"],
            ["Lin", "yes (1)"]
        ])
    );
    sleep(Duration::from_millis(600));
    b.screenshot(&figures().join("teacher.png")).unwrap();

    // A switch for everyone, then end every session.
    b.eval("document.getElementById('switch').value = 'friction'; document.getElementById('value').value = '0.5'; document.getElementById('set').click()")
        .unwrap();
    b.wait_for(
        "document.getElementById('said').textContent === 'friction = 0.5 for 3 students'",
        10.0,
    )
    .unwrap();
    sleep(Duration::from_millis(300));
    b.eval("document.getElementById('endall').click()").unwrap();
    b.wait_for(
        "document.getElementById('said').textContent === 'ended 3 sessions' && [...document.querySelectorAll('#students tbody tr')].every(r => r.children[1].textContent === 'ended')",
        20.0,
    )
    .unwrap();
    // The zip of the three recordings, from the page's own link.
    let zip = b
        .eval("fetch(document.getElementById('zip').href).then(r => r.arrayBuffer()).then(a => { const v = new DataView(a); return [a.byteLength, v.getUint32(0, true), v.getUint16(a.byteLength - 12, true)]; })")
        .unwrap();
    assert_eq!(zip[1], 0x0403_4b50, "a zip's first local header");
    assert_eq!(zip[2], 3, "three recordings in the zip");
    // Each ended session has its Watch link: the first opens the replay page, which loads the
    // student's session re-simulated from their recording.
    let watch = b
        .eval("[...document.querySelectorAll('#students tbody tr a')].filter(a => a.textContent === 'Watch').map(a => a.href)")
        .unwrap();
    let watch = watch.as_array().unwrap();
    assert_eq!(watch.len(), 3, "{watch:?}");
    b.open(watch[0].as_str().unwrap()).unwrap();
    b.wait_for("window.__replay && window.__replay.ready", 30.0)
        .unwrap();
    let ticks = b.eval("__replay.index.ticks").unwrap().as_u64().unwrap();
    assert!(ticks > 0);
    b.check().unwrap();
    links_stop.store(true, Ordering::Relaxed);
    assert!(
        grace.join().unwrap() >= 1,
        "Grace's page was told the switch"
    );
    assert!(lin.join().unwrap() >= 1, "Lin's page was told the switch");

    stop.store(true, Ordering::Relaxed);
    let s = class.join().unwrap().unwrap();
    assert_eq!(s.students.len(), 3);
    for st in &s.students {
        assert_eq!(st.session.end, "stopped", "{}", st.line());
        let rec = read_recording_file(&st.session.recording, false).unwrap();
        assert!(
            haptic_loop::replay::verify(&rec).unwrap().ok(),
            "{}",
            st.line()
        );
        // The teacher's switch is in every recording, as the tick's input.
        let switched = rec
            .messages
            .iter()
            .any(|m| m.channel.topic() == "/scene/switch");
        assert!(switched, "{}: no /scene/switch", st.name);
    }
    assert_eq!(s.refused.total(), 0, "{:?}", s.refused);
    let _ = std::fs::remove_dir_all(&dir);
}
