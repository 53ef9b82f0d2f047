//! The class report (`docs/teaching.md`, "The class report"): where each student is, the time
//! each spent on each step, the largest force they felt and their score there, every answer,
//! and the pre- and post-test results, as two CSV files for a spreadsheet and a Markdown page
//! with two charts.
//!
//! It is made from the students' [`Progress`] and what their sessions measured on each step
//! ([`StepFigures`]); it reads no clock and no file, so the same class gives the same report.

use crate::cells::{csv, csv_num, md};
use crate::file::{Lesson, Question, QuestionKind};
use crate::progress::{Answer, Place, Progress, describe};
use chart::{Bar, BarChart, Scale};
use std::path::{Path, PathBuf};
use world_form::fmt_num;

/// The report's files, as [`ClassReport::write`] names them.
pub const STEPS_CSV: &str = "class-steps.csv";
/// The tests' answers, one row per student and question.
pub const TESTS_CSV: &str = "class-tests.csv";
/// The Markdown page.
pub const MARKDOWN: &str = "class-report.md";
/// The chart of the median time per step.
pub const TIME_CHART: &str = "class-time-per-step.png";
/// The chart of the share of correct answers per test question, before and after.
pub const TEST_CHART: &str = "class-pre-post.png";

/// The charts' size, px.
const CHART_PX: (u32, u32) = (900, 420);

/// What a student's session measured on one step, beside the progress.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepFigures {
    /// The largest force the student felt on the step, N (`None`: not measured, not reached).
    pub peak_force_n: Option<f64>,
    /// The world's score at the step's end, if its scene scores (the brick house, 0–100).
    pub score: Option<f64>,
}

/// One student, as the report reads them.
#[derive(Clone, Copy, Debug)]
pub struct StudentRecord<'a> {
    /// The name they joined with.
    pub name: &'a str,
    /// Their way through the lesson.
    pub progress: &'a Progress,
    /// What their sessions measured, by step (shorter than the lesson: the rest unmeasured).
    pub figures: &'a [StepFigures],
}

/// The report, made; [`ClassReport::write`] puts it in a folder.
#[derive(Clone, Debug)]
pub struct ClassReport {
    /// One row per student and step: where they are on it, the time, the force, the score and
    /// the answers before and after.
    pub steps_csv: String,
    /// One row per student, test (pre or post) and question: the answer and whether it is
    /// correct.
    pub tests_csv: String,
    /// The page: where each student is, time per step, forces, scores, the tests, the answers.
    pub markdown: String,
    time_chart: Option<BarChart>,
    test_chart: Option<BarChart>,
}

/// Why the report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportWriteError {
    /// A file could not be written.
    #[error("cannot write {path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        reason: String,
    },
    /// A chart could not be drawn.
    #[error("cannot draw {path}: {reason}")]
    Chart {
        /// The chart's file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
}

impl ClassReport {
    /// Writes the two CSV files, the page and its charts (those with data) into `dir` (made if
    /// missing); returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, ReportWriteError> {
        let io = |path: &Path, e: std::io::Error| ReportWriteError::Io {
            path: path.to_path_buf(),
            reason: e.to_string(),
        };
        std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
        let mut written = Vec::new();
        for (name, text) in [
            (STEPS_CSV, &self.steps_csv),
            (TESTS_CSV, &self.tests_csv),
            (MARKDOWN, &self.markdown),
        ] {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|e| io(&p, e))?;
            written.push(p);
        }
        for (name, chart) in [
            (TIME_CHART, &self.time_chart),
            (TEST_CHART, &self.test_chart),
        ] {
            if let Some(c) = chart {
                let p = dir.join(name);
                c.write_png(&p, CHART_PX.0, CHART_PX.1)
                    .map_err(|e| ReportWriteError::Chart {
                        path: p.clone(),
                        reason: e.to_string(),
                    })?;
                written.push(p);
            }
        }
        Ok(written)
    }
}

/// Where a student is on step `s`, in a word: `done`, `waiting` (locked, for the teacher),
/// `before` / `doing` / `after` (there now), or `not reached`.
pub fn step_state(p: &Progress, s: usize) -> &'static str {
    match p.place() {
        Place::Waiting(x) if x == s => "waiting",
        Place::Before(x) if x == s => "before",
        Place::Doing(x) if x == s => "doing",
        Place::After(x) if x == s => "after",
        _ if p.steps().get(s).is_some_and(|r| r.met_at.is_some()) => "done",
        _ => "not reached",
    }
}

/// An answer in words: the choice's text, or the text.
pub fn answer_text(q: &Question, a: &Answer) -> String {
    match (&q.kind, a) {
        (QuestionKind::Choice { choices, .. }, Answer::Choice(i)) => {
            choices.get(*i).cloned().unwrap_or_default()
        }
        (_, Answer::Text(t)) => t.clone(),
        (QuestionKind::Text, Answer::Choice(i)) => format!("choice {i}"),
    }
}

/// Whether `a` is `q`'s correct choice (`None`: the question has no correct answer).
fn correct(q: &Question, a: &Answer) -> Option<bool> {
    match (&q.kind, a) {
        (
            QuestionKind::Choice {
                correct: Some(k), ..
            },
            Answer::Choice(i),
        ) => Some(i == k),
        (
            QuestionKind::Choice {
                correct: Some(_), ..
            },
            Answer::Text(_),
        ) => Some(false),
        _ => None,
    }
}

/// The seconds student `p` spent doing step `s`'s task.
fn seconds(lesson: &Lesson, p: &Progress, s: usize) -> f64 {
    let ticks = p.steps().get(s).map_or(0, |r| r.ticks);
    ticks as f64 / f64::from(lesson.steps[s].rate_hz.max(1))
}

/// The median of `v` (the mean of the middle two for an even count); `None` when empty.
pub fn median(v: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    })
}

/// A number for the page, rounded to `digits` decimals; `–` for none.
fn num(v: Option<f64>, digits: i32) -> String {
    let scale = 10f64.powi(digits);
    v.filter(|x| x.is_finite())
        .map_or("–".into(), |x| fmt_num((x * scale).round() / scale))
}

/// Makes the report of `students` on `lesson`.
pub fn class_report(lesson: &Lesson, students: &[StudentRecord]) -> ClassReport {
    let fig = |st: &StudentRecord, s: usize| st.figures.get(s).cloned().unwrap_or_default();
    // The steps' CSV.
    let mut steps_csv = String::from(
        "student,step,step_id,step_title,state,seconds,met_at_s,peak_force_n,score,before,after\n",
    );
    for st in students {
        for (s, step) in lesson.steps.iter().enumerate() {
            let r = st.progress.steps().get(s).cloned().unwrap_or_default();
            let f = fig(st, s);
            let ans = |q: &Option<Question>, a: &Option<Answer>| match (q, a) {
                (Some(q), Some(a)) => csv(&answer_text(q, a)),
                _ => String::new(),
            };
            let rate = f64::from(step.rate_hz.max(1));
            steps_csv.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{}\n",
                csv(st.name),
                s + 1,
                csv(&step.id),
                csv(&step.title),
                step_state(st.progress, s),
                csv_num(Some(seconds(lesson, st.progress, s))),
                csv_num(r.met_at.map(|t| t as f64 / rate)),
                csv_num(f.peak_force_n),
                csv_num(f.score),
                ans(&step.before, &r.before),
                ans(&step.after, &r.after),
            ));
        }
    }
    // The tests' CSV.
    let mut tests_csv = String::from("student,test,question,prompt,answer,correct\n");
    for st in students {
        for (test, answers) in [
            ("pre", st.progress.pre_test()),
            ("post", st.progress.post_test()),
        ] {
            for (q, question) in lesson.test.iter().enumerate() {
                let a = answers.get(q).cloned().flatten();
                let (text, ok) = match &a {
                    Some(a) => (answer_text(question, a), correct(question, a)),
                    None => (String::new(), None),
                };
                tests_csv.push_str(&format!(
                    "{},{test},{},{},{},{}\n",
                    csv(st.name),
                    q + 1,
                    csv(&question.prompt),
                    csv(&text),
                    match ok {
                        Some(true) => "yes",
                        Some(false) => "no",
                        None => "",
                    }
                ));
            }
        }
    }
    let (markdown, time_chart, test_chart) = page(lesson, students);
    ClassReport {
        steps_csv,
        tests_csv,
        markdown,
        time_chart,
        test_chart,
    }
}

/// The Markdown page and its two charts.
fn page(
    lesson: &Lesson,
    students: &[StudentRecord],
) -> (String, Option<BarChart>, Option<BarChart>) {
    let plural = |n: usize| if n == 1 { "" } else { "s" };
    let mut m = format!(
        "# Class report: {}\n\n{} student{}, a lesson of {} step{} and {} test question{}.\n\n",
        md(&lesson.title),
        students.len(),
        plural(students.len()),
        lesson.steps.len(),
        plural(lesson.steps.len()),
        lesson.test.len(),
        plural(lesson.test.len())
    );
    m.push_str(&where_each_is(lesson, students));
    let (times, time_chart) = time_per_step(lesson, students);
    m.push_str(&times);
    let (tests, test_chart) = tests(lesson, students);
    m.push_str(&tests);
    m.push_str(&answers(lesson, students));
    (m, time_chart, test_chart)
}

fn score_cell(p: &Progress, pre: bool, asked: bool) -> String {
    let (right, n) = p.test_score(pre);
    if asked {
        format!("{right} of {n}")
    } else {
        "–".into()
    }
}

fn where_each_is(lesson: &Lesson, students: &[StudentRecord]) -> String {
    let mut m = String::from(
        "## Where each student is\n\n| student | now at | steps done | time on the tasks (s) | \
         pre-test | post-test |\n|---|---|---:|---:|---:|---:|\n",
    );
    for st in students {
        let p = st.progress;
        let done = (0..lesson.steps.len())
            .filter(|&s| step_state(p, s) == "done")
            .count();
        let total: f64 = (0..lesson.steps.len()).map(|s| seconds(lesson, p, s)).sum();
        let pre_asked = p.pre_test().iter().all(Option::is_some);
        let post_asked = p.post_test().iter().all(Option::is_some);
        m.push_str(&format!(
            "| {} | {} | {done} of {} | {} | {} | {} |\n",
            md(st.name),
            describe(p.place()),
            lesson.steps.len(),
            num(Some(total), 1),
            score_cell(p, true, pre_asked && !lesson.test.is_empty()),
            score_cell(p, false, post_asked && !lesson.test.is_empty()),
        ));
    }
    m.push('\n');
    m
}

fn time_per_step(lesson: &Lesson, students: &[StudentRecord]) -> (String, Option<BarChart>) {
    let mut m = String::from(
        "## Time per step, forces felt, scores\n\nOf the students who finished the step: the \
         time they spent doing its task, the largest force each felt there, and the world's \
         score at its end.\n\n",
    );
    let mut bars = Vec::new();
    let mut rows = String::from(
        "| step | done by | time, median (s) | shortest (s) | longest (s) | largest force, \
         median (N) | largest force, max (N) | score, median |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for (s, step) in lesson.steps.iter().enumerate() {
        let done: Vec<&StudentRecord> = students
            .iter()
            .filter(|st| step_state(st.progress, s) == "done")
            .collect();
        let t: Vec<f64> = done
            .iter()
            .map(|st| seconds(lesson, st.progress, s))
            .collect();
        let f: Vec<f64> = done
            .iter()
            .filter_map(|st| st.figures.get(s).and_then(|x| x.peak_force_n))
            .collect();
        let sc: Vec<f64> = done
            .iter()
            .filter_map(|st| st.figures.get(s).and_then(|x| x.score))
            .collect();
        let fmax = f.iter().copied().reduce(f64::max);
        rows.push_str(&format!(
            "| {}. {} | {} | {} | {} | {} | {} | {} | {} |\n",
            s + 1,
            md(&step.title),
            done.len(),
            num(median(&t), 1),
            num(t.iter().copied().reduce(f64::min), 1),
            num(t.iter().copied().reduce(f64::max), 1),
            num(median(&f), 2),
            num(fmax, 2),
            num(median(&sc), 0),
        ));
        if let Some(v) = median(&t) {
            bars.push(Bar {
                group: "steps".into(),
                label: format!("{}", s + 1),
                value: v,
                color: [70, 110, 190],
            });
        }
    }
    let chart = (!bars.is_empty()).then(|| BarChart {
        title: "Median time per step (students who finished it)".into(),
        y_label: "time doing the task (s)".into(),
        y_scale: Scale::Linear,
        bars,
    });
    if chart.is_some() {
        m.push_str(&format!("![Median time per step]({TIME_CHART})\n\n"));
    }
    m.push_str(&rows);
    m.push('\n');
    (m, chart)
}

fn tests(lesson: &Lesson, students: &[StudentRecord]) -> (String, Option<BarChart>) {
    if lesson.test.is_empty() {
        return (String::new(), None);
    }
    let mut m = String::from(
        "## Pre- and post-test\n\nCorrect answers per question, of the students who answered \
         it.\n\n",
    );
    let mut bars = Vec::new();
    let mut rows = String::from(
        "| question | correct answer | before the lesson | after the lesson |\n|---|---|---:|---:|\n",
    );
    let share = |q: usize, pre: bool| {
        let mut right = 0usize;
        let mut asked = 0usize;
        for st in students {
            let answers = if pre {
                st.progress.pre_test()
            } else {
                st.progress.post_test()
            };
            if let Some(Some(a)) = answers.get(q) {
                asked += 1;
                right += usize::from(correct(&lesson.test[q], a) == Some(true));
            }
        }
        (right, asked)
    };
    for (q, question) in lesson.test.iter().enumerate() {
        let right_answer = match &question.kind {
            QuestionKind::Choice {
                choices,
                correct: Some(k),
            } => choices.get(*k).cloned().unwrap_or_default(),
            _ => "–".into(),
        };
        let (pr, pa) = share(q, true);
        let (qr, qa) = share(q, false);
        rows.push_str(&format!(
            "| {}. {} | {} | {pr} of {pa} | {qr} of {qa} |\n",
            q + 1,
            md(&question.prompt),
            md(&right_answer)
        ));
        for (group, (r, a), color) in [
            ("before", (pr, pa), [150, 150, 150]),
            ("after", (qr, qa), [60, 150, 90]),
        ] {
            if a > 0 {
                bars.push(Bar {
                    group: format!("Q{}", q + 1),
                    label: group.into(),
                    value: 100.0 * r as f64 / a as f64,
                    color,
                });
            }
        }
    }
    let both: Vec<(usize, usize, usize)> = students
        .iter()
        .filter(|st| {
            st.progress.pre_test().iter().all(Option::is_some)
                && st.progress.post_test().iter().all(Option::is_some)
        })
        .map(|st| {
            let (a, n) = st.progress.test_score(true);
            (a, st.progress.test_score(false).0, n)
        })
        .collect();
    let chart = bars.iter().any(|b| b.value > 0.0).then(|| BarChart {
        title: "Correct answers per question, before and after the lesson".into(),
        y_label: "correct (% of those who answered)".into(),
        y_scale: Scale::Linear,
        bars,
    });
    if chart.is_some() {
        m.push_str(&format!(
            "![Correct answers before and after]({TEST_CHART})\n\n"
        ));
    }
    m.push_str(&rows);
    if !both.is_empty() {
        let pre: usize = both.iter().map(|b| b.0).sum();
        let post: usize = both.iter().map(|b| b.1).sum();
        let n = both.len() as f64;
        m.push_str(&format!(
            "\nThe {} student{} who took both: {} correct answers per student before, {} after \
             (a change of {}).\n",
            both.len(),
            if both.len() == 1 { "" } else { "s" },
            num(Some(pre as f64 / n), 2),
            num(Some(post as f64 / n), 2),
            num(Some((post as f64 - pre as f64) / n), 2),
        ));
    }
    m.push('\n');
    (m, chart)
}

/// Every question's answers: counts per choice, or each student's text.
fn answers(lesson: &Lesson, students: &[StudentRecord]) -> String {
    let mut m = String::from("## Answers\n\n");
    for (s, step) in lesson.steps.iter().enumerate() {
        for (when, q) in [("before", &step.before), ("after", &step.after)] {
            let Some(q) = q else { continue };
            let given: Vec<(&str, Answer)> = students
                .iter()
                .filter_map(|st| {
                    let r = st.progress.steps().get(s)?;
                    let a = if when == "before" {
                        &r.before
                    } else {
                        &r.after
                    };
                    a.clone().map(|a| (st.name, a))
                })
                .collect();
            m.push_str(&format!(
                "### Step {}, {}: {} ({when})\n\n{}\n",
                s + 1,
                md(&step.title),
                md(&q.prompt),
                answer_list(q, &given)
            ));
        }
    }
    m
}

fn answer_list(q: &Question, given: &[(&str, Answer)]) -> String {
    if given.is_empty() {
        return "No answers yet.\n".into();
    }
    match &q.kind {
        QuestionKind::Choice { choices, .. } => {
            let mut t = String::from("| answer | students |\n|---|---:|\n");
            for (i, c) in choices.iter().enumerate() {
                let n = given
                    .iter()
                    .filter(|(_, a)| *a == Answer::Choice(i))
                    .count();
                t.push_str(&format!("| {} | {n} |\n", md(c)));
            }
            t
        }
        QuestionKind::Text => given
            .iter()
            .map(|(name, a)| format!("- **{}**: {}\n", md(name), md(&answer_text(q, a))))
            .collect(),
    }
}
