//! Replay and bit-exact verification of a recording.
//!
//! The scene is rebuilt from the description (scene text and device model), the device inputs
//! and deadline flags are played back through a [`ReplayDevice`], and every verified output
//! message (state, force, events, Foxglove channels) is recomputed and compared byte for byte
//! with the recorded one. The first difference names its tick and channel.

use crate::device::{DeviceModel, HapticDevice, ReplayDevice};
use crate::haptic::HapticLoop;
use crate::record::messages::{Channel, ForceMsg, StateMsg};
use crate::record::{Recording, RecordingError, TickMessages};
use crate::scene::load_scene;
use crate::session::{Pacing, SessionError, drive};

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

fn describe(channel: Channel, rec: &[u8], rep: &[u8], n_fields: usize) -> String {
    match channel {
        Channel::Force => {
            if let (Ok(a), Ok(b)) = (ForceMsg::decode(rec), ForceMsg::decode(rep)) {
                return format!(
                    "recorded world {:?} N, device {:?} N, status {}; replayed world {:?} N, \
                     device {:?} N, status {}",
                    a.world_force_n,
                    a.device_force_n,
                    a.status,
                    b.world_force_n,
                    b.device_force_n,
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
                    "recorded cursor {:?} m, state {:?}; replayed cursor {:?} m, state {:?}",
                    a.cursor_m, a.values, b.cursor_m, b.values
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

/// Replays `rec` from its inputs and compares every verified output bit for bit.
pub fn verify(rec: &Recording) -> Result<VerifyReport, SessionError> {
    let d = &rec.description;
    let model = DeviceModel::from_name(&d.device_model)?;
    let loaded = load_scene(&d.scene_toml, Some(model))?;
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
    let n_fields = d.state_fields.len();
    if loaded.scene.state_fields() != d.state_fields {
        return Ok(VerifyReport {
            ticks: 0,
            messages_compared: 0,
            divergence: Some(Divergence {
                tick: 0,
                channel: Channel::State.topic().into(),
                detail: format!(
                    "recorded state fields {:?}, the scene now has {:?}",
                    d.state_fields,
                    loaded.scene.state_fields()
                ),
            }),
        });
    }
    let mut dev = ReplayDevice::from_recording(rec, loaded.config.specs.clone(), period)?;
    let ticks = dev.ticks();
    // Expected outputs, grouped by tick, in file order.
    let mut expected: Vec<Vec<(Channel, &[u8])>> = vec![Vec::new(); ticks as usize];
    for m in rec.messages.iter().filter(|m| m.channel.verified()) {
        let t = m.log_time_ns / period;
        if m.log_time_ns % period != 0 || t >= ticks {
            return Err(SessionError::Recording(RecordingError::BadMessage {
                topic: m.channel.topic().into(),
                log_time_ns: m.log_time_ns,
                detail: format!("log time is not one of the {ticks} recorded ticks"),
            }));
        }
        expected[t as usize].push((m.channel, m.data.as_slice()));
    }
    let flags: Vec<bool> = (0..ticks).map(|t| dev.deadline_missed(t)).collect();
    let missed = |t: u64| flags.get(t as usize).copied().unwrap_or(false);
    let mut lp = HapticLoop::new(loaded.config, loaded.scene);
    let mut compared = 0u64;
    let mut divergence: Option<Divergence> = None;
    let mut sink = |t: TickMessages| -> Result<(), SessionError> {
        if divergence.is_some() {
            return Ok(());
        }
        let want = &expected[t.tick as usize];
        for ch in Channel::ALL.into_iter().filter(|c| c.verified()) {
            let w: Vec<&[u8]> = want.iter().filter(|m| m.0 == ch).map(|m| m.1).collect();
            let g: Vec<&[u8]> = t
                .msgs
                .iter()
                .filter(|m| m.channel == ch)
                .map(|m| m.data.as_slice())
                .collect();
            let mut detail = None;
            for (a, b) in w.iter().zip(&g) {
                compared += 1;
                if a != b {
                    detail = Some(describe(ch, a, b, n_fields));
                    break;
                }
            }
            if detail.is_none() && w.len() != g.len() {
                detail = Some(if w.len() < g.len() {
                    "replay produced a message that was not recorded".to_string()
                } else {
                    "recorded a message that replay did not produce".to_string()
                });
            }
            if let Some(detail) = detail {
                divergence = Some(Divergence {
                    tick: t.tick,
                    channel: ch.topic().to_string(),
                    detail,
                });
                break;
            }
        }
        Ok(())
    };
    drive(
        &mut lp,
        &mut dev as &mut dyn HapticDevice,
        ticks,
        Pacing::Recorded(&missed),
        &mut sink,
        &mut |_, _| {},
    )?;
    Ok(VerifyReport {
        ticks,
        messages_compared: compared,
        divergence,
    })
}
