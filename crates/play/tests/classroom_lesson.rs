//! A lesson in the classroom without a browser (`classroom --lesson`): two students join and
//! answer through their page links, each step's world runs on the class's workers and
//! completes by itself, and the teacher follows them. The teacher's link shows each student's
//! step, their time on it and their answers as they come. The teacher's "open the next step"
//! reaches both students, and "hold" stops one before a step. A finished step replays from
//! the teacher page. The zip holds every step's recording and the class report, and every
//! recording replays bit for bit.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::class::{Page, TWO_STEP_LESSON, Ws, get, hand, join, read_for, send, start_with, ws};
use recording::read_recording_file;
use serde_json::{Value, json};
use std::sync::atomic::Ordering;

/// The teacher's latest `class` message.
fn class_now(teacher: &mut Ws) -> Value {
    let got = read_for(teacher, 0.4);
    got.into_iter()
        .rev()
        .find(|m| m["type"] == "class")
        .expect("a class message")
}

fn student<'a>(class: &'a Value, name: &str) -> &'a Value {
    class["students"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no {name} in {class}"))
}

/// The names of a stored zip's entries, from their local headers.
fn zip_names(zip: &[u8]) -> Vec<String> {
    let mut names = Vec::new();
    let mut at = 0;
    while at + 30 <= zip.len() && zip[at..at + 4] == 0x0403_4b50u32.to_le_bytes() {
        let u16_at = |k: usize| usize::from(u16::from_le_bytes([zip[at + k], zip[at + k + 1]]));
        let size = u32::from_le_bytes(zip[at + 18..at + 22].try_into().unwrap()) as usize;
        let (n, extra) = (u16_at(26), u16_at(28));
        names.push(String::from_utf8(zip[at + 30..at + 30 + n].to_vec()).unwrap());
        at += 30 + n + extra + size;
    }
    names
}

#[test]
fn a_class_takes_a_lesson_the_teacher_follows_opens_and_holds() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-class-lesson-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two.lesson.toml");
    std::fs::write(&file, TWO_STEP_LESSON).unwrap();
    let lesson = teaching::load_lesson(&file).unwrap();
    let c = start_with("lesson", 4, Some(lesson));
    let host = c.host.clone();
    assert!(get(&host, "/").contains("Lesson: <b>Two worlds</b>"));
    let (ada, bo) = (join(&host, "Ada"), join(&host, "Bo"));
    let mut pa = Page::new(ws(&host, &format!("/ws?s={ada}")));
    let mut pb = Page::new(ws(&host, &format!("/ws?s={bo}")));
    let mut teacher = ws(&host, "/teacher/ws?code=TEACH123");

    // Both begin with the pre-test: no world yet, so no hello.
    for p in [&mut pa, &mut pb] {
        let got = p.until_place("pre_test");
        assert!(got.iter().all(|m| m["type"] != "hello"), "{got:?}");
    }
    send(&mut pa.ws, json!({"type": "answer", "choice": 1}));
    send(&mut pb.ws, json!({"type": "answer", "choice": 0}));
    // The step's world opens for each: its hello, then Start.
    let (mut sa, mut sb) = (0, 0);
    for (p, seq) in [(&mut pa, &mut sa), (&mut pb, &mut sb)] {
        p.until_place("doing");
        assert_eq!(p.hello_kind(), "brickworld");
        send(&mut p.ws, json!({"type": "start"}));
        hand(p, seq);
    }
    // The 0.3 s step completes by itself; each is asked what they noticed.
    pa.until_place("after");
    pb.until_place("after");
    // The teacher sees both on step 1, after its task, with their time on it and the
    // pre-test answers as they came.
    let class = class_now(&mut teacher);
    assert_eq!(class["lesson"]["title"], "Two worlds");
    assert_eq!(
        class["lesson"]["steps"],
        json!([
            {"id": "float", "title": "No gravity", "locked": false},
            {"id": "atoms", "title": "Atoms", "locked": true}
        ])
    );
    for (name, right) in [("Ada", 1), ("Bo", 0)] {
        let l = &student(&class, name)["lesson"];
        assert_eq!(l["place"], "after", "{l}");
        assert_eq!(l["step_id"], "float");
        assert_eq!(l["done"], json!(["float"]));
        assert_eq!(l["pre"], json!([right, 1]));
        let on = l["on_step_s"].as_f64().unwrap();
        assert!(on > 0.25 && on < 30.0, "{on}");
        let a = &l["answers"][0];
        assert_eq!(a["at"], "pre-test 1");
        assert_eq!(
            a["answer"],
            ["Their weight", "Surface attraction"][right as usize]
        );
        assert_eq!(student(&class, name)["steps_run"], json!(["float"]));
    }
    // Ada says what she saw and reaches the locked step: she waits there; Bo stays at step 1.
    send(
        &mut pa.ws,
        json!({"type": "answer", "text": "they floated"}),
    );
    pa.until_place("waiting");
    let class = class_now(&mut teacher);
    let l = &student(&class, "Ada")["lesson"];
    assert_eq!(
        (l["place"].as_str(), l["step"].as_u64()),
        (Some("waiting"), Some(1))
    );
    assert_eq!(l["answers"][1]["at"], "float, after");
    assert_eq!(l["answers"][1]["answer"], "they floated");
    assert_eq!(student(&class, "Bo")["lesson"]["place"], "after");
    // In a lesson, each step sets its own switches: the teacher's switch is refused.
    send(
        &mut teacher,
        json!({"type": "switch", "name": "friction", "value": 0.5}),
    );
    // The teacher opens the next step: it reaches both.
    send(&mut teacher, json!({"type": "open_next"}));
    let r = read_for(&mut teacher, 0.5);
    assert!(
        r.iter().any(|m| m["type"] == "error"
            && m["message"]
                == "in a lesson each step sets its own switches: open or hold steps instead"),
        "{r:?}"
    );
    assert!(
        r.iter().any(|m| m["type"] == "done"
            && m["message"] == "step 2 (atoms) is open for everyone: 2 students told"),
        "{r:?}"
    );
    pa.until_place("doing");
    assert_eq!(pa.hello_kind(), "nanoworld");
    hand(&mut pa, &mut sa);
    pa.until_place("post_test");
    send(&mut pa.ws, json!({"type": "answer", "choice": 1}));
    pa.until_place("finished");
    // Every step is open now: "open the next step" says so.
    send(&mut teacher, json!({"type": "open_next"}));
    // The teacher holds the class before the atoms again: Bo, who has not entered it, waits
    // there once he answers.
    send(&mut teacher, json!({"type": "hold_step", "step": "atoms"}));
    send(&mut teacher, json!({"type": "hold_step", "step": "nope"}));
    let r = read_for(&mut teacher, 0.5);
    assert!(
        r.iter()
            .any(|m| m["type"] == "error" && m["message"] == "every step of the lesson is open"),
        "{r:?}"
    );
    assert!(
        r.iter().any(|m| m["type"] == "done"
            && m["message"] == "the class is held before step 2 (atoms): 1 students told"),
        "{r:?}"
    );
    assert!(
        r.iter().any(|m| m["type"] == "error"
            && m["field"] == "step"
            && m["message"] == "step `nope` is not in the lesson (its steps: float, atoms)"),
        "{r:?}"
    );
    send(
        &mut pb.ws,
        json!({"type": "answer", "text": "nothing fell"}),
    );
    pb.until_place("waiting");
    let class = class_now(&mut teacher);
    let a = &student(&class, "Ada")["lesson"];
    assert_eq!(a["place"], "finished");
    assert_eq!(
        (a["pre"].clone(), a["post"].clone()),
        (json!([1, 1]), json!([1, 1]))
    );
    assert_eq!(a["done"], json!(["float", "atoms"]));
    assert_eq!(student(&class, "Ada")["status"]["phase"], "ended");
    let b = &student(&class, "Bo")["lesson"];
    assert_eq!(
        (b["place"].as_str(), b["step"].as_u64()),
        (Some("waiting"), Some(1))
    );
    assert_eq!(class["lesson"]["steps"][1]["locked"], true);

    // A finished step replays from the teacher page; one not run is refused with the reason.
    let index = get(
        &host,
        &format!("/replay/index.json?s={ada}&step=atoms&code=TEACH123"),
    );
    assert!(index.starts_with("HTTP/1.1 200 OK"), "{index}");
    let index: Value = serde_json::from_str(index.split("\r\n\r\n").nth(1).unwrap()).unwrap();
    assert_eq!(index["ticks"], 200, "0.2 s at 1 kHz, met on its last tick");
    let not_run = get(
        &host,
        &format!("/replay/index.json?s={bo}&step=atoms&code=TEACH123"),
    );
    assert!(not_run.starts_with("HTTP/1.1 409 Conflict"), "{not_run}");
    assert!(not_run.contains(
        "Bo has no finished step `atoms` yet: a step can be replayed once its world has closed"
    ));
    let no_step = get(&host, &format!("/replay?s={bo}&code=TEACH123"));
    assert!(no_step.starts_with("HTTP/1.1 400"), "{no_step}");

    // The zip: the class report as it stands and every closed step's recording.
    let zip = common::class::get_bytes(&host, "/recordings.zip?code=TEACH123");
    let at = zip.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    assert!(zip.starts_with(b"HTTP/1.1 200 OK\r\nContent-Type: application/zip"));
    let mut names = zip_names(&zip[at + 4..]);
    names.sort();
    let folder = |n: &str| {
        names
            .iter()
            .find(|f| f.starts_with(&format!("{n}-")) && f.ends_with("/float.mcap"))
            .map(|f| f.trim_end_matches("/float.mcap").to_string())
            .unwrap_or_else(|| panic!("{n}'s folder in {names:?}"))
    };
    let (fa, fb) = (folder("Ada"), folder("Bo"));
    use teaching::class_report::{MARKDOWN, STEPS_CSV, TEST_CHART, TESTS_CSV, TIME_CHART};
    let mut want: Vec<String> = [MARKDOWN, STEPS_CSV, TESTS_CSV, TIME_CHART, TEST_CHART]
        .map(String::from)
        .to_vec();
    want.extend([
        format!("{fa}/atoms.mcap"),
        format!("{fa}/float.mcap"),
        format!("{fb}/float.mcap"),
    ]);
    want.sort();
    assert_eq!(names, want);

    c.stop.store(true, Ordering::Relaxed);
    let summary = c.handle.join().unwrap().unwrap();
    // One session per step's world: Ada's two, Bo's one, each completed by its condition.
    let mut runs: Vec<(String, String, u64)> = summary
        .students
        .iter()
        .map(|s| {
            (
                s.name.clone(),
                s.step.clone().unwrap(),
                s.session.stats.ticks,
            )
        })
        .collect();
    runs.sort();
    assert_eq!(
        runs,
        [
            ("Ada".into(), "atoms".into(), 200),
            ("Ada".into(), "float".into(), 300),
            ("Bo".into(), "float".into(), 300)
        ]
    );
    for s in &summary.students {
        assert_eq!(s.session.end, "completed", "{}", s.line());
        let rec = read_recording_file(&s.session.recording, false).unwrap();
        let v = haptic_loop::replay::verify(&rec).unwrap();
        assert!(v.ok(), "{}: {:?}", s.line(), v);
        assert_eq!(v.ticks, s.session.stats.ticks);
    }
    // The class report written at the end: each student's row of each step.
    let steps = std::fs::read_to_string(c.dir.join("class-steps.csv")).unwrap();
    let rows: Vec<Vec<&str>> = steps
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(7).collect())
        .collect();
    assert_eq!(
        rows,
        [
            ["Ada", "1", "float", "No gravity", "done", "0.3", "0.299"],
            ["Ada", "2", "atoms", "Atoms", "done", "0.2", "0.199"],
            ["Bo", "1", "float", "No gravity", "done", "0.3", "0.299"],
            ["Bo", "2", "atoms", "Atoms", "waiting", "0", ""],
        ]
    );
    assert!(steps.lines().nth(1).unwrap().ends_with(",they floated"));
    let tests = std::fs::read_to_string(c.dir.join("class-tests.csv")).unwrap();
    assert!(tests.contains("Bo,pre,1,Which force holds a few atoms to a surface?,Their weight,no"));
    assert!(
        tests.contains(
            "Ada,post,1,Which force holds a few atoms to a surface?,Surface attraction,yes"
        )
    );
    assert!(
        summary
            .report
            .iter()
            .any(|p| p.ends_with("class-report.md"))
    );
    let _ = std::fs::remove_dir_all(&c.dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_lesson_at_two_rates_or_with_a_session_length_is_refused() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-class-rates-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("rates.lesson.toml");
    std::fs::write(
        &file,
        "[lesson]\ntitle = \"Rates\"\n\
         [[step]]\nid = \"a\"\ntitle = \"A\"\nscene = \"brickworld\"\ntask = \"t\"\n\
         done = { when = \"time\", seconds = 1.0 }\n\
         [[step]]\nid = \"b\"\ntitle = \"B\"\nscene = \"optical_tweezers_10khz\"\ntask = \"t\"\n\
         done = { when = \"time\", seconds = 1.0 }\n",
    )
    .unwrap();
    let mut c = play::classroom::ClassConfig::new(
        haptic_loop::session::SceneSource::resolve("brickworld".as_ref()).unwrap(),
        dir.join("class"),
    );
    c.port = 0;
    c.lesson = Some(teaching::load_lesson(&file).unwrap());
    let stop = std::sync::atomic::AtomicBool::new(false);
    let e = play::classroom::run(&c, &stop, &mut |_| panic!("served")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "lesson: step `a` ticks at 1000 Hz and step `b` at 10000 Hz: a class ticks every \
         session on one schedule, so every step must tick at the same rate"
    );
    // A session length has no meaning in a lesson: refused, not ignored.
    c.lesson = Some(teaching::builtin::module().unwrap());
    c.seconds = Some(60.0);
    let e = play::classroom::run(&c, &stop, &mut |_| panic!("served")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "--seconds does not apply to a lesson: each step ends when its condition is met, and \
         the lesson when the student finishes it or is ended"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
