//! A session's link to its pages: what is played, the pages' bounded queues, the hand's
//! input and the switches the pages asked for.

use crate::input::SharedInput;
use crate::protocol::ServerMsg;
use haptic_types::SwitchSpec;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use tungstenite::Message;

/// Messages queued per page before frames are dropped.
pub const PAGE_QUEUE: usize = 512;
/// A page whose connection accepts nothing for this long is closed, s (its queue dropped
/// frames meanwhile; the tick never waits for it).
pub const WRITE_TIMEOUT_S: u64 = 5;

/// What the scene offers the page, known once the scene is built.
#[derive(Clone, Debug)]
pub struct SceneLink {
    /// The switches of the menu.
    pub switches: &'static [SwitchSpec],
    /// The scene kind (for switch errors).
    pub kind: &'static str,
    /// Workspace radius of the device, m.
    pub workspace_radius_m: f64,
    /// Bits of the device's buttons.
    pub button_mask: u32,
    /// Whether the page is the hand (false: a bridged device is).
    pub page_is_hand: bool,
}

/// A switch asked for by a page: (page id, name as the scene names it, value).
pub type SwitchRequest = (u64, String, f64);

/// State shared by the server's threads, the tick's live hook and the publisher.
#[derive(Default)]
pub struct Shared {
    /// The `hello` message (JSON) for pages, once the scene is known.
    pub hello: Mutex<Option<String>>,
    /// The scene's link to the pages, once built.
    pub scene: Mutex<Option<SceneLink>>,
    /// The `end` message (JSON) once the session ended.
    pub end: Mutex<Option<String>>,
    /// The finished recording, served on `/recording.mcap`.
    pub recording: Mutex<Option<PathBuf>>,
    /// The page's hand.
    pub input: Arc<SharedInput>,
    /// The `lesson` message (JSON) now, for pages that connect later (`play --lesson`).
    pub lesson: Mutex<Option<String>>,
    /// What pages asked of the lesson, (page id, ask), waiting for its driver (`None`: no lesson
    /// runs).
    pub lesson_asks: Mutex<Option<Vec<(u64, crate::protocol::LessonAsk)>>>,
    /// Switches waiting for the next tick.
    pub switches: Mutex<Vec<SwitchRequest>>,
    /// The player asked to end the session.
    pub end_requested: AtomicBool,
    /// The page that is the hand, if any.
    pub player: Mutex<Option<u64>>,
    /// Pages connected now.
    pub pages: Mutex<Vec<Page>>,
    /// Pages ever connected.
    pub pages_served: AtomicU64,
    /// Messages dropped because a page's queue was full.
    pub dropped: AtomicU64,
    /// Page messages refused (protocol or switch errors).
    pub refused: AtomicU64,
    /// Set when the server stops: every page link closes.
    pub shutdown: AtomicBool,
    pub(crate) next_id: AtomicU64,
}

/// A connected page's outgoing queue.
pub struct Page {
    /// Its id.
    pub id: u64,
    pub(crate) tx: SyncSender<Message>,
    /// Wakes its link when a message is queued (`None`: the link polls every 2 ms).
    pub(crate) wake: Option<crate::wslink::Wake>,
}

impl Shared {
    /// Queues `m` for every page (dropped for a page whose queue is full).
    pub fn broadcast(&self, m: &Message) {
        if let Ok(pages) = self.pages.lock() {
            for p in pages.iter() {
                self.queue(p, m.clone());
            }
        }
    }

    /// Queues `m` for page `id`.
    pub fn send_to(&self, id: u64, m: Message) {
        if let Ok(pages) = self.pages.lock()
            && let Some(p) = pages.iter().find(|p| p.id == id)
        {
            self.queue(p, m);
        }
    }

    fn queue(&self, p: &Page, m: Message) {
        match p.tx.try_send(m) {
            Err(TrySendError::Full(_)) => {
                self.dropped.fetch_add(1, Ordering::Relaxed);
            }
            Ok(()) => {
                if let Some(w) = &p.wake {
                    w.wake();
                }
            }
            Err(TrySendError::Disconnected(_)) => {}
        }
    }

    pub(crate) fn error_to(&self, id: u64, field: &str, message: &str) {
        self.refused.fetch_add(1, Ordering::Relaxed);
        let m = ServerMsg::Error {
            field: field.to_string(),
            message: message.to_string(),
        };
        self.send_to(id, Message::text(m.to_json()));
    }
}
