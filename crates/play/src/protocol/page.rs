//! Page → server: the JSON messages ([`PageMsg`]), read and checked by [`parse`] with a typed
//! [`ProtocolError`] naming the field and its allowed range.

use super::lesson::PageAnswer;
use serde::Serialize;
use serde_json::Value;

/// Largest page message accepted, bytes.
pub const MAX_MESSAGE_BYTES: usize = 4096;

/// A page message that cannot be used.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ProtocolError {
    /// Not a JSON object.
    #[error("page message is not a JSON object: {0}")]
    NotJson(String),
    /// Longer than [`MAX_MESSAGE_BYTES`].
    #[error("page message of {0} bytes is too long (allowed: at most {MAX_MESSAGE_BYTES} bytes)")]
    TooLong(usize),
    /// A binary frame (the page sends text only).
    #[error("page message is binary (allowed: JSON text)")]
    Binary,
    /// An unknown `type`.
    #[error(
        "page message `type` = {0} is unknown (allowed: start, input, switch, end, answer, step)"
    )]
    UnknownType(String),
    /// A field missing or of the wrong type.
    #[error("page message field `{field}` is {got} (expected: {expected})")]
    Field {
        /// The field, e.g. `input.pos[2]`.
        field: String,
        /// What it was (`missing`, `a string`).
        got: String,
        /// What it must be.
        expected: &'static str,
    },
    /// A number out of its range.
    #[error("page message field `{field}` = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// The field.
        field: String,
        /// The value given.
        value: String,
        /// The allowed range.
        allowed: String,
    },
}

impl ProtocolError {
    /// The field the error is about (`type` for the message as a whole).
    pub fn field(&self) -> &str {
        match self {
            ProtocolError::Field { field, .. } | ProtocolError::OutOfRange { field, .. } => field,
            _ => "type",
        }
    }
}

/// The hand as the page sent it (the fields of an `input` message).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PageInput {
    /// The page's sequence number of the input.
    pub seq: u64,
    /// A point of the unit ball (right, away, up in the device frame).
    pub pos: [f64; 3],
    /// Button bits (bit `i`: the device's button `i`).
    pub buttons: u32,
    /// When the input happened by the page's clock, ms since the Unix epoch (information only:
    /// the input-to-force latency).
    pub t_ms: f64,
}

/// A message from a page to the server (JSON text, tagged by `type`), as [`parse`] read and
/// checked it.
///
/// The wire form is `{"type": "<name>", ...fields}`; the names are [`PageMsg::TYPES`].
/// [`PageMsg::to_json`] writes one (for tests and programs that play the page's part);
/// the server reads them with [`parse`] only, never with serde, so every field is checked.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum PageMsg {
    /// The player pressed Start.
    Start,
    /// The hand.
    Input(PageInput),
    /// A menu switch (name and value still to check against the scene's switches).
    Switch {
        /// Switch name.
        name: String,
        /// Its value.
        value: f64,
    },
    /// The player ends the session.
    End,
    /// The student's answer to the lesson's question now.
    Answer {
        /// The answer: a choice's index or a short text.
        #[serde(flatten)]
        answer: PageAnswer,
    },
    /// Open the lesson at step `id` for a demonstration (the page's `?step=ID`).
    Step {
        /// The step's id.
        id: String,
    },
}

impl PageMsg {
    /// The `type` of every page message, in the order of the enum's variants.
    pub const TYPES: &'static [&'static str] =
        &["start", "input", "switch", "end", "answer", "step"];

    /// The message's `type` on the wire.
    pub fn type_name(&self) -> &'static str {
        match self {
            PageMsg::Start => "start",
            PageMsg::Input(_) => "input",
            PageMsg::Switch { .. } => "switch",
            PageMsg::End => "end",
            PageMsg::Answer { .. } => "answer",
            PageMsg::Step { .. } => "step",
        }
    }

    /// One example of every page message, in [`PageMsg::TYPES`] order (for tests, docs and
    /// programs that play the page's part).
    pub fn examples() -> Vec<PageMsg> {
        let msgs = vec![
            PageMsg::Start,
            PageMsg::Input(PageInput {
                seq: 7,
                pos: [0.6, 0.0, -0.8],
                buttons: 9,
                t_ms: 1_764_000_000_000.5,
            }),
            PageMsg::Switch {
                name: "friction".into(),
                value: 0.5,
            },
            PageMsg::End,
            PageMsg::Answer {
                answer: PageAnswer::Choice(1),
            },
            PageMsg::Step { id: "float".into() },
        ];
        // A new variant stops this match from compiling: give it an example above and its
        // `type` in `PageMsg::TYPES` (and a row in docs/play.md's table).
        for m in &msgs {
            match m {
                PageMsg::Start
                | PageMsg::Input(_)
                | PageMsg::Switch { .. }
                | PageMsg::End
                | PageMsg::Answer { .. }
                | PageMsg::Step { .. } => {}
            }
        }
        msgs
    }

    /// The message as a page sends it (JSON text).
    pub fn to_json(&self) -> String {
        // A non-finite number is written as `null`, which [`parse`] refuses, as it should.
        serde_json::to_string(self).unwrap_or_default()
    }
}

fn kind(v: Option<&Value>) -> String {
    match v {
        None => "missing".into(),
        Some(Value::Null) => "null".into(),
        Some(Value::Bool(_)) => "a boolean".into(),
        Some(Value::Number(n)) => format!("the number {n}"),
        Some(Value::String(_)) => "a string".into(),
        Some(Value::Array(a)) => format!("a list of {}", a.len()),
        Some(Value::Object(_)) => "an object".into(),
    }
}

fn number(obj: &Value, key: &str, field: &str) -> Result<f64, ProtocolError> {
    let v = obj.get(key);
    v.and_then(Value::as_f64)
        .ok_or_else(|| ProtocolError::Field {
            field: field.into(),
            got: kind(v),
            expected: "a number",
        })
}

/// Largest integer a page's JavaScript number holds exactly.
const MAX_SAFE_INTEGER: u64 = (1 << 53) - 1;

/// Parses and checks a page message; `button_mask` has a bit for each button of the device.
pub fn parse(text: &str, button_mask: u32) -> Result<PageMsg, ProtocolError> {
    if text.len() > MAX_MESSAGE_BYTES {
        return Err(ProtocolError::TooLong(text.len()));
    }
    let v: Value = serde_json::from_str(text).map_err(|e| ProtocolError::NotJson(e.to_string()))?;
    if !v.is_object() {
        return Err(ProtocolError::NotJson(format!("got {}", kind(Some(&v)))));
    }
    let t = match v.get("type") {
        Some(Value::String(s)) => s.as_str(),
        other => {
            return Err(ProtocolError::Field {
                field: "type".into(),
                got: kind(other),
                expected: "one of start, input, switch, end, answer, step",
            });
        }
    };
    match t {
        "start" => Ok(PageMsg::Start),
        "end" => Ok(PageMsg::End),
        "switch" => parse_switch(&v),
        "input" => parse_input(&v, button_mask),
        "answer" => parse_answer(&v),
        "step" => parse_step(&v),
        other => Err(ProtocolError::UnknownType(format!(
            "\"{}\"",
            other.escape_default()
        ))),
    }
}

/// A `switch` message: a name of 1–64 characters and a number.
fn parse_switch(v: &Value) -> Result<PageMsg, ProtocolError> {
    let name = match v.get("name") {
        Some(Value::String(s)) if (1..=64).contains(&s.len()) => s.clone(),
        other => {
            return Err(ProtocolError::Field {
                field: "switch.name".into(),
                got: kind(other),
                expected: "a switch name of 1–64 characters",
            });
        }
    };
    let value = number(v, "value", "switch.value")?;
    Ok(PageMsg::Switch { name, value })
}

/// An `input` message: its sequence number, position, buttons and page time.
fn parse_input(v: &Value, button_mask: u32) -> Result<PageMsg, ProtocolError> {
    let seq = input_seq(v)?;
    let pos = input_pos(v)?;
    let buttons = input_buttons(v, button_mask)?;
    let t_ms = number(v, "t_ms", "input.t_ms")?;
    if !(0.0..1e14).contains(&t_ms) {
        return Err(ProtocolError::OutOfRange {
            field: "input.t_ms".into(),
            value: t_ms.to_string(),
            allowed: "0 ≤ t_ms < 1e14 (ms since the Unix epoch)".into(),
        });
    }
    Ok(PageMsg::Input(PageInput {
        seq,
        pos,
        buttons,
        t_ms,
    }))
}

/// `input.seq`: an integer a page's JavaScript number holds exactly.
fn input_seq(v: &Value) -> Result<u64, ProtocolError> {
    input_integer(
        v,
        "seq",
        |s| s <= MAX_SAFE_INTEGER,
        || format!("an integer 0 ≤ seq ≤ {MAX_SAFE_INTEGER}"),
    )
}

/// The integer `input.{key}`, refused as out of range (`allowed` says what is) when it is
/// negative, fractional or fails `ok`.
fn input_integer(
    v: &Value,
    key: &str,
    ok: impl FnOnce(u64) -> bool,
    allowed: impl FnOnce() -> String,
) -> Result<u64, ProtocolError> {
    match v.get(key) {
        Some(Value::Number(n)) => match n.as_u64() {
            Some(i) if ok(i) => Ok(i),
            _ => Err(ProtocolError::OutOfRange {
                field: format!("input.{key}"),
                value: n.to_string(),
                allowed: allowed(),
            }),
        },
        other => Err(ProtocolError::Field {
            field: format!("input.{key}"),
            got: kind(other),
            expected: "an integer",
        }),
    }
}

/// `input.pos`: a point of the unit ball (the device workspace, normalised).
fn input_pos(v: &Value) -> Result<[f64; 3], ProtocolError> {
    let arr = match v.get("pos") {
        Some(Value::Array(a)) if a.len() == 3 => a,
        other => {
            return Err(ProtocolError::Field {
                field: "input.pos".into(),
                got: kind(other),
                expected: "a list of 3 numbers",
            });
        }
    };
    let mut pos = [0.0; 3];
    for (i, x) in arr.iter().enumerate() {
        let field = format!("input.pos[{i}]");
        let n = x.as_f64().ok_or_else(|| ProtocolError::Field {
            field: field.clone(),
            got: kind(Some(x)),
            expected: "a number",
        })?;
        if !(-1.0..=1.0).contains(&n) {
            return Err(ProtocolError::OutOfRange {
                field,
                value: n.to_string(),
                allowed: "-1 ≤ value ≤ 1".into(),
            });
        }
        pos[i] = n;
    }
    let r2 = pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2];
    if r2 > 1.0 {
        return Err(ProtocolError::OutOfRange {
            field: "input.pos".into(),
            value: format!("[{}, {}, {}] (norm {})", pos[0], pos[1], pos[2], r2.sqrt()),
            allowed: "a point of the unit ball, norm ≤ 1".into(),
        });
    }
    Ok(pos)
}

/// `input.buttons`: an integer whose bits are among the device's buttons (`button_mask`).
fn input_buttons(v: &Value, button_mask: u32) -> Result<u32, ProtocolError> {
    let b = input_integer(
        v,
        "buttons",
        |b| b & !u64::from(button_mask) == 0,
        || format!("an integer whose bits are the device's buttons, 0–{button_mask}"),
    )?;
    // every bit is one of the mask's: it fits in a u32
    Ok(b as u32)
}

/// Most choices a lesson's question has (the answer's index is below it).
const MAX_CHOICES: u64 = 8;

/// An `answer` message: exactly one of `choice` (an integer 0 ≤ choice < 8) and `text` (a
/// string; its length is checked against the question by the lesson).
fn parse_answer(v: &Value) -> Result<PageMsg, ProtocolError> {
    let answer = match (v.get("choice"), v.get("text")) {
        (Some(Value::Number(n)), None) => match n.as_u64() {
            Some(i) if i < MAX_CHOICES => PageAnswer::Choice(i as usize),
            _ => {
                return Err(ProtocolError::OutOfRange {
                    field: "answer.choice".into(),
                    value: n.to_string(),
                    allowed: format!("an integer 0 ≤ choice < {MAX_CHOICES}"),
                });
            }
        },
        (None, Some(Value::String(t))) => PageAnswer::Text(t.clone()),
        (Some(c), None) => {
            return Err(ProtocolError::Field {
                field: "answer.choice".into(),
                got: kind(Some(c)),
                expected: "an integer",
            });
        }
        (None, Some(t)) => {
            return Err(ProtocolError::Field {
                field: "answer.text".into(),
                got: kind(Some(t)),
                expected: "a string",
            });
        }
        (c, _) => {
            return Err(ProtocolError::Field {
                field: "answer".into(),
                got: if c.is_some() {
                    "both choice and text".into()
                } else {
                    "missing choice and text".into()
                },
                expected: "exactly one of choice (an integer) and text (a string)",
            });
        }
    };
    Ok(PageMsg::Answer { answer })
}

/// A `step` message: a step id of 1–64 characters (whether the lesson has it is the lesson's
/// to say).
fn parse_step(v: &Value) -> Result<PageMsg, ProtocolError> {
    match v.get("id") {
        Some(Value::String(s)) if (1..=64).contains(&s.chars().count()) => {
            Ok(PageMsg::Step { id: s.clone() })
        }
        other => Err(ProtocolError::Field {
            field: "step.id".into(),
            got: kind(other),
            expected: "a step id of 1–64 characters",
        }),
    }
}
