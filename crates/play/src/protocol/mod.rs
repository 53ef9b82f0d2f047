//! The page ↔ server protocol over the WebSocket (`/ws`): one type per direction.
//!
//! - **Server → page**: [`ServerMsg`], JSON text messages tagged by `type` (`hello`, `waiting`,
//!   `role`, `frame`, `switched`, `error`, `end`, `lesson`), written by [`ServerMsg::to_json`] (the one
//!   place a server message becomes text), and binary sound ticks ([`SoundTicks`]).
//! - **Page → server**: [`PageMsg`], JSON text messages tagged by `type` (`start`, `input`,
//!   `switch`, `end`, `answer`, `step`), read by [`parse`], which checks every field: a bad one gets a typed
//!   [`ProtocolError`] naming the field and its allowed range (sent back to the page as an
//!   `error` message; the session goes on).
//!
//! Both types serialise and deserialise, so another program (a test, a classroom server
//! watching several sessions) can speak the protocol with the same types. The table of every
//! message, its fields with units and when it is sent is in `docs/play.md`; a test
//! (`tests/protocol_doc.rs`) keeps that table and these types in step.
//!
//! **Binary sound ticks** (server → page): what the page's sound synthesis needs of each tick
//! (its wall time, the distance to the nearest object for the proximity tone, and the sounds
//! that start on it), sent as soon as the publisher has them; the page synthesises the sound
//! itself (`synth.js`, an AudioWorklet port of [`render::audio::StreamSynth`]). The layout is
//! [`SoundTicks::encode`]'s.

mod lesson;
mod page;
mod server;
mod sound;
#[cfg(test)]
mod tests;

pub use lesson::{LessonAsk, LessonView, PageAnswer, QuestionView, Scores};
pub use page::{MAX_MESSAGE_BYTES, PageInput, PageMsg, ProtocolError, parse};
pub use server::{
    EndReport, EventAt, Frame, FrameView, Hello, LatencyMs, Mapping, Role, ServerMsg, SoundAt,
    SwitchInfo, TickWorkMs,
};
pub use sound::{
    SOUND_ON_BYTES, SOUND_TICK_BYTES, SOUND_TICKS_HEADER_BYTES, SoundKind, SoundOn, SoundTick,
    SoundTicks, SoundTicksError,
};
