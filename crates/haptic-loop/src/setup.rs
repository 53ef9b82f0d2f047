//! The one set-up of a session, shared by every way of running one: [`run_session`], the
//! [`Stepper`] and the browser game all build their loop, header and sinks here, so a
//! session is described, checked and recorded the same way whoever drives it. Also the scene
//! source every session starts from ([`SceneSource`]).
//!
//! Not for: choosing or opening the device (that is [`haptic_devices::source`]) or running
//! the ticks (that is the [`Runner`](haptic_engine::runner::Runner)).
//!
//! [`run_session`]: crate::session::run_session
//! [`Stepper`]: crate::stepper::Stepper
//!
//! ```
//! use haptic_loop::setup::{SceneSource, Setup, SetupOptions};
//! let scene = SceneSource::builtin("wall").unwrap();
//! let specs = haptic_types::DeviceModel::Falcon.specs().clone();
//! let s = Setup::new(&SetupOptions::new(&scene, specs, "batch", "script")).unwrap();
//! assert_eq!(s.header.scene_kind, "wall");
//! assert_eq!(s.rate_hz(), 1000);
//! ```

use crate::arrays::SessionArrays;
use crate::error::SessionError;
use crate::scene::{SceneFile, load_scene_for};
use crate::sinks::SessionSinks;
use haptic_devices::source::DeviceSource;
use haptic_engine::check::SceneError;
use haptic_engine::haptic::HapticLoop;
use haptic_engine::header::SessionHeader;
use haptic_types::DeviceSpecs;
use haptic_types::textpos::Location;
use recording::channels::messages;
use std::path::{Path, PathBuf};

/// A scene file's text and the folder it came from (to find its default script).
#[derive(Clone, Debug)]
pub struct SceneSource {
    /// TOML text.
    pub text: String,
    /// Where the text came from, as errors name it: the path, or `built-in NAME`.
    pub origin: String,
    /// Folder for relative paths in the file.
    pub dir: Option<PathBuf>,
    /// Scripts that come with the scene (a built-in scene's default script), file name → text;
    /// consulted before the disk.
    pub scripts: Vec<(String, String)>,
}

/// Reads a TOML text file; a recording or other binary file is named as such.
pub fn read_toml_text(path: &Path) -> Result<String, SessionError> {
    let io = |message: String| SessionError::Io {
        path: path.display().to_string(),
        message,
    };
    let bytes = std::fs::read(path).map_err(|e| io(e.to_string()))?;
    if bytes.starts_with(recording::MAGIC) {
        return Err(io(
            "this is an MCAP recording, not a TOML file (recordings are for \
             `nanohaptics replay`, `info` and `render`)"
                .into(),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        let ok = e.utf8_error().valid_up_to();
        let text = String::from_utf8_lossy(&e.as_bytes()[..ok]).into_owned();
        let at = haptic_types::textpos::position(&text, ok);
        io(format!(
            "not UTF-8 text: byte {ok} (line {}, column {}) is not valid UTF-8 (a TOML file is text)",
            at.line, at.column
        ))
    })
}

impl SceneSource {
    /// A scene from its TOML text; `origin` names it in errors (a path, `built-in wall`).
    pub fn from_text(text: impl Into<String>, origin: impl Into<String>) -> Self {
        SceneSource {
            text: text.into(),
            origin: origin.into(),
            dir: None,
            scripts: Vec::new(),
        }
    }

    /// Reads a scene file.
    pub fn from_path(path: &Path) -> Result<Self, SessionError> {
        Ok(SceneSource {
            text: read_toml_text(path)?,
            origin: path.display().to_string(),
            dir: path.parent().map(Path::to_path_buf),
            scripts: Vec::new(),
        })
    }

    /// `error`, located in this scene's text: `file:line:column: message`.
    pub fn locate(&self, error: SceneError) -> SessionError {
        SessionError::SceneFile {
            at: Location {
                file: self.origin.clone(),
                at: error.position(&self.text),
            },
            error: Box::new(error),
        }
    }

    /// Parses the scene's text, errors located.
    pub fn parse(&self) -> Result<SceneFile, SessionError> {
        SceneFile::parse(&self.text).map_err(|e| self.locate(e))
    }

    /// The built-in scene `name` (`wall` or `wall.toml`) with its default script.
    pub fn builtin(name: &str) -> Option<Self> {
        crate::builtin::find(name).map(|b| SceneSource {
            text: b.scene.to_string(),
            origin: format!("built-in {}", b.name),
            dir: None,
            scripts: vec![(b.script_file.to_string(), b.script.to_string())],
        })
    }

    /// A scene file on disk, or else a built-in scene by name (`wall`, `wall.toml`): files on
    /// disk override the built-ins, so this works from any directory.
    pub fn resolve(arg: &Path) -> Result<Self, SessionError> {
        if arg.exists() {
            return Self::from_path(arg);
        }
        // `wall`, `wall.toml` or `scenes/wall.toml` (the repository's path, from anywhere).
        let parent_ok = arg
            .parent()
            .is_none_or(|p| p.as_os_str().is_empty() || p == Path::new("scenes"));
        let name = arg
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        match Self::builtin(&name) {
            Some(s) if parent_ok => Ok(s),
            _ => Err(SessionError::Io {
                path: arg.display().to_string(),
                message: format!(
                    "no such file, and not a built-in scene (built-in: {}; `nanohaptics scenes export DIR` writes editable copies)",
                    crate::builtin::names()
                ),
            }),
        }
    }
}

/// What a session is set up from, besides its scene and device.
#[derive(Clone, Debug)]
pub struct SetupOptions<'a> {
    /// The scene.
    pub scene: &'a SceneSource,
    /// The device's specifications (a local model's, or what a bridged device announced).
    pub specs: DeviceSpecs,
    /// The recording's mode: `batch`, `realtime` or `stepped`.
    pub mode: &'a str,
    /// How the device is connected, as recorded (`script`, `udp:127.0.0.1:7000`, `python`).
    pub link: String,
    /// Who holds the device, as recorded; `None`: the link.
    pub operator: Option<String>,
    /// The script's name and TOML text, as recorded; `None`: no script.
    pub script: Option<(String, String)>,
    /// Session start, ns since the Unix epoch; `None`: the wall clock now.
    pub start_time_ns: Option<u64>,
    /// Keep the per-tick arrays.
    pub keep_arrays: bool,
    /// Record to this MCAP file.
    pub out: Option<PathBuf>,
}

impl<'a> SetupOptions<'a> {
    /// `scene` on a device with `specs`, connected by `link`, in `mode`: no script, keeping
    /// the arrays, not recorded, starting now.
    pub fn new(scene: &'a SceneSource, specs: DeviceSpecs, mode: &'a str, link: &str) -> Self {
        SetupOptions {
            scene,
            specs,
            mode,
            link: link.to_string(),
            operator: None,
            script: None,
            start_time_ns: None,
            keep_arrays: true,
            out: None,
        }
    }
}

/// A session made ready to run: its loop, its header and its sinks (no live view yet:
/// set [`SessionSinks::live`] to serve one).
pub struct Setup {
    /// The loop, at tick 0.
    pub lp: HapticLoop,
    /// The session's header (the recorder writes it as the file's description).
    pub header: SessionHeader,
    /// The session's sinks.
    pub sinks: SessionSinks,
}

impl Setup {
    /// Builds the scene for the device (errors name the scene file's line and column), checks
    /// its state fields are recordable names, writes the header and makes the sinks.
    pub fn new(o: &SetupOptions) -> Result<Setup, SessionError> {
        let loaded =
            load_scene_for(&o.scene.text, o.specs.clone()).map_err(|e| o.scene.locate(e))?;
        let fields = loaded.scene.state_fields();
        if let Some(bad) = fields.iter().find(|f| !messages::valid_field_name(f)) {
            return Err(SessionError::StateField(bad.clone()));
        }
        let rate = loaded.config.rate_hz;
        let mut header = loaded.header(
            &o.scene.text,
            o.mode,
            &o.link,
            o.start_time_ns.unwrap_or_else(now_unix_ns),
        );
        if let Some((name, toml)) = &o.script {
            header.script_name = name.clone();
            header.script_toml = toml.clone();
        }
        if let Some(op) = &o.operator {
            header.operator = op.clone();
        }
        let lp = HapticLoop::new(loaded.config, loaded.scene);
        let arrays = SessionArrays::new(rate, fields);
        let sinks = SessionSinks::new(arrays, o.keep_arrays, o.out.clone());
        Ok(Setup { lp, header, sinks })
    }

    /// The loop's tick rate, Hz.
    pub fn rate_hz(&self) -> u32 {
        self.lp.config().rate_hz
    }
}

/// The device a session of `file` that starts at `start_time_ns` (ns since the Unix epoch)
/// is played on: the one named (`None`: the scene's model). A bridged device is welcomed with
/// the scene's tick rate, name, start time and button roles, so every way of running a bridged session
/// (`run`, `play`, the wheel) tells the device the same.
pub fn session_device(
    file: &SceneFile,
    device: Option<&DeviceSource>,
    start_time_ns: u64,
) -> DeviceSource {
    match device {
        Some(DeviceSource::Udp(b)) => DeviceSource::Udp(
            b.clone()
                .for_session(file.loop_.rate_hz, &file.scene.name, start_time_ns)
                // The scene's role names were checked when it was read (`SceneFile::parse`
                // keeps them; `load_scene` refuses a bad one); a bad one here maps nothing.
                .with_buttons(file.device.button_overrides().unwrap_or_default()),
        ),
        Some(DeviceSource::Model(m)) => DeviceSource::Model(*m),
        None => DeviceSource::Model(file.device.model),
    }
}

/// Wall-clock time now, ns since the Unix epoch (information only: it never reaches the
/// physics).
pub fn now_unix_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}
