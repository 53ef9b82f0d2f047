//! The MCAP recorder as a sink of the runner: encodes each tick's messages and hands them to
//! the writer thread (never blocking the tick). Also the one conversion between the engine's
//! [`SessionHeader`] and the file's description ([`description_of`], [`header_of`]).

use crate::encode::LoopEncoder;
use haptic_engine::haptic::HapticLoop;
use haptic_engine::header::SessionHeader;
use haptic_engine::pacing::TickStats;
use haptic_engine::sink::{SessionInfo, Sink, SinkError, TickView};
use recording::channels::messages::DescriptionMsg;
use recording::{Recorder, RecorderSetup, TickEncoder, TickMessages, WriteSummary};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Records a session to an MCAP file.
pub struct RecorderSink {
    path: PathBuf,
    recorder: Option<Recorder>,
    enc: Option<LoopEncoder>,
    mode: String,
    /// Metadata record `buttons`: the roles in force (issue 41).
    buttons: BTreeMap<String, String>,
    summary: Option<WriteSummary>,
}

impl RecorderSink {
    /// A recorder that will create `path` when the session starts.
    pub fn new(path: PathBuf) -> Self {
        RecorderSink {
            path,
            recorder: None,
            enc: None,
            mode: String::new(),
            buttons: BTreeMap::new(),
            summary: None,
        }
    }

    /// What the writer did (after the session finished).
    pub fn summary(&self) -> Option<&WriteSummary> {
        self.summary.as_ref()
    }
}

/// The recording's description of a session: its header, in the file's current format.
pub fn description_of(h: &SessionHeader) -> DescriptionMsg {
    let d = &h.device;
    DescriptionMsg {
        format: recording::channels::FORMAT_VERSION.to_string(),
        scene_name: h.scene_name.clone(),
        scene_kind: h.scene_kind.clone(),
        scene_toml: h.scene_toml.clone(),
        device_model: d.name.to_string(),
        rate_hz: h.rate_hz,
        mode: h.mode.clone(),
        script_name: h.script_name.clone(),
        script_toml: h.script_toml.clone(),
        operator: h.operator.clone(),
        state_fields: h.state_fields.clone(),
        start_time_ns: h.start_time_ns,
        device_link: h.device_link.clone(),
        device_max_force_n: d.limits.max_force_n,
        device_max_stiffness_n_per_m: d.limits.max_stiffness_n_per_m,
        device_workspace_radius_m: d.workspace_radius_m,
        device_buttons: d.button_names.iter().map(|b| b.to_string()).collect(),
    }
}

/// The header of a recorded session, read back from its description (a replay runs with it).
pub fn header_of(d: &DescriptionMsg) -> SessionHeader {
    SessionHeader {
        scene_name: d.scene_name.clone(),
        scene_kind: d.scene_kind.clone(),
        scene_toml: d.scene_toml.clone(),
        rate_hz: d.rate_hz,
        mode: d.mode.clone(),
        script_name: d.script_name.clone(),
        script_toml: d.script_toml.clone(),
        operator: d.operator.clone(),
        state_fields: d.state_fields.clone(),
        start_time_ns: d.start_time_ns,
        device_link: d.device_link.clone(),
        device: d.device_specs(),
    }
}

/// Metadata record `buttons` of a recording: the button that plays each role (`grip`, `turn_x`,
/// `turn_y`, `turn_z`; empty for none) and `mapping`, the whole mapping in words, as the
/// recorded device's buttons and the recorded scene's `[device] buttons` give it (what a replay
/// uses: the record states it, it does not drive it).
pub fn buttons_metadata(h: &SessionHeader) -> BTreeMap<String, String> {
    let names = h.device.button_strs();
    let Ok(roles) = crate::scene::device::roles_in(&h.scene_toml, &h.device) else {
        return BTreeMap::new();
    };
    let mut m: BTreeMap<String, String> = haptic_types::Role::ALL
        .into_iter()
        .map(|r| {
            let b = roles
                .bit(r)
                .and_then(|b| names.get(b as usize).copied())
                .unwrap_or("");
            (r.name().to_string(), b.to_string())
        })
        .collect();
    m.insert("mapping".into(), roles.describe(&names));
    m
}

/// Metadata record `session` of a recording: the tick statistics and the mode.
pub fn stats_metadata(stats: &TickStats, mode: &str) -> BTreeMap<String, String> {
    let mut m = BTreeMap::new();
    m.insert("mode".into(), mode.into());
    m.insert("ticks".into(), stats.ticks.to_string());
    m.insert("compute_p50_ns".into(), stats.compute.p50_ns.to_string());
    m.insert("compute_p99_ns".into(), stats.compute.p99_ns.to_string());
    m.insert("compute_max_ns".into(), stats.compute.max_ns.to_string());
    m.insert("jitter_p99_ns".into(), stats.jitter.p99_ns.to_string());
    m.insert("jitter_max_ns".into(), stats.jitter.max_ns.to_string());
    m.insert("missed_deadlines".into(), stats.missed.to_string());
    m.insert("wakeup_p50_ns".into(), stats.wakeup.p50_ns.to_string());
    m.insert("wakeup_p99_ns".into(), stats.wakeup.p99_ns.to_string());
    m.insert("wakeup_p999_ns".into(), stats.wakeup.p999_ns.to_string());
    m.insert("wakeup_max_ns".into(), stats.wakeup.max_ns.to_string());
    for (k, v) in stats.realtime.metadata() {
        m.insert(k.into(), v);
    }
    m.insert("wall_s".into(), format!("{:.6}", stats.wall_s));
    m
}

impl Sink for RecorderSink {
    fn name(&self) -> &'static str {
        "recorder"
    }

    fn start(&mut self, info: &SessionInfo<'_>, lp: &HapticLoop) -> Result<(), SinkError> {
        self.recorder = Some(
            Recorder::create(
                &self.path,
                RecorderSetup {
                    description: description_of(info.header),
                    flush_every_ns: 1_000_000_000,
                },
            )
            .map_err(SinkError::new)?,
        );
        self.enc = Some(LoopEncoder::new(lp, info.header.start_time_ns));
        self.mode = info.header.mode.clone();
        self.buttons = buttons_metadata(info.header);
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let (Some(rec), Some(enc)) = (self.recorder.as_mut(), self.enc.as_mut()) else {
            return Ok(());
        };
        let n = t.result.tick;
        let mut msgs = Vec::with_capacity(8);
        msgs.push(TickEncoder::input(n, &t.sample, t.deadline_missed));
        msgs.extend(TickEncoder::switches(t.result));
        enc.outputs(t.result, t.lp, &mut msgs);
        msgs.push(TickEncoder::timing(n, t.start_late_ns, t.compute_ns));
        rec.write(TickMessages {
            tick: n,
            log_time_ns: enc.log_time_ns(n),
            msgs,
        })
        .map_err(SinkError::new)?;
        Ok(())
    }

    fn finish(&mut self, stats: &TickStats, link: &[(&'static str, u64)]) -> Result<(), SinkError> {
        if let Some(mut rec) = self.recorder.take() {
            rec.metadata("session", stats_metadata(stats, &self.mode))
                .map_err(SinkError::new)?;
            if !self.buttons.is_empty() {
                rec.metadata("buttons", std::mem::take(&mut self.buttons))
                    .map_err(SinkError::new)?;
            }
            if !link.is_empty() {
                rec.metadata(
                    "device_link",
                    link.iter()
                        .map(|(k, v)| (k.to_string(), v.to_string()))
                        .collect(),
                )
                .map_err(SinkError::new)?;
            }
            self.summary = Some(rec.finish().map_err(SinkError::new)?);
        }
        Ok(())
    }
}
