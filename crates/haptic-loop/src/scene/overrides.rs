//! Overrides: a scene (or a script) with some fields changed by their dotted names, as a
//! parameter study changes them — `optical_tweezers.stiffness_n_per_m = 0.4`,
//! `loop.rate_hz = 2000`, `mapping.origin_m[2] = 0.01`.
//!
//! An override edits the parsed TOML table before it is deserialized, so it is checked by the
//! very rules of the file: an unknown name is refused with the list of the valid names at that
//! level (serde's `deny_unknown_fields`), a value of the wrong type is refused naming the
//! dotted field, and ranges are then checked by the scene's own validation
//! ([`crate::scene::load_scene`]), with the same `scene: \`field\` = … is out of range` errors
//! as a scene file. The result is TOML text: a session run from it records that text, so a
//! recording of an overridden run replays bit for bit like any other.
//!
//! ```
//! use haptic_loop::scene::overrides::override_scene;
//! let wall = "[scene]\nname = \"w\"\nkind = \"wall\"\n[wall]\nnormal = [0.0, 0.0, 1.0]\n\
//!             stiffness_n_per_m = 2000.0\n";
//! let text = override_scene(wall, &[("loop.rate_hz".into(), toml::Value::Integer(2000))]).unwrap();
//! assert_eq!(haptic_loop::scene::load_scene(&text, None).unwrap().config.rate_hz, 2000);
//! let e = override_scene(wall, &[("wall.stifness_n_per_m".into(), toml::Value::Float(1.0))]);
//! assert!(e.unwrap_err().to_string().starts_with(
//!     "override `wall.stifness_n_per_m`: unknown field `stifness_n_per_m`, expected"));
//! ```

use super::file::SceneFile;
use haptic_devices::script::{Script, ScriptError};
use haptic_engine::check::SceneError;
use haptic_types::DeviceSpecs;
use toml::{Table, Value};

/// Errors of an override.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OverrideError {
    /// The override names no field, names it badly, or gives a value the field cannot take.
    #[error("override `{field}`: {problem}")]
    Field {
        /// The dotted name as given, e.g. `optical_tweezers.stiffness_n_per_m`.
        field: String,
        /// What is wrong, with the valid names or the expected type.
        problem: String,
    },
    /// The scene file itself (before any override) is not valid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The script file itself (before any override) is not valid.
    #[error(transparent)]
    Script(#[from] ScriptError),
}

/// One step of a dotted name: a key, optionally with an array index (`origin_m[2]`).
#[derive(Debug, PartialEq)]
struct Segment<'a> {
    key: &'a str,
    index: Option<usize>,
}

fn segments<'a>(path: &'a str) -> Result<Vec<Segment<'a>>, String> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, index) = match part.find('[') {
            Some(open) => {
                let inner = part[open + 1..]
                    .strip_suffix(']')
                    .ok_or_else(|| format!("`{part}`: an index is written `name[k]`"))?;
                let k = inner
                    .parse::<usize>()
                    .map_err(|_| format!("`{part}`: the index must be a whole number ≥ 0"))?;
                (&part[..open], Some(k))
            }
            None => (part, None),
        };
        let bare = key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if key.is_empty() || !bare {
            return Err(format!(
                "`{part}` is not a field name (dotted names of the file's fields, e.g. \
                 `optical_tweezers.stiffness_n_per_m` or `mapping.origin_m[2]`)"
            ));
        }
        out.push(Segment { key, index });
    }
    Ok(out)
}

/// The scene `text` with each (role, button name) of `pairs` set in its `[device] buttons`
/// (the command line's `--buttons`); the buttons are checked against the device when the
/// session starts.
pub fn override_buttons(
    text: &str,
    pairs: &[(haptic_types::Role, String)],
) -> Result<String, OverrideError> {
    let overrides: Vec<(String, Value)> = pairs
        .iter()
        .map(|(role, button)| {
            (
                format!("device.buttons.{}", role.name()),
                Value::String(button.clone()),
            )
        })
        .collect();
    override_scene(text, &overrides)
}

/// Sets `value` at `path` inside `table`, creating tables that the file left out (they take
/// their defaults otherwise).
fn set(table: &mut Table, path: &str, value: Value) -> Result<(), String> {
    let segs = segments(path)?;
    let mut here = table;
    let mut walked = String::new();
    let last = segs.len() - 1;
    for (i, seg) in segs.iter().enumerate() {
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(seg.key);
        if i == last && seg.index.is_none() {
            here.insert(seg.key.to_string(), value);
            return Ok(());
        }
        let slot = match seg.index {
            None => here
                .entry(seg.key.to_string())
                .or_insert_with(|| Value::Table(Table::new())),
            Some(k) => {
                let arr = match here.get_mut(seg.key) {
                    Some(Value::Array(a)) => a,
                    Some(_) => return Err(format!("`{walked}` is not an array")),
                    None => {
                        return Err(format!(
                            "`{walked}` is not in the file, so it has no element {k} to change: \
                             set the whole array (`{walked}` = [...])"
                        ));
                    }
                };
                let len = arr.len();
                let item = arr.get_mut(k).ok_or_else(|| {
                    let allowed = match len.checked_sub(1) {
                        Some(top) => format!("0 ≤ index ≤ {top} (`{walked}` has {len} elements)"),
                        None => format!("none (`{walked}` is empty)"),
                    };
                    haptic_types::value::out_of_range(
                        &format!("index into `{walked}`"),
                        k,
                        &allowed,
                    )
                })?;
                walked.push_str(&format!("[{k}]"));
                if i == last {
                    *item = value;
                    return Ok(());
                }
                item
            }
        };
        here = match slot {
            Value::Table(t) => t,
            _ => return Err(format!("`{walked}` is a value, not a table of fields")),
        };
    }
    Ok(())
}

/// Applies `overrides` in order to the TOML `text`, checking the whole file with `check` (a
/// parse that refuses unknown fields and wrong types) after each one, so that an error is
/// attributed to the override that caused it. No overrides: the text comes back unchanged.
fn apply(
    text: &str,
    overrides: &[(String, Value)],
    what: &str,
    check: &dyn Fn(&str) -> Result<(), String>,
) -> Result<Option<String>, OverrideError> {
    if overrides.is_empty() {
        return Ok(None);
    }
    let field = |f: &str, problem: String| OverrideError::Field {
        field: f.to_string(),
        problem,
    };
    // The file has been checked by the caller, so it parses as TOML.
    let mut table: Table =
        toml::from_str(text).map_err(|e| field("", e.message().trim().to_string()))?;
    let mut said = Vec::with_capacity(overrides.len());
    for (path, value) in overrides {
        said.push(format!("{path} = {value}"));
        set(&mut table, path, value.clone()).map_err(|p| field(path, p))?;
        let out = toml::to_string(&table).map_err(|e| field(path, e.to_string()))?;
        check(&out).map_err(|p| field(path, p))?;
    }
    let body = toml::to_string(&table).map_err(|e| field("", e.to_string()))?;
    Ok(Some(format!(
        "# {what} with overrides: {}\n{body}",
        said.join(", ")
    )))
}

/// Whether the override `name` changes the script's simulated hand (`operator`,
/// `operator.stiffness_n_per_m`, ...: the script's `[operator]` table) rather than the scene.
pub fn is_script_field(name: &str) -> bool {
    name == "operator" || name.starts_with("operator.") || name.starts_with("operator[")
}

/// The scene file `text` with `overrides` (dotted field name → value) applied: unknown names,
/// wrong types and misplaced values are [`OverrideError::Field`] errors naming the dotted
/// field. Ranges are checked when the scene is built ([`crate::scene::load_scene`]).
pub fn override_scene(text: &str, overrides: &[(String, Value)]) -> Result<String, OverrideError> {
    SceneFile::parse(text)?;
    let check = |t: &str| match SceneFile::parse(t) {
        Ok(_) => Ok(()),
        Err(SceneError::Syntax { message, .. }) => Err(message),
        Err(e) => Err(e.to_string()),
    };
    Ok(apply(text, overrides, "scene", &check)?.unwrap_or_else(|| text.to_string()))
}

/// The script file `text` with `overrides` applied (e.g. `operator.stiffness_n_per_m`, the
/// simulated hand's stiffness): names and types are checked as in [`override_scene`]; ranges
/// by [`Script::from_toml`] when the script is loaded for a device with `specs`.
pub fn override_script(
    text: &str,
    overrides: &[(String, Value)],
    specs: &DeviceSpecs,
) -> Result<String, OverrideError> {
    Script::from_toml(text, specs)?;
    let check = |t: &str| match Script::from_toml(t, specs) {
        Err(ScriptError::Syntax { message, .. }) => Err(message),
        // Ranges are the script's own validation, reported when it is loaded.
        _ => Ok(()),
    };
    Ok(apply(text, overrides, "script", &check)?.unwrap_or_else(|| text.to_string()))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::scene::load_scene;
    use haptic_types::DeviceModel;

    const OT: &str = include_str!("../../../../scenes/optical_tweezers.toml");
    const SCRIPT: &str = include_str!("../../../../scenes/optical_tweezers.script.toml");

    fn ov(pairs: &[(&str, Value)]) -> Vec<(String, Value)> {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect()
    }

    fn err(text: &str, pairs: &[(&str, Value)]) -> String {
        match override_scene(text, &ov(pairs)) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn no_overrides_keep_the_file_as_written() {
        assert_eq!(override_scene(OT, &[]).unwrap(), OT);
    }

    #[test]
    fn overridden_fields_reach_the_scene() {
        let text = override_scene(
            OT,
            &ov(&[
                ("optical_tweezers.stiffness_n_per_m", Value::Float(0.4)),
                ("loop.rate_hz", Value::Integer(2000)),
                ("loop.watchdog_grace_s", Value::Float(0.005)),
                ("mapping.origin_m[2]", Value::Float(0.5)),
                // an integer where the file has a float: as in a scene file
                ("optical_tweezers.cursor_radius_nm", Value::Integer(200)),
            ]),
        )
        .unwrap();
        assert!(text.starts_with(
            "# scene with overrides: optical_tweezers.stiffness_n_per_m = 0.4, loop.rate_hz = \
             2000, loop.watchdog_grace_s = 0.005, mapping.origin_m[2] = 0.5, \
             optical_tweezers.cursor_radius_nm = 200\n"
        ));
        let f = SceneFile::parse(&text).unwrap();
        let ot = f
            .world::<crate::scene::optical::OtParams>()
            .unwrap()
            .unwrap();
        assert_eq!(ot.stiffness_n_per_m, 0.4);
        assert_eq!(ot.cursor_radius_nm, 200.0);
        assert_eq!(f.loop_.rate_hz, 2000);
        assert_eq!(f.loop_.watchdog_grace_s, 0.005);
        assert_eq!(f.mapping.origin_m, [0.0, 0.0, 0.5]);
        // everything else as in the file, bit for bit
        let base = SceneFile::parse(OT).unwrap();
        assert_eq!(f.display, base.display);
        assert_eq!(
            ot.waist_x_nm,
            base.world::<crate::scene::optical::OtParams>()
                .unwrap()
                .unwrap()
                .waist_x_nm
        );
        let loaded = load_scene(&text, None).unwrap();
        assert_eq!(loaded.config.rate_hz, 2000);
    }

    #[test]
    fn unknown_names_are_refused_with_the_valid_ones() {
        let e = err(
            OT,
            &[("optical_tweezers.stifness_n_per_m", Value::Float(0.4))],
        );
        assert!(
            e.starts_with(
                "override `optical_tweezers.stifness_n_per_m`: unknown field `stifness_n_per_m`, \
                 expected one of `depth_nj`, `waist_x_nm`"
            ),
            "{e}"
        );
        assert!(e.contains("`stiffness_n_per_m`"), "{e}");
        let e = err(OT, &[("lop.rate_hz", Value::Integer(2000))]);
        assert!(
            e.starts_with("override `lop.rate_hz`: unknown field `lop`, expected one of `scene`"),
            "{e}"
        );
        assert!(e.contains("`loop`"), "{e}");
    }

    #[test]
    fn wrong_types_and_shapes_name_the_field() {
        assert_eq!(
            err(OT, &[("loop.rate_hz", Value::String("fast".into()))]),
            "override `loop.rate_hz`: invalid type: string \"fast\", expected u32"
        );
        assert_eq!(
            err(OT, &[("loop.rate_hz.x", Value::Integer(1))]),
            "override `loop.rate_hz.x`: `loop.rate_hz` is a value, not a table of fields"
        );
        assert_eq!(
            err(OT, &[("optical_tweezers.start_um[2]", Value::Float(1.0))]),
            "override `optical_tweezers.start_um[2]`: index into `optical_tweezers.start_um` = 2 \
             is out of range: allowed 0 ≤ index ≤ 1 (`optical_tweezers.start_um` has 2 elements)"
        );
        assert_eq!(
            err(OT, &[("optical_tweezers.depth_nj[0]", Value::Float(1.0))]),
            "override `optical_tweezers.depth_nj[0]`: `optical_tweezers.depth_nj` is not an array"
        );
        assert_eq!(
            err(OT, &[("loop..rate_hz", Value::Integer(1))]),
            "override `loop..rate_hz`: `` is not a field name (dotted names of the file's \
             fields, e.g. `optical_tweezers.stiffness_n_per_m` or `mapping.origin_m[2]`)"
        );
        assert_eq!(
            err(OT, &[("mapping.origin_m[x]", Value::Integer(1))]),
            "override `mapping.origin_m[x]`: `origin_m[x]`: the index must be a whole number ≥ 0"
        );
    }

    #[test]
    fn ranges_are_the_scene_files_own_errors() {
        let text = override_scene(
            OT,
            &ov(&[("optical_tweezers.stiffness_n_per_m", Value::Float(-1.0))]),
        )
        .unwrap();
        let e = load_scene(&text, None).err().unwrap().to_string();
        assert!(
            e.starts_with("scene: `optical_tweezers.stiffness_n_per_m` = -1 is out of range"),
            "{e}"
        );
        let text = override_scene(OT, &ov(&[("loop.rate_hz", Value::Integer(999))])).unwrap();
        assert_eq!(
            load_scene(&text, None).err().unwrap().to_string(),
            "scene: `loop.rate_hz` = 999 is out of range: allowed 100 ≤ rate_hz ≤ 20000 with \
             10^9 / rate_hz a whole number"
        );
    }

    #[test]
    fn script_overrides_change_the_simulated_hand() {
        let specs = DeviceModel::Falcon.specs();
        let text = override_script(
            SCRIPT,
            &ov(&[("operator.stiffness_n_per_m", Value::Float(150.0))]),
            specs,
        )
        .unwrap();
        let s = Script::from_toml(&text, specs).unwrap();
        assert_eq!(s.operator.unwrap().stiffness_n_per_m, 150.0);
        // the other hand parameters take their defaults, the waypoints are the script's
        assert_eq!(s.operator.unwrap().mass_kg, 0.3);
        assert_eq!(
            s.duration_s,
            Script::from_toml(SCRIPT, specs).unwrap().duration_s
        );
        let e = override_script(
            SCRIPT,
            &ov(&[("operator.stifness", Value::Float(1.0))]),
            specs,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with(
                "override `operator.stifness`: unknown field `stifness`, expected one of `mass_kg`"
            ),
            "{e}"
        );
        let text = override_script(
            SCRIPT,
            &ov(&[("operator.stiffness_n_per_m", Value::Float(-1.0))]),
            specs,
        )
        .unwrap();
        let e = Script::from_toml(&text, specs).err().unwrap().to_string();
        assert!(
            e.contains("`operator.stiffness_n_per_m` = -1 is out of range"),
            "{e}"
        );
    }

    #[test]
    fn a_bad_base_file_is_the_files_error() {
        assert!(matches!(
            override_scene("[scene]\n", &[]),
            Err(OverrideError::Scene(SceneError::Syntax { .. }))
        ));
    }
}
