//! A session driven one tick at a time from outside (a Python driver, a notebook, a test), as
//! `mujoco.mj_step` is: the caller hands in each device reading and gets the force back. The
//! same sinks as every other session (recorder, per-tick arrays) see each tick, so a stepped
//! session records and replays bit for bit like any other.
//!
//! ```
//! use haptic_loop::stepper::{Stepper, StepperOptions};
//! use haptic_loop::session::SceneSource;
//! use haptic_types::{Buttons, DeviceSample};
//! let scene = SceneSource::from_path("../../scenes/wall.toml".as_ref()).unwrap();
//! let mut s = Stepper::new(StepperOptions::new(scene)).unwrap();
//! for k in 0..500 {
//!     let z = -0.001 * k as f64 / 100.0; // press 5 mm down over 0.5 s
//!     let f = s.tick(DeviceSample::new([0.0, 0.0, z], Buttons(0))).unwrap().device_force_n;
//!     assert!(f[2] >= 0.0);
//! }
//! let report = s.finish().unwrap();
//! assert_eq!(report.arrays.tick.len(), 500);
//! ```

use crate::arrays::SessionArrays;
use crate::session::{SceneSource, SessionError};
use crate::setup::{Setup, SetupOptions};
use crate::sinks::SessionSinks;
use haptic_engine::clock::Batch;
use haptic_engine::haptic::HapticLoop;
use haptic_engine::header::SessionHeader;
use haptic_engine::pacing::TickStats;
use haptic_engine::runner::TickEngine;
use haptic_types::DeviceModel;
use haptic_types::DeviceSample;
use haptic_types::ForceCommand;
use haptic_types::TickResult;
use haptic_types::{DeviceError, DeviceSpecs, HapticDevice, TickTime};
use recording::WriteSummary;
use std::path::PathBuf;

/// Options of a stepped session.
#[derive(Clone, Debug)]
pub struct StepperOptions {
    /// The scene.
    pub scene: SceneSource,
    /// Device model overriding the scene file's.
    pub device: Option<DeviceModel>,
    /// Record to this MCAP file.
    pub out: Option<PathBuf>,
    /// Keep the per-tick arrays.
    pub arrays: bool,
    /// Session start, ns since the Unix epoch (`None`: now).
    pub start_time_ns: Option<u64>,
    /// How the caller is connected, as written in the recording (`python`).
    pub link: String,
}

impl StepperOptions {
    /// A stepped session of `scene` keeping arrays, not recorded.
    pub fn new(scene: SceneSource) -> Self {
        StepperOptions {
            scene,
            device: None,
            out: None,
            arrays: true,
            start_time_ns: None,
            link: "python".into(),
        }
    }
}

/// What a stepped session produced.
#[derive(Debug)]
pub struct StepperReport {
    /// The session's header (as recorded).
    pub header: SessionHeader,
    /// Per-tick arrays (empty when turned off).
    pub arrays: SessionArrays,
    /// Tick-time statistics (work of each `tick` call).
    pub stats: TickStats,
    /// What the writer did, when recording.
    pub written: Option<WriteSummary>,
}

/// A session stepped by its caller.
pub struct Stepper {
    lp: HapticLoop,
    header: SessionHeader,
    sinks: SessionSinks,
    engine: TickEngine,
}

impl Stepper {
    /// Builds the scene and starts the sinks (the recording file is created now).
    pub fn new(opts: StepperOptions) -> Result<Self, SessionError> {
        let file = opts.scene.parse()?;
        let model = opts.device.unwrap_or(file.device.model);
        let Setup {
            lp,
            header,
            mut sinks,
        } = Setup::new(&SetupOptions {
            start_time_ns: opts.start_time_ns,
            keep_arrays: opts.arrays,
            out: opts.out.clone(),
            ..SetupOptions::new(&opts.scene, model.specs().clone(), "stepped", &opts.link)
        })?;
        let mut engine = TickEngine::new(Vec::new());
        engine.start(&mut sinks.list(), &lp, &header, None)?;
        Ok(Stepper {
            lp,
            header,
            sinks,
            engine,
        })
    }

    /// Runs one tick on `sample` and hands it to the sinks (the caller renders the force:
    /// [`command`](Self::command)).
    pub fn tick(&mut self, sample: DeviceSample) -> Result<&TickResult, SessionError> {
        let mut given = Given {
            specs: &self.header.device,
            sample,
        };
        self.engine.cycle(
            &mut self.sinks.list(),
            &mut self.lp,
            &mut given,
            &mut Batch,
            None,
        )?;
        Ok(self.lp.last_result())
    }

    /// Sets a run-time switch of the scene before the next tick (recorded as that tick's
    /// input, like a script's `[[switch]]`); errors name the switch and its allowed range.
    pub fn switch(&mut self, name: &str, value: f64) -> Result<(), SessionError> {
        let tick = self.lp.next_tick();
        self.lp
            .switch(name, value)
            .map_err(|error| SessionError::Switch { tick, error })
    }

    /// The command for the device after the last tick (force, local stiffness, status).
    pub fn command(&self) -> ForceCommand {
        self.lp.command(0)
    }

    /// The loop (configuration, scene state, drawing).
    pub fn haptic_loop(&self) -> &HapticLoop {
        &self.lp
    }

    /// The session's header.
    pub fn header(&self) -> &SessionHeader {
        &self.header
    }

    /// Per-tick arrays so far (`None` when turned off).
    pub fn arrays(&self) -> Option<&SessionArrays> {
        self.sinks.keep_arrays.then_some(&self.sinks.arrays)
    }

    /// Ends the session: closes the recording and returns what it produced.
    pub fn finish(mut self) -> Result<StepperReport, SessionError> {
        let stats = self.engine.finish(&mut self.sinks.list(), &[])?;
        let written = self.sinks.written();
        Ok(StepperReport {
            header: self.header,
            arrays: if self.sinks.keep_arrays {
                self.sinks.arrays
            } else {
                SessionArrays::default()
            },
            stats,
            written,
        })
    }
}

/// The caller's sample as the device of one cycle: the caller renders the force itself
/// ([`Stepper::command`]).
struct Given<'a> {
    specs: &'a DeviceSpecs,
    sample: DeviceSample,
}

impl HapticDevice for Given<'_> {
    fn specs(&self) -> &DeviceSpecs {
        self.specs
    }
    fn sample(&mut self, _time: TickTime) -> Result<DeviceSample, DeviceError> {
        Ok(self.sample)
    }
    fn set_force(&mut self, _cmd: &ForceCommand) -> Result<(), DeviceError> {
        Ok(())
    }
}
