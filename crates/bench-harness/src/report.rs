//! The frame of a report section: where it goes, what it states at its top, how it is written.
//!
//! A report named `N` writes `docs/bench/N.md` (one section of BENCHMARKS.md, which
//! `scripts/bench.sh --assemble` puts together) and its figures under `docs/figures/`, both
//! relative to the workspace root. The section opens with its `##` heading and one line of
//! machine facts (CPU model, cores, load average at start and at end, run time), then the body
//! the report wrote.

use crate::machine::{LoadAvg, Machine, facts_line};
use crate::table::Table;
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The workspace root (two levels above this crate's manifest).
pub fn workspace_root() -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    p.canonicalize().unwrap_or(p)
}

/// The value after `--out` on the command line, if any (a report's section written elsewhere).
pub fn out_arg() -> Option<PathBuf> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
}

/// A report section being written; `fmt::Write` appends Markdown to its body.
#[derive(Debug)]
pub struct Report {
    title: String,
    root: PathBuf,
    out: PathBuf,
    body: String,
    machine: Machine,
    load_start: Option<LoadAvg>,
    started: Instant,
}

impl Report {
    /// Starts report `name` (the section `docs/bench/<name>.md`) with heading `title`, in the
    /// workspace; creates `docs/bench/` and `docs/figures/` and reads the load average.
    pub fn start(name: &str, title: &str) -> std::io::Result<Self> {
        Self::start_in(&workspace_root(), name, title)
    }

    /// As [`Report::start`], under another root directory.
    pub fn start_in(root: &Path, name: &str, title: &str) -> std::io::Result<Self> {
        std::fs::create_dir_all(root.join("docs/bench"))?;
        std::fs::create_dir_all(root.join("docs/figures"))?;
        Ok(Self {
            title: title.to_string(),
            root: root.to_path_buf(),
            out: root.join("docs/bench").join(format!("{name}.md")),
            body: String::new(),
            machine: Machine::detect(),
            load_start: LoadAvg::now(),
            started: Instant::now(),
        })
    }

    /// Writes the section to `out` instead (when `Some`), e.g. from [`out_arg`].
    pub fn output(mut self, out: Option<PathBuf>) -> Self {
        if let Some(o) = out {
            self.out = o;
        }
        self
    }

    /// The root directory (the workspace root unless started with [`Report::start_in`]).
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Where the section will be written.
    pub fn out_path(&self) -> &Path {
        &self.out
    }

    /// The path of figure `file` (`docs/figures/<file>`).
    pub fn figure(&self, file: &str) -> PathBuf {
        self.root.join("docs/figures").join(file)
    }

    /// Appends the Markdown image of figure `file` with text `alt`, as a paragraph (the path is
    /// relative to `docs/bench/`; the assembly rewrites it for BENCHMARKS.md).
    pub fn image(&mut self, alt: &str, file: &str) {
        self.body += &format!("![{alt}](../figures/{file})\n\n");
    }

    /// Appends a `###` heading.
    pub fn heading(&mut self, text: &str) {
        self.body += &format!("### {text}\n\n");
    }

    /// Appends a paragraph (text and a blank line).
    pub fn para(&mut self, text: &str) {
        self.body += text;
        self.body += "\n\n";
    }

    /// Appends a table and a blank line.
    pub fn table(&mut self, t: &Table) {
        self.body += &t.to_string();
        self.body += "\n";
    }

    /// The body written so far.
    pub fn body(&self) -> &str {
        &self.body
    }

    /// Seconds since the report started (wall clock).
    pub fn elapsed_s(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }

    /// The whole section as it stands: heading, machine facts (load now as the end), body.
    pub fn section(&self) -> String {
        let facts = facts_line(
            &self.machine,
            self.load_start,
            LoadAvg::now(),
            self.elapsed_s(),
        );
        format!("## {}\n\n{facts}\n\n{}\n", self.title, self.body.trim_end())
    }

    /// Writes the section (creating the output's directory) and returns its path and text.
    pub fn finish(self) -> std::io::Result<(PathBuf, String)> {
        let text = self.section();
        if let Some(dir) = self.out.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(&self.out, &text)?;
        eprintln!("wrote {} in {:.0} s", self.out.display(), self.elapsed_s());
        Ok((self.out, text))
    }
}

impl fmt::Write for Report {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.body.push_str(s);
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::table::{Align, Table};
    use std::fmt::Write as _;

    #[test]
    fn writes_the_section_with_facts_body_and_figure_paths() {
        let dir = std::env::current_exe()
            .unwrap()
            .with_file_name("test-tmp")
            .join(format!("bench-harness-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let mut r = Report::start_in(&dir, "demo", "demo — a section").unwrap();
        assert!(dir.join("docs/figures").is_dir());
        assert_eq!(r.figure("demo-a.png"), dir.join("docs/figures/demo-a.png"));
        assert_eq!(r.out_path(), dir.join("docs/bench/demo.md"));
        r.heading("Cases");
        let mut t = Table::new(["case", "µs"]).align(1, Align::Right);
        t.row(["a", "1.5"]).unwrap();
        r.table(&t);
        writeln!(r, "Ratio **{:.1}×**.", 3.04).unwrap();
        r.image("speed", "demo-a.png");
        let (path, text) = r.finish().unwrap();
        assert_eq!(path, dir.join("docs/bench/demo.md"));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
        let (head, rest) = text.split_once("\n\n").unwrap();
        assert_eq!(head, "## demo — a section");
        let (facts, body) = rest.split_once("\n\n").unwrap();
        assert!(facts.starts_with("Machine: "), "{facts}");
        assert!(facts.contains(" cores. Load average (1, 5, 15 min) at start "));
        assert_eq!(
            body,
            "### Cases\n\n| case | µs |\n|---|---:|\n| a | 1.5 |\n\nRatio **3.0×**.\n![speed](../figures/demo-a.png)\n"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn output_override_and_root() {
        let dir = std::env::current_exe()
            .unwrap()
            .with_file_name("test-tmp")
            .join(format!("bench-harness-out-{}", std::process::id()));
        let r = Report::start_in(&dir, "x", "x")
            .unwrap()
            .output(Some(dir.join("elsewhere/x.md")));
        assert_eq!(r.out_path(), dir.join("elsewhere/x.md"));
        assert_eq!(r.root(), dir.as_path());
        let (p, _) = r.finish().unwrap();
        assert!(p.is_file());
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(workspace_root().join("Cargo.toml").is_file());
    }
}
