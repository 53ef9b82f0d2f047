//! docs/play.md's protocol table against the protocol's types: every server message
//! ([`ServerMsg`]) and every page message ([`PageMsg`]) has its row, the table lists no other
//! message, each row names every field its message carries, and the page's JavaScript handles
//! every server message and sends only page messages.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_types::primitive::Primitive as Shape;
use play::protocol::{PageMsg, ServerMsg};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::PathBuf;

const HEADER: &str = "| direction | type | fields (units) | when sent |";
const SERVER: &str = "server → page";
const PAGE: &str = "page → server";
/// The one row whose message is not JSON (it has no `type`).
const BINARY: &str = "binary sound ticks";

fn crate_file(rel: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// A row of the table: direction, type (the name inside the backticks, or [`BINARY`]),
/// fields.
struct Row {
    direction: String,
    kind: String,
    fields: String,
}

/// The protocol table of docs/play.md (there is one).
fn table(doc: &str) -> Vec<Row> {
    let lines: Vec<&str> = doc.lines().collect();
    let heads: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].trim() == HEADER)
        .collect();
    assert_eq!(heads.len(), 1, "docs/play.md has one protocol table");
    let mut rows = Vec::new();
    for line in lines[heads[0] + 2..]
        .iter()
        .take_while(|l| l.starts_with('|'))
    {
        let cells: Vec<&str> = line
            .trim()
            .trim_matches('|')
            .split('|')
            .map(str::trim)
            .collect();
        assert_eq!(cells.len(), 4, "a row of four cells: {line}");
        let (direction, kind) = (cells[0], cells[1]);
        assert!(
            direction == SERVER || direction == PAGE,
            "direction `{direction}` (allowed: {SERVER}, {PAGE}): {line}"
        );
        let kind = match kind.strip_prefix('`').and_then(|k| k.strip_suffix('`')) {
            Some(k) if !k.is_empty() && !k.contains('`') => k.to_string(),
            _ => {
                assert_eq!(
                    kind, BINARY,
                    "a type in backticks, or the binary block: {line}"
                );
                assert_eq!(direction, SERVER, "{line}");
                kind.to_string()
            }
        };
        rows.push(Row {
            direction: direction.to_string(),
            kind,
            fields: cells[2].to_string(),
        });
    }
    rows
}

/// The field names of a message, with the names inside its objects (`mapping.origin_m` as
/// `origin_m`; a list's first object's too), leaving out the keys of the state maps (the
/// scene's state field names) and of the shapes (tabled above the table).
fn field_names(v: &Value, out: &mut BTreeSet<String>) {
    let Value::Object(m) = v else { return };
    for (k, x) in m {
        if k == "type" {
            continue;
        }
        out.insert(k.clone());
        if k == "state" || k == "prims" {
            continue;
        }
        match x {
            Value::Object(_) => field_names(x, out),
            Value::Array(a) => {
                if let Some(first) = a.first() {
                    field_names(first, out);
                }
            }
            _ => {}
        }
    }
}

#[test]
fn the_protocol_table_lists_every_message_and_no_other() {
    let rows = table(&crate_file("../../docs/play.md"));
    let names = |dir: &str| -> Vec<String> {
        rows.iter()
            .filter(|r| r.direction == dir && r.kind != BINARY)
            .map(|r| r.kind.clone())
            .collect()
    };
    let (server, page) = (names(SERVER), names(PAGE));
    let sorted = |v: &[String]| v.iter().cloned().collect::<BTreeSet<_>>();
    assert_eq!(
        sorted(&server).len(),
        server.len(),
        "a message twice: {server:?}"
    );
    assert_eq!(sorted(&page).len(), page.len(), "a message twice: {page:?}");
    let want = |t: &[&str]| t.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
    assert_eq!(
        sorted(&server),
        want(ServerMsg::TYPES),
        "server → page rows"
    );
    assert_eq!(sorted(&page), want(PageMsg::TYPES), "page → server rows");
    assert_eq!(rows.iter().filter(|r| r.kind == BINARY).count(), 1);
}

#[test]
fn each_row_names_every_field_of_its_message() {
    let rows = table(&crate_file("../../docs/play.md"));
    let row = |dir: &str, t: &str| {
        rows.iter()
            .find(|r| r.direction == dir && r.kind == t)
            .unwrap_or_else(|| panic!("no row for {dir} `{t}`"))
    };
    let check = |dir: &str, t: &str, json: String| {
        let v: Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["type"], t);
        let mut fields = BTreeSet::new();
        field_names(&v, &mut fields);
        let r = row(dir, t);
        for f in fields {
            assert!(
                r.fields.contains(&format!("`{f}`")),
                "docs/play.md's row for `{t}` does not name the field `{f}`"
            );
        }
    };
    // The examples hold one message of each type, every optional part present.
    for m in ServerMsg::examples() {
        check(SERVER, m.type_name(), m.to_json());
    }
    for m in PageMsg::examples() {
        check(PAGE, m.type_name(), m.to_json());
    }
}

#[test]
fn every_shape_key_is_documented() {
    let doc = crate_file("../../docs/play.md");
    let shapes = Shape::examples();
    // A new shape stops this match from compiling: add it to `Primitive::examples` and to
    // docs/play.md.
    for s in &shapes {
        match s {
            Shape::Sphere { .. }
            | Shape::Cursor { .. }
            | Shape::Box { .. }
            | Shape::Slot { .. }
            | Shape::Ellipse { .. }
            | Shape::Polyline { .. }
            | Shape::Arrow { .. }
            | Shape::Label { .. } => {}
        }
    }
    for s in &shapes {
        let Value::Object(m) = serde_json::to_value(s).unwrap() else {
            panic!("a shape is an object")
        };
        for (k, v) in &m {
            assert!(
                doc.contains(&format!("`{k}`")),
                "shape key `{k}` undocumented"
            );
            if k == "k" {
                let kind = v.as_str().unwrap();
                assert!(
                    doc.contains(&format!("`{kind}`")),
                    "shape `{kind}` undocumented"
                );
            }
        }
    }
}

/// The quoted names in `text` that follow `marker` (`['hello', …` → `hello`).
fn quoted_after(text: &str, marker: &str) -> BTreeSet<String> {
    text.split(marker)
        .skip(1)
        .filter_map(|rest| rest.strip_prefix('\''))
        .filter_map(|rest| rest.split('\'').next())
        .map(str::to_string)
        .collect()
}

#[test]
fn the_page_handles_every_server_message_and_sends_only_page_messages() {
    let messages = crate_file("src/page/messages.js");
    let start = messages
        .find("const HANDLERS = new Map([")
        .expect("messages.js has its dispatch table");
    let end = start + messages[start..].find("]);").unwrap();
    let handled = quoted_after(&messages[start..end], "\n  [");
    let want: BTreeSet<String> = ServerMsg::TYPES.iter().map(|s| s.to_string()).collect();
    assert_eq!(handled, want, "HANDLERS in messages.js");
    let mut sent = BTreeSet::new();
    for f in play::server::PAGE_FILES
        .iter()
        .filter(|f| f.path.ends_with(".js"))
    {
        sent.extend(quoted_after(f.body, "send({ type: "));
    }
    let page: BTreeSet<String> = PageMsg::TYPES.iter().map(|s| s.to_string()).collect();
    assert_eq!(sent, page, "the page sends every page message and no other");
}

#[test]
fn the_binary_row_gives_the_sound_ticks_layout_the_page_reads() {
    use play::protocol::{
        SOUND_ON_BYTES, SOUND_TICK_BYTES, SOUND_TICKS_HEADER_BYTES, SoundKind, SoundOn, SoundTick,
        SoundTicks,
    };
    let rows = table(&crate_file("../../docs/play.md"));
    let row = rows.iter().find(|r| r.kind == BINARY).unwrap();
    // The sizes, the fields and the kinds' codes of the layout.
    for s in [
        format!("{SOUND_TICKS_HEADER_BYTES}-byte header"),
        format!("{SOUND_TICK_BYTES} bytes per tick"),
        format!("{SOUND_ON_BYTES} bytes per sound"),
    ] {
        assert!(row.fields.contains(&s), "the binary row says `{s}`");
    }
    for f in [
        "first_tick",
        "tone_on_distance_m",
        "wall_ms",
        "nearest_m",
        "tick",
        "index",
        "kind",
        "amplitude",
    ] {
        assert!(row.fields.contains(&format!("`{f}`")), "field `{f}`");
    }
    for code in 0..5u32 {
        let k = SoundKind::from_code(code).unwrap();
        assert!(
            row.fields.contains(&format!("{code} {}", k.name())),
            "{code}"
        );
    }
    assert_eq!(SoundKind::from_code(5), None);
    // The worklet reads the same sizes.
    let synth = crate_file("src/page/synth.js");
    assert!(synth.contains(&format!(
        "const HEADER = {SOUND_TICKS_HEADER_BYTES}, TICK = {SOUND_TICK_BYTES}, SOUND = {SOUND_ON_BYTES};"
    )));
    // A message's bytes: the header, 16 per tick, 24 per sound; and back.
    let m = SoundTicks {
        first_tick: 417,
        tone_on_distance_m: Some(0.1),
        ticks: vec![
            SoundTick {
                wall_ms: 1.7e12 + 0.25,
                nearest_m: 0.05,
            },
            SoundTick {
                wall_ms: 1.7e12 + 1.25,
                nearest_m: f64::NAN,
            },
        ],
        sounds: vec![SoundOn {
            tick: 418,
            index: 3,
            kind: SoundKind::Clack,
            amplitude: 0.25,
        }],
    };
    let b = m.encode();
    assert_eq!(b.len(), 24 + 2 * 16 + 24);
    assert_eq!(&b[0..8], &417u64.to_le_bytes());
    assert_eq!(&b[16..20], &2u32.to_le_bytes());
    assert_eq!(&b[20..24], &1u32.to_le_bytes());
    assert_eq!(&b[56..64], &418u64.to_le_bytes());
    assert_eq!(&b[68..72], &1u32.to_le_bytes());
    let back = SoundTicks::decode(&b).unwrap();
    assert_eq!(back.first_tick, 417);
    assert_eq!(back.tone_on_distance_m, Some(0.1));
    assert_eq!(back.sounds, m.sounds);
    assert_eq!(back.ticks[0], m.ticks[0]);
    assert!(back.ticks[1].nearest_m.is_nan());
    // No tone: NaN on the wire. Bad bytes are errors, never a panic.
    let none = SoundTicks {
        tone_on_distance_m: None,
        ticks: vec![m.ticks[0]],
        ..m.clone()
    };
    assert_eq!(SoundTicks::decode(&none.encode()).unwrap(), none);
    assert_eq!(
        SoundTicks::decode(&b[..10]).unwrap_err().to_string(),
        "sound ticks message: 10 bytes is too short"
    );
    assert_eq!(
        SoundTicks::decode(&b[..b.len() - 1])
            .unwrap_err()
            .to_string(),
        "sound ticks message: 79 bytes for 2 ticks and 1 sounds (allowed: 80)"
    );
    let mut bad = b.clone();
    bad[68] = 9;
    assert_eq!(
        SoundTicks::decode(&bad).unwrap_err().to_string(),
        "sound ticks message: sound kind 9 (allowed: 0–4)"
    );
}
