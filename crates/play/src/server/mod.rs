//! One loopback port for the page (HTTP) and its live link (WebSocket on `/ws`), on plain
//! threads: one accepting, one per connection. Nothing here runs on the tick thread: the tick
//! hands its data to the publisher thread ([`crate::publish`]), which queues it for each page
//! (bounded queues; a page that cannot keep up loses frames, never the tick's time).
//!
//! - [`shared`]: a session's link to its pages (what is played, the pages' queues, the hand's
//!   input, the switches asked for);
//! - this module: the listener, its routes and the page's files;
//! - [`page_link`]: a page's WebSocket and its messages;
//! - [`play_server`]: `play`'s own server and routes.

mod page_link;
mod play_server;
mod shared;
#[cfg(test)]
mod tests;

#[cfg(test)]
pub(crate) use page_link::on_message as on_page_message;
pub use page_link::page_link;
pub use play_server::{PlayRoutes, Server};
pub use shared::{PAGE_QUEUE, Page, SceneLink, Shared, SwitchRequest, WRITE_TIMEOUT_S};

use crate::http::{respond, respond_text};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::Duration;
use webguard::gate::{Gate, Limits};
use webguard::{Guard, Head};

/// A file of the page, built into the binary.
#[derive(Clone, Copy, Debug)]
pub struct PageFile {
    /// Its path on the server (`/main.js`).
    pub path: &'static str,
    /// Its `Content-Type`.
    pub content_type: &'static str,
    /// Its text.
    pub body: &'static str,
}

const HTML: &str = "text/html; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";
const INDEX_HTML: &str = include_str!("../page/index.html");

/// A page file at `path` of `content_type` holding `body`.
const fn file(path: &'static str, content_type: &'static str, body: &'static str) -> PageFile {
    PageFile {
        path,
        content_type,
        body,
    }
}

/// Every file of the page: the HTML, the style sheet and the JavaScript modules (`main.js`
/// imports the others; `messages.js` starts `link.js`, a Worker, which imports `route.js`). These paths, `/ws`, `/favicon.ico` and `/recording.mcap` are all the
/// server answers; anything else is 404.
pub const PAGE_FILES: &[PageFile] = &[
    file("/", HTML, INDEX_HTML),
    file("/index.html", HTML, INDEX_HTML),
    file("/play.css", CSS, include_str!("../page/play.css")),
    file("/main.js", JS, include_str!("../page/main.js")),
    file("/page.js", JS, include_str!("../page/page.js")),
    file("/camera.js", JS, include_str!("../page/camera.js")),
    file("/draw.js", JS, include_str!("../page/draw.js")),
    file("/input.js", JS, include_str!("../page/input.js")),
    file("/sound.js", JS, include_str!("../page/sound.js")),
    file("/synth.js", JS, include_str!("../page/synth.js")),
    file("/messages.js", JS, include_str!("../page/messages.js")),
    file("/link.js", JS, include_str!("../page/link.js")),
    file("/route.js", JS, include_str!("../page/route.js")),
    file("/events.js", JS, include_str!("../page/events.js")),
    file("/lesson.js", JS, include_str!("../page/lesson.js")),
];

/// What a listening server does with a request that passed its [`Gate`] and its
/// `Host`/`Origin` check: the play session's routes, or the classroom's.
pub trait Routes: Send + Sync + 'static {
    /// Answers `head` on `stream` (a WebSocket upgrade keeps the stream until it closes).
    fn route(&self, stream: TcpStream, head: Head, gate: &Arc<Gate>);

    /// The paths that take a form `POST` (a state change from the server's own page, checked
    /// by the route with `webguard::form`); every other path is `GET` only.
    fn post_paths(&self) -> &'static [&'static str] {
        &[]
    }
}

/// A listening page server: one thread accepting, one per connection, each connection
/// admitted by the [`Gate`] (limits) and checked (`Host`, `Origin`) before it is routed.
pub struct Listener {
    addr: SocketAddr,
    gate: Arc<Gate>,
    shutdown: Arc<AtomicBool>,
    accept: Option<JoinHandle<()>>,
}

impl Listener {
    /// Binds `bind` (port 0: any free port) and serves `routes` behind a gate of `limits`; a
    /// loopback address answers only to loopback host names, any other to IP addresses too.
    pub fn start(
        bind: SocketAddr,
        limits: Limits,
        routes: Arc<dyn Routes>,
        shutdown: Arc<AtomicBool>,
    ) -> std::io::Result<Listener> {
        let listener = TcpListener::bind(bind)?;
        listener.set_nonblocking(true)?;
        let addr = listener.local_addr()?;
        let gate = Arc::new(Gate::new(
            Guard {
                port: addr.port(),
                loopback_only: bind.ip().is_loopback(),
                other_origins: Vec::new(),
            },
            limits,
        ));
        let (g, g2, sd) = (gate.clone(), gate.clone(), shutdown.clone());
        let accept = std::thread::Builder::new()
            .name("page-accept".into())
            .spawn(move || {
                webguard::serve::accept_until(listener, g, sd, "page-conn", move |stream| {
                    let _ = stream.set_write_timeout(Some(Duration::from_secs(WRITE_TIMEOUT_S)));
                    connection(stream, &g2, routes.as_ref())
                })
            })?;
        Ok(Listener {
            addr,
            gate,
            shutdown,
            accept: Some(accept),
        })
    }

    /// The address served.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The gate (limits and refusal counts).
    pub fn gate(&self) -> &Arc<Gate> {
        &self.gate
    }

    /// Stops accepting, closes the connections and joins the threads.
    pub fn stop(&mut self) {
        self.shutdown.store(true, Ordering::Relaxed);
        if let Some(h) = self.accept.take() {
            let _ = h.join();
        }
    }
}

impl Drop for Listener {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Reads and checks one request, then routes it.
fn connection(mut stream: TcpStream, gate: &Arc<Gate>, routes: &dyn Routes) {
    let _ = stream.set_nodelay(true);
    let Some((_, head)) = webguard::serve::checked_head(&mut stream, gate) else {
        return;
    };
    let post = head.method == "POST" && routes.post_paths().contains(&head.path());
    if head.method != "GET" && !post {
        respond_text(&mut stream, "405 Method Not Allowed", "GET only");
        return webguard::serve::drain_body(&mut stream, &head, webguard::form::MAX_FORM_BYTES);
    }
    routes.route(stream, head, gate);
}

/// Serves a page file of [`PAGE_FILES`] at `path`; false when there is none.
pub fn serve_page_file(stream: &mut TcpStream, path: &str) -> bool {
    match PAGE_FILES.iter().find(|f| f.path == path) {
        Some(f) => {
            respond(stream, "200 OK", f.content_type, "", f.body.as_bytes());
            true
        }
        None => false,
    }
}

/// Serves the file at `file` as a download (`404` with `missing` when there is none yet).
pub fn serve_download(stream: &mut TcpStream, file: Option<PathBuf>, missing: &str) {
    match file.map(|p| (std::fs::read(&p), p)) {
        Some((Ok(bytes), p)) => {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().replace(['"', '\\', '\r', '\n'], "_"))
                .unwrap_or_else(|| "recording.mcap".into());
            respond(
                stream,
                "200 OK",
                "application/octet-stream",
                &format!("Content-Disposition: attachment; filename=\"{name}\"\r\n"),
                &bytes,
            );
        }
        Some((Err(e), _)) => respond_text(
            stream,
            "500 Internal Server Error",
            &format!("cannot read the recording: {e}"),
        ),
        None => respond_text(stream, "404 Not Found", missing),
    }
}
