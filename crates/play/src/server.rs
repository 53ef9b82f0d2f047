//! One loopback port for the page (HTTP) and its live link (WebSocket on `/ws`), on plain
//! threads: one accepting, one per connection. Nothing here runs on the tick thread: the tick
//! hands its data to the publisher thread ([`crate::publish`]), which queues it for each page
//! (bounded queues; a page that cannot keep up loses frames, never the tick's time).

use crate::http::{accept_upgrade, respond, respond_text};
use crate::input::{SharedInput, page_to_device};
use crate::protocol::{self, PageMsg, ProtocolError, Role, ServerMsg};
use crate::wslink::{self, Incoming, LinkConfig};
use haptic_types::SwitchSpec;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::Message;
use webguard::gate::{Gate, Limits};
use webguard::{Guard, Head, HeadError, read_head};

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
const INDEX_HTML: &str = include_str!("page/index.html");

/// Every file of the page: the HTML, the style sheet and the JavaScript modules (`main.js`
/// imports the others). These paths, `/ws`, `/favicon.ico` and `/recording.mcap` are all the
/// server answers; anything else is 404.
pub const PAGE_FILES: &[PageFile] = &[
    PageFile {
        path: "/",
        content_type: HTML,
        body: INDEX_HTML,
    },
    PageFile {
        path: "/index.html",
        content_type: HTML,
        body: INDEX_HTML,
    },
    PageFile {
        path: "/play.css",
        content_type: CSS,
        body: include_str!("page/play.css"),
    },
    PageFile {
        path: "/main.js",
        content_type: JS,
        body: include_str!("page/main.js"),
    },
    PageFile {
        path: "/page.js",
        content_type: JS,
        body: include_str!("page/page.js"),
    },
    PageFile {
        path: "/camera.js",
        content_type: JS,
        body: include_str!("page/camera.js"),
    },
    PageFile {
        path: "/draw.js",
        content_type: JS,
        body: include_str!("page/draw.js"),
    },
    PageFile {
        path: "/input.js",
        content_type: JS,
        body: include_str!("page/input.js"),
    },
    PageFile {
        path: "/sound.js",
        content_type: JS,
        body: include_str!("page/sound.js"),
    },
    PageFile {
        path: "/synth.js",
        content_type: JS,
        body: include_str!("page/synth.js"),
    },
    PageFile {
        path: "/messages.js",
        content_type: JS,
        body: include_str!("page/messages.js"),
    },
    PageFile {
        path: "/events.js",
        content_type: JS,
        body: include_str!("page/events.js"),
    },
];

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
    next_id: AtomicU64,
}

/// A connected page's outgoing queue.
pub struct Page {
    /// Its id.
    pub id: u64,
    tx: SyncSender<Message>,
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
        if let Err(TrySendError::Full(_)) = p.tx.try_send(m) {
            self.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn error_to(&self, id: u64, field: &str, message: &str) {
        self.refused.fetch_add(1, Ordering::Relaxed);
        let m = ServerMsg::Error {
            field: field.to_string(),
            message: message.to_string(),
        };
        self.send_to(id, Message::text(m.to_json()));
    }
}

/// What a listening server does with a request that passed its [`Gate`] and its
/// `Host`/`Origin` check: the play session's routes, or the classroom's.
pub trait Routes: Send + Sync + 'static {
    /// Answers `head` on `stream` (a WebSocket upgrade keeps the stream until it closes).
    fn route(&self, stream: TcpStream, head: Head, gate: &Arc<Gate>);
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
        let (g, sd) = (gate.clone(), shutdown.clone());
        let accept = std::thread::Builder::new()
            .name("page-accept".into())
            .spawn(move || accept_loop(listener, g, routes, sd))?;
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

fn accept_loop(
    listener: TcpListener,
    gate: Arc<Gate>,
    routes: Arc<dyn Routes>,
    shutdown: Arc<AtomicBool>,
) {
    let mut conns: Vec<JoinHandle<()>> = Vec::new();
    while !shutdown.load(Ordering::Relaxed) {
        match listener.accept() {
            Ok((mut stream, peer)) => {
                let _ = stream.set_nonblocking(false);
                let _ = stream.set_write_timeout(Some(Duration::from_secs(WRITE_TIMEOUT_S)));
                if let Some(b) = gate.limits.send_buffer_bytes {
                    webguard::gate::set_send_buffer(&stream, b);
                }
                let ticket = match gate.admit(peer.ip()) {
                    Ok(t) => t,
                    Err(message) => {
                        respond_text(&mut stream, "503 Service Unavailable", &message);
                        continue;
                    }
                };
                let (g, r) = (gate.clone(), routes.clone());
                if let Ok(h) =
                    std::thread::Builder::new()
                        .name("page-conn".into())
                        .spawn(move || {
                            connection(stream, &g, r.as_ref());
                            drop(ticket);
                        })
                {
                    conns.push(h);
                }
                conns.retain(|h| !h.is_finished());
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(Duration::from_millis(5));
            }
            Err(_) => std::thread::sleep(Duration::from_millis(5)),
        }
    }
    for h in conns {
        let _ = h.join();
    }
}

/// Reads and checks one request, then routes it.
fn connection(mut stream: TcpStream, gate: &Arc<Gate>, routes: &dyn Routes) {
    let _ = stream.set_nodelay(true);
    let head = match read_head(&mut stream) {
        Ok(h) => h,
        Err(HeadError::Closed) => return gate.refused.count("head"),
        Err(e) => {
            gate.refused.count("head");
            return respond_text(&mut stream, "400 Bad Request", &e.to_string());
        }
    };
    if let Err(r) = gate.guard.check(&head) {
        gate.refused.count(r.kind());
        return respond_text(&mut stream, "403 Forbidden", &r.to_string());
    }
    if head.method != "GET" {
        return respond_text(&mut stream, "405 Method Not Allowed", "GET only");
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

/// Handles one page message from page `id`.
fn on_message(shared: &Shared, id: u64, text: &str) {
    let link = shared.scene.lock().ok().and_then(|s| s.clone());
    let mask = link.as_ref().map_or(0, |l| l.button_mask);
    let msg = match protocol::parse(text, mask) {
        Ok(m) => m,
        Err(e) => return shared.error_to(id, e.field(), &e.to_string()),
    };
    let is_player = |sh: &Shared| sh.player.lock().map(|p| *p == Some(id)).unwrap_or(false);
    match msg {
        PageMsg::Start => {
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
        PageMsg::End => {
            if is_player(shared) || link.as_ref().is_some_and(|l| !l.page_is_hand) {
                shared.end_requested.store(true, Ordering::Relaxed);
            } else {
                shared.error_to(id, "type", "only the page that plays can end the session");
            }
        }
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
    if let Ok(mut pages) = shared.pages.lock() {
        pages.push(Page { id, tx });
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
    wslink::run(stream, gate, link, &mut peer);
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

#[cfg(test)]
mod tests {
    use super::*;
    use haptic_loop::scene::brick::BRICK_SWITCHES;

    fn shared(page_is_hand: bool) -> (Arc<Shared>, Receiver<Message>, Receiver<Message>) {
        let sh = Arc::new(Shared::default());
        *sh.scene.lock().unwrap() = Some(SceneLink {
            switches: &BRICK_SWITCHES,
            kind: "brickworld",
            workspace_radius_m: 0.04,
            button_mask: 0b1111,
            page_is_hand,
        });
        let (t1, r1) = sync_channel(16);
        let (t2, r2) = sync_channel(16);
        sh.pages.lock().unwrap().push(Page { id: 1, tx: t1 });
        sh.pages.lock().unwrap().push(Page { id: 2, tx: t2 });
        (sh, r1, r2)
    }

    fn last_error(rx: &Receiver<Message>) -> serde_json::Value {
        let mut last = serde_json::Value::Null;
        while let Ok(m) = rx.try_recv() {
            if let Message::Text(t) = m {
                last = serde_json::from_str(t.as_str()).unwrap();
            }
        }
        last
    }

    /// The modules `body` imports, and those it loads by URL (`new URL('./synth.js',
    /// import.meta.url)`: the AudioWorklet's module).
    fn imports(body: &str) -> Vec<String> {
        let imported = body
            .lines()
            .filter(|l| l.starts_with("import "))
            .filter_map(|l| l.split("from './").nth(1));
        let by_url = body.split("new URL('./").skip(1);
        imported
            .chain(by_url)
            .filter_map(|rest| rest.split('\'').next())
            .map(|m| format!("/{m}"))
            .collect()
    }

    #[test]
    fn the_page_files_are_served_and_import_only_served_modules() {
        let served: Vec<&str> = PAGE_FILES.iter().map(|f| f.path).collect();
        // Every file in src/page is served (and nothing else is listed).
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/page");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| format!("/{}", e.unwrap().file_name().to_string_lossy()))
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = served
            .iter()
            .filter(|p| **p != "/")
            .map(|p| p.to_string())
            .collect();
        listed.sort();
        assert_eq!(on_disk, listed);
        // Modules are JavaScript; the page loads main.js as a module and the style sheet.
        for f in PAGE_FILES {
            assert_eq!(
                f.path.ends_with(".js"),
                f.content_type == "text/javascript; charset=utf-8",
                "{}",
                f.path
            );
        }
        let index = PAGE_FILES[0].body;
        assert!(index.contains(r#"<script type="module" src="/main.js"></script>"#));
        assert!(index.contains(r#"href="/play.css""#));
        // Every module is reached from main.js, and every import is served.
        let mut reached = vec!["/main.js".to_string()];
        let mut i = 0;
        while i < reached.len() {
            let f = PAGE_FILES.iter().find(|f| f.path == reached[i]).unwrap();
            for m in imports(f.body) {
                assert!(served.contains(&m.as_str()), "{} imports {m}", f.path);
                if !reached.contains(&m) {
                    reached.push(m);
                }
            }
            i += 1;
        }
        let js = served.iter().filter(|p| p.ends_with(".js")).count();
        assert_eq!(
            reached.len(),
            js,
            "modules reached from main.js: {reached:?}"
        );
    }

    #[test]
    fn switches_are_checked_before_they_reach_the_tick() {
        let (sh, r1, _) = shared(true);
        on_message(&sh, 1, r#"{"type":"switch","name":"gravity","value":1}"#);
        let e = last_error(&r1);
        assert_eq!(e["field"], "switch.name");
        assert_eq!(
            e["message"],
            "the brickworld scene has no switch `gravity` (its switches: gravity_m_per_s2, \
             restitution, friction, inertia, brick_mass_kg)"
        );
        on_message(&sh, 1, r#"{"type":"switch","name":"friction","value":11}"#);
        let e = last_error(&r1);
        assert_eq!(e["field"], "switch.value");
        assert_eq!(
            e["message"],
            "switch `friction` = 11 is out of range: allowed 0 ≤ value ≤ 10"
        );
        on_message(&sh, 1, r#"{"type":"switch","name":"inertia","value":0.5}"#);
        assert_eq!(last_error(&r1)["field"], "switch.value");
        assert!(sh.switches.lock().unwrap().is_empty());
        // Good ones wait for the tick, the old name under the switch's own.
        on_message(
            &sh,
            2,
            r#"{"type":"switch","name":"gravity_m_s2","value":0}"#,
        );
        on_message(
            &sh,
            1,
            r#"{"type":"switch","name":"friction","value":0.25}"#,
        );
        assert_eq!(
            *sh.switches.lock().unwrap(),
            vec![
                (2, "gravity_m_per_s2".to_string(), 0.0),
                (1, "friction".to_string(), 0.25)
            ]
        );
        assert_eq!(sh.refused.load(Ordering::Relaxed), 3);
    }

    #[test]
    fn the_first_page_to_start_is_the_hand_and_the_others_watch() {
        let (sh, r1, r2) = shared(true);
        on_message(&sh, 2, r#"{"type":"start"}"#);
        on_message(&sh, 1, r#"{"type":"start"}"#);
        assert_eq!(last_error(&r2)["role"], "hand");
        assert_eq!(last_error(&r1)["role"], "view");
        let input = r#"{"type":"input","seq":1,"pos":[0.5,0,-0.5],"buttons":1,"t_ms":1}"#;
        on_message(&sh, 1, input);
        assert_eq!(
            last_error(&r1)["message"],
            "another page is the hand: this page watches"
        );
        assert_eq!(sh.input.latest().0.count, 0);
        on_message(&sh, 2, input);
        let (l, at) = sh.input.latest();
        assert!(at.is_some());
        assert_eq!((l.count, l.buttons, l.t_ms), (1, 1, 1.0));
        assert_eq!(l.position_m, page_to_device([0.5, 0.0, -0.5], 0.04));
        // Only the hand ends the session.
        on_message(&sh, 1, r#"{"type":"end"}"#);
        assert!(!sh.end_requested.load(Ordering::Relaxed));
        on_message(&sh, 2, r#"{"type":"end"}"#);
        assert!(sh.end_requested.load(Ordering::Relaxed));
        // Bad input is answered with its field and range, and changes nothing.
        on_message(
            &sh,
            2,
            r#"{"type":"input","seq":2,"pos":[0,0,2],"buttons":0,"t_ms":1}"#,
        );
        let e = last_error(&r2);
        assert_eq!(e["field"], "input.pos[2]");
        assert_eq!(sh.input.latest().0.count, 1);
    }

    #[test]
    fn with_a_device_as_the_hand_the_pages_only_watch() {
        let (sh, r1, _) = shared(false);
        on_message(&sh, 1, r#"{"type":"start"}"#);
        assert_eq!(last_error(&r1)["role"], "view");
        on_message(
            &sh,
            1,
            r#"{"type":"input","seq":1,"pos":[0,0,0],"buttons":0,"t_ms":1}"#,
        );
        assert_eq!(
            last_error(&r1)["message"],
            "a device is the hand in this session: the page only watches"
        );
        assert_eq!(sh.input.latest().0.count, 0);
    }
}
