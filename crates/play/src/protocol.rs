//! The page ↔ server protocol over the WebSocket (`/ws`).
//!
//! Page → server: JSON text messages, checked here; a bad one gets a typed [`ProtocolError`]
//! naming the field and its allowed range (sent back to the page as an `error` message; the
//! session goes on).
//!
//! | `type` | fields | meaning |
//! |---|---|---|
//! | `start` | | the player pressed Start (the page becomes the hand if no other page is) |
//! | `input` | `seq` (integer 0–2⁵³), `pos` (3 numbers, each −1–1, norm ≤ 1), `buttons` (integer, bits of the device's buttons), `t_ms` (the page's clock when the input happened, ms since the Unix epoch; information only) | the hand: a point of the unit ball mapped onto the device workspace (see [`crate::input`]) |
//! | `switch` | `name` (a switch of the scene), `value` (number in its range) | the menu |
//! | `end` | | the player ends the session |
//!
//! Server → page: JSON text messages `hello`, `waiting`, `frame`, `switched`, `error`, `end`
//! (built in [`crate::publish`]) and binary sound blocks: 8 bytes little-endian index of the
//! first sample (u64), 8 bytes the wall time of that sample's tick (f64, ms since the Unix
//! epoch), then the samples (f32 little-endian, mono, at the hello's `sample_rate_hz`).

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
    #[error("page message `type` = {0} is unknown (allowed: start, input, switch, end)")]
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

/// The hand as the page sent it.
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// A checked page message.
#[derive(Clone, Debug, PartialEq)]
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
                expected: "one of start, input, switch, end",
            });
        }
    };
    match t {
        "start" => Ok(PageMsg::Start),
        "end" => Ok(PageMsg::End),
        "switch" => parse_switch(&v),
        "input" => parse_input(&v, button_mask),
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
    match v.get("seq") {
        Some(Value::Number(n)) if n.as_u64().is_some_and(|s| s <= MAX_SAFE_INTEGER) => {
            Ok(n.as_u64().unwrap_or(0))
        }
        Some(Value::Number(n)) => Err(ProtocolError::OutOfRange {
            field: "input.seq".into(),
            value: n.to_string(),
            allowed: format!("an integer 0 ≤ seq ≤ {MAX_SAFE_INTEGER}"),
        }),
        other => Err(ProtocolError::Field {
            field: "input.seq".into(),
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
    match v.get("buttons") {
        Some(Value::Number(n)) if n.as_u64().is_some_and(|b| b & !u64::from(button_mask) == 0) => {
            Ok(n.as_u64().unwrap_or(0) as u32)
        }
        Some(Value::Number(n)) => Err(ProtocolError::OutOfRange {
            field: "input.buttons".into(),
            value: n.to_string(),
            allowed: format!("an integer whose bits are the device's buttons, 0–{button_mask}"),
        }),
        other => Err(ProtocolError::Field {
            field: "input.buttons".into(),
            got: kind(other),
            expected: "an integer",
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text, 0b1111).unwrap_err().to_string()
    }

    #[test]
    fn good_messages_parse() {
        assert_eq!(parse(r#"{"type":"start"}"#, 1), Ok(PageMsg::Start));
        assert_eq!(parse(r#"{"type":"end"}"#, 1), Ok(PageMsg::End));
        assert_eq!(
            parse(r#"{"type":"switch","name":"friction","value":0.5}"#, 1),
            Ok(PageMsg::Switch {
                name: "friction".into(),
                value: 0.5
            })
        );
        assert_eq!(
            parse(
                r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
                0b1111
            ),
            Ok(PageMsg::Input(PageInput {
                seq: 7,
                pos: [0.6, 0.0, -0.8],
                buttons: 9,
                t_ms: 1_764_000_000_000.5
            }))
        );
    }

    #[test]
    fn bad_messages_name_the_field_and_range() {
        assert!(err("nope").starts_with("page message is not a JSON object: expected"));
        assert_eq!(
            err("[1]"),
            "page message is not a JSON object: got a list of 1"
        );
        assert_eq!(
            err(r#"{"kind":"input"}"#),
            "page message field `type` is missing (expected: one of start, input, switch, end)"
        );
        assert_eq!(
            err(r#"{"type":"jump"}"#),
            "page message `type` = \"jump\" is unknown (allowed: start, input, switch, end)"
        );
        let input = |rest: &str| format!(r#"{{"type":"input","seq":1,{rest}}}"#);
        assert_eq!(
            err(&input(r#""pos":[0,0,1.5],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos[2]` = 1.5 is out of range: allowed -1 ≤ value ≤ 1"
        );
        assert_eq!(
            err(&input(r#""pos":[0.8,0.8,0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos` = [0.8, 0.8, 0] (norm 1.1313708498984762) is out of \
             range: allowed a point of the unit ball, norm ≤ 1"
        );
        assert_eq!(
            err(&input(r#""pos":[0,"a",0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos[1]` is a string (expected: a number)"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0],"buttons":0,"t_ms":0"#)),
            "page message field `input.pos` is a list of 2 (expected: a list of 3 numbers)"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":16,"t_ms":0"#)),
            "page message field `input.buttons` = 16 is out of range: allowed an integer whose \
             bits are the device's buttons, 0–15"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":-1,"t_ms":0"#)),
            "page message field `input.buttons` = -1 is out of range: allowed an integer whose \
             bits are the device's buttons, 0–15"
        );
        assert_eq!(
            err(&input(r#""pos":[0,0,0],"buttons":0"#)),
            "page message field `input.t_ms` is missing (expected: a number)"
        );
        assert_eq!(
            err(r#"{"type":"input","seq":-3,"pos":[0,0,0],"buttons":0,"t_ms":0}"#),
            "page message field `input.seq` = -3 is out of range: allowed an integer 0 ≤ seq ≤ \
             9007199254740991"
        );
        assert_eq!(
            err(r#"{"type":"switch","name":"friction","value":"lots"}"#),
            "page message field `switch.value` is a string (expected: a number)"
        );
        assert_eq!(
            err(r#"{"type":"switch","value":1}"#),
            "page message field `switch.name` is missing (expected: a switch name of 1–64 characters)"
        );
        let long = format!(r#"{{"type":"start","pad":"{}"}}"#, "x".repeat(5000));
        assert_eq!(
            err(&long),
            "page message of 5025 bytes is too long (allowed: at most 4096 bytes)"
        );
        // JSON has no NaN or infinity: `1e999` overflows and is refused as not a number.
        assert!(parse(&input(r#""pos":[1e999,0,0],"buttons":0,"t_ms":0"#), 1).is_err());
        assert_eq!(
            ProtocolError::OutOfRange {
                field: "input.pos[2]".into(),
                value: "2".into(),
                allowed: String::new()
            }
            .field(),
            "input.pos[2]"
        );
    }

    #[test]
    fn no_input_panics() {
        // Every prefix of good and bad messages, and odd bytes: errors, never a panic.
        let samples = [
            r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
            r#"{"type":"switch","name":"friction","value":0.5}"#,
            "{\"type\":\"\u{0}\"}",
            r#"{"type":"input","seq":1e300,"pos":[null,{},[]],"buttons":1.5,"t_ms":-1}"#,
        ];
        for s in samples {
            for i in 0..=s.len() {
                if s.is_char_boundary(i) {
                    let _ = parse(&s[..i], 0b11);
                }
            }
        }
    }
}
