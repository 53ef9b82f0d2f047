//! A page's WebSocket: its messages to the session, its queue to the page.

use super::{PAGE_QUEUE, Page, SceneLink, Shared};
use crate::input::page_to_device;
use crate::protocol::{self, LessonAsk, PageMsg, ProtocolError, Role, ServerMsg};
use crate::wslink::{self, Incoming, LinkConfig};
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::time::{Duration, Instant};
use tungstenite::Message;
use webguard::gate::Gate;

/// Handles one page message from page `id`.
pub(crate) fn on_message(shared: &Shared, id: u64, text: &str) {
    let link = shared.scene.lock().ok().and_then(|s| s.clone());
    let mask = link.as_ref().map_or(0, |l| l.button_mask);
    let msg = match protocol::parse(text, mask) {
        Ok(m) => m,
        Err(e) => return shared.error_to(id, e.field(), &e.to_string()),
    };
    let is_player = |sh: &Shared| sh.player.lock().map(|p| *p == Some(id)).unwrap_or(false);
    match msg {
        PageMsg::Start => {
            // Before the session is open nobody knows yet whether the page is the hand: the
            // page offers Start only after the hello, so an early one is answered, not kept.
            if link.is_none() {
                return shared.error_to(
                    id,
                    "type",
                    "the session is not open yet: press Start after its hello",
                );
            }
            if link.as_ref().is_some_and(|l| l.page_is_hand)
                && let Ok(mut p) = shared.player.lock()
                && p.is_none()
            {
                *p = Some(id);
            }
            let role = role_of(shared, id, link.as_ref());
            shared.send_to(id, Message::text(ServerMsg::Role { role }.to_json()));
        }
        PageMsg::Input(i) => {
            let Some(l) = link else {
                return shared.error_to(id, "type", "the session has not started yet");
            };
            if !l.page_is_hand {
                return shared.error_to(
                    id,
                    "type",
                    "a device is the hand in this session: the page only watches",
                );
            }
            if !is_player(shared) {
                return shared.error_to(id, "type", "another page is the hand: this page watches");
            }
            shared.input.set(
                page_to_device(i.pos, l.workspace_radius_m),
                i.buttons,
                i.t_ms,
            );
        }
        PageMsg::Switch { name, value } => {
            let Some(l) = link else {
                return shared.error_to(id, "switch.name", "the session has not started yet");
            };
            match haptic_types::switch::check(l.kind, l.switches, &name, value) {
                Ok(spec) => {
                    if let Ok(mut q) = shared.switches.lock() {
                        q.push((id, spec.name.to_string(), value));
                    }
                }
                Err(e) => {
                    let field = match e {
                        haptic_types::SwitchError::Unknown { .. } => "switch.name",
                        _ => "switch.value",
                    };
                    shared.error_to(id, field, &e.to_string());
                }
            }
        }
        PageMsg::Answer { answer } => ask_lesson(shared, id, "answer", LessonAsk::Answer(answer)),
        PageMsg::Step { id: step } => ask_lesson(shared, id, "step.id", LessonAsk::Step(step)),
        PageMsg::End => {
            if is_player(shared) || link.as_ref().is_some_and(|l| !l.page_is_hand) {
                shared.end_requested.store(true, Ordering::Relaxed);
            } else {
                shared.error_to(id, "type", "only the page that plays can end the session");
            }
        }
    }
}

/// Queues page `id`'s ask for the lesson's driver; refused (`field`) when no lesson runs.
fn ask_lesson(shared: &Shared, id: u64, field: &str, ask: LessonAsk) {
    let queued = match shared.lesson_asks.lock() {
        Ok(mut q) => q.as_mut().map(|q| q.push((id, ask))).is_some(),
        Err(_) => false,
    };
    if !queued {
        shared.error_to(
            id,
            field,
            "this session runs no lesson (a lesson is played with nanohaptics play --lesson)",
        );
    }
}

fn role_of(shared: &Shared, id: u64, link: Option<&SceneLink>) -> Role {
    match link {
        Some(l) if !l.page_is_hand => Role::View,
        _ if shared
            .player
            .lock()
            .map(|p| *p == Some(id))
            .unwrap_or(false) =>
        {
            Role::Hand
        }
        _ => Role::View,
    }
}

/// A page's WebSocket: reads its messages, writes its queue.
///
/// The page's messages are bounded by the gate's limits: larger than
/// [`Limits::max_message_bytes`] closes the link (counted), faster than
/// [`Limits::messages_per_s`] is refused message by message (counted, one error a second).
pub fn page_link(stream: TcpStream, shared: &Arc<Shared>, gate: &Gate) {
    crate::background::lower_priority();
    let id = shared.next_id.fetch_add(1, Ordering::Relaxed) + 1;
    shared.pages_served.fetch_add(1, Ordering::Relaxed);
    let (tx, rx): (SyncSender<Message>, Receiver<Message>) = sync_channel(PAGE_QUEUE);
    // The greeting first: the hello (or that the session waits), and the end if it is over.
    let hello = shared.hello.lock().ok().and_then(|h| h.clone());
    let _ = tx.try_send(Message::text(hello.unwrap_or_else(|| {
        ServerMsg::Waiting {
            waiting_for: "the device's hello".into(),
        }
        .to_json()
    })));
    if let Some(end) = shared.end.lock().ok().and_then(|e| e.clone()) {
        let _ = tx.try_send(Message::text(end));
    }
    if let Some(lesson) = shared.lesson.lock().ok().and_then(|l| l.clone()) {
        let _ = tx.try_send(Message::text(lesson));
    }
    let (wake, wake_rx) = wslink::wake_pair().unzip();
    if let Ok(mut pages) = shared.pages.lock() {
        pages.push(Page { id, tx, wake });
    }
    let mut peer = PagePeer {
        shared,
        id,
        rx,
        messages_per_s: gate.limits.messages_per_s,
        told_rate: None,
    };
    let link = LinkConfig {
        read_wait: Duration::from_millis(2),
        max_write_buffer_bytes: Some(gate.limits.max_write_buffer_bytes),
    };
    wslink::run(stream, gate, link, &mut peer, wake_rx.as_ref());
    if let Ok(mut pages) = shared.pages.lock() {
        pages.retain(|p| p.id != id);
    }
    if let Ok(mut p) = shared.player.lock()
        && *p == Some(id)
    {
        *p = None;
    }
}

/// A game page's end of its link: its messages go to the session, its queue to the page.
struct PagePeer<'a> {
    shared: &'a Arc<Shared>,
    id: u64,
    rx: Receiver<Message>,
    messages_per_s: u32,
    told_rate: Option<Instant>,
}

impl wslink::Peer for PagePeer<'_> {
    fn stopped(&self) -> bool {
        self.shared.shutdown.load(Ordering::Relaxed)
    }

    fn receive(&mut self, msg: Incoming<'_>) {
        match msg {
            Incoming::Text(t) => on_message(self.shared, self.id, t),
            Incoming::Binary => {
                self.shared
                    .error_to(self.id, "type", &ProtocolError::Binary.to_string());
            }
            // Told at most once a second.
            Incoming::TooFast => {
                if self
                    .told_rate
                    .is_none_or(|t| t.elapsed() >= Duration::from_secs(1))
                {
                    self.told_rate = Some(Instant::now());
                    let m = format!(
                        "too many messages: at most {} per second (this one was dropped)",
                        self.messages_per_s
                    );
                    self.shared.error_to(self.id, "type", &m);
                }
            }
        }
    }

    fn next_out(&mut self) -> Option<Message> {
        self.rx.try_recv().ok()
    }

    fn dropped(&mut self) {
        self.shared.dropped.fetch_add(1, Ordering::Relaxed);
    }
}
