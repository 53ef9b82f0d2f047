//! Each kind of mistake in a lesson file is refused with its exact message: the file, line
//! and column, the field and what is allowed. The example of docs/teaching.md reads.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use teaching::parse_lesson;

/// A small valid lesson: one brick step, one nano step.
const GOOD: &str = r#"[lesson]
title = "t"

[[test]]
prompt = "Which force?"
answer = "choice"
choices = ["gravity", "adhesion"]
correct = "adhesion"

[[step]]
id = "throw"
title = "Throw"
scene = "brickworld"
switches = { gravity_m_per_s2 = 0.0, inertia = true }
task = "Throw a brick."
done = { when = "brick_thrown" }
before = { prompt = "What will it do?", answer = "choice", choices = ["fall", "fly"] }

[[step]]
id = "snap"
title = "Snap"
scene = "nanoworld"
task = "Come down."
done = { when = "atom_snapped" }
after = { prompt = "What did you feel?", answer = "text" }
"#;

fn err(text: &str) -> String {
    match parse_lesson(text, "my.lesson.toml", None) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_missing_file_is_named() {
    let e = teaching::load_lesson(std::path::Path::new("no/such.lesson.toml")).unwrap_err();
    assert_eq!(
        e.to_string(),
        "no/such.lesson.toml: lesson: cannot read the file: No such file or directory (os error 2)"
    );
}

#[test]
fn a_good_lesson_reads() {
    let l = parse_lesson(GOOD, "my.lesson.toml", None).unwrap();
    assert_eq!(l.steps.len(), 2);
    assert_eq!(
        l.steps[0].switch_pairs().collect::<Vec<_>>(),
        [("gravity_m_per_s2", 0.0), ("inertia", 1.0)]
    );
}

/// Each mistake, the lesson with it, and the exact message.
fn cases() -> Vec<(&'static str, String, &'static str)> {
    let r = |from: &str, to: &str| GOOD.replace(from, to);
    vec![
        (
            "unknown field",
            r(
                "task = \"Throw a brick.\"",
                "task = \"Throw a brick.\"\ncolour = 1",
            ),
            "my.lesson.toml:16:1: lesson: unknown field `colour`, expected one of `id`, `title`, \
             `scene`, `task`, `switches`, `done`, `locked`, `before`, `after`",
        ),
        (
            "unknown scene",
            r("scene = \"nanoworld\"", "scene = \"moon\""),
            "my.lesson.toml:22:9: lesson: `step[1].scene` = \"moon\": cannot read moon: no such \
             file, and not a built-in scene (built-in: brickworld, nanoworld, optical_tweezers, \
             optical_tweezers_10khz, wall; `nanohaptics scenes export DIR` writes editable copies)",
        ),
        (
            "switch out of range",
            r("gravity_m_per_s2 = 0.0", "gravity_m_per_s2 = 150.0"),
            "my.lesson.toml:14:33: lesson: `step[0].switches.gravity_m_per_s2`: switch \
             `gravity_m_per_s2` = 150 is out of range: allowed 0 ≤ value ≤ 100",
        ),
        (
            "unknown switch",
            r("gravity_m_per_s2 = 0.0", "gravity = 0.0"),
            "my.lesson.toml:14:24: lesson: `step[0].switches.gravity`: the brickworld scene has \
             no switch `gravity` (its switches: gravity_m_per_s2, restitution, friction, inertia, \
             brick_mass_kg)",
        ),
        (
            "unknown condition",
            r("\"brick_thrown\"", "\"brick_kicked\""),
            "my.lesson.toml:16:17: lesson: `step[0].done.when` = \"brick_kicked\" is not a \
             condition (allowed: house_complete, brick_lifted, brick_thrown, brick_placed, \
             atom_snapped, atom_picked_up, atom_pulled_off, atom_put_back, time)",
        ),
        (
            "condition the scene cannot meet",
            r("\"atom_snapped\"", "\"brick_thrown\""),
            "my.lesson.toml:24:17: lesson: `step[1].done.when` = \"brick_thrown\" cannot happen \
             in scene \"nanoworld\": it reads brick.thrown, which a nanoworld scene never emits \
             (allowed in a nanoworld scene: house_complete, atom_snapped, atom_picked_up, \
             atom_pulled_off, atom_put_back, time)",
        ),
        (
            "a condition in a scene without either world",
            r("scene = \"nanoworld\"", "scene = \"wall\""),
            "my.lesson.toml:24:17: lesson: `step[1].done.when` = \"atom_snapped\" cannot happen \
             in scene \"wall\": it reads nano.snap, which a wall scene never emits (allowed in a \
             wall scene: time)",
        ),
        (
            "question without choices",
            r(", choices = [\"fall\", \"fly\"]", ""),
            "my.lesson.toml:17:1: lesson: `step[0].before.choices` is missing: a choice question \
             (answer = \"choice\") lists 2 to 8 choices",
        ),
        (
            "one choice",
            r("[\"fall\", \"fly\"]", "[\"fall\"]"),
            "my.lesson.toml:17:60: lesson: `step[0].before.choices` lists 1 choice: a choice \
             question lists 2 to 8",
        ),
        (
            "correct answer not among the choices",
            r("correct = \"adhesion\"", "correct = \"magnetism\""),
            "my.lesson.toml:8:11: lesson: `test[0].correct` = \"magnetism\" is not one of the \
             choices (allowed: \"gravity\", \"adhesion\")",
        ),
        (
            "empty steps",
            GOOD[..GOOD.find("[[step]]").unwrap()].to_string(),
            "my.lesson.toml:1:2: lesson: `step` lists no steps: a lesson has 1 to 100 steps, \
             each a [[step]] table",
        ),
        (
            "empty steps written out",
            format!("step = []\n{}", &GOOD[..GOOD.find("[[step]]").unwrap()]),
            "my.lesson.toml:1:1: lesson: `step` lists no steps: a lesson has 1 to 100 steps, \
             each a [[step]] table",
        ),
        (
            "a text question with choices",
            r(
                "answer = \"text\"",
                "answer = \"text\", choices = [\"a\", \"b\"]",
            ),
            "my.lesson.toml:25:59: lesson: `step[1].after.choices` is not allowed in a text \
             question (answer = \"text\"); a question with choices has answer = \"choice\"",
        ),
        (
            "a condition without its parameter",
            r("{ when = \"atom_snapped\" }", "{ when = \"time\" }"),
            "my.lesson.toml:24:1: lesson: `step[1].done.seconds` is missing: `time` needs 0 < \
             seconds ≤ 3600",
        ),
        (
            "a parameter the condition does not take",
            r(
                "{ when = \"atom_snapped\" }",
                "{ when = \"atom_snapped\", seconds = 3.0 }",
            ),
            "my.lesson.toml:24:43: lesson: `step[1].done.seconds` is not a parameter of \
             `atom_snapped` (its parameters: none)",
        ),
        (
            "a parameter out of range",
            r(
                "{ when = \"atom_snapped\" }",
                "{ when = \"time\", seconds = -1.0 }",
            ),
            "my.lesson.toml:24:35: lesson: `step[1].done.seconds` = -1 is out of range: allowed \
             0 < seconds ≤ 3600",
        ),
        (
            "a duplicate id",
            r("id = \"snap\"", "id = \"throw\""),
            "my.lesson.toml:20:6: lesson: `step[1].id` = \"throw\" is the id of step[0] too: each \
             step has its own id",
        ),
        (
            "a test question without its correct answer",
            r("correct = \"adhesion\"\n", ""),
            "my.lesson.toml:4:1: lesson: `test[0].correct` is missing: a test question gives its \
             correct answer, one of its choices",
        ),
        (
            "an id that is not one",
            r("id = \"snap\"", "id = \"Snap It\""),
            "my.lesson.toml:20:6: lesson: `step[1].id` = \"Snap It\" is not an id: allowed 1 to \
             64 lower-case letters, digits, - and _",
        ),
        (
            "a switch value that is not a number",
            r("gravity_m_per_s2 = 0.0", "gravity_m_per_s2 = \"zero\""),
            "my.lesson.toml:14:33: lesson: invalid type: string \"zero\", expected a number, or \
             true / false",
        ),
        (
            "an on/off switch given a number between",
            r("inertia = true", "inertia = 0.5"),
            "my.lesson.toml:14:48: lesson: `step[0].switches.inertia`: switch `inertia` = 0.5 is \
             out of range: allowed true / false (1 / 0)",
        ),
        (
            "an empty task",
            r("task = \"Come down.\"", "task = \"  \""),
            "my.lesson.toml:23:8: lesson: `step[1].task` is empty: allowed 1 to 2000 characters",
        ),
    ]
}

#[test]
fn each_mistake_is_named_with_its_line_and_column() {
    for (what, text, want) in cases() {
        assert_eq!(err(&text), want, "{what}");
    }
}

/// A scene file with a mistake: the lesson's field, then the scene file's own place.
#[test]
fn a_scene_file_with_a_mistake_is_named_in_both_files() {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("nh-teaching-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = haptic_loop::builtin::find("nanoworld").unwrap().scene;
    let bad_scene = scene.replace("[loop]\nrate_hz = 1000", "[loop]\nrate_hz = 999");
    assert_ne!(bad_scene, scene);
    std::fs::write(dir.join("bad.toml"), &bad_scene).unwrap();
    let text = GOOD.replace("scene = \"nanoworld\"", "scene = \"bad.toml\"");
    let e = parse_lesson(&text, "my.lesson.toml", Some(&dir))
        .unwrap_err()
        .to_string();
    let bad = dir.join("bad.toml").display().to_string();
    let line = 1 + bad_scene
        .lines()
        .position(|l| l == "rate_hz = 999")
        .unwrap();
    assert_eq!(
        e,
        format!(
            "my.lesson.toml:22:9: lesson: `step[1].scene` = \"bad.toml\": {bad}:{line}:11: scene: \
             `loop.rate_hz` = 999 is out of range: allowed 100 ≤ rate_hz ≤ 20000 with 10^9 / \
             rate_hz a whole number"
        )
    );
}

/// The complete example of docs/teaching.md reads (its first ```toml block).
#[test]
fn the_example_of_the_docs_reads() {
    let doc = include_str!("../../../docs/teaching.md");
    let start = doc.find("```toml\n").expect("a toml block") + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let l =
        parse_lesson(&doc[start..end], "docs/teaching.md", None).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(l.title, "Sticky atoms");
    assert_eq!(l.steps.len(), 3);
    assert_eq!(l.test.len(), 1);
    assert!(l.steps[2].locked);
}

/// The rows of the first Markdown table after `heading` in `doc`, cells trimmed.
fn table_after(doc: &str, heading: &str) -> Vec<Vec<String>> {
    let from = doc.find(heading).expect(heading);
    doc[from..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split(" | ")
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect()
}

/// docs/teaching.md's tables say what the module and the vocabulary are.
#[test]
fn the_tables_of_the_docs_are_the_module_and_the_vocabulary() {
    let doc = include_str!("../../../docs/teaching.md");
    let m = teaching::builtin::module().unwrap();
    let rows = table_after(doc, "## The built-in module");
    assert_eq!(rows.len(), m.steps.len());
    for (i, (row, s)) in rows.iter().zip(&m.steps).enumerate() {
        assert_eq!(row[0], (i + 1).to_string());
        let id = if s.locked {
            format!("`{}` (locked)", s.id)
        } else {
            format!("`{}`", s.id)
        };
        assert_eq!(row[1], id);
        assert!(row[2].starts_with(s.kind), "{row:?}");
        for (name, _) in s.switch_pairs() {
            assert!(row[2].contains(name), "{row:?}");
        }
        assert_eq!(row[2].contains(','), !s.switches.is_empty(), "{row:?}");
        assert!(
            row[4].starts_with(&format!("`{}`", s.done.name())),
            "{row:?}"
        );
    }
    let rows = table_after(doc, "## The condition vocabulary");
    assert_eq!(rows.len(), teaching::condition::WORDS.len());
    for (row, w) in rows.iter().zip(teaching::condition::WORDS.iter()) {
        assert_eq!(row[0], format!("`{}`", w.name));
        let kinds = if w.kinds.is_empty() {
            "every scene".to_string()
        } else {
            w.kinds.join(", ")
        };
        assert_eq!(row[2], kinds);
        for p in w.params {
            assert!(row[1].contains(&format!("`{}`", p.name)), "{row:?}");
        }
    }
}
