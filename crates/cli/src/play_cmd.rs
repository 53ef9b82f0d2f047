//! `nanohaptics play`: the teaching game in a browser (the `play` crate serves the page).

use crate::status;
use haptic_devices::source::DeviceSource;
use haptic_loop::session::SceneSource;
use std::path::PathBuf;

/// Arguments of `nanohaptics play`.
#[derive(clap::Args, Debug)]
pub struct PlayArgs {
    /// Scene file or built-in scene name (brickworld, nanoworld, wall, optical_tweezers).
    #[arg(default_value = "brickworld")]
    pub scene: PathBuf,
    /// Loopback port of the page and its WebSocket (0: any free port).
    #[arg(long, default_value_t = play::DEFAULT_PORT)]
    pub port: u16,
    /// A real device over the UDP bridge (udp:HOST:PORT, or udp:PORT on loopback) as the
    /// hand; the page is then the view and the sound.
    #[arg(long)]
    pub device: Option<String>,
    /// The session's recording (MCAP), also offered for download on the end screen.
    #[arg(long, default_value = "play.mcap")]
    pub out: PathBuf,
    /// Session length, s (0 < s ≤ 3600); without it the session ends when the player ends it
    /// on the page or presses Ctrl-C.
    #[arg(long)]
    pub seconds: Option<f64>,
    /// Take the student through a lesson (FILE, or without it the built-in module): each
    /// step runs its own scene (SCENE is then unused), recorded to --out without its
    /// extension, a directory, as STEP-ID.mcap.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    pub lesson: Option<Option<PathBuf>>,
    #[command(flatten)]
    pub(crate) rt: crate::rt_args::RtArgs,
}

/// The lesson of `--lesson`: the file's (refused with its line, column, field and what is
/// allowed), or the built-in module.
pub(crate) fn lesson(arg: Option<&Option<PathBuf>>) -> Result<Option<teaching::Lesson>, String> {
    match arg {
        None => Ok(None),
        Some(None) => teaching::builtin::module()
            .map(Some)
            .map_err(|e| e.to_string()),
        Some(Some(path)) => teaching::load_lesson(path)
            .map(Some)
            .map_err(|e| e.to_string()),
    }
}

/// `--device` of a page front end: a device in another process over the bridge (`None`: the
/// page is the hand); a device model is refused, saying whose hand the page is (`hand`).
pub(crate) fn bridged_device(
    device: Option<&str>,
    hand: &str,
) -> Result<Option<haptic_devices::bridge::BridgeConfig>, String> {
    match device.map(DeviceSource::parse).transpose() {
        Ok(None) => Ok(None),
        Ok(Some(DeviceSource::Udp(b))) => Ok(Some(b)),
        Ok(Some(DeviceSource::Model(m))) => Err(format!(
            "--device `{}`: {hand}; --device names a device in another process (udp:HOST:PORT \
             or udp:PORT)",
            m.name()
        )),
        Err(e) => Err(format!("--device: {e}")),
    }
}

/// Runs `nanohaptics play`: prints the page's address, runs the session, prints its figures.
/// After the session the end screen and the download stay up until Ctrl-C.
pub fn cmd(a: &PlayArgs) -> Result<u8, String> {
    let scene = SceneSource::resolve(&a.scene).map_err(|e| e.to_string())?;
    let mut c = play::PlayConfig::new(scene, a.out.clone());
    c.port = a.port;
    c.seconds = a.seconds;
    c.lesson = lesson(a.lesson.as_ref())?;
    c.rt = a.rt.request()?;
    c.device = crate::play_cmd::bridged_device(a.device.as_deref(), "play's own hand is the page")?;
    let stop = crate::run_cmd::interrupt_flag()?;
    let s = play::run(&c, &stop, &mut |url| {
        println!("open {url} in a browser (Ctrl-C ends the session)");
    })
    .map_err(|e| e.to_string())?;
    println!("{}", s.line());
    if let Some(l) = &s.lesson {
        let (pre, post) = (l.progress.test_score(true), l.progress.test_score(false));
        println!(
            "lesson: {} steps done, pre-test {} of {}, post-test {} of {}, recordings in {}",
            l.runs.iter().filter(|r| r.met_at.is_some()).count(),
            pre.0,
            pre.1,
            post.0,
            post.1,
            l.dir.display()
        );
        if let Some(md) = l
            .report
            .iter()
            .find(|p| p.extension().is_some_and(|e| e == "md"))
        {
            println!("lesson report: {}", md.display());
        }
    }
    Ok(status::SUCCESS)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::lesson;
    use crate::{main_with_args, status};
    use std::path::PathBuf;

    /// `--lesson` alone is the built-in module; a file with a mistake is refused with its line,
    /// column, field and what is allowed, as a command error (status 1, as other bad input).
    #[test]
    fn play_lesson_reads_the_builtin_module_and_refuses_a_bad_file() {
        let builtin = lesson(Some(&None)).unwrap().unwrap();
        assert_eq!(builtin.steps.len(), 11);
        assert!(lesson(None).unwrap().is_none());
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-play-lesson");
        std::fs::create_dir_all(&dir).unwrap();
        let bad = dir.join("bad.lesson.toml");
        std::fs::write(
            &bad,
            "[lesson]\ntitle = \"x\"\n[[step]]\nid = \"a\"\ntitle = \"A\"\nscene = \"brickworld\"\n\
             task = \"t\"\ndone = { when = \"atom_snapped\" }\n",
        )
        .unwrap();
        let e = lesson(Some(&Some(bad.clone()))).unwrap_err();
        assert_eq!(
            e,
            format!(
                "{}:8:17: lesson: `step[0].done.when` = \"atom_snapped\" cannot happen in scene \
                 \"brickworld\": it reads nano.snap, which a brickworld scene never emits (allowed \
                 in a brickworld scene: house_complete, brick_lifted, brick_thrown, brick_placed, \
                 time)",
                bad.display()
            )
        );
        let arg = bad.to_string_lossy().to_string();
        assert_eq!(
            main_with_args([
                "nanohaptics",
                "play",
                "--lesson",
                arg.as_str(),
                "--port",
                "0"
            ]),
            status::ERROR
        );
    }
}
