//! The live view's door: the Foxglove server listens on a private loopback port, and this
//! guard on the address the user asked for. Each connection's request head is checked —
//! `Host` one of this machine's addresses (never a rebinding page's name), `Origin` absent (the
//! Foxglove desktop app), the Foxglove web app's or the page's own — and only then passed on,
//! byte for byte, to the server. A page of another site in the same browser can therefore
//! neither watch the session nor set its switches (the Parameters panel drives the live menu).

use std::io::{Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;
use webguard::Guard;
use webguard::gate::{Gate, Limits};
use webguard::serve::{accept_until, checked_head, respond_text};

/// The Foxglove web app's origin, allowed to connect (Foxglove's desktop app sends none).
pub const FOXGLOVE_APP_ORIGIN: &str = "https://app.foxglove.dev";
/// What the guard accepts: connections at once (in all and per address; the Foxglove app
/// opens one or two) — the same limits and refusal counters as the game's servers.
pub fn limits() -> Limits {
    Limits {
        max_connections: 32,
        max_per_address: 32,
        ..Limits::default()
    }
}

/// The running guard.
pub struct LiveGuard {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    /// What it refused.
    pub gate: Arc<Gate>,
}

impl LiveGuard {
    /// Listens on `bind` and passes checked connections to `backend`.
    pub fn start(bind: SocketAddr, backend: SocketAddr) -> std::io::Result<LiveGuard> {
        let listener = TcpListener::bind(bind)?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let guard = Guard {
            port: addr.port(),
            loopback_only: bind.ip().is_loopback(),
            other_origins: vec![FOXGLOVE_APP_ORIGIN.to_string()],
        };
        let stop = Arc::new(AtomicBool::new(false));
        let gate = Arc::new(Gate::new(guard, limits()));
        let (s, g) = (stop.clone(), gate.clone());
        let thread = std::thread::Builder::new()
            .name("live-guard".into())
            .spawn(move || {
                let (g2, s2) = (g.clone(), s.clone());
                accept_until(listener, g, s, "live-guard-conn", move |stream| {
                    connection(stream, &g2, backend, &s2)
                })
            })?;
        Ok(LiveGuard {
            addr,
            stop,
            thread: Some(thread),
            gate,
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }
}

impl Drop for LiveGuard {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn connection(mut client: TcpStream, gate: &Gate, backend: SocketAddr, stop: &AtomicBool) {
    let _ = client.set_nonblocking(false);
    let Some((bytes, _)) = checked_head(&mut client, gate) else {
        return;
    };
    let Ok(mut server) = TcpStream::connect(backend) else {
        return respond_text(
            &mut client,
            "502 Bad Gateway",
            "the live view is not serving",
        );
    };
    let _ = server.set_nodelay(true);
    let _ = client.set_nodelay(true);
    if server.write_all(&bytes).is_err() {
        return;
    }
    // Both directions, until either side closes (or the session ends).
    let (Ok(mut c2), Ok(mut s2)) = (client.try_clone(), server.try_clone()) else {
        return;
    };
    let up = std::thread::spawn(move || {
        let _ = std::io::copy(&mut c2, &mut s2);
        let _ = s2.shutdown(Shutdown::Write);
    });
    let _ = client.set_read_timeout(None);
    let _ = server.set_read_timeout(Some(Duration::from_millis(200)));
    let mut buf = [0u8; 16 * 1024];
    loop {
        match server.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => {
                if client.write_all(&buf[..n]).is_err() {
                    break;
                }
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
            }
            Err(_) => break,
        }
    }
    let _ = client.shutdown(Shutdown::Both);
    let _ = server.shutdown(Shutdown::Both);
    let _ = up.join();
}
