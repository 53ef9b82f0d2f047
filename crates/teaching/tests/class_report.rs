//! The class report: two students, one through the whole lesson and one stopped at step 2;
//! every row of both CSV files, the page's tables and figures, and the charts written.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use teaching::class_report::{
    self, MARKDOWN, STEPS_CSV, StepFigures, StudentRecord, TEST_CHART, TESTS_CSV, TIME_CHART,
};
use teaching::{Answer, Lesson, Progress, parse_lesson};

const LESSON: &str = r#"
[lesson]
title = "Sticky atoms"

[[test]]
prompt = "What happens just before a tip touches a surface?"
answer = "choice"
choices = ["Nothing", "It jumps into contact", "It is pushed away"]
correct = "It jumps into contact"

[[test]]
prompt = "Can you always put an atom back where it was?"
answer = "choice"
choices = ["Yes", "No"]
correct = "No"

[[step]]
id = "drop"
title = "Drop a brick"
scene = "brickworld"
task = "Hold a brick for two seconds."
done = { when = "time", seconds = 2.0 }
before = { prompt = "What will the brick do?", answer = "choice", choices = ["Fall", "Float"] }
after = { prompt = "What did you notice?", answer = "text" }

[[step]]
id = "snap"
title = "Snap to contact"
scene = "nanoworld"
task = "Come down slowly."
done = { when = "time", seconds = 1.0 }
after = { prompt = "What did you feel?", answer = "text" }
"#;

fn lesson() -> Lesson {
    parse_lesson(LESSON, "sticky.toml", None).unwrap_or_else(|e| panic!("{e}"))
}

/// Ticks the task now `n` times, the last meeting the condition.
fn do_task(p: &mut Progress, n: u64) {
    for k in 0..n {
        p.tick(k + 1 == n).unwrap();
    }
}

#[test]
fn the_report_holds_every_students_place_times_forces_scores_and_answers() {
    let l = lesson();
    let brick_hz = l.steps[0].rate_hz;
    let nano_hz = l.steps[1].rate_hz;
    // Ada: pre-test 1 of 2, the whole lesson, post-test 2 of 2.
    let mut ada = Progress::new(&l);
    ada.answer(Answer::Choice(0)).unwrap();
    ada.answer(Answer::Choice(1)).unwrap();
    ada.answer(Answer::Choice(0)).unwrap();
    do_task(&mut ada, 3 * u64::from(brick_hz));
    ada.answer(Answer::Text("it fell, fast\n\"really\"".into()))
        .unwrap();
    do_task(&mut ada, u64::from(nano_hz) / 2);
    ada.answer(Answer::Text("=a pull".into())).unwrap();
    ada.answer(Answer::Choice(1)).unwrap();
    ada.answer(Answer::Choice(1)).unwrap();
    // Bo: both pre-test questions right, step 1 done in 1 s, now doing step 2.
    let mut bo = Progress::new(&l);
    bo.answer(Answer::Choice(1)).unwrap();
    bo.answer(Answer::Choice(1)).unwrap();
    bo.answer(Answer::Choice(1)).unwrap();
    do_task(&mut bo, u64::from(brick_hz));
    bo.answer(Answer::Text("<b>floats</b> | up".into()))
        .unwrap();
    for _ in 0..11 {
        bo.tick(false).unwrap();
    }
    let fa = [
        StepFigures {
            peak_force_n: Some(2.5),
            score: Some(40.0),
        },
        StepFigures {
            peak_force_n: Some(0.75),
            score: None,
        },
    ];
    let fb = [StepFigures {
        peak_force_n: Some(3.5),
        score: Some(60.0),
    }];
    let students = [
        StudentRecord {
            name: "Ada",
            progress: &ada,
            figures: &fa,
        },
        StudentRecord {
            name: "Bo, B.",
            progress: &bo,
            figures: &fb,
        },
    ];
    let r = class_report::class_report(&l, &students);

    let nano_s = |ticks: u64| world_form::fmt_num(ticks as f64 / f64::from(nano_hz));
    assert_eq!(
        r.steps_csv,
        format!(
            "student,step,step_id,step_title,state,seconds,met_at_s,peak_force_n,score,before,after\n\
             Ada,1,drop,Drop a brick,done,3,{},2.5,40,Fall,\"it fell, fast\n\"\"really\"\"\"\n\
             Ada,2,snap,Snap to contact,done,{},{},0.75,,,'=a pull\n\
             \"Bo, B.\",1,drop,Drop a brick,done,1,{},3.5,60,Float,<b>floats</b> | up\n\
             \"Bo, B.\",2,snap,Snap to contact,doing,{},,,,,\n",
            world_form::fmt_num((3 * u64::from(brick_hz) - 1) as f64 / f64::from(brick_hz)),
            nano_s(u64::from(nano_hz) / 2),
            nano_s(u64::from(nano_hz) / 2 - 1),
            world_form::fmt_num((u64::from(brick_hz) - 1) as f64 / f64::from(brick_hz)),
            nano_s(11),
        )
    );
    let tests: Vec<&str> = r.tests_csv.lines().collect();
    assert_eq!(tests[0], "student,test,question,prompt,answer,correct");
    assert_eq!(
        tests[1],
        "Ada,pre,1,What happens just before a tip touches a surface?,Nothing,no"
    );
    assert_eq!(
        tests[2],
        "Ada,pre,2,Can you always put an atom back where it was?,No,yes"
    );
    assert_eq!(
        tests[3],
        "Ada,post,1,What happens just before a tip touches a surface?,It jumps into contact,yes"
    );
    assert_eq!(
        tests[7],
        "\"Bo, B.\",post,1,What happens just before a tip touches a surface?,,"
    );
    assert_eq!(tests.len(), 9);

    let m = &r.markdown;
    assert!(
        m.starts_with(
            "# Class report: Sticky atoms\n\n2 students, a lesson of 2 steps and 2 test questions."
        ),
        "{m}"
    );
    assert!(
        m.contains("| Ada | the end of the lesson | 2 of 2 | 3.5 | 1 of 2 | 2 of 2 |"),
        "{m}"
    );
    assert!(
        m.contains(&format!(
            "| Bo, B. | step 2, doing the task | 1 of 2 | {} | 2 of 2 | – |",
            world_form::fmt_num(((1.0 + 11.0 / f64::from(nano_hz)) * 10.0).round() / 10.0)
        )),
        "{m}"
    );
    // Step 1: both done, 3 s and 1 s (median 2), forces 2.5 and 3.5 N, scores 40 and 60.
    assert!(
        m.contains("| 1. Drop a brick | 2 | 2 | 1 | 3 | 3 | 3.5 | 50 |"),
        "{m}"
    );
    assert!(
        m.contains("| 2. Snap to contact | 1 | 0.5 | 0.5 | 0.5 | 0.75 | 0.75 | – |"),
        "{m}"
    );
    // The tests: Q1 right 0 of 2 before, 1 of 1 after.
    assert!(m.contains("| 1. What happens just before a tip touches a surface? | It jumps into contact | 1 of 2 | 1 of 1 |"), "{m}");
    assert!(m.contains("The 1 student who took both: 1 correct answers per student before, 2 after (a change of 1)."), "{m}");
    // The answers: the choices counted, the texts shown as text.
    assert!(m.contains("| Fall | 1 |\n| Float | 1 |"), "{m}");
    assert!(
        m.contains("- **Bo, B.**: &lt;b&gt;floats&lt;/b&gt; \\| up"),
        "{m}"
    );
    assert!(m.contains("- **Ada**: it fell, fast \"really\""), "{m}");
    assert!(
        m.contains("### Step 2, Snap to contact: What did you feel? (after)\n\n- **Ada**: =a pull"),
        "{m}"
    );
    assert!(m.contains(&format!("]({TIME_CHART})")) && m.contains(&format!("]({TEST_CHART})")));

    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("class-report");
    let _ = std::fs::remove_dir_all(&dir);
    let files = r.write(&dir).unwrap();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [STEPS_CSV, TESTS_CSV, MARKDOWN, TIME_CHART, TEST_CHART]
    );
    for f in &files[3..] {
        let b = std::fs::read(f).unwrap();
        assert_eq!(&b[1..4], b"PNG");
        assert!(b.len() > 5000, "{}: {} bytes", f.display(), b.len());
    }
    assert_eq!(std::fs::read_to_string(&files[0]).unwrap(), r.steps_csv);
}

#[test]
fn a_class_with_nobody_done_gives_a_report_without_charts() {
    let l = lesson();
    let p = Progress::new(&l);
    let r = class_report::class_report(
        &l,
        &[StudentRecord {
            name: "Cy",
            progress: &p,
            figures: &[],
        }],
    );
    assert!(
        r.markdown
            .contains("| Cy | pre-test question 1 | 0 of 2 | 0 | – | – |"),
        "{}",
        r.markdown
    );
    assert!(
        r.markdown
            .contains("| 1. Drop a brick | 0 | – | – | – | – | – | – |")
    );
    assert!(!r.markdown.contains("!["));
    assert!(r.markdown.contains("No answers yet."));
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("class-report-empty");
    let files = r.write(&dir).unwrap();
    assert_eq!(files.len(), 3);
}

#[test]
fn the_median_is_the_middle_or_the_mean_of_the_middle_two() {
    use class_report::median;
    assert_eq!(median(&[]), None);
    assert_eq!(median(&[3.0]), Some(3.0));
    assert_eq!(median(&[3.0, 1.0]), Some(2.0));
    assert_eq!(median(&[5.0, 1.0, 3.0]), Some(3.0));
    assert_eq!(median(&[f64::NAN, 1.0]), Some(1.0));
}

#[test]
fn one_student_one_step_is_said_in_the_singular() {
    let mut l = lesson();
    l.steps.truncate(1);
    l.test.truncate(1);
    let p = Progress::new(&l);
    let r = class_report::class_report(
        &l,
        &[StudentRecord {
            name: "Di",
            progress: &p,
            figures: &[],
        }],
    );
    assert!(
        r.markdown.starts_with(
            "# Class report: Sticky atoms\n\n1 student, a lesson of 1 step and 1 test question.\n"
        ),
        "{}",
        r.markdown
    );
}
