//! `nanohaptics scenes` and `demo`: the built-in scenes listed or exported, and every scene
//! recorded and replayed once.

use crate::render_cmd;
use crate::run_cmd::{print_summary, progress_bar, summary_json};
use crate::status;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionError, SessionOptions, run_session};
use recording::read_recording_file;
use std::path::{Path, PathBuf};

pub(crate) fn scenes(action: Option<&str>, dir: Option<&Path>) -> Result<u8, String> {
    match (action, dir) {
        (None, _) => {
            for b in haptic_loop::builtin::SCENES {
                let name = haptic_loop::scene::SceneFile::parse(b.scene)
                    .map(|f| f.scene.name)
                    .unwrap_or_default();
                println!("{:<18} {name} (script: {})", b.name, b.script_file);
            }
            Ok(status::SUCCESS)
        }
        (Some("export"), Some(d)) => {
            let files = haptic_loop::builtin::export(d)?;
            for f in &files {
                println!("{}", f.display());
            }
            Ok(status::SUCCESS)
        }
        (Some("export"), None) => {
            Err("scenes export: give the folder, e.g. `nanohaptics scenes export my-scenes`".into())
        }
        (Some(other), _) => Err(format!("scenes `{other}`: the only action is `export DIR`")),
    }
}

pub(crate) fn demo(scenes: Option<&Path>, out: &Path, json: bool) -> Result<u8, String> {
    // Scene files on disk (`--scenes`, or `./scenes` when it exists: files on disk override),
    // or else the built-in scenes.
    let local = Path::new("scenes");
    let scenes = scenes.or_else(|| local.is_dir().then_some(local));
    let files: Vec<PathBuf> = match scenes {
        Some(dir) => {
            let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
                .map_err(|e| format!("cannot list {}: {e}", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().is_some_and(|x| x == "toml")
                        && !p.to_string_lossy().ends_with(".script.toml")
                })
                .collect();
            files.sort();
            if files.is_empty() {
                return Err(format!("no scene files (*.toml) in {}", dir.display()));
            }
            files
        }
        None => haptic_loop::builtin::SCENES
            .iter()
            .map(|b| PathBuf::from(b.name))
            .collect(),
    };
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut rows = Vec::new();
    let mut all_ok = true;
    for f in &files {
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let rec = out.join(format!("{stem}.mcap"));
        let source = match scenes {
            Some(_) => SceneSource::from_path(f),
            None => SceneSource::resolve(f),
        };
        let mut opts = SessionOptions::new(source.map_err(|e: SessionError| e.to_string())?);
        opts.out = Some(rec.clone());
        opts.arrays = false;
        let pb = (!json).then(|| progress_bar(0, &stem));
        let report = run_session(&opts, &mut |done, total| {
            if let Some(pb) = &pb {
                pb.set_length(total);
                pb.set_position(done);
            }
        })
        .map_err(|e| format!("{}: {e}", f.display()))?;
        if let Some(pb) = pb {
            pb.finish_and_clear();
        }
        let r = read_recording_file(&rec, false).map_err(|e| format!("{}: {e}", rec.display()))?;
        let v = verify(&r).map_err(|e| e.to_string())?;
        all_ok &= v.ok();
        let png = out.join(format!("{stem}.png"));
        render_cmd::final_picture(&rec, &png, 800)
            .map_err(|e| format!("{}: {e}", png.display()))?;
        let mut j = summary_json(&report);
        j["recording"] = serde_json::json!(rec.display().to_string());
        j["replay_verified"] = serde_json::json!(v.ok());
        j["picture"] = serde_json::json!(png.display().to_string());
        j["divergence"] = serde_json::json!(v.divergence);
        if !json {
            print_summary(&report);
            println!(
                "  -> {} ; replay {}",
                rec.display(),
                if v.ok() { "bit-exact" } else { "DIVERGED" }
            );
            println!("  -> {}", png.display());
        }
        rows.push(j);
    }
    if json {
        println!(
            "{}",
            serde_json::json!({"scenes": rows, "all_verified": all_ok})
        );
    } else {
        println!(
            "{} scenes run, recorded and replay-verified: {}",
            rows.len(),
            if all_ok {
                "all bit-exact"
            } else {
                "DIVERGENCE"
            }
        );
    }
    Ok(if all_ok {
        status::SUCCESS
    } else {
        status::DIVERGED
    })
}
