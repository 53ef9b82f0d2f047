//! The channel table and the per-message field tables of `docs/recording-format.md`, generated
//! from the declarations (a test checks the file against them and names any field that is
//! missing or extra; `NANOHAPTICS_BLESS=1 cargo test -p nanohaptics-recording --release channels::doc`
//! rewrites the generated part).

use super::declare::{FieldInfo, MessageInfo};
use super::messages::{Channel, MESSAGES};

/// The line that opens the generated part of `docs/recording-format.md`.
pub const BEGIN: &str =
    "<!-- BEGIN generated from crates/recording/src/channels/messages.rs: do not edit by hand -->";
/// The line that closes it.
pub const END: &str = "<!-- END generated -->";

fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

fn field_row(f: &FieldInfo) -> String {
    let ty = if f.per_scene {
        "`float64` per state field".to_string()
    } else {
        format!("`{}`", f.msg_type)
    };
    let col = f.column.map_or(String::new(), |c| format!("`{c}`"));
    format!(
        "| `{}` | {ty} | {col} | {} |\n",
        f.name,
        cell(&f.doc_line())
    )
}

fn message_section(ch: Channel, m: &MessageInfo) -> String {
    let mut s = format!(
        "### `{}`\n\n`{}`: {}\n\n| field | type | column | meaning |\n|---|---|---|---|\n",
        m.schema_name,
        ch.topic(),
        cell(m.comment)
    );
    for f in m.fields {
        s.push_str(&field_row(f));
    }
    s
}

/// The generated part of `docs/recording-format.md` (between [`BEGIN`] and [`END`], exclusive):
/// the channel table, then one field table per CDR message.
pub fn markdown() -> String {
    let mut s = String::from("| topic | schema (encoding) | rate | replay |\n|---|---|---|---|\n");
    for ch in Channel::ALL {
        let enc = match ch.message_encoding() {
            "cdr" => "ros2msg / cdr",
            other => other,
        };
        s.push_str(&format!(
            "| `{}` | `{}` ({enc}) | {} | {} |\n",
            ch.topic(),
            ch.schema_name(),
            cell(ch.rate()),
            ch.role().words()
        ));
    }
    s.push_str(
        "\nThe column of a field is its name in the per-tick arrays (`SessionArrays`, and the \
         dict of `nanohaptics.run_scene` / `read_recording`).\n",
    );
    for ch in Channel::ALL {
        if let Some(m) = ch.message() {
            s.push('\n');
            s.push_str(&message_section(ch, m));
        }
    }
    s
}

/// The field names of each `### \`schema\`` table in `text`, in order.
fn doc_fields(text: &str) -> Vec<(String, Vec<String>)> {
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for line in text.lines() {
        if let Some(h) = line.strip_prefix("### ") {
            out.push((h.trim_matches('`').to_string(), Vec::new()));
        } else if let (Some(last), Some(row)) = (out.last_mut(), line.strip_prefix("| `")) {
            if let Some(name) = row.split('`').next() {
                last.1.push(name.to_string());
            }
        }
    }
    out
}

/// Where the generated part of `doc` disagrees with the declarations: each message or field
/// missing from the doc or extra in it, by name; else the first differing line. Empty when
/// they agree.
pub fn disagreements(doc: &str) -> Vec<String> {
    let Some(a) = doc.find(BEGIN) else {
        return vec![format!("no `{BEGIN}` line")];
    };
    let Some(b) = doc.find(END) else {
        return vec![format!("no `{END}` line")];
    };
    let found = doc[a + BEGIN.len()..b].trim_matches('\n');
    let want = markdown();
    if found == want.trim_matches('\n') {
        return Vec::new();
    }
    let mut out = Vec::new();
    let in_doc = doc_fields(found);
    for m in MESSAGES {
        let Some((_, names)) = in_doc.iter().find(|(h, _)| h == m.schema_name) else {
            out.push(format!("message `{}` has no field table", m.schema_name));
            continue;
        };
        for f in m.fields {
            if !names.iter().any(|n| n == f.name) {
                out.push(format!(
                    "`{}`: field `{}` is declared but missing from the doc",
                    m.schema_name, f.name
                ));
            }
        }
        for n in names {
            if !m.fields.iter().any(|f| f.name == n) {
                out.push(format!(
                    "`{}`: field `{n}` is in the doc but not declared",
                    m.schema_name
                ));
            }
        }
    }
    for (h, _) in &in_doc {
        if !MESSAGES.iter().any(|m| m.schema_name == h) {
            out.push(format!(
                "table `{h}` is in the doc but no message is declared so"
            ));
        }
    }
    if out.is_empty() {
        let (mut fl, mut wl) = (found.lines(), want.lines());
        for k in 1.. {
            match (fl.next(), wl.next()) {
                (None, None) => break,
                (f, w) if f == w => {}
                (f, w) => {
                    out.push(format!(
                        "generated line {k}: the doc has `{}`, the declarations give `{}`",
                        f.unwrap_or("(end)"),
                        w.unwrap_or("(end)")
                    ));
                    break;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::channels::messages::TickColumns;

    const DOC: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/recording-format.md"
    );

    #[test]
    fn recording_format_doc_matches_the_declarations() {
        let doc = std::fs::read_to_string(DOC).expect("docs/recording-format.md");
        let bad = disagreements(&doc);
        if bad.is_empty() {
            return;
        }
        if std::env::var("NANOHAPTICS_BLESS").is_ok_and(|v| v == "1") {
            let a = doc.find(BEGIN).expect("BEGIN line") + BEGIN.len();
            let b = doc.find(END).expect("END line");
            let new = format!("{}\n\n{}\n{}", &doc[..a], markdown(), &doc[b..]);
            std::fs::write(DOC, new).expect("write the doc");
            return;
        }
        panic!(
            "docs/recording-format.md disagrees with the channel declarations:\n  {}\n\
             (regenerate: NANOHAPTICS_BLESS=1 cargo test -p nanohaptics-recording --release --lib \
             channels::doc)",
            bad.join("\n  ")
        );
    }

    /// Every declared column is named in the Python stub's description of `run_scene`.
    #[test]
    fn python_stub_names_every_column() {
        let stub = concat!(env!("CARGO_MANIFEST_DIR"), "/../ot-py/nanohaptics.pyi");
        let text = std::fs::read_to_string(stub).expect("nanohaptics.pyi");
        let start = text.find("def run_scene(").expect("run_scene in the stub");
        let end = start
            + text[start..]
                .find("\"\"\"\n")
                .expect("end of its docstring");
        let doc = &text[start..end];
        let words: Vec<&str> = doc
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .collect();
        let missing: Vec<&str> = TickColumns::INFO
            .iter()
            .map(|c| c.name)
            .filter(|n| !words.contains(n))
            .collect();
        assert_eq!(
            missing,
            Vec::<&str>::new(),
            "columns missing from run_scene's docstring in nanohaptics.pyi"
        );
    }

    #[test]
    fn a_missing_or_extra_field_is_named() {
        let good = format!("x\n{BEGIN}\n\n{}\n{END}\n", markdown());
        assert_eq!(disagreements(&good), Vec::<String>::new());
        let missing = good.replace(
            "| `watchdog` | `float64` | `watchdog` | Watchdog factor applied to the force, 0–1 \
             (1: device samples fresh). |\n",
            "",
        );
        assert_eq!(
            disagreements(&missing),
            vec![
                "`nanohaptics_msgs/msg/Force`: field `watchdog` is declared but missing from the doc"
            ]
        );
        let extra = good.replace(
            "| `seq` |",
            "| `bogus_n` | `float64` | | A field nobody declared. |\n| `seq` |",
        );
        assert_eq!(
            disagreements(&extra),
            vec![
                "`nanohaptics_msgs/msg/DeviceInput`: field `bogus_n` is in the doc but not declared"
            ]
        );
        let reworded = good.replace("Tick rate, Hz.", "Tick rate.");
        assert_eq!(
            disagreements(&reworded),
            vec![
                "generated line 27: the doc has `| `rate_hz` | `uint32` |  | Tick rate. |`, the \
                 declarations give `| `rate_hz` | `uint32` |  | Tick rate, Hz. |`"
            ]
        );
        assert_eq!(disagreements("nothing"), vec![format!("no `{BEGIN}` line")]);
    }
}
