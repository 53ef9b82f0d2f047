//! The one WebSocket loop of everything `play` serves: a game page's link and the teacher
//! page's. It reads the peer's messages within the gate's limits (a message larger than
//! [`Limits::max_message_bytes`](webguard::gate::Limits) closes the link, one faster than
//! [`Limits::messages_per_s`](webguard::gate::Limits) is refused — both counted), hands each to
//! the [`Peer`], and writes what the peer has to send, within a bounded write buffer (a
//! message that does not fit is dropped and the peer told).

use std::net::TcpStream;
use std::time::{Duration, Instant};
use tungstenite::protocol::{Role, WebSocketConfig};
use tungstenite::{Message, WebSocket};
use webguard::gate::{Gate, RateLimit};

/// What arrived from the peer's page.
pub enum Incoming<'a> {
    /// A text message (the pages' protocol is JSON).
    Text(&'a str),
    /// A binary message (no page sends one).
    Binary,
    /// A message over the rate limit (dropped, counted as `rate`).
    TooFast,
}

/// One end of a link: what it does with the page's messages and what it sends.
pub trait Peer {
    /// Whether the link should close (the session or the class is shutting down).
    fn stopped(&self) -> bool;
    /// Handles a message from the page.
    fn receive(&mut self, msg: Incoming<'_>);
    /// The next message to send, if any (called until `None` after each read).
    fn next_out(&mut self) -> Option<Message>;
    /// A message did not fit the page's write buffer: it was dropped.
    fn dropped(&mut self) {}
}

/// How a link reads and buffers.
#[derive(Clone, Copy, Debug)]
pub struct LinkConfig {
    /// How long a read waits for the page before the peer's messages are written.
    pub read_wait: Duration,
    /// Most bytes buffered for writing before a message is dropped (`None`: tungstenite's
    /// default, no drop).
    pub max_write_buffer_bytes: Option<usize>,
}

/// Runs the link on `stream` until the page closes it, the peer stops, or a limit of `gate`
/// closes it; then closes the WebSocket.
pub fn run(stream: TcpStream, gate: &Gate, link: LinkConfig, peer: &mut dyn Peer) {
    let _ = stream.set_read_timeout(Some(link.read_wait));
    let max = gate.limits.max_message_bytes;
    let mut config = WebSocketConfig::default()
        .max_message_size(Some(max))
        .max_frame_size(Some(max));
    if let Some(wmax) = link.max_write_buffer_bytes {
        let wmax = wmax.max(2 * max);
        config = config
            .write_buffer_size((wmax / 2).min(128 * 1024))
            .max_write_buffer_size(wmax);
    }
    let mut ws = WebSocket::from_raw_socket(stream, Role::Server, Some(config));
    let mut rate = RateLimit::new(gate.limits.messages_per_s);
    'link: while !peer.stopped() {
        let mut msg = ws.read();
        if matches!(msg, Ok(Message::Text(_) | Message::Binary(_))) && !rate.take(Instant::now()) {
            gate.refused.count("rate");
            peer.receive(Incoming::TooFast);
            msg = Ok(Message::Pong(Default::default()));
        }
        match msg {
            Ok(Message::Text(t)) => peer.receive(Incoming::Text(t.as_str())),
            Ok(Message::Binary(_)) => peer.receive(Incoming::Binary),
            Ok(Message::Close(_)) => break,
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(tungstenite::Error::Capacity(_)) => {
                gate.refused.count("size");
                break;
            }
            Err(_) => break,
        }
        let mut wrote = false;
        while let Some(m) = peer.next_out() {
            match ws.write(m) {
                Ok(()) => wrote = true,
                Err(tungstenite::Error::Io(e)) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    wrote = true;
                }
                // The page has not taken what was written: this message is dropped, counted,
                // and the rest wait in the peer's bounded queue.
                Err(tungstenite::Error::WriteBufferFull(_)) => {
                    peer.dropped();
                    wrote = true;
                    break;
                }
                Err(_) => break 'link,
            }
        }
        if wrote && ws.flush().is_err() {
            let _ = ws.flush();
        }
    }
    let _ = ws.close(None);
    let _ = ws.flush();
}
