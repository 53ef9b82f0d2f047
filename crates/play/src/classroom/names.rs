//! A student's name: what is allowed (a bounded length, letters, digits, spaces and `-_.'`),
//! and the recording's file name made from it, which never leaves the class's folder.

use std::path::{Path, PathBuf};

/// Longest name, characters.
pub const MAX_NAME_CHARS: usize = 32;

/// Why a name was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NameError {
    /// Empty (or only spaces).
    #[error("name is empty: allowed 1 to 32 letters, digits, spaces or - _ . '")]
    Empty,
    /// Too long.
    #[error("name has {chars} characters: allowed 1 to 32")]
    TooLong {
        /// Its length, characters.
        chars: usize,
    },
    /// A character outside the allowed set.
    #[error("name contains `{ch}`: allowed letters, digits, spaces and - _ . '")]
    Character {
        /// The first character refused.
        ch: char,
    },
}

/// Checks a name as typed (surrounding spaces are dropped) and returns it.
pub fn check_name(raw: &str) -> Result<String, NameError> {
    let name = raw.trim();
    if name.is_empty() {
        return Err(NameError::Empty);
    }
    let chars = name.chars().count();
    if chars > MAX_NAME_CHARS {
        return Err(NameError::TooLong { chars });
    }
    if let Some(ch) = name
        .chars()
        .find(|c| !(c.is_alphanumeric() || matches!(c, ' ' | '-' | '_' | '.' | '\'')))
    {
        return Err(NameError::Character { ch });
    }
    Ok(name.to_string())
}

/// The file-name stem of a checked name: ASCII letters and digits kept, every other run of
/// characters one `_`, never empty, never starting with `.` (so never `.`, `..` or hidden).
pub fn file_stem(name: &str) -> String {
    let mut out = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    let out = out.trim_matches('_').to_string();
    if out.is_empty() {
        "student".into()
    } else {
        out
    }
}

/// `DIR/STEM-START.mcap` for a student starting at `start_s` (Unix seconds), with `-2`, `-3`, …
/// added when a file of that name exists or is `taken`.
pub fn recording_path(dir: &Path, name: &str, start_s: u64, taken: &[PathBuf]) -> PathBuf {
    let stem = format!("{}-{start_s}", file_stem(name));
    let mut k = 1;
    loop {
        let file = if k == 1 {
            format!("{stem}.mcap")
        } else {
            format!("{stem}-{k}.mcap")
        };
        let p = dir.join(file);
        // A lesson's student records into the folder of the same name without `.mcap`.
        let folder = p.with_extension("");
        if !p.exists() && !folder.exists() && !taken.contains(&p) && !taken.contains(&folder) {
            return p;
        }
        k += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_bounded_in_length_and_characters() {
        assert_eq!(check_name("  Ada Lovelace "), Ok("Ada Lovelace".into()));
        assert_eq!(check_name("Zoë O'Brien-2"), Ok("Zoë O'Brien-2".into()));
        assert_eq!(check_name("   ").unwrap_err(), NameError::Empty);
        assert_eq!(
            check_name(&"a".repeat(33)).unwrap_err().to_string(),
            "name has 33 characters: allowed 1 to 32"
        );
        for (bad, ch) in [
            ("../etc/passwd", '/'),
            ("a\\b", '\\'),
            ("x\0", '\0'),
            ("<script>", '<'),
            ("a:b", ':'),
        ] {
            assert_eq!(check_name(bad), Err(NameError::Character { ch }), "{bad}");
        }
        assert_eq!(
            check_name("a/b").unwrap_err().to_string(),
            "name contains `/`: allowed letters, digits, spaces and - _ . '"
        );
    }

    #[test]
    fn a_file_name_never_leaves_the_folder() {
        assert_eq!(file_stem("Ada Lovelace"), "Ada_Lovelace");
        assert_eq!(file_stem(".."), "student");
        assert_eq!(file_stem("Zoë"), "Zo");
        assert_eq!(file_stem("..hidden"), "hidden");
        let dir = std::env::current_exe()
            .unwrap()
            .with_file_name("test-tmp")
            .join(format!("nh-names-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = recording_path(&dir, "Ada", 7, &[]);
        assert_eq!(a, dir.join("Ada-7.mcap"));
        let b = recording_path(&dir, "Ada", 7, std::slice::from_ref(&a));
        assert_eq!(b, dir.join("Ada-7-2.mcap"));
        for name in ["..", ".", "a..b", "…", "x y"] {
            let p = recording_path(&dir, name, 1, &[]);
            assert_eq!(p.parent(), Some(dir.as_path()), "{name}");
            assert!(!p.file_name().unwrap().to_string_lossy().starts_with('.'));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
