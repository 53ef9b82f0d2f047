//! Any recording replayed in the browser (`nanohaptics replay FILE --serve`, issue 42): a page
//! with play and pause, speed, a timeline to scrub, the world drawn as in the game with the
//! force arrow, the events in words and the sound. The recording is the source: its session is
//! re-simulated from its inputs into the frames a live page is sent ([`book`]), and the page
//! is served them over `GET` only ([`server`]).

pub mod book;
pub mod server;

pub use book::{ReplayBook, SAMPLE_RATE_HZ};
pub use server::{MAX_FRAMES, ReplayServer};
