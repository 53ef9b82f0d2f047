//! The end of a read: a truncated file keeps its complete ticks and its description (with
//! salvage), or is an error saying how many ticks are readable; then the scene description is
//! decoded and its format version checked.

use super::walk::Walk;
use super::{Recording, RecordingError};
use crate::channels::FORMAT_VERSION;
use crate::channels::messages::{Channel, DescriptionMsg};

/// The recording read into `w` (a file of `bytes` bytes), `truncated` saying why it ends early.
pub(super) fn finish(
    mut w: Walk,
    truncated: Option<String>,
    salvage: bool,
    bytes: u64,
) -> Result<Recording, RecordingError> {
    if let Some(detail) = &truncated {
        w.ticks.keep_complete();
        if !salvage {
            return Err(RecordingError::Truncated {
                ticks: w.ticks.timings,
                detail: detail.clone(),
            });
        }
        if w.ticks.timings == 0 {
            return Err(RecordingError::NothingToSalvage {
                detail: detail.clone(),
            });
        }
    }
    w.integrity.ticks = w.ticks.timings;
    let desc_msg = w
        .ticks
        .messages
        .iter()
        .find(|m| m.channel == Channel::Description)
        .ok_or(RecordingError::NoDescription)?;
    let description =
        DescriptionMsg::decode(&desc_msg.data).map_err(|e| RecordingError::BadMessage {
            topic: Channel::Description.topic().to_string(),
            log_time_ns: desc_msg.log_time_ns,
            detail: e.to_string(),
        })?;
    if description.format != FORMAT_VERSION {
        return Err(RecordingError::Version {
            found: description.format,
        });
    }
    Ok(Recording {
        description,
        messages: w.ticks.messages,
        metadata: w.metadata,
        channels: w.channels,
        unknown_topics: w.unknown_topics,
        truncated,
        bytes,
        integrity: w.integrity,
    })
}
