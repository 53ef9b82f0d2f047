//! The accept loop of every server of the project (the page servers and the live view's
//! guard), and its plain answers: each connection admitted by the [`Gate`] or refused with
//! `503` and the gate's reason, then handled on its own thread while it holds its ticket.

use crate::gate::{Gate, set_send_buffer};
use crate::{Head, HeadError, read_head_bytes};
use std::io::Write;
use std::net::{TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;

/// How long the loop sleeps when no connection is waiting, ms.
const IDLE_MS: u64 = 5;

/// The cross-origin isolation every response asks for: a page of ours shares no window with
/// another origin's (`Cross-Origin-Opener-Policy`), loads nothing another origin did not
/// offer (`Cross-Origin-Embedder-Policy`; every page loads only its own server's files), and
/// is loaded by no other origin's page (`Cross-Origin-Resource-Policy`). An isolated page may
/// share memory between its threads (`SharedArrayBuffer`): the play page's sound ring
/// (docs/play.md).
pub const ISOLATION: &str = "Cross-Origin-Opener-Policy: same-origin\r\nCross-Origin-Embedder-Policy: require-corp\r\nCross-Origin-Resource-Policy: same-origin\r\n";

/// Writes a complete response (`Connection: close`, never cached, cross-origin isolated:
/// [`ISOLATION`]); `extra` is more header lines, each ending in `\r\n`.
pub fn respond(stream: &mut TcpStream, status: &str, ctype: &str, extra: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {ctype}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\n{ISOLATION}{extra}Connection: close\r\n\r\n",
        body.len()
    );
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(body);
    let _ = stream.flush();
}

/// Answers with a plain-text message (status line such as `403 Forbidden`).
pub fn respond_text(stream: &mut TcpStream, status: &str, message: &str) {
    respond(
        stream,
        status,
        "text/plain; charset=utf-8",
        "",
        format!("{message}\n").as_bytes(),
    );
}

/// Discards up to `limit` bytes of a refused request's body (waiting at most 100 ms for
/// them) after its answer was written: a connection closed with unread bytes is reset, and
/// the client would lose the answer that says why.
pub fn drain_body(stream: &mut TcpStream, head: &Head, limit: usize) {
    let n = head
        .header("content-length")
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(0)
        .min(limit);
    if n == 0
        || stream
            .set_read_timeout(Some(Duration::from_millis(100)))
            .is_err()
    {
        return;
    }
    let mut left = n;
    let mut buf = [0u8; 512];
    while left > 0 {
        match std::io::Read::read(stream, &mut buf[..left.min(512)]) {
            Ok(0) | Err(_) => break,
            Ok(k) => left -= k,
        }
    }
}

/// Reads a connection's request head within bounds and checks its `Host` and `Origin`: the
/// head's bytes (to pass on unchanged) and the head, or `None` when it was refused. A head
/// that never came or broke a bound is counted as `head` and answered `400 Bad Request`
/// (a connection closed before its head gets no answer); a refused `Host` or `Origin` is
/// counted by its kind and answered `403 Forbidden`, each with the reason.
pub fn checked_head(stream: &mut TcpStream, gate: &Gate) -> Option<(Vec<u8>, Head)> {
    match read_head_bytes(stream) {
        Ok((bytes, head)) => match gate.guard.check(&head) {
            Ok(()) => Some((bytes, head)),
            Err(r) => {
                gate.refused.count(r.kind());
                respond_text(stream, "403 Forbidden", &r.to_string());
                drain_body(stream, &head, crate::form::MAX_FORM_BYTES);
                None
            }
        },
        Err(e) => {
            gate.refused.count("head");
            if !matches!(e, HeadError::Closed) {
                respond_text(stream, "400 Bad Request", &e.to_string());
            }
            None
        }
    }
}

/// Accepts connections on `listener` (non-blocking) until `stop` is raised. Each accepted
/// stream is made blocking and given the gate's send buffer; a connection the gate does not
/// admit is answered `503 Service Unavailable` with the reason; an admitted one is handed to
/// `handle` on a thread named `thread_name`, its ticket held until `handle` returns. On
/// `stop`, the connections' threads are joined (a handler should watch `stop` or its own
/// time-outs).
pub fn accept_until<H>(
    listener: TcpListener,
    gate: Arc<Gate>,
    stop: Arc<AtomicBool>,
    thread_name: &str,
    handle: H,
) where
    H: Fn(TcpStream) + Send + Sync + 'static,
{
    let handle = Arc::new(handle);
    let mut conns: Vec<JoinHandle<()>> = Vec::new();
    while !stop.load(Ordering::Relaxed) {
        let Ok((mut stream, peer)) = listener.accept() else {
            std::thread::sleep(Duration::from_millis(IDLE_MS));
            continue;
        };
        let _ = stream.set_nonblocking(false);
        if let Some(b) = gate.limits.send_buffer_bytes {
            set_send_buffer(&stream, b);
        }
        let ticket = match gate.admit(peer.ip()) {
            Ok(t) => t,
            Err(message) => {
                respond_text(&mut stream, "503 Service Unavailable", &message);
                continue;
            }
        };
        let h = handle.clone();
        if let Ok(t) = std::thread::Builder::new()
            .name(thread_name.to_string())
            .spawn(move || {
                h(stream);
                drop(ticket);
            })
        {
            conns.push(t);
        }
        conns.retain(|t| !t.is_finished());
    }
    for t in conns {
        let _ = t.join();
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::Guard;
    use crate::gate::Limits;
    use std::io::Read;
    use std::sync::mpsc;

    /// One connection is admitted and held by its handler; a second from the same address is
    /// answered 503 with the gate's reason and counted; on stop the loop joins the handler.
    #[test]
    fn a_connection_over_the_limit_is_told_why_and_stop_joins_the_handlers() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        listener.set_nonblocking(true).unwrap();
        let addr = listener.local_addr().unwrap();
        let limits = Limits {
            max_connections: 8,
            max_per_address: 1,
            ..Limits::default()
        };
        let guard = Guard {
            port: addr.port(),
            loopback_only: true,
            other_origins: Vec::new(),
        };
        let gate = Arc::new(Gate::new(guard, limits));
        let stop = Arc::new(AtomicBool::new(false));
        let (held_tx, held_rx) = mpsc::channel();
        let (g, s, s2) = (gate.clone(), stop.clone(), stop.clone());
        let held_tx = std::sync::Mutex::new(held_tx);
        let server = std::thread::spawn(move || {
            accept_until(listener, g, s, "test-conn", move |mut stream| {
                held_tx.lock().unwrap().send(()).unwrap();
                while !s2.load(Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(2));
                }
                respond_text(&mut stream, "200 OK", "bye");
            })
        });
        let mut first = TcpStream::connect(addr).unwrap();
        held_rx.recv_timeout(Duration::from_secs(5)).unwrap();
        let mut second = TcpStream::connect(addr).unwrap();
        let mut refused = String::new();
        second.read_to_string(&mut refused).unwrap();
        assert!(
            refused.starts_with("HTTP/1.1 503 Service Unavailable\r\n"),
            "{refused}"
        );
        assert!(
            refused.ends_with(
                "\r\n\r\n127.0.0.1 has 1 connections open, the limit per address: close a tab \
                 or try again shortly\n"
            ),
            "{refused}"
        );
        assert_eq!(gate.refused.snapshot().total(), 1);
        stop.store(true, Ordering::Relaxed);
        server.join().unwrap();
        let mut bye = String::new();
        first.read_to_string(&mut bye).unwrap();
        assert!(
            bye.starts_with("HTTP/1.1 200 OK\r\n") && bye.ends_with("bye\n"),
            "{bye}"
        );
    }

    /// What a client sends and what `checked_head` answered it (`None`: let through).
    fn exchange(request: &str) -> (Option<String>, crate::gate::RefusedCounts) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        let guard = Guard {
            port,
            loopback_only: true,
            other_origins: Vec::new(),
        };
        let gate = Gate::new(guard, Limits::default());
        let mut client = TcpStream::connect(("127.0.0.1", port)).unwrap();
        client
            .write_all(request.replace("PORT", &port.to_string()).as_bytes())
            .unwrap();
        let (mut server, _) = listener.accept().unwrap();
        let passed = checked_head(&mut server, &gate);
        drop(server);
        let answer = passed.is_none().then(|| {
            let mut a = String::new();
            client.read_to_string(&mut a).unwrap();
            a.split("\r\n\r\n").nth(1).unwrap_or_default().to_string()
        });
        (answer, gate.refused.snapshot())
    }

    #[test]
    fn a_head_is_let_through_or_answered_with_its_refusal() {
        let (ok, counts) = exchange("GET / HTTP/1.1\r\nHost: 127.0.0.1:PORT\r\n\r\n");
        assert_eq!((ok, counts.total()), (None, 0));
        let (answer, counts) = exchange(
            "GET /ws HTTP/1.1\r\nHost: localhost:PORT\r\nOrigin: https://evil.example\r\n\r\n",
        );
        assert!(answer.unwrap().contains("https://evil.example"));
        assert_eq!((counts.origin, counts.total()), (1, 1));
        let (answer, counts) = exchange("NONSENSE\r\n\r\n");
        assert_eq!(
            answer.unwrap(),
            "the request line is not `METHOD TARGET HTTP/1.1`\n"
        );
        assert_eq!((counts.head, counts.total()), (1, 1));
    }

    #[test]
    fn every_answer_asks_for_cross_origin_isolation() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let mut client = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (mut server, _) = listener.accept().unwrap();
        respond(&mut server, "200 OK", "text/html", "X-Extra: 1\r\n", b"<p>");
        drop(server);
        let mut a = String::new();
        client.read_to_string(&mut a).unwrap();
        let (head, body) = a.split_once("\r\n\r\n").unwrap();
        let lines: Vec<&str> = head.split("\r\n").collect();
        for want in [
            "Cross-Origin-Opener-Policy: same-origin",
            "Cross-Origin-Embedder-Policy: require-corp",
            "Cross-Origin-Resource-Policy: same-origin",
            "X-Extra: 1",
            "Content-Length: 3",
        ] {
            assert!(lines.contains(&want), "{want} in {lines:?}");
        }
        assert_eq!(body, "<p>");
    }
}
