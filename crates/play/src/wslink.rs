//! The one WebSocket loop of everything `play` serves: a game page's link and the teacher
//! page's. It reads the peer's messages within the gate's limits (a message larger than
//! [`Limits::max_message_bytes`](webguard::gate::Limits) closes the link, one faster than
//! [`Limits::messages_per_s`](webguard::gate::Limits) is refused — both counted), hands each to
//! the [`Peer`], and writes what the peer has to send, within a bounded write buffer (a
//! message that does not fit is dropped and the peer told).
//!
//! A link with a [`WakeRx`] (a game page's, on unix) waits for the page's socket and for its
//! peer's queue at once (`poll`), so a queued message (a tick's sound input) goes out as soon
//! as it is queued; without one, the loop waits up to `read_wait` for the page and writes
//! after each wait, so a message can wait up to `read_wait` (2 ms) for its turn.
//!
//! On unix the socket never blocks: what a page does not take stays in the bounded write
//! buffer and is tried again each turn, so a page that stops reading holds neither its link's
//! reads nor the server's end. At the close, what is left gets [`CLOSE_WAIT`] to go out.

use std::net::TcpStream;
#[cfg(unix)]
use std::os::unix::net::UnixStream;
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

/// The queue's end of a link's wake-up: [`Wake::wake`] after queueing a message for the link.
pub struct Wake {
    #[cfg(unix)]
    tx: UnixStream,
}

/// The link's end of its wake-up.
pub struct WakeRx {
    #[cfg(unix)]
    rx: UnixStream,
}

/// A wake-up for one link (`None` where the platform has none, or the sockets could not be
/// made: the link then reads with its `read_wait` timeout).
pub fn wake_pair() -> Option<(Wake, WakeRx)> {
    #[cfg(unix)]
    {
        let (tx, rx) = UnixStream::pair().ok()?;
        tx.set_nonblocking(true).ok()?;
        rx.set_nonblocking(true).ok()?;
        Some((Wake { tx }, WakeRx { rx }))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

impl Wake {
    /// Wakes the link (a full socket means it is awake already).
    pub fn wake(&self) {
        #[cfg(unix)]
        {
            use std::io::Write;
            let _ = (&self.tx).write(&[1]);
        }
    }
}

impl WakeRx {
    /// Takes the wake-ups sent so far.
    fn drain(&self) {
        #[cfg(unix)]
        {
            use std::io::Read;
            let mut b = [0u8; 64];
            while matches!((&self.rx).read(&mut b), Ok(n) if n > 0) {}
        }
    }
}

/// How long the close waits for a page to take what is left (its last messages, the close).
pub const CLOSE_WAIT: Duration = Duration::from_millis(500);

/// Waits up to `timeout` for the socket `fd` or the wake-up to be readable: (socket, wake-up).
#[cfg(unix)]
#[allow(unsafe_code)] // one libc::poll on the descriptors this link owns
fn wait(fd: std::os::fd::RawFd, wake: Option<&WakeRx>, timeout: Duration) -> (bool, bool) {
    use std::os::fd::AsRawFd;
    let poll_fd = |fd| libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    let mut fds = [poll_fd(fd), poll_fd(wake.map_or(-1, |w| w.rx.as_raw_fd()))];
    let ms = i32::try_from(timeout.as_millis())
        .unwrap_or(i32::MAX)
        .max(1);
    let n_fds: libc::nfds_t = if wake.is_some() { 2 } else { 1 };
    // SAFETY: `fds` is an array of two initialised pollfd, valid for the call's duration, and
    // `n_fds` is at most its length.
    let n = unsafe { libc::poll(fds.as_mut_ptr(), n_fds, ms) };
    if n < 0 {
        // Interrupted or failed: read as if the socket were ready (it does not block).
        return (true, false);
    }
    let ready = |f: &libc::pollfd| f.revents & (libc::POLLIN | libc::POLLHUP | libc::POLLERR) != 0;
    (ready(&fds[0]), wake.is_some() && ready(&fds[1]))
}

/// Runs the link on `stream` until the page closes it, the peer stops, or a limit of `gate`
/// closes it; then closes the WebSocket. With `wake`, it also writes as soon as woken.
pub fn run(
    stream: TcpStream,
    gate: &Gate,
    link: LinkConfig,
    peer: &mut dyn Peer,
    wake: Option<&WakeRx>,
) {
    #[cfg(unix)]
    let fd = std::os::fd::AsRawFd::as_raw_fd(&stream);
    #[cfg(unix)]
    let _ = stream.set_nonblocking(true);
    #[cfg(not(unix))]
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
    // The last read returned a message: more may wait in the WebSocket's buffer, unseen by poll.
    let mut again = false;
    while !peer.stopped() {
        #[cfg(unix)]
        let readable = again || {
            let (readable, woken) = wait(fd, wake, link.read_wait);
            if woken && let Some(w) = wake {
                w.drain();
            }
            readable
        };
        #[cfg(not(unix))]
        let readable = {
            let _ = (again, wake);
            true
        };
        let mut msg = if readable {
            ws.read()
        } else {
            Err(tungstenite::Error::Io(
                std::io::ErrorKind::WouldBlock.into(),
            ))
        };
        again = msg.is_ok();
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
        if !write_out(&mut ws, peer) {
            break;
        }
    }
    close(ws, peer);
}

/// Writes what the peer has queued and flushes; false when the link is gone.
fn write_out(ws: &mut WebSocket<TcpStream>, peer: &mut dyn Peer) -> bool {
    while let Some(m) = peer.next_out() {
        match ws.write(m) {
            Ok(()) => {}
            // Buffered: it goes out when the page takes what is before it.
            Err(tungstenite::Error::Io(e)) if e.kind() == std::io::ErrorKind::WouldBlock => {}
            // The page has not taken what was written: this message is dropped, counted,
            // and the rest wait in the peer's bounded queue.
            Err(tungstenite::Error::WriteBufferFull(_)) => {
                peer.dropped();
                break;
            }
            Err(_) => return false,
        }
    }
    // Every turn, so what a busy page left in the buffer goes out once it reads again.
    match ws.flush() {
        Ok(()) => true,
        Err(tungstenite::Error::Io(e)) => e.kind() == std::io::ErrorKind::WouldBlock,
        Err(_) => false,
    }
}

/// Closes the link: the close and what is left get CLOSE_WAIT, not the socket's whole write
/// timeout.
fn close(mut ws: WebSocket<TcpStream>, peer: &mut dyn Peer) {
    let _ = ws.get_mut().set_nonblocking(false);
    let _ = ws.get_mut().set_write_timeout(Some(CLOSE_WAIT));
    // What the peer queued before it stopped (a session's end) goes before the close.
    while let Some(m) = peer.next_out() {
        if ws.write(m).is_err() {
            break;
        }
    }
    let _ = ws.close(None);
    let _ = ws.flush();
}
