//! A Markdown table builder: header, column alignment, rows.

use std::fmt;

/// How a column is aligned (the Markdown separator under its header).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Align {
    /// `---`: the renderer's default (left).
    #[default]
    Default,
    /// `:---`
    Left,
    /// `---:`: numbers.
    Right,
    /// `:---:`
    Center,
}

impl Align {
    fn separator(self) -> &'static str {
        match self {
            Align::Default => "---",
            Align::Left => ":---",
            Align::Right => "---:",
            Align::Center => ":---:",
        }
    }
}

/// A row whose cell count differs from the header's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("table row {row} has {cells} cells; the header has {columns} columns")]
pub struct RowWidthError {
    /// 0-based index the row would have had.
    pub row: usize,
    /// Cells given.
    pub cells: usize,
    /// Columns in the header.
    pub columns: usize,
}

/// A Markdown table; `Display` writes it, one line per row, ending in a newline.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Table {
    header: Vec<String>,
    align: Vec<Align>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column headers, every column [`Align::Default`].
    pub fn new<S: Into<String>>(header: impl IntoIterator<Item = S>) -> Self {
        let header: Vec<String> = header.into_iter().map(Into::into).collect();
        let align = vec![Align::Default; header.len()];
        Self {
            header,
            align,
            rows: Vec::new(),
        }
    }

    /// Sets the alignment of every column from column `first` (0-based) on.
    pub fn align_from(mut self, first: usize, align: Align) -> Self {
        for a in self.align.iter_mut().skip(first) {
            *a = align;
        }
        self
    }

    /// Sets the alignment of column `column` (0-based); a column past the end is ignored.
    pub fn align(mut self, column: usize, align: Align) -> Self {
        if let Some(a) = self.align.get_mut(column) {
            *a = align;
        }
        self
    }

    /// Appends a row; its cell count must equal the header's.
    pub fn row<S: Into<String>>(
        &mut self,
        cells: impl IntoIterator<Item = S>,
    ) -> Result<&mut Self, RowWidthError> {
        let cells: Vec<String> = cells.into_iter().map(Into::into).collect();
        if cells.len() != self.header.len() {
            return Err(RowWidthError {
                row: self.rows.len(),
                cells: cells.len(),
                columns: self.header.len(),
            });
        }
        self.rows.push(cells);
        Ok(self)
    }

    /// Rows so far.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True before the first row.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// A cell's text with `|` escaped and line breaks turned into spaces, so it stays one cell.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace(['\n', '\r'], " ")
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let line = |f: &mut fmt::Formatter<'_>, cells: &mut dyn Iterator<Item = String>| {
            write!(f, "|")?;
            for c in cells {
                write!(f, " {c} |")?;
            }
            writeln!(f)
        };
        line(f, &mut self.header.iter().map(|h| cell(h)))?;
        write!(f, "|")?;
        for a in &self.align {
            write!(f, "{}|", a.separator())?;
        }
        writeln!(f)?;
        for r in &self.rows {
            line(f, &mut r.iter().map(|c| cell(c)))?;
        }
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn writes_header_alignment_and_rows() {
        let mut t = Table::new(["scene", "p50 (µs)", "p99 (µs)"]).align_from(1, Align::Right);
        t.row(["empty", "1.0", "2.5"]).unwrap();
        t.row(vec![
            "100 bricks".to_string(),
            format!("{:.1}", 3.26),
            "4".into(),
        ])
        .unwrap();
        assert_eq!(
            t.to_string(),
            "| scene | p50 (µs) | p99 (µs) |\n|---|---:|---:|\n| empty | 1.0 | 2.5 |\n| 100 bricks | 3.3 | 4 |\n"
        );
        assert_eq!(t.len(), 2);
    }

    #[test]
    fn every_alignment_and_escaping() {
        let mut t = Table::new(["a", "b", "c", "d"])
            .align(1, Align::Left)
            .align(2, Align::Center)
            .align(3, Align::Right)
            .align(9, Align::Right);
        assert!(t.is_empty());
        t.row(["x|y", "two\nlines", "", "z"]).unwrap();
        assert_eq!(
            t.to_string(),
            "| a | b | c | d |\n|---|:---|:---:|---:|\n| x\\|y | two lines |  | z |\n"
        );
    }

    #[test]
    fn a_row_of_the_wrong_width_is_refused() {
        let mut t = Table::new(["a", "b"]);
        t.row(["1", "2"]).unwrap();
        let e = t.row(["1"]).unwrap_err();
        assert_eq!(
            e,
            RowWidthError {
                row: 1,
                cells: 1,
                columns: 2
            }
        );
        assert_eq!(
            e.to_string(),
            "table row 1 has 1 cells; the header has 2 columns"
        );
        assert_eq!(t.len(), 1);
    }
}
