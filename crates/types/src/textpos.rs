//! Where in a TOML file something is: line and column of a byte offset, and of a field named
//! by its dotted path (`mapping.force_scale`, `waypoint[2].t_s`). Errors of scene and script
//! files use it to say `file:line:column`.

use std::fmt;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// A 1-based line and column (the column counts characters, not bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Position {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// A place in a file as errors name it: `file:line:column`, or `file` when the place in it
/// is unknown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// The file (a path, or `built-in NAME`).
    pub file: String,
    /// Line and column, when known.
    pub at: Option<Position>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.at {
            Some(p) => write!(f, "{}:{p}", self.file),
            None => f.write_str(&self.file),
        }
    }
}

/// The position of byte `offset` of `text` (an offset past the end is the end; one inside a
/// multi-byte character is that character).
pub fn position(text: &str, offset: usize) -> Position {
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let before = &text[..end];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    Position {
        line,
        column: before[line_start..].chars().count() + 1,
    }
}

/// One step of a field path: a key, then the array indices that follow it.
fn steps(path: &str) -> Vec<(&str, Vec<usize>)> {
    path.split('.')
        .map(|seg| {
            let (key, rest) = seg.split_at(seg.find('[').unwrap_or(seg.len()));
            let idx = rest
                .split(['[', ']'])
                .filter(|s| !s.is_empty())
                .filter_map(|s| s.parse().ok())
                .collect();
            (key, idx)
        })
        .collect()
}

/// The position of the value of field `path` in the TOML `text` (or, when the field itself
/// is absent, of the deepest table on its path that is present). `None` when the text is not
/// TOML or not even the first key is there.
pub fn field_position(text: &str, path: &str) -> Option<Position> {
    let doc = DeTable::parse(text).ok()?;
    let mut table: &DeTable<'_> = doc.get_ref();
    let mut found: Option<std::ops::Range<usize>> = None;
    for (key, indices) in steps(path) {
        let Some((k, v)): Option<(&Spanned<_>, &Spanned<DeValue<'_>>)> =
            table.iter().find(|(k, _)| k.get_ref().as_ref() == key)
        else {
            break;
        };
        let mut value = v;
        // Point at the key for a table or array of tables (its header), at the value else.
        found = Some(match v.get_ref() {
            DeValue::Table(_) | DeValue::Array(_) => k.span(),
            _ => v.span(),
        });
        for i in indices {
            match value.get_ref() {
                DeValue::Array(a) => match a.get(i) {
                    Some(item) => {
                        value = item;
                        found = Some(item.span());
                    }
                    None => return found.map(|s| position(text, s.start)),
                },
                _ => return found.map(|s| position(text, s.start)),
            }
        }
        match value.get_ref() {
            DeValue::Table(t) => table = t,
            _ => break,
        }
    }
    found.map(|s| position(text, s.start))
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = "[scene]\nkind = \"wall\"\n\n[mapping]\nforce_scale = 2.5 # N\n\n\
                       [[waypoint]]\nt_s = 0.0\n[[waypoint]]\nt_s = -1.0\npos_m = [0.0, 1.0, 2e9]\n";

    #[test]
    fn positions_count_lines_and_characters() {
        assert_eq!(position("ab\ncd", 0), Position { line: 1, column: 1 });
        assert_eq!(position("ab\ncd", 4), Position { line: 2, column: 2 });
        // "é" is two bytes and one column.
        assert_eq!(position("é=1", 2), Position { line: 1, column: 2 });
        assert_eq!(position("é=1", 1), Position { line: 1, column: 1 });
        assert_eq!(position("ab", 99), Position { line: 1, column: 3 });
    }

    #[test]
    fn fields_are_found_by_dotted_path() {
        let at = |p| field_position(DOC, p).map(|p| p.to_string());
        assert_eq!(at("scene.kind").as_deref(), Some("2:8"));
        assert_eq!(at("mapping.force_scale").as_deref(), Some("5:15"));
        assert_eq!(at("waypoint[1].t_s").as_deref(), Some("10:7"));
        assert_eq!(at("waypoint[1].pos_m[2]").as_deref(), Some("11:20"));
        // Absent field: the deepest table present (the `[mapping]` header's key).
        assert_eq!(at("mapping.workspace_scale").as_deref(), Some("4:2"));
        assert_eq!(at("nothing.here"), None);
        assert_eq!(field_position("garbage = [", "garbage"), None);
    }
}
