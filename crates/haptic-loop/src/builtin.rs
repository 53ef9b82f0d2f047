//! The scenes and scripts shipped inside the program and the wheel, so `nanohaptics run wall`,
//! `nanohaptics demo` and `nanohaptics.run_scene("wall")` work from any directory. Files on disk
//! override them: a path that exists is always read from disk.

/// A built-in scene: its name, its TOML text and its default script (file name, text).
#[derive(Clone, Copy, Debug)]
pub struct Builtin {
    /// Name (`wall`), also accepted as `wall.toml`.
    pub name: &'static str,
    /// The scene file's text.
    pub scene: &'static str,
    /// The default script's file name, as the scene names it.
    pub script_file: &'static str,
    /// The default script's text.
    pub script: &'static str,
}

macro_rules! builtin {
    ($name:literal) => {
        builtin!($name, $name)
    };
    ($name:literal, $script:literal) => {
        Builtin {
            name: $name,
            scene: include_str!(concat!("../../../scenes/", $name, ".toml")),
            script_file: concat!($script, ".script.toml"),
            script: include_str!(concat!("../../../scenes/", $script, ".script.toml")),
        }
    };
}

/// Every built-in scene, in the order `demo` runs them.
pub const SCENES: &[Builtin] = &[
    builtin!("brickworld"),
    builtin!("nanoworld"),
    builtin!("optical_tweezers"),
    builtin!("optical_tweezers_10khz", "optical_tweezers"),
    builtin!("wall"),
];

/// The built-in scene called `name` (or `name.toml`).
pub fn find(name: &str) -> Option<&'static Builtin> {
    let n = name.strip_suffix(".toml").unwrap_or(name);
    SCENES.iter().find(|b| b.name == n)
}

/// The built-in script named `name`: its file name (`optical_tweezers.script.toml`), that name
/// without `.script.toml`, or a built-in scene's name (its default script); the file name and
/// the text.
pub fn script(name: &str) -> Option<(&'static str, &'static str)> {
    let stem = name
        .strip_suffix(".script.toml")
        .or_else(|| name.strip_suffix(".toml"))
        .unwrap_or(name);
    SCENES
        .iter()
        .find(|b| b.script_file.strip_suffix(".script.toml") == Some(stem) || b.name == stem)
        .map(|b| (b.script_file, b.script))
}

/// Names of the built-in scenes, comma-separated (for error messages).
pub fn names() -> String {
    SCENES.iter().map(|b| b.name).collect::<Vec<_>>().join(", ")
}

/// Writes editable copies of every built-in scene and its script into `dir` (created if
/// needed); refuses to overwrite an existing file. Returns the files written.
pub fn export(dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut written = Vec::new();
    for b in SCENES {
        for (file, text) in [
            (format!("{}.toml", b.name), b.scene),
            (b.script_file.to_string(), b.script),
        ] {
            let p = dir.join(file);
            if written.contains(&p) {
                continue; // a script shared by two scenes
            }
            if p.exists() {
                return Err(format!("{} exists: not overwriting it", p.display()));
            }
            std::fs::write(&p, text).map_err(|e| format!("cannot write {}: {e}", p.display()))?;
            written.push(p);
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    #[test]
    fn a_builtin_script_is_found_by_its_file_name_its_stem_or_its_scenes_name() {
        let (file, text) = script("optical_tweezers.script.toml").unwrap();
        assert_eq!(file, "optical_tweezers.script.toml");
        assert!(text.contains("drag it fast"));
        assert_eq!(script("optical_tweezers").unwrap().0, file);
        assert_eq!(script("optical_tweezers_10khz").unwrap().0, file);
        assert_eq!(script("wall.toml").unwrap().0, "wall.script.toml");
        assert!(script("no_such_script").is_none());
    }

    #[test]
    fn every_builtin_scene_loads_and_names_its_shipped_script() {
        for b in SCENES {
            let s = load_scene(b.scene, None).unwrap_or_else(|e| panic!("{}: {e}", b.name));
            assert_eq!(
                s.file.scene.default_script.as_deref(),
                Some(b.script_file),
                "{}",
                b.name
            );
        }
        assert_eq!(find("wall.toml").map(|b| b.name), Some("wall"));
        assert!(find("moon").is_none());
        assert_eq!(
            names(),
            "brickworld, nanoworld, optical_tweezers, optical_tweezers_10khz, wall"
        );
    }
}
