//! `play`'s own server: one session's pages on loopback.

use super::{Listener, Routes, Shared, page_link, serve_download, serve_page_file};
use crate::http::{accept_upgrade, respond, respond_text};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use webguard::Head;
use webguard::gate::{Gate, Limits};

/// The routes of a play session: the page, `/ws`, `/favicon.ico` and `/recording.mcap`.
pub struct PlayRoutes {
    /// The session.
    pub shared: Arc<Shared>,
}

impl Routes for PlayRoutes {
    fn route(&self, mut stream: TcpStream, head: Head, gate: &Arc<Gate>) {
        let path = head.path();
        if serve_page_file(&mut stream, path) {
            return;
        }
        match path {
            "/favicon.ico" => respond(&mut stream, "204 No Content", "image/x-icon", "", b""),
            "/recording.mcap" => {
                let file = self.shared.recording.lock().ok().and_then(|r| r.clone());
                serve_download(
                    &mut stream,
                    file,
                    "the recording is served once the session has ended",
                );
            }
            "/ws" if head.is_upgrade() => {
                if accept_upgrade(&mut stream, &head).is_ok() {
                    page_link(stream, &self.shared, gate);
                }
            }
            "/ws" => respond_text(
                &mut stream,
                "400 Bad Request",
                "a WebSocket upgrade is expected here",
            ),
            _ => respond_text(&mut stream, "404 Not Found", "not found"),
        }
    }
}

/// The running play server: a [`Listener`] on loopback with the [`PlayRoutes`].
pub struct Server {
    listener: Listener,
}

impl Server {
    /// Binds `127.0.0.1:port` (0: any free port) and starts serving, with `limits`.
    pub fn start(port: u16, shared: Arc<Shared>, limits: Limits) -> std::io::Result<Server> {
        let routes = Arc::new(PlayRoutes {
            shared: shared.clone(),
        });
        let shutdown = Arc::new(AtomicBool::new(false));
        let listener = Listener::start(
            SocketAddr::from(([127, 0, 0, 1], port)),
            limits,
            routes,
            shutdown,
        )?;
        Ok(Server { listener })
    }

    /// The address served.
    pub fn addr(&self) -> SocketAddr {
        self.listener.addr()
    }

    /// The gate (limits and refusal counts).
    pub fn gate(&self) -> &Arc<Gate> {
        self.listener.gate()
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr())
    }

    /// Stops accepting, closes the pages and joins the threads.
    pub fn stop(&mut self, shared: &Shared) {
        shared.shutdown.store(true, Ordering::Relaxed);
        self.listener.stop();
    }
}
