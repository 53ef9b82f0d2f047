//! A page's messages against a session's link.

use super::page_link::on_message;
use super::*;
use crate::input::page_to_device;
use haptic_loop::scene::brick::BRICK_SWITCHES;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, sync_channel};
use tungstenite::Message;

fn shared(page_is_hand: bool) -> (Arc<Shared>, Receiver<Message>, Receiver<Message>) {
    let sh = Arc::new(Shared::default());
    *sh.scene.lock().unwrap() = Some(SceneLink {
        switches: &BRICK_SWITCHES,
        kind: "brickworld",
        workspace_radius_m: 0.04,
        button_mask: 0b1111,
        page_is_hand,
    });
    let (t1, r1) = sync_channel(16);
    let (t2, r2) = sync_channel(16);
    sh.pages.lock().unwrap().push(Page {
        id: 1,
        tx: t1,
        wake: None,
    });
    sh.pages.lock().unwrap().push(Page {
        id: 2,
        tx: t2,
        wake: None,
    });
    (sh, r1, r2)
}

fn last_error(rx: &Receiver<Message>) -> serde_json::Value {
    let mut last = serde_json::Value::Null;
    while let Ok(m) = rx.try_recv() {
        if let Message::Text(t) = m {
            last = serde_json::from_str(t.as_str()).unwrap();
        }
    }
    last
}

/// The modules `body` imports, and those it loads by URL (`new URL('./synth.js',
/// import.meta.url)`: the AudioWorklet's module; `./link.js`: the link's Worker).
fn imports(body: &str) -> Vec<String> {
    let imported = body
        .lines()
        .filter(|l| l.starts_with("import "))
        .filter_map(|l| l.split("from './").nth(1));
    let by_url = body.split("new URL('./").skip(1);
    imported
        .chain(by_url)
        .filter_map(|rest| rest.split('\'').next())
        .map(|m| format!("/{m}"))
        .collect()
}

#[test]
fn the_page_files_are_served_and_import_only_served_modules() {
    let served: Vec<&str> = PAGE_FILES.iter().map(|f| f.path).collect();
    // Every file in src/page is served (and nothing else is listed).
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/page");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| format!("/{}", e.unwrap().file_name().to_string_lossy()))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = served
        .iter()
        .filter(|p| **p != "/")
        .map(|p| p.to_string())
        .collect();
    listed.sort();
    assert_eq!(on_disk, listed);
    // Modules are JavaScript; the page loads main.js as a module and the style sheet.
    for f in PAGE_FILES {
        assert_eq!(
            f.path.ends_with(".js"),
            f.content_type == "text/javascript; charset=utf-8",
            "{}",
            f.path
        );
    }
    let index = PAGE_FILES[0].body;
    assert!(index.contains(r#"<script type="module" src="/main.js"></script>"#));
    assert!(index.contains(r#"href="/play.css""#));
    // Every module is reached from main.js, and every import is served.
    let mut reached = vec!["/main.js".to_string()];
    let mut i = 0;
    while i < reached.len() {
        let f = PAGE_FILES.iter().find(|f| f.path == reached[i]).unwrap();
        for m in imports(f.body) {
            assert!(served.contains(&m.as_str()), "{} imports {m}", f.path);
            if !reached.contains(&m) {
                reached.push(m);
            }
        }
        i += 1;
    }
    let js = served.iter().filter(|p| p.ends_with(".js")).count();
    assert_eq!(
        reached.len(),
        js,
        "modules reached from main.js: {reached:?}"
    );
}

#[test]
fn switches_are_checked_before_they_reach_the_tick() {
    let (sh, r1, _) = shared(true);
    on_message(&sh, 1, r#"{"type":"switch","name":"gravity","value":1}"#);
    let e = last_error(&r1);
    assert_eq!(e["field"], "switch.name");
    assert_eq!(
        e["message"],
        "the brickworld scene has no switch `gravity` (its switches: gravity_m_per_s2, \
         restitution, friction, inertia, brick_mass_kg)"
    );
    on_message(&sh, 1, r#"{"type":"switch","name":"friction","value":11}"#);
    let e = last_error(&r1);
    assert_eq!(e["field"], "switch.value");
    assert_eq!(
        e["message"],
        "switch `friction` = 11 is out of range: allowed 0 ≤ value ≤ 10"
    );
    on_message(&sh, 1, r#"{"type":"switch","name":"inertia","value":0.5}"#);
    assert_eq!(last_error(&r1)["field"], "switch.value");
    assert!(sh.switches.lock().unwrap().is_empty());
    // Good ones wait for the tick, the old name under the switch's own.
    on_message(
        &sh,
        2,
        r#"{"type":"switch","name":"gravity_m_s2","value":0}"#,
    );
    on_message(
        &sh,
        1,
        r#"{"type":"switch","name":"friction","value":0.25}"#,
    );
    assert_eq!(
        *sh.switches.lock().unwrap(),
        vec![
            (2, "gravity_m_per_s2".to_string(), 0.0),
            (1, "friction".to_string(), 0.25)
        ]
    );
    assert_eq!(sh.refused.load(Ordering::Relaxed), 3);
}

#[test]
fn the_first_page_to_start_is_the_hand_and_the_others_watch() {
    let (sh, r1, r2) = shared(true);
    on_message(&sh, 2, r#"{"type":"start"}"#);
    on_message(&sh, 1, r#"{"type":"start"}"#);
    assert_eq!(last_error(&r2)["role"], "hand");
    assert_eq!(last_error(&r1)["role"], "view");
    let input = r#"{"type":"input","seq":1,"pos":[0.5,0,-0.5],"buttons":1,"t_ms":1}"#;
    on_message(&sh, 1, input);
    assert_eq!(
        last_error(&r1)["message"],
        "another page is the hand: this page watches"
    );
    assert_eq!(sh.input.latest().0.count, 0);
    on_message(&sh, 2, input);
    let (l, at) = sh.input.latest();
    assert!(at.is_some());
    assert_eq!((l.count, l.buttons, l.t_ms), (1, 1, 1.0));
    assert_eq!(l.position_m, page_to_device([0.5, 0.0, -0.5], 0.04));
    // Only the hand ends the session.
    on_message(&sh, 1, r#"{"type":"end"}"#);
    assert!(!sh.end_requested.load(Ordering::Relaxed));
    on_message(&sh, 2, r#"{"type":"end"}"#);
    assert!(sh.end_requested.load(Ordering::Relaxed));
    // Bad input is answered with its field and range, and changes nothing.
    on_message(
        &sh,
        2,
        r#"{"type":"input","seq":2,"pos":[0,0,2],"buttons":0,"t_ms":1}"#,
    );
    let e = last_error(&r2);
    assert_eq!(e["field"], "input.pos[2]");
    assert_eq!(sh.input.latest().0.count, 1);
}

#[test]
fn with_a_device_as_the_hand_the_pages_only_watch() {
    let (sh, r1, _) = shared(false);
    on_message(&sh, 1, r#"{"type":"start"}"#);
    assert_eq!(last_error(&r1)["role"], "view");
    on_message(
        &sh,
        1,
        r#"{"type":"input","seq":1,"pos":[0,0,0],"buttons":0,"t_ms":1}"#,
    );
    assert_eq!(
        last_error(&r1)["message"],
        "a device is the hand in this session: the page only watches"
    );
    assert_eq!(sh.input.latest().0.count, 0);
}

#[test]
fn a_start_before_the_hello_is_refused_by_name_and_a_start_after_it_plays() {
    let (sh, r1, _) = shared(true);
    let link = sh.scene.lock().unwrap().take();
    // The session is not open yet (no scene, no hello): the start is answered, not lost.
    on_message(&sh, 1, r#"{"type":"start"}"#);
    let e = last_error(&r1);
    assert_eq!(e["type"], "error");
    assert_eq!(e["field"], "type");
    assert_eq!(
        e["message"],
        "the session is not open yet: press Start after its hello"
    );
    assert_eq!(*sh.player.lock().unwrap(), None);
    // Once it is open, the same page's start makes it the hand.
    *sh.scene.lock().unwrap() = link;
    on_message(&sh, 1, r#"{"type":"start"}"#);
    assert_eq!(last_error(&r1)["role"], "hand");
}
