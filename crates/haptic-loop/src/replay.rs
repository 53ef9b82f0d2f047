//! Replay and bit-exact verification of a recording.
//!
//! The scene is rebuilt from the description (scene text and the device's specifications), the
//! device inputs, sample ages and deadline flags are played back through a [`ReplayDevice`] by
//! the [runner](haptic_engine::runner), and the verifier sink recomputes every verified output message
//! (state, force, events, Foxglove channels) and compares it byte for byte with the recorded
//! one. The first difference names its tick and channel.

use crate::encode::LoopEncoder;
use crate::error::SessionError;
use crate::replay_device::ReplayDevice;
use crate::scene::load_scene_for;
use haptic_engine::haptic::HapticLoop;
use haptic_engine::pacing::Pacing;
use haptic_engine::runner::Runner;
use haptic_engine::sink::{SessionInfo, Sink, SinkError, TickView};
use recording::channels::messages::{Channel, ForceMsg, StateMsg};
use recording::{OutMsg, Recording, RecordingError};

/// The first difference between a recording and its replay.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Divergence {
    /// Tick index.
    pub tick: u64,
    /// Topic of the channel.
    pub channel: String,
    /// What differs.
    pub detail: String,
}

/// Outcome of a verification.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct VerifyReport {
    /// Ticks replayed.
    pub ticks: u64,
    /// Output messages compared.
    pub messages_compared: u64,
    /// The first divergence, if any.
    pub divergence: Option<Divergence>,
}

impl VerifyReport {
    /// True when every output matched bit for bit.
    pub fn ok(&self) -> bool {
        self.divergence.is_none()
    }
}

fn fmt3(v: [f64; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

fn fmt_list(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| x.to_string()).collect();
    format!("[{}]", parts.join(", "))
}

fn describe(channel: Channel, rec: &[u8], rep: &[u8], n_fields: usize) -> String {
    match channel {
        Channel::Force => {
            if let (Ok(a), Ok(b)) = (ForceMsg::decode(rec), ForceMsg::decode(rep)) {
                return format!(
                    "recorded world {} N, device {} N, status {}; replayed world {} N, \
                     device {} N, status {}",
                    fmt3(a.world_force_n),
                    fmt3(a.device_force_n),
                    a.status,
                    fmt3(b.world_force_n),
                    fmt3(b.device_force_n),
                    b.status
                );
            }
        }
        Channel::State => {
            if let (Ok(a), Ok(b)) = (
                StateMsg::decode(rec, n_fields),
                StateMsg::decode(rep, n_fields),
            ) {
                return format!(
                    "recorded cursor {} m, state {}; replayed cursor {} m, state {}",
                    fmt3(a.cursor_m),
                    fmt_list(&a.values),
                    fmt3(b.cursor_m),
                    fmt_list(&b.values)
                );
            }
        }
        _ => {}
    }
    let at = rec
        .iter()
        .zip(rep)
        .position(|(a, b)| a != b)
        .unwrap_or(rec.len().min(rep.len()));
    format!(
        "recorded {} bytes, replayed {} bytes, first difference at byte {at}",
        rec.len(),
        rep.len()
    )
}

/// The verifier as a sink: encodes each replayed tick exactly as the recorder did and compares.
pub struct VerifySink<'r> {
    expected: Vec<Vec<(Channel, &'r [u8])>>,
    n_fields: usize,
    enc: Option<LoopEncoder>,
    msgs: Vec<OutMsg>,
    /// Output messages compared.
    pub compared: u64,
    /// The first divergence.
    pub divergence: Option<Divergence>,
}

impl Sink for VerifySink<'_> {
    fn name(&self) -> &'static str {
        "verifier"
    }

    fn start(&mut self, info: &SessionInfo<'_>, lp: &HapticLoop) -> Result<(), SinkError> {
        self.enc = Some(LoopEncoder::new(lp, info.header.start_time_ns));
        Ok(())
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let Some(enc) = self.enc.as_mut() else {
            return Ok(());
        };
        if self.divergence.is_some() {
            return Ok(());
        }
        self.msgs.clear();
        enc.outputs(t.result, t.lp, &mut self.msgs);
        let tick = t.result.tick;
        let Some(want) = self.expected.get(tick as usize) else {
            return Ok(());
        };
        for ch in Channel::ALL.into_iter().filter(|c| c.verified()) {
            let w = want.iter().filter(|m| m.0 == ch).map(|m| m.1);
            let mut g = self
                .msgs
                .iter()
                .filter(|m| m.channel == ch)
                .map(|m| m.data.as_slice());
            let mut detail = None;
            for a in w {
                match g.next() {
                    Some(b) => {
                        self.compared += 1;
                        if a != b {
                            detail = Some(describe(ch, a, b, self.n_fields));
                            break;
                        }
                    }
                    None => {
                        detail = Some("recorded a message that replay did not produce".into());
                        break;
                    }
                }
            }
            if detail.is_none() && g.next().is_some() {
                detail = Some("replay produced a message that was not recorded".into());
            }
            if let Some(detail) = detail {
                self.divergence = Some(Divergence {
                    tick,
                    channel: ch.topic().to_string(),
                    detail,
                });
                break;
            }
        }
        Ok(())
    }
}

/// A recording made ready to run again: its scene rebuilt from the description for the
/// recorded device, its inputs (positions, buttons, sample ages, deadline flags) as a
/// [`ReplayDevice`], its switches as the runner's schedule. The one re-simulation path of
/// `replay`, `render` and `demo`.
pub struct Resimulation<'r> {
    rec: &'r Recording,
    file: crate::scene::SceneFile,
    lp: HapticLoop,
    dev: ReplayDevice,
    switches: Vec<(u64, haptic_types::Switch)>,
}

impl<'r> Resimulation<'r> {
    /// Rebuilds `rec`'s session. Errors: the scene no longer loads, its rate is not the
    /// recorded one, its state fields changed ([`SessionError::StateFieldsChanged`]), or the
    /// recorded inputs or switches are malformed.
    pub fn prepare(rec: &'r Recording) -> Result<Self, SessionError> {
        let d = &rec.description;
        let specs = d.device_specs();
        let loaded = load_scene_for(&d.scene_toml, specs.clone())?;
        let period = loaded.config.period_ns();
        if loaded.config.rate_hz != d.rate_hz {
            return Err(SessionError::Recording(RecordingError::BadMessage {
                topic: Channel::Description.topic().into(),
                log_time_ns: 0,
                detail: format!(
                    "rate_hz {} does not match the scene's {}",
                    d.rate_hz, loaded.config.rate_hz
                ),
            }));
        }
        let now = loaded.scene.state_fields();
        if now != d.state_fields {
            return Err(SessionError::StateFieldsChanged {
                recorded: d.state_fields.clone(),
                now,
            });
        }
        let dev = ReplayDevice::from_recording(rec, specs, period)?;
        let switches = recording::switch_schedule(rec, period)?;
        Ok(Resimulation {
            rec,
            file: loaded.file,
            lp: HapticLoop::new(loaded.config, loaded.scene),
            dev,
            switches,
        })
    }

    /// The scene file recorded in the description, parsed.
    pub fn scene_file(&self) -> &crate::scene::SceneFile {
        &self.file
    }

    /// Ticks the recording holds.
    pub fn ticks(&self) -> u64 {
        self.dev.ticks()
    }

    /// The rebuilt loop (its configuration and scene before the run).
    pub fn haptic_loop(&self) -> &HapticLoop {
        &self.lp
    }

    /// World positions of the cursor at every tick, read from the recorded inputs (no physics).
    pub fn cursor_path(&self) -> Vec<haptic_types::Vec3> {
        let c = self.lp.config();
        self.dev
            .positions_m()
            .map(|p| c.mapping.to_world(p))
            .collect()
    }

    /// Runs every recorded tick through the runner into `sinks` (recorded pacing: the
    /// recorded deadline flags) and returns the loop at the end of the recording.
    pub fn run(mut self, sinks: Vec<&mut dyn Sink>) -> Result<HapticLoop, SessionError> {
        let ticks = self.dev.ticks();
        let flags = self.dev.deadline_flags();
        Runner::new(sinks).with_switches(self.switches).run(
            &mut self.lp,
            &mut self.dev,
            &crate::record_sink::header_of(&self.rec.description),
            Some(ticks),
            Pacing::Recorded(flags),
            &mut |_, _| {},
        )?;
        Ok(self.lp)
    }
}

/// Replays `rec` from its inputs and compares every verified output bit for bit.
pub fn verify(rec: &Recording) -> Result<VerifyReport, SessionError> {
    let sim = match Resimulation::prepare(rec) {
        Ok(sim) => sim,
        Err(e @ SessionError::StateFieldsChanged { .. }) => {
            return Ok(VerifyReport {
                ticks: 0,
                messages_compared: 0,
                divergence: Some(Divergence {
                    tick: 0,
                    channel: Channel::State.topic().into(),
                    detail: e.to_string(),
                }),
            });
        }
        Err(e) => return Err(e),
    };
    let d = &rec.description;
    let period = sim.haptic_loop().config().period_ns();
    let ticks = sim.ticks();
    // Expected outputs, grouped by tick, in file order.
    let mut expected: Vec<Vec<(Channel, &[u8])>> = vec![Vec::new(); ticks as usize];
    for m in rec.messages.iter().filter(|m| m.channel.verified()) {
        let rel = m.log_time_ns.checked_sub(d.start_time_ns);
        let t = rel.map_or(u64::MAX, |r| r / period);
        if rel.is_none_or(|r| r % period != 0) || t >= ticks {
            return Err(SessionError::Recording(RecordingError::BadMessage {
                topic: m.channel.topic().into(),
                log_time_ns: m.log_time_ns,
                detail: format!("log time is not one of the {ticks} recorded ticks"),
            }));
        }
        expected[t as usize].push((m.channel, m.data.as_slice()));
    }
    let mut sink = VerifySink {
        expected,
        n_fields: d.state_fields.len(),
        enc: None,
        msgs: Vec::with_capacity(8),
        compared: 0,
        divergence: None,
    };
    sim.run(vec![&mut sink])?;
    Ok(VerifyReport {
        ticks,
        messages_compared: sink.compared,
        divergence: sink.divergence,
    })
}
