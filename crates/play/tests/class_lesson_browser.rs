//! A lesson in the classroom, in real browsers (Debian's headless `chromium`, through the
//! DevTools Protocol): a student joins on the join page and takes the lesson by keyboard
//! alone, a second student takes it through a page link and stops at step 1, and the teacher
//! page (in a second browser) follows both. It shows each student's step and their answers as
//! they come. Its "Open the next step" reaches both. A student's finished step plays again
//! from its Watch link, and the zip holds the class report and every step's recording. The
//! screenshot of the teacher page goes to the target folder's `tmp/figures/play/`
//! (`scripts/figures.sh` writes it to docs/figures/play/).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::cdp::Browser;
use common::class::{Page, TWO_STEP_LESSON, hand, join, send, start_with, ws};
use common::figures;
use recording::read_recording_file;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::thread::sleep;
use std::time::Duration;

fn place_is(b: &mut Browser, place: &str) {
    b.wait_for(
        &format!("!!window.__play && window.__play.lesson !== null && window.__play.lesson.place === '{place}'"),
        20.0,
    )
    .unwrap();
}

/// Chooses the `i`-th choice of the radio group in focus by keyboard and submits with Enter.
fn choose(b: &mut Browser, i: usize) {
    assert_eq!(b.eval("document.activeElement.type").unwrap(), "radio");
    if i == 0 {
        b.press(" ");
    }
    for _ in 0..i {
        b.press("ArrowDown");
    }
    b.press("Enter");
}

/// Types `text` into the focused element, key by key.
fn type_text(b: &mut Browser, text: &str) {
    for c in text.chars() {
        b.press(&c.to_string());
    }
}

/// The teacher page's rows: name, state, step, and the answers table's rows.
fn teacher_rows(t: &mut Browser) -> Value {
    t.eval("[[...document.querySelectorAll('#students tbody tr')].map(r => [r.children[0].textContent, r.children[1].textContent, r.children[2].textContent]), [...document.querySelectorAll('#answers tbody tr')].map(r => [...r.children].map(c => c.textContent))]").unwrap()
}

#[test]
fn the_teacher_page_follows_a_class_through_a_lesson() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-class-lesson-browser-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two.lesson.toml");
    std::fs::write(&file, TWO_STEP_LESSON).unwrap();
    let c = start_with(
        "lesson-browser",
        4,
        Some(teaching::load_lesson(&file).unwrap()),
    );
    let host = c.host.clone();
    let mut s = Browser::launch(1100, 700).unwrap_or_else(|e| panic!("{e}"));
    let mut t = Browser::launch(1280, 900).unwrap_or_else(|e| panic!("{e}"));
    t.open(&c.addr.teacher_url).unwrap();

    // Ada joins by keyboard: her name typed in the focused field, Enter.
    s.open(&c.addr.student_url).unwrap();
    s.wait_for(
        "document.activeElement === document.querySelector('input[name=name]')",
        10.0,
    )
    .unwrap();
    type_text(&mut s, "Ada");
    s.press("Enter");
    place_is(&mut s, "pre_test");
    choose(&mut s, 1);
    // Bo takes the lesson through a page link: the pre-test wrong, then step 1's world.
    let bo = join(&host, "Bo");
    let mut pb = Page::new(ws(&host, &format!("/ws?s={bo}")));
    pb.until_place("pre_test");
    send(&mut pb.ws, json!({"type": "answer", "choice": 0}));
    pb.until_place("doing");
    assert_eq!(pb.hello_kind(), "brickworld");
    send(&mut pb.ws, json!({"type": "start"}));
    hand(&mut pb, &mut 0);

    // Ada: Start by Enter; the 0.3 s step completes by itself; what she noticed, typed.
    place_is(&mut s, "doing");
    s.wait_for("window.__play.hello !== null && !document.getElementById('go').disabled && document.activeElement === document.getElementById('go')", 10.0).unwrap();
    s.press("Enter");
    place_is(&mut s, "after");
    type_text(&mut s, "they floated");
    s.press("Tab");
    s.press("Enter");
    // The next step is locked: she waits for the teacher.
    place_is(&mut s, "waiting");
    pb.until_place("after");

    // The teacher page: both students, their steps, the answers as they came.
    t.wait_for(
        "[...document.querySelectorAll('#students tbody tr')].some(r => r.children[2].textContent.includes('waiting for you')) && document.querySelectorAll('#answers tbody tr').length === 3 && [...document.querySelectorAll('#students tbody tr')].some(r => r.children[2].textContent.includes('saying what they noticed'))",
        20.0,
    )
    .unwrap();
    let seen = teacher_rows(&mut t);
    assert_eq!(
        seen[0],
        json!([
            ["Ada", "playing", "2 of 2 · Atoms · waiting for you"],
            [
                "Bo",
                "playing",
                "1 of 2 · No gravity · saying what they noticed"
            ]
        ])
    );
    let prompt = "Which force holds a few atoms to a surface?";
    assert_eq!(
        seen[1],
        json!([
            ["Ada", "pre-test 1", prompt, "Surface attraction"],
            [
                "Ada",
                "float, after",
                "What did the bricks do?",
                "they floated"
            ],
            ["Bo", "pre-test 1", prompt, "Their weight"]
        ])
    );
    assert_eq!(
        t.eval("[document.getElementById('open-next').textContent, [...document.querySelectorAll('#lesson-steps li')].map(l => [l.textContent, l.className])]").unwrap(),
        json!(["Open the next step (Atoms)", [["No gravity: Bo", ""], ["Atoms: Ada", "locked"]]])
    );
    sleep(Duration::from_millis(300));
    assert!(
        t.eval("document.getElementById('summary').textContent")
            .unwrap()
            .as_str()
            .unwrap()
            .starts_with("2 joined, 2 playing, 0 ended"),
        "a closed step is not an ended session"
    );
    t.screenshot(&figures().join("teacher-lesson.png")).unwrap();

    // "Open the next step" reaches both: Ada goes on to the atoms; Bo's progress has it open.
    t.eval("document.getElementById('open-next').click()")
        .unwrap();
    t.wait_for(
        "document.getElementById('said').textContent === 'step 2 (atoms) is open for everyone: 2 students told'",
        10.0,
    )
    .unwrap();
    place_is(&mut s, "post_test");
    choose(&mut s, 1);
    place_is(&mut s, "finished");
    send(
        &mut pb.ws,
        json!({"type": "answer", "text": "nothing fell"}),
    );
    let got = pb.until_place("doing");
    assert!(
        got.iter().all(|m| m["place"] != "waiting"),
        "Bo did not wait: the step was opened for him too"
    );
    pb.until_place("post_test");
    t.wait_for(
        "[...document.querySelectorAll('#students tbody tr')].some(r => r.children[0].textContent === 'Ada' && r.children[2].textContent === 'the end of the lesson') && document.getElementById('open-next').disabled && document.querySelectorAll('a.watch-step').length === 4",
        20.0,
    )
    .unwrap();

    // Ada's finished step plays again from its Watch link.
    let watch = t
        .eval("[...document.querySelectorAll('a.watch-step')].map(a => [a.textContent, a.href])")
        .unwrap();
    let watch = watch.as_array().unwrap();
    let names: Vec<&str> = watch.iter().map(|w| w[0].as_str().unwrap()).collect();
    assert_eq!(
        names,
        ["Watch float", "Watch atoms", "Watch float", "Watch atoms"]
    );
    // The zip from the page's own link: the report's five files and four recordings.
    let zip = t
        .eval("fetch(document.getElementById('zip').href).then(r => r.arrayBuffer()).then(a => { const v = new DataView(a); return v.getUint16(a.byteLength - 12, true); })")
        .unwrap();
    assert_eq!(zip, 9, "five report files and four step recordings");
    t.open(watch[1][1].as_str().unwrap()).unwrap();
    t.wait_for("window.__replay && window.__replay.ready", 30.0)
        .unwrap();
    assert_eq!(t.eval("__replay.index.ticks").unwrap(), 200);
    s.check().unwrap();
    t.check().unwrap();

    c.stop.store(true, Ordering::Relaxed);
    let summary = c.handle.join().unwrap().unwrap();
    let mut runs: Vec<(String, String, &str)> = summary
        .students
        .iter()
        .map(|st| (st.name.clone(), st.step.clone().unwrap(), st.session.end))
        .collect();
    runs.sort();
    assert_eq!(
        runs,
        [
            ("Ada".into(), "atoms".into(), "completed"),
            ("Ada".into(), "float".into(), "completed"),
            ("Bo".into(), "atoms".into(), "completed"),
            ("Bo".into(), "float".into(), "completed"),
        ]
    );
    for st in &summary.students {
        let rec = read_recording_file(&st.session.recording, false).unwrap();
        assert!(
            haptic_loop::replay::verify(&rec).unwrap().ok(),
            "{}",
            st.line()
        );
    }
    let _ = std::fs::remove_dir_all(&c.dir);
    let _ = std::fs::remove_dir_all(&dir);
}
