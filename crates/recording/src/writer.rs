//! The MCAP writer thread.
//!
//! The tick appends its encoded messages to a shared queue with `try_lock` (if the writer
//! happens to hold the lock, the tick keeps them in a local buffer and hands them over on a
//! later tick): the tick never waits and never wakes another thread (a wake-up can make the
//! scheduler preempt the waker). The writer thread polls the queue every 2 ms, swaps it out and
//! writes the messages into zstd-compressed chunks. Every second
//! of session time the thread closes the chunk and flushes it to the file, so a crash loses at
//! most the last second. The thread compresses single-threaded (`compression_threads(0)`) to
//! leave the other core to the loop.

use crate::channels::messages::{self, Channel, DescriptionMsg};
use crate::encode::{OutMsg, TickMessages};
use crate::foxglove_out;
use foxglove::schemas::{FrameTransform, Log, SceneUpdate};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the writer thread drains the queue.
const POLL: Duration = Duration::from_millis(2);

struct Shared {
    queue: Mutex<Vec<Cmd>>,
    done: AtomicBool,
    failed: AtomicBool,
}

/// Errors while recording.
#[derive(Clone, Debug, thiserror::Error)]
pub enum RecordError {
    /// The file could not be created or written.
    #[error("recording {path}: {message}")]
    Io {
        /// Path of the recording.
        path: String,
        /// What failed.
        message: String,
    },
    /// Writing failed after the file was created (a full disk, a lost mount): the OS error,
    /// and how many ticks were flushed to the file before it.
    #[error("recording {path}: {message}; {ticks_on_disk} ticks reached the disk")]
    Write {
        /// Path of the recording.
        path: String,
        /// The OS error (e.g. `No space left on device (os error 28)`).
        message: String,
        /// The OS error number, when the error came from the OS.
        os_code: Option<i32>,
        /// Ticks flushed to the file before the error.
        ticks_on_disk: u64,
    },
    /// The writer thread stopped (after an earlier error) or panicked.
    #[error("the recording writer stopped: {0}")]
    WriterStopped(String),
}

impl RecordError {
    /// The OS error number behind this error, if any (`ENOSPC` = 28 for a full disk).
    pub fn os_code(&self) -> Option<i32> {
        match self {
            RecordError::Write { os_code, .. } => *os_code,
            _ => None,
        }
    }
}

/// The I/O error inside an MCAP error (whose own text hides it): the OS's words and number.
fn os_error(e: &mcap::McapError) -> (String, Option<i32>) {
    let mut src: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(s) = src {
        if let Some(io) = s.downcast_ref::<std::io::Error>() {
            return (io.to_string(), io.raw_os_error());
        }
        src = s.source();
    }
    (e.to_string(), None)
}

/// A write error after `ticks_on_disk` ticks were flushed.
fn write_err(path: &str, e: &mcap::McapError, ticks_on_disk: u64) -> RecordError {
    let (message, os_code) = os_error(e);
    RecordError::Write {
        path: path.to_string(),
        message,
        os_code,
        ticks_on_disk,
    }
}

/// What the writer needs before the first tick.
#[derive(Clone, Debug)]
pub struct RecorderSetup {
    /// The scene description (written once at tick 0).
    pub description: DescriptionMsg,
    /// Flush a chunk to the file every this many ns of session time (crash loss bound).
    pub flush_every_ns: u64,
}

/// What the writer thread did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct WriteSummary {
    /// Messages written.
    pub messages: u64,
    /// File size, bytes.
    pub bytes: u64,
    /// Chunks flushed to the file.
    pub flushes: u64,
    /// Largest number of ticks waiting in the queue.
    pub max_queue_ticks: usize,
}

enum Cmd {
    Tick(TickMessages),
    Metadata(String, BTreeMap<String, String>),
}

/// Handle to the writer thread.
pub struct Recorder {
    shared: Arc<Shared>,
    local: Vec<Cmd>,
    handle: Option<JoinHandle<Result<WriteSummary, RecordError>>>,
    max_queued: usize,
    path: String,
}

type McapWriter = mcap::Writer<BufWriter<File>>;

fn io_err(path: &str, e: impl std::fmt::Display) -> RecordError {
    RecordError::Io {
        path: path.to_string(),
        message: e.to_string(),
    }
}

fn open(
    path: &str,
    setup: &RecorderSetup,
) -> Result<(McapWriter, BTreeMap<Channel, u16>), RecordError> {
    let file = File::create(path).map_err(|e| io_err(path, e))?;
    let opts = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .compression_threads(0)
        .chunk_size(Some(8 << 20))
        .profile("")
        .library(concat!(
            "nanohaptics haptic-loop ",
            env!("CARGO_PKG_VERSION")
        ));
    let mut w = opts
        .create(BufWriter::with_capacity(1 << 20, file))
        .map_err(|e| write_err(path, &e, 0))?;
    let mut ids = BTreeMap::new();
    let meta = BTreeMap::new();
    for ch in Channel::ALL {
        let (name, enc, data) = channel_schema(ch, &setup.description);
        let sid = w
            .add_schema(&name, &enc, &data)
            .map_err(|e| write_err(path, &e, 0))?;
        let cid = w
            .add_channel(sid, ch.topic(), ch.message_encoding(), &meta)
            .map_err(|e| write_err(path, &e, 0))?;
        ids.insert(ch, cid);
    }
    Ok((w, ids))
}

/// The schema (name, encoding, bytes) written for `ch` in a recording of the session `d`: the
/// declared `.msg` text of a CDR channel (the state's with the scene's fields), Foxglove's
/// protobuf descriptor set for its channels.
pub fn channel_schema(ch: Channel, d: &DescriptionMsg) -> (String, String, Vec<u8>) {
    match ch {
        Channel::State => {
            let (name, text) = messages::state_schema(&d.scene_kind, &d.state_fields);
            (name, "ros2msg".into(), text.into_bytes())
        }
        Channel::FoxgloveScene => foxglove_out::schema::<SceneUpdate>(),
        Channel::FoxgloveTf => foxglove_out::schema::<FrameTransform>(),
        Channel::FoxgloveLog => foxglove_out::schema::<Log>(),
        _ => match ch.ros2_schema() {
            Some((name, text)) => (name.to_string(), "ros2msg".into(), text.into_bytes()),
            None => (ch.schema_name().to_string(), String::new(), Vec::new()),
        },
    }
}

fn write_msgs(
    w: &mut McapWriter,
    ids: &BTreeMap<Channel, u16>,
    seq: &mut u32,
    log_time: u64,
    msgs: &[OutMsg],
    path: &str,
    on_disk: u64,
) -> Result<u64, RecordError> {
    for m in msgs {
        let channel_id = ids[&m.channel];
        *seq = seq.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id,
            sequence: *seq,
            log_time,
            publish_time: log_time,
        };
        w.write_to_known_channel(&header, &m.data)
            .map_err(|e| write_err(path, &e, on_disk))?;
    }
    Ok(msgs.len() as u64)
}

fn run_thread(
    path: String,
    setup: RecorderSetup,
    shared: Arc<Shared>,
    ready: mpsc::Sender<Result<(), RecordError>>,
) -> Result<WriteSummary, RecordError> {
    let res = write_all(&path, &setup, &shared, ready);
    if res.is_err() {
        shared.failed.store(true, Ordering::Release);
    }
    res
}

fn write_all(
    path: &str,
    setup: &RecorderSetup,
    shared: &Shared,
    ready: mpsc::Sender<Result<(), RecordError>>,
) -> Result<WriteSummary, RecordError> {
    let (mut w, ids) = match open(path, setup) {
        Ok(x) => {
            let _ = ready.send(Ok(()));
            x
        }
        Err(e) => {
            let _ = ready.send(Err(e.clone()));
            return Err(e);
        }
    };
    let mut sum = WriteSummary::default();
    let mut seq = 0u32;
    // Ticks handed to the MCAP writer, and ticks in chunks flushed to the file.
    let mut ticks = 0u64;
    let mut on_disk = 0u64;
    let desc = OutMsg {
        channel: Channel::Description,
        data: setup.description.encode(),
    };
    // The description is logged at the session's start, so the file's timeline is the session's.
    let at = setup.description.start_time_ns;
    sum.messages += write_msgs(&mut w, &ids, &mut seq, at, &[desc], path, on_disk)?;
    w.flush().map_err(|e| write_err(path, &e, on_disk))?;
    let mut next_flush = setup
        .description
        .start_time_ns
        .saturating_add(setup.flush_every_ns);
    let mut batch: Vec<Cmd> = Vec::new();
    loop {
        // Read the flag before draining: whatever was queued before `done` is then drained.
        let done = shared.done.load(Ordering::Acquire);
        {
            let mut q = shared
                .queue
                .lock()
                .map_err(|_| RecordError::WriterStopped("queue lock poisoned".into()))?;
            std::mem::swap(&mut *q, &mut batch);
        }
        for cmd in batch.drain(..) {
            match cmd {
                Cmd::Tick(t) => {
                    if t.log_time_ns >= next_flush {
                        // Close the chunk of the previous second and push it to the OS.
                        w.flush().map_err(|e| write_err(path, &e, on_disk))?;
                        on_disk = ticks;
                        sum.flushes += 1;
                        while next_flush <= t.log_time_ns {
                            next_flush += setup.flush_every_ns;
                        }
                    }
                    sum.messages += write_msgs(
                        &mut w,
                        &ids,
                        &mut seq,
                        t.log_time_ns,
                        &t.msgs,
                        path,
                        on_disk,
                    )?;
                    ticks += 1;
                }
                Cmd::Metadata(name, metadata) => {
                    w.write_metadata(&mcap::records::Metadata { name, metadata })
                        .map_err(|e| write_err(path, &e, on_disk))?;
                }
            }
        }
        if done {
            break;
        }
        std::thread::sleep(POLL);
    }
    w.finish().map_err(|e| write_err(path, &e, on_disk))?;
    // The summary is written into the buffer; push it to the file.
    let mut file = w.into_inner();
    std::io::Write::flush(&mut file).map_err(|e| RecordError::Write {
        path: path.to_string(),
        message: e.to_string(),
        os_code: e.raw_os_error(),
        ticks_on_disk: on_disk,
    })?;
    drop(file);
    sum.bytes = std::fs::metadata(path).map_err(|e| io_err(path, e))?.len();
    Ok(sum)
}

impl Recorder {
    /// Creates the file and starts the writer thread.
    pub fn create(path: &Path, setup: RecorderSetup) -> Result<Recorder, RecordError> {
        let path_s = path.display().to_string();
        let (ready_tx, ready_rx) = mpsc::channel();
        let shared = Arc::new(Shared {
            queue: Mutex::new(Vec::with_capacity(4096)),
            done: AtomicBool::new(false),
            failed: AtomicBool::new(false),
        });
        let s2 = shared.clone();
        let p2 = path_s.clone();
        let handle = std::thread::Builder::new()
            .name("mcap-writer".into())
            .spawn(move || run_thread(p2, setup, s2, ready_tx))
            .map_err(|e| io_err(&path_s, e))?;
        match ready_rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(e),
            Err(_) => return Err(RecordError::WriterStopped("writer thread died".into())),
        }
        Ok(Recorder {
            shared,
            local: Vec::with_capacity(64),
            handle: Some(handle),
            max_queued: 0,
            path: path_s,
        })
    }

    fn hand_over(&mut self) {
        if let Ok(mut q) = self.shared.queue.try_lock() {
            q.append(&mut self.local);
            self.max_queued = self.max_queued.max(q.len());
        }
    }

    /// Queues a tick's messages for the writer thread (never blocks, never wakes a thread).
    pub fn write(&mut self, t: TickMessages) -> Result<(), RecordError> {
        if self.shared.failed.load(Ordering::Acquire) {
            // The thread has ended with its error (the OS's words, the path, the ticks on
            // disk): hand that error to the session, not a generic one.
            return Err(match self.handle.take().map(JoinHandle::join) {
                Some(Ok(Err(e))) => e,
                _ => RecordError::WriterStopped(format!("{}: the writer failed", self.path)),
            });
        }
        self.local.push(Cmd::Tick(t));
        self.hand_over();
        Ok(())
    }

    /// Queues a metadata record (e.g. the session summary).
    pub fn metadata(&mut self, name: &str, m: BTreeMap<String, String>) -> Result<(), RecordError> {
        self.local.push(Cmd::Metadata(name.to_string(), m));
        self.hand_over();
        Ok(())
    }

    /// Hands over what is left, waits for the thread to write the summary and returns what it
    /// did (or the first error it met).
    pub fn finish(mut self) -> Result<WriteSummary, RecordError> {
        {
            let mut q = self
                .shared
                .queue
                .lock()
                .map_err(|_| RecordError::WriterStopped("queue lock poisoned".into()))?;
            q.append(&mut self.local);
        }
        self.shared.done.store(true, Ordering::Release);
        let h = self
            .handle
            .take()
            .ok_or_else(|| RecordError::WriterStopped("already finished".into()))?;
        let mut sum = h
            .join()
            .map_err(|_| RecordError::WriterStopped("writer thread panicked".into()))??;
        sum.max_queue_ticks = self.max_queued;
        Ok(sum)
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        if let Ok(mut q) = self.shared.queue.lock() {
            q.append(&mut self.local);
        }
        self.shared.done.store(true, Ordering::Release);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}
