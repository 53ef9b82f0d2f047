//! Lesson files: TOML, read with unknown fields refused and checked against the scenes they
//! name (their switches and the events their worlds emit); every error names the field, what is
//! allowed, and the line and column (`docs/teaching.md` is the reference).
//!
//! ```toml
//! [lesson]
//! title = "Forces at the nanoscale"
//! description = "optional free text"
//!
//! [[test]]                         # content questions, asked before the first step and again
//! prompt = "Which force …?"        # after the last (a pre- and a post-test)
//! answer = "choice"                # test questions are multiple choice
//! choices = ["gravity", "van der Waals attraction"]
//! correct = "van der Waals attraction"
//!
//! [[step]]
//! id = "throw-no-gravity"          # unique; lower case letters, digits, - and _
//! title = "Throw a brick with gravity off"
//! scene = "brickworld"             # a built-in scene or a scene file (relative to this file)
//! switches = { gravity_m_per_s2 = 0.0, inertia = true }   # the scene's switches, in range
//! task = "Pick up a brick and throw it."
//! done = { when = "brick_thrown" } # the condition vocabulary: crate::condition
//! locked = true                    # optional: closed until the teacher opens it
//! before = { prompt = "What will the brick do?", answer = "choice", choices = ["fall", "fly on"] }
//! after = { prompt = "What did you notice?", answer = "text" }
//! ```

use crate::condition::{self, Condition};
use crate::error::{LessonError, LessonFileError};
use haptic_engine::scene::Scene;
use haptic_loop::session::SceneSource;
use haptic_types::{Switch, SwitchError};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use world_form::fmt_num;

/// Most steps a lesson may have.
pub const MAX_STEPS: usize = 100;
/// Most choices a question may have (and fewest: 2).
pub const MAX_CHOICES: usize = 8;
/// Longest text of a title, task, prompt or choice, characters.
pub const MAX_TEXT_CHARS: usize = 2000;

/// A lesson, read and checked.
#[derive(Clone, Debug)]
pub struct Lesson {
    /// Its title.
    pub title: String,
    /// Free text (empty when the file has none).
    pub description: String,
    /// The content questions, asked before the first step (pre-test) and after the last
    /// (post-test); multiple choice with their correct answers.
    pub test: Vec<Question>,
    /// The steps, in order (at least one).
    pub steps: Vec<Step>,
}

/// One step of a lesson.
#[derive(Clone, Debug)]
pub struct Step {
    /// Unique id (`throw-no-gravity`).
    pub id: String,
    /// Title.
    pub title: String,
    /// The scene as written (`brickworld`, `my-bricks.toml`).
    pub scene: String,
    /// The scene, read (run a session of the step from it).
    pub source: SceneSource,
    /// The scene's world kind (`brickworld`, `nanoworld`, …).
    pub kind: &'static str,
    /// The scene's tick rate, Hz.
    pub rate_hz: u32,
    /// The scene's state fields, in the order each tick's state lists them.
    pub state_fields: Vec<String>,
    /// The switches the step sets (their scene's names, values in range; booleans 0 / 1), in
    /// name order.
    pub switches: Vec<Switch>,
    /// What the student is asked to do.
    pub task: String,
    /// How the world says the step is done.
    pub done: Condition,
    /// Closed until the teacher opens it.
    pub locked: bool,
    /// A question before the step (a prediction).
    pub before: Option<Question>,
    /// A question after it (what the student noticed).
    pub after: Option<Question>,
}

/// A question.
#[derive(Clone, Debug, PartialEq)]
pub struct Question {
    /// What is asked.
    pub prompt: String,
    /// How it is answered.
    pub kind: QuestionKind,
}

/// How a question is answered.
#[derive(Clone, Debug, PartialEq)]
pub enum QuestionKind {
    /// One of the choices.
    Choice {
        /// The choices (2 to [`MAX_CHOICES`], all different).
        choices: Vec<String>,
        /// The index of the correct choice (content questions), if any.
        correct: Option<usize>,
    },
    /// A short text.
    Text,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLesson {
    lesson: RawHeader,
    #[serde(default)]
    test: Vec<RawQuestion>,
    #[serde(default)]
    step: Vec<RawStep>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeader {
    title: String,
    #[serde(default)]
    description: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStep {
    id: String,
    title: String,
    scene: String,
    task: String,
    #[serde(default)]
    switches: BTreeMap<String, SwitchValue>,
    done: RawDone,
    #[serde(default)]
    locked: bool,
    #[serde(default)]
    before: Option<RawQuestion>,
    #[serde(default)]
    after: Option<RawQuestion>,
}

/// A switch's value as written: a number, or `true` / `false` (1 / 0).
struct SwitchValue(f64);

impl<'de> Deserialize<'de> for SwitchValue {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = SwitchValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number, or true / false")
            }
            fn visit_bool<E>(self, b: bool) -> Result<SwitchValue, E> {
                Ok(SwitchValue(f64::from(u8::from(b))))
            }
            fn visit_i64<E>(self, x: i64) -> Result<SwitchValue, E> {
                Ok(SwitchValue(x as f64))
            }
            fn visit_u64<E>(self, x: u64) -> Result<SwitchValue, E> {
                Ok(SwitchValue(x as f64))
            }
            fn visit_f64<E>(self, x: f64) -> Result<SwitchValue, E> {
                Ok(SwitchValue(x))
            }
        }
        d.deserialize_any(V)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDone {
    when: String,
    #[serde(default)]
    height_m: Option<f64>,
    #[serde(default)]
    within_nm: Option<f64>,
    #[serde(default)]
    away_nm: Option<f64>,
    #[serde(default)]
    seconds: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawQuestion {
    prompt: String,
    answer: AnswerKind,
    #[serde(default)]
    choices: Option<Vec<String>>,
    #[serde(default)]
    correct: Option<String>,
}

#[derive(Clone, Copy, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case")]
enum AnswerKind {
    Choice,
    Text,
}

/// Reads the lesson file at `path` (scenes relative to its folder); errors name the path,
/// line and column.
pub fn load_lesson(path: &Path) -> Result<Lesson, LessonFileError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| LessonFileError {
        at: haptic_types::textpos::Location {
            file: file.clone(),
            at: None,
        },
        error: Box::new(LessonError::Io {
            message: e.to_string(),
        }),
    })?;
    parse_lesson(&text, &file, path.parent())
}

/// Reads a lesson from its `text`; `file` names it in errors (a path, `built-in nanoscale`),
/// `dir` is the folder scene files are read from (`None`: built-in scenes and the working
/// folder only).
pub fn parse_lesson(text: &str, file: &str, dir: Option<&Path>) -> Result<Lesson, LessonFileError> {
    check(text, dir).map_err(|e| LessonFileError::locate(e, text, file))
}

fn check(text: &str, dir: Option<&Path>) -> Result<Lesson, LessonError> {
    let raw: RawLesson = toml::from_str(text).map_err(|e| LessonError::Syntax {
        message: e.message().trim().to_string(),
        offset: e.span().map(|s| s.start),
    })?;
    let title = non_empty("lesson.title", &raw.lesson.title)?;
    let description = raw.lesson.description.unwrap_or_default();
    text_len("lesson.description", &description)?;
    let mut test = Vec::with_capacity(raw.test.len());
    for (i, q) in raw.test.iter().enumerate() {
        let field = format!("test[{i}]");
        let question = question(&field, q)?;
        match &question.kind {
            QuestionKind::Choice {
                correct: Some(_), ..
            } => {}
            QuestionKind::Choice { correct: None, .. } => {
                return Err(LessonError::invalid(
                    format!("{field}.correct"),
                    "is missing: a test question gives its correct answer, one of its choices",
                ));
            }
            QuestionKind::Text => {
                return Err(LessonError::invalid(
                    format!("{field}.answer"),
                    "= \"text\": a test question is multiple choice (answer = \"choice\", with \
                     its choices and the correct one)",
                ));
            }
        }
        test.push(question);
    }
    if raw.step.is_empty() {
        return Err(LessonError::invalid(
            "step",
            format!("lists no steps: a lesson has 1 to {MAX_STEPS} steps, each a [[step]] table"),
        ));
    }
    if raw.step.len() > MAX_STEPS {
        return Err(LessonError::invalid(
            "step",
            format!(
                "lists {} steps: a lesson has 1 to {MAX_STEPS} steps",
                raw.step.len()
            ),
        ));
    }
    let mut scenes = SceneCache::default();
    let mut steps: Vec<Step> = Vec::with_capacity(raw.step.len());
    for (i, s) in raw.step.iter().enumerate() {
        let step = step(i, s, dir, &mut scenes)?;
        if let Some(j) = steps.iter().position(|t| t.id == step.id) {
            return Err(LessonError::invalid(
                format!("step[{i}].id"),
                format!(
                    "= \"{}\" is the id of step[{j}] too: each step has its own id",
                    step.id
                ),
            ));
        }
        steps.push(step);
    }
    Ok(Lesson {
        title,
        description,
        test,
        steps,
    })
}

fn step(
    i: usize,
    s: &RawStep,
    dir: Option<&Path>,
    scenes: &mut SceneCache,
) -> Result<Step, LessonError> {
    let at = |f: &str| format!("step[{i}].{f}");
    let id = s.id.trim();
    if id.is_empty()
        || id.len() > 64
        || !id
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-' || c == '_')
    {
        return Err(LessonError::invalid(
            at("id"),
            format!(
                "= \"{}\" is not an id: allowed 1 to 64 lower-case letters, digits, - and _",
                s.id
            ),
        ));
    }
    let title = non_empty(&at("title"), &s.title)?;
    let task = non_empty(&at("task"), &s.task)?;
    let mut scene = scenes.get(&at("scene"), &s.scene, dir)?;
    let kind = scene.world.kind();
    let mut switches = Vec::with_capacity(s.switches.len());
    for (name, &SwitchValue(value)) in &s.switches {
        let field = at(&format!("switches.{name}"));
        let spec = haptic_types::switch::check(kind, scene.world.switches(), name, value).map_err(
            |source| LessonError::Switch {
                field: field.clone(),
                source,
            },
        )?;
        scene
            .world
            .set_switch(spec.name, value)
            .map_err(|message| LessonError::Switch {
                field: field.clone(),
                source: SwitchError::Refused {
                    name: name.clone(),
                    value,
                    message,
                },
            })?;
        switches.push(Switch {
            name: spec.name.to_string(),
            value,
        });
    }
    let done = condition(&at("done"), &s.done, kind, &s.scene)?;
    let state_fields = scene.world.state_fields();
    // The condition's state fields are the scene's (a world that reports other fields is
    // refused here, not when the step runs).
    crate::evaluate::Evaluator::new(done, kind, &state_fields, scene.rate_hz).map_err(|e| {
        LessonError::invalid(at("done.when"), format!("= \"{}\": {e}", s.done.when))
    })?;
    let before = s
        .before
        .as_ref()
        .map(|q| question(&at("before"), q))
        .transpose()?;
    let after = s
        .after
        .as_ref()
        .map(|q| question(&at("after"), q))
        .transpose()?;
    Ok(Step {
        id: id.to_string(),
        title,
        scene: s.scene.clone(),
        source: scene.source,
        kind,
        rate_hz: scene.rate_hz,
        state_fields,
        switches,
        task,
        done,
        locked: s.locked,
        before,
        after,
    })
}

/// The scenes a lesson names, read once each.
#[derive(Default)]
struct SceneCache {
    read: BTreeMap<String, SceneSource>,
}

/// A step's scene: its source, rate and a world built from it (to check switches on).
struct StepScene {
    source: SceneSource,
    rate_hz: u32,
    world: Box<dyn Scene>,
}

impl SceneCache {
    fn get(
        &mut self,
        field: &str,
        scene: &str,
        dir: Option<&Path>,
    ) -> Result<StepScene, LessonError> {
        let err = |message: String| LessonError::Scene {
            field: field.to_string(),
            scene: scene.to_string(),
            message,
        };
        let source = match self.read.get(scene) {
            Some(s) => s.clone(),
            None => {
                let local: Option<PathBuf> = dir.map(|d| d.join(scene)).filter(|p| p.exists());
                match local {
                    Some(p) => SceneSource::from_path(&p),
                    None => SceneSource::resolve(Path::new(scene)),
                }
                .map_err(|e| err(e.to_string()))?
            }
        };
        let loaded = haptic_loop::scene::load_scene(&source.text, None)
            .map_err(|e| err(source.locate(e).to_string()))?;
        let rate_hz = loaded.config.rate_hz;
        self.read.insert(scene.to_string(), source.clone());
        Ok(StepScene {
            source,
            rate_hz,
            world: loaded.scene,
        })
    }
}

fn condition(field: &str, d: &RawDone, kind: &str, scene: &str) -> Result<Condition, LessonError> {
    let when_field = format!("{field}.when");
    let Some(word) = condition::word(&d.when) else {
        return Err(LessonError::invalid(
            when_field,
            format!(
                "= \"{}\" is not a condition (allowed: {})",
                d.when,
                condition::names()
            ),
        ));
    };
    if !word.can_happen_in(kind) {
        return Err(LessonError::invalid(
            when_field,
            format!(
                "= \"{}\" cannot happen in scene \"{scene}\": it reads {}, which a {kind} scene \
                 never emits (allowed in a {kind} scene: {})",
                d.when,
                word.reads,
                condition::names_for(kind)
            ),
        ));
    }
    let given = [
        ("height_m", d.height_m),
        ("within_nm", d.within_nm),
        ("away_nm", d.away_nm),
        ("seconds", d.seconds),
    ];
    for (name, v) in given {
        if v.is_some() && !word.params.iter().any(|p| p.name == name) {
            let takes: Vec<String> = word.params.iter().map(|p| p.name.to_string()).collect();
            return Err(LessonError::invalid(
                format!("{field}.{name}"),
                format!(
                    "is not a parameter of `{}` (its parameters: {})",
                    word.name,
                    if takes.is_empty() {
                        "none".to_string()
                    } else {
                        takes.join(", ")
                    }
                ),
            ));
        }
    }
    let need = |name: &str, v: Option<f64>, lo_open: f64, hi: f64, allowed: &str| {
        let f = format!("{field}.{name}");
        match v {
            None => Err(LessonError::invalid(
                f,
                format!("is missing: `{}` needs {allowed}", word.name),
            )),
            Some(x) if x.is_finite() && x > lo_open && x <= hi => Ok(x),
            Some(x) => Err(LessonError::invalid(
                f,
                format!("= {} is out of range: allowed {allowed}", fmt_num(x)),
            )),
        }
    };
    let allowed = |name: &str| {
        word.params
            .iter()
            .find(|p| p.name == name)
            .map_or("", |p| p.allowed)
    };
    Ok(match word.name {
        "house_complete" => Condition::HouseComplete,
        "brick_lifted" => Condition::BrickLifted {
            height_m: need("height_m", d.height_m, 0.0, 1.0, allowed("height_m"))?,
        },
        "brick_thrown" => Condition::BrickThrown,
        "brick_placed" => Condition::BrickPlaced,
        "atom_snapped" => Condition::AtomSnapped,
        "atom_picked_up" => Condition::AtomPickedUp,
        "atom_pulled_off" => Condition::AtomPulledOff,
        "atom_put_back" => {
            let within = need("within_nm", d.within_nm, 0.0, 10.0, allowed("within_nm"))?;
            let away = need("away_nm", d.away_nm, within, 20.0, allowed("away_nm"))?;
            Condition::AtomPutBack {
                within_m: within * 1e-9,
                away_m: away * 1e-9,
            }
        }
        _ => Condition::Time {
            seconds: need("seconds", d.seconds, 0.0, 3600.0, allowed("seconds"))?,
        },
    })
}

fn question(field: &str, q: &RawQuestion) -> Result<Question, LessonError> {
    let prompt = non_empty(&format!("{field}.prompt"), &q.prompt)?;
    let kind = match q.answer {
        AnswerKind::Text => {
            for (name, given) in [
                ("choices", q.choices.is_some()),
                ("correct", q.correct.is_some()),
            ] {
                if given {
                    return Err(LessonError::invalid(
                        format!("{field}.{name}"),
                        "is not allowed in a text question (answer = \"text\"); a question \
                         with choices has answer = \"choice\"",
                    ));
                }
            }
            QuestionKind::Text
        }
        AnswerKind::Choice => {
            let choices_field = format!("{field}.choices");
            let Some(choices) = &q.choices else {
                return Err(LessonError::invalid(
                    choices_field,
                    format!(
                        "is missing: a choice question (answer = \"choice\") lists 2 to \
                         {MAX_CHOICES} choices"
                    ),
                ));
            };
            if choices.len() < 2 || choices.len() > MAX_CHOICES {
                return Err(LessonError::invalid(
                    choices_field,
                    format!(
                        "lists {} choice{}: a choice question lists 2 to {MAX_CHOICES}",
                        choices.len(),
                        if choices.len() == 1 { "" } else { "s" }
                    ),
                ));
            }
            let mut checked: Vec<String> = Vec::with_capacity(choices.len());
            for (k, c) in choices.iter().enumerate() {
                let c = non_empty(&format!("{choices_field}[{k}]"), c)?;
                if checked.contains(&c) {
                    return Err(LessonError::invalid(
                        format!("{choices_field}[{k}]"),
                        format!("= \"{c}\" is listed twice: the choices are all different"),
                    ));
                }
                checked.push(c);
            }
            let correct = match &q.correct {
                None => None,
                Some(c) => Some(checked.iter().position(|x| x == c.trim()).ok_or_else(|| {
                    let list: Vec<String> = checked.iter().map(|x| format!("\"{x}\"")).collect();
                    LessonError::invalid(
                        format!("{field}.correct"),
                        format!(
                            "= \"{c}\" is not one of the choices (allowed: {})",
                            list.join(", ")
                        ),
                    )
                })?),
            };
            QuestionKind::Choice {
                choices: checked,
                correct,
            }
        }
    };
    Ok(Question { prompt, kind })
}

/// A text field that must say something: trimmed, 1 to [`MAX_TEXT_CHARS`] characters.
fn non_empty(field: &str, s: &str) -> Result<String, LessonError> {
    let t = s.trim();
    if t.is_empty() {
        return Err(LessonError::invalid(
            field,
            format!("is empty: allowed 1 to {MAX_TEXT_CHARS} characters"),
        ));
    }
    text_len(field, t)?;
    Ok(t.to_string())
}

fn text_len(field: &str, s: &str) -> Result<(), LessonError> {
    let n = s.chars().count();
    if n > MAX_TEXT_CHARS {
        return Err(LessonError::invalid(
            field,
            format!("has {n} characters: allowed 1 to {MAX_TEXT_CHARS}"),
        ));
    }
    Ok(())
}

impl Step {
    /// The switches as a scene's menu sets them: `(name, value)`, the scene's switch names.
    pub fn switch_pairs(&self) -> impl Iterator<Item = (&str, f64)> {
        self.switches.iter().map(|s| (s.name.as_str(), s.value))
    }
}
