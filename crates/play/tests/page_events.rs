//! The page's words for the session's events (`src/page/events.js`) class every event name the
//! worlds and the loop emit, and nothing else: the names are read from the workspace's
//! sources (every `Event::new` of every crate), so a world or a loop report added later fails
//! here until the page says whether the player hears it. The loop's timing, safety and device
//! reports are classed as never said.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The page's table: event name → class (`GAME`, `NOW`, `QUIET` or `LOOP`), from the
/// `['name', [CLASS, …]]` rows of `EVENTS` in events.js.
fn page_classes() -> BTreeMap<String, String> {
    let text = std::fs::read_to_string(workspace().join("crates/play/src/page/events.js")).unwrap();
    let start = text
        .find("export const EVENTS = new Map([")
        .expect("events.js has its EVENTS table");
    let end = start
        + text[start..]
            .find("\n]);")
            .expect("the table ends with `]);`");
    let mut classes = BTreeMap::new();
    for line in text[start..end].lines().skip(1) {
        let t = line.trim();
        if t.is_empty() || t.starts_with("//") {
            continue;
        }
        let row = t
            .strip_prefix("['")
            .unwrap_or_else(|| panic!("a row of EVENTS this test cannot read: {t}"));
        let (name, rest) = row.split_once("', [").expect("['name', [CLASS, …]]");
        let class = rest.split([',', ']']).next().unwrap().trim().to_string();
        assert!(
            ["GAME", "NOW", "QUIET", "LOOP"].contains(&class.as_str()),
            "{name}: class {class}"
        );
        assert!(
            classes.insert(name.to_string(), class).is_none(),
            "{name} is classed twice"
        );
    }
    classes
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// A source file without its comment lines and without its unit tests (a `#[cfg(test)]`
/// module written in the file, up to its closing brace).
fn code_of(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut code = String::new();
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim_start();
        if t.starts_with("#[cfg(test)]") {
            let next = (i + 1..lines.len()).find(|&j| !lines[j].trim().is_empty());
            if let Some(j) = next
                && lines[j].trim_start().starts_with("mod ")
                && lines[j].contains('{')
            {
                // Skip to the module's closing brace.
                let mut depth = 0i32;
                let mut k = j;
                loop {
                    depth += lines[k].matches('{').count() as i32;
                    depth -= lines[k].matches('}').count() as i32;
                    k += 1;
                    if depth <= 0 || k >= lines.len() {
                        break;
                    }
                }
                i = k;
                continue;
            }
        }
        if !t.starts_with("//") {
            code.push_str(lines[i]);
            code.push('\n');
        }
        i += 1;
    }
    code
}

/// The string literals in `text`.
fn literals(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(a) = rest.find('"') {
        let Some(b) = rest[a + 1..].find('"') else {
            break;
        };
        out.push(rest[a + 1..a + 1 + b].to_string());
        rest = &rest[a + b + 2..];
    }
    out
}

/// The body of `fn NAME(` in `code` (from its `{` to the matching `}`).
fn fn_body<'a>(code: &'a str, name: &str) -> Option<&'a str> {
    let at = code.find(&format!("fn {name}("))?;
    let open = at + code[at..].find('{')?;
    let mut depth = 0;
    for (k, c) in code[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(&code[open..open + k + 1]);
                }
            }
            _ => {}
        }
    }
    None
}

/// The string each arm of a `match` returns (`Variant { .. } => "name",`).
fn arm_names(body: &str) -> Vec<String> {
    body.split("=>")
        .skip(1)
        .filter_map(|arm| {
            let t = arm.trim_start();
            t.strip_prefix('"')
                .and_then(|r| r.split_once('"'))
                .map(|(s, _)| s.to_string())
        })
        .collect()
}

/// Worlds whose event enum lives in another crate than the scene that prefixes its names
/// (`format!("ot.{}", e.name())`): the prefix and the file of that enum's `fn name`.
const NAMES_ELSEWHERE: &[(&str, &str)] = &[("ot.", "crates/ot-envelope/src/world/mod.rs")];

/// Every event name the workspace's crates emit: the first argument of every `Event::new`
/// outside tests and comments, read as a literal, a `format!("prefix.{}", e.name())` over an
/// enum's `fn name`, a function `event_name(e)` whose match arms give the names, or a local
/// `let kind = if … { "a" } else { "b" };`. A call in any other form fails: the test must be
/// taught to read it (and the page to class its names).
fn emitted_names() -> BTreeSet<String> {
    let mut files = Vec::new();
    for e in std::fs::read_dir(workspace().join("crates")).unwrap() {
        let src = e.unwrap().path().join("src");
        if src.is_dir() {
            rust_files(&src, &mut files);
        }
    }
    files.sort();
    let mut names = BTreeSet::new();
    let mut calls = 0;
    for f in &files {
        let code = code_of(f);
        let rel = f
            .strip_prefix(workspace())
            .unwrap_or(f)
            .display()
            .to_string();
        // The event type's own constructor is the only struct literal allowed.
        if !rel.ends_with("crates/types/src/event.rs") {
            let squeezed: String = code.split_whitespace().collect::<Vec<_>>().join(" ");
            assert!(
                !squeezed.contains("Event { name:"),
                "{rel} builds an Event by hand: use Event::new, which this test reads"
            );
        }
        let mut rest = code.as_str();
        while let Some(at) = rest.find("Event::new(") {
            // `SoundEvent::new(` and the like are other types.
            if rest[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
            {
                rest = &rest[at + 1..];
                continue;
            }
            calls += 1;
            let arg = rest[at + "Event::new(".len()..].trim_start();
            let unreadable = || -> ! {
                panic!(
                    "{rel}: the event name of `Event::new({}…` is in a form this test cannot \
                     read: teach emitted_names to read it",
                    arg.chars().take(40).collect::<String>()
                )
            };
            let ident: String = arg
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let after_ident = &arg[ident.len()..];
            if let Some(lit) = arg.strip_prefix('"') {
                names.insert(lit.split_once('"').unwrap().0.to_string());
            } else if let Some(fmt) = arg.strip_prefix("format!(\"") {
                let (pattern, after) = fmt.split_once('"').unwrap();
                let Some(prefix) = pattern.strip_suffix("{}") else {
                    unreadable()
                };
                if !after.trim_start().starts_with(", e.name())") {
                    unreadable();
                }
                let source = match NAMES_ELSEWHERE.iter().find(|(p, _)| *p == prefix) {
                    Some((_, file)) => code_of(&workspace().join(file)),
                    None => code.clone(),
                };
                let body = fn_body(&source, "name").unwrap_or_else(|| unreadable());
                let arms = arm_names(body);
                assert!(!arms.is_empty(), "{rel}: no names in `{prefix}`'s fn name");
                names.extend(arms.into_iter().map(|a| format!("{prefix}{a}")));
            } else if !ident.is_empty() && after_ident.starts_with('(') {
                // A function of the same file whose match arms give the names.
                let body = fn_body(&code, &ident).unwrap_or_else(|| unreadable());
                let arms = arm_names(body);
                assert!(!arms.is_empty(), "{rel}: no names in fn {ident}");
                names.extend(arms);
            } else if !ident.is_empty() && after_ident.trim_start().starts_with(',') {
                // A local variable: `let kind = if … { "a" } else { "b" };` before the call.
                let before = &code[..code.len() - rest.len() + at];
                let Some(def) = before.rfind(&format!("let {ident} = ")) else {
                    unreadable()
                };
                let stmt = before[def..]
                    .split_once(';')
                    .unwrap_or_else(|| unreadable())
                    .0;
                let lits = literals(stmt);
                if lits.is_empty() {
                    unreadable();
                }
                names.extend(lits);
            } else {
                unreadable();
            }
            rest = &rest[at + 1..];
        }
    }
    assert!(
        calls >= 20,
        "only {calls} Event::new calls found: the scan is broken"
    );
    names
}

#[test]
fn the_page_classes_every_event_the_worlds_and_the_loop_emit() {
    let emitted = emitted_names();
    let classes = page_classes();
    // The scan reads every world and the loop (one name of each, as a check of the scan).
    for n in [
        "brick.grabbed",
        "brick.slot_filled",
        "nano.snap",
        "nano.pull_off",
        "wall.contact_begin",
        "ot.grab",
        "button.down",
        "deadline.missed",
        "safety.config",
        "device.lost",
    ] {
        assert!(
            emitted.contains(n),
            "{n} not found in the sources: {emitted:?}"
        );
    }
    let unclassed: Vec<&String> = emitted
        .iter()
        .filter(|n| !classes.contains_key(*n))
        .collect();
    assert!(
        unclassed.is_empty(),
        "events emitted but not classed by the page (src/page/events.js's EVENTS: GAME, NOW, \
         QUIET or LOOP): {unclassed:?}"
    );
    let stale: Vec<&String> = classes.keys().filter(|n| !emitted.contains(*n)).collect();
    assert!(
        stale.is_empty(),
        "events.js classes names nothing emits: {stale:?}"
    );
}

#[test]
fn the_loops_timing_safety_and_device_reports_are_never_said() {
    let classes = page_classes();
    // The loop's own reports: its timing, the safety layer, the device link, the force and
    // input checks, and a world's numeric or setup reports.
    let loop_reports = [
        "deadline.",
        "safety.",
        "device.",
        "force.",
        "input.",
        "scene.",
    ];
    for (name, class) in &classes {
        if loop_reports.iter().any(|p| name.starts_with(p))
            || name.ends_with("_error")
            || name.ends_with(".error")
        {
            assert_eq!(class, "LOOP", "{name} must never be read out");
        }
    }
    for n in [
        "nano.saturated",
        "wall.stiffness_capped",
        "ot.tick_map",
        "ot.envelope_grid",
        "ot.clipped",
        "brick.input_rejected",
    ] {
        assert_eq!(classes[n], "LOOP", "{n}");
    }
    // And the game is said: grab, release, snap, pull-off, slot (the grip at once).
    for n in [
        "brick.grabbed",
        "brick.released",
        "brick.slot_filled",
        "nano.snap",
        "nano.pull_off",
        "nano.slot_filled",
        "ot.grab",
        "wall.contact_begin",
    ] {
        assert_eq!(classes[n], "GAME", "{n}");
    }
    assert_eq!(classes["button.down"], "NOW");
}
