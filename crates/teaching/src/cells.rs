//! Text made safe for the class report's two formats: a CSV cell a spreadsheet opens as text
//! (quoted, and never read as a formula), and a Markdown table cell that neither breaks the
//! table nor becomes HTML.

/// `text` as one CSV cell (RFC 4180): quoted when it holds a comma, a quote or a line break,
/// quotes doubled; a cell a spreadsheet would read as a formula (starting `=`, `+`, `-`, `@`,
/// a tab or a carriage return) gets a leading `'`, so a student's answer is shown, not run.
pub fn csv(text: &str) -> String {
    let guarded = match text.chars().next() {
        Some('=' | '+' | '-' | '@' | '\t' | '\r') => format!("'{text}"),
        _ => text.to_string(),
    };
    if guarded.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", guarded.replace('"', "\"\""))
    } else {
        guarded
    }
}

/// A number as a CSV cell: shortest form that reads back to the same `f64`; empty for none.
pub fn csv_num(v: Option<f64>) -> String {
    v.filter(|x| x.is_finite())
        .map_or(String::new(), world_form::fmt_num)
}

/// `text` as one Markdown table cell: line breaks become spaces, `|` and `\` are escaped, and
/// `<`, `>` and `&` are written as entities (a report shown in a browser runs no student's
/// HTML).
pub fn md(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\n' | '\r' | '\t' => out.push(' '),
            '|' => out.push_str("\\|"),
            '\\' => out.push_str("\\\\"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '`' => out.push_str("\\`"),
            '*' | '_' | '[' | ']' => {
                out.push('\\');
                out.push(c);
            }
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_csv_cell_is_quoted_and_never_a_formula() {
        assert_eq!(csv("plain"), "plain");
        assert_eq!(csv("a, b"), "\"a, b\"");
        assert_eq!(csv("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(csv("two\nlines"), "\"two\nlines\"");
        assert_eq!(csv("=HYPERLINK(\"x\")"), "\"'=HYPERLINK(\"\"x\"\")\"");
        assert_eq!(csv("-1"), "'-1");
        assert_eq!(csv("@sum"), "'@sum");
        assert_eq!(csv(""), "");
        assert_eq!(csv_num(Some(2.5)), "2.5");
        assert_eq!(csv_num(Some(f64::NAN)), "");
        assert_eq!(csv_num(None), "");
    }

    #[test]
    fn a_markdown_cell_neither_breaks_the_table_nor_becomes_html() {
        assert_eq!(md("a | b"), "a \\| b");
        assert_eq!(md("line\nbreak"), "line break");
        assert_eq!(
            md("<script>alert(1)</script>"),
            "&lt;script&gt;alert(1)&lt;/script&gt;"
        );
        assert_eq!(md("**bold** [link](x)"), "\\*\\*bold\\*\\* \\[link\\](x)");
        assert_eq!(md("it fell"), "it fell");
    }
}
