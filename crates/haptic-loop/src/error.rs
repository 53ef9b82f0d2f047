//! The engine's one error type: what can go wrong in a session, a replay or a re-simulation.

use crate::live::LiveError;
use haptic_devices::ScriptError;
use haptic_engine::check::SceneError;
use haptic_engine::runner::RunError;
use haptic_engine::sink::SinkError;
use haptic_types::DeviceError;
use haptic_types::textpos::Location;
use recording::RecordingError;
use recording::writer::RecordError;

/// Errors of a session.
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// The scene (one without a file: the copy inside a recording, a built-in table).
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The script (one without a file).
    #[error(transparent)]
    Script(#[from] ScriptError),
    /// An error in a scene file, with where it is.
    #[error("{at}: {error}")]
    SceneFile {
        /// File and, when known, line and column.
        at: Location,
        /// What is wrong.
        error: Box<SceneError>,
    },
    /// An error in a script file, with where it is.
    #[error("{at}: {error}")]
    ScriptFile {
        /// File and, when known, line and column.
        at: Location,
        /// What is wrong.
        error: Box<ScriptError>,
    },
    /// The scene's default script cannot be read.
    #[error(
        "{at}: `scene.default_script` = \"{script}\": cannot read {path}: {message} (pass \
         --script FILE, or keep the script next to the scene; `nanohaptics scenes export DIR` \
         writes the built-in scenes with their scripts)"
    )]
    DefaultScript {
        /// The scene file and the field's line and column.
        at: Location,
        /// The file name the scene gives.
        script: String,
        /// Where it was looked for.
        path: String,
        /// OS error.
        message: String,
    },
    /// The device.
    #[error("device: {0}")]
    Device(#[from] DeviceError),
    /// Writing the recording.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Reading a recording.
    #[error(transparent)]
    Recording(#[from] RecordingError),
    /// No script given and the scene names no default script.
    #[error("no script: pass --script or set `scene.default_script` in the scene file")]
    NoScript,
    /// A file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// Path.
        path: String,
        /// OS error.
        message: String,
    },
    /// Session length out of range (not finite, not in `0 < length ≤ 3600 s`, or shorter
    /// than half a tick, which would round to no tick at all), in the one wording of
    /// [`ValueError`](haptic_types::value::ValueError).
    #[error(transparent)]
    Seconds(haptic_types::value::ValueError),
    /// A scene reported a state field name that cannot be a message field.
    #[error("scene state field `{0}` is not a lower-snake-case field name")]
    StateField(String),
    /// A recording's state fields are not the ones its scene has now (another version of it).
    #[error("recorded state fields {}, the scene now has {}", recorded.join(", "), now.join(", "))]
    StateFieldsChanged {
        /// The recording's state fields.
        recorded: Vec<String>,
        /// The rebuilt scene's.
        now: Vec<String>,
    },
    /// The live view could not start or publish.
    #[error("live view: {0}")]
    Live(String),
    /// An option out of range or inconsistent with another.
    #[error("{0}")]
    Option(String),
    /// A sink (live view, frames) failed.
    #[error("{0}")]
    Sink(String),
    /// A switch that the scene refused at a tick (scheduled by a script or a recording).
    #[error("tick {tick}: {error}")]
    Switch {
        /// The tick it was to apply to.
        tick: u64,
        /// Why it was refused.
        error: haptic_types::SwitchError,
    },
}

impl From<SinkError> for SessionError {
    /// Gives a sink's error back its type: a recording's write error stays
    /// [`SessionError::Record`] (with its OS error), a read error [`SessionError::Recording`].
    fn from(e: SinkError) -> Self {
        let e = match e.0.downcast::<SessionError>() {
            Ok(s) => return *s,
            Err(e) => e,
        };
        let e = match e.downcast::<RecordError>() {
            Ok(r) => return SessionError::Record(*r),
            Err(e) => e,
        };
        let e = match e.downcast::<RecordingError>() {
            Ok(r) => return SessionError::Recording(*r),
            Err(e) => e,
        };
        match e.downcast::<LiveError>() {
            Ok(l) => (*l).into(),
            Err(e) => SessionError::Sink(e.to_string()),
        }
    }
}

impl From<LiveError> for SessionError {
    fn from(e: LiveError) -> Self {
        match e {
            LiveError::Option(m) => SessionError::Option(m),
            LiveError::Serve(m) => SessionError::Live(m),
        }
    }
}

impl From<RunError> for SessionError {
    fn from(e: RunError) -> Self {
        match e {
            RunError::Device(d) => SessionError::Device(d),
            RunError::Sink(s) => s.into(),
            RunError::Switch { tick, error } => SessionError::Switch { tick, error },
        }
    }
}
