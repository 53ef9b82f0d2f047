//! The replay page's server: `GET` only, on loopback, behind the same gate and `Host`/`Origin`
//! checks as `play` ([`crate::server::Listener`]). Nothing changes state: the page asks for the
//! index, frames by range and the sound, and plays them itself.
//!
//! | path | answer |
//! |---|---|
//! | `/`, `/index.html` | the replay page |
//! | `/replay.js`, and the play page's `/play.css`, `/page.js`, `/camera.js`, `/draw.js`, `/events.js` | its modules |
//! | `/replay/hello.json` | the `hello` message, as a live page is sent it |
//! | `/replay/index.json` | rate, ticks, each frame's tick, the sound's rate and length |
//! | `/replay/frames.json?from=K&count=N` | frames `K..K+N` (JSON array; at most [`MAX_FRAMES`]) |
//! | `/replay/sound.f32` | the sound track, f32 little-endian mono |
//! | `/recording.mcap` | the recording |

use super::ReplayBook;
use crate::http::{respond, respond_text};
use crate::server::{Listener, Routes, serve_download, serve_page_file};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use webguard::Head;
use webguard::gate::{Gate, Limits};

/// Most frames one request returns.
pub const MAX_FRAMES: usize = 500;

const HTML: &str = include_str!("page/index.html");
const JS: &str = include_str!("page/replay.js");

/// The play page's modules the replay page imports, served from the play page's files.
const SHARED: [&str; 5] = [
    "/play.css",
    "/page.js",
    "/camera.js",
    "/draw.js",
    "/events.js",
];

struct ReplayRoutes {
    book: Arc<ReplayBook>,
    file: PathBuf,
}

fn json(stream: &mut TcpStream, body: &str) {
    respond(
        stream,
        "200 OK",
        "application/json; charset=utf-8",
        "",
        body.as_bytes(),
    );
}

/// `frames.json?from=K&count=N` of `book`: the range checked, named in the refusal.
fn frames(stream: &mut TcpStream, head: &Head, book: &ReplayBook) {
    let n = book.frames.len();
    let arg = |key: &str, default: usize| -> Result<usize, String> {
        match head.query(key) {
            None => Ok(default),
            Some(v) => v
                .parse::<usize>()
                .map_err(|_| format!("`{key}` = \"{}\" is not a count", v.escape_default())),
        }
    };
    let range = arg("from", 0).and_then(|from| {
        let count = arg("count", MAX_FRAMES)?;
        if from > n {
            return Err(format!(
                "`from` = {from} is out of range: allowed 0 ≤ from ≤ {n}"
            ));
        }
        if count > MAX_FRAMES {
            return Err(format!(
                "`count` = {count} is out of range: allowed 0 ≤ count ≤ {MAX_FRAMES}"
            ));
        }
        Ok(from..(from + count).min(n))
    });
    match range {
        Ok(r) => json(stream, &format!("[{}]", book.frames[r].join(","))),
        Err(e) => respond_text(stream, "400 Bad Request", &e),
    }
}

/// Whether `path` is one of the replay's data paths (`/replay/…`).
pub fn is_data_path(path: &str) -> bool {
    path.starts_with("/replay/")
}

/// Serves the replay page's own files: the page (at `page_path`), `/replay.js` and the play
/// page's modules it imports; false for any other path.
pub fn serve_page(stream: &mut TcpStream, path: &str, page_path: &str) -> bool {
    if path == page_path {
        respond(
            stream,
            "200 OK",
            "text/html; charset=utf-8",
            "",
            HTML.as_bytes(),
        );
    } else if path == "/replay.js" {
        respond(
            stream,
            "200 OK",
            "text/javascript; charset=utf-8",
            "",
            JS.as_bytes(),
        );
    } else if SHARED.contains(&path) {
        serve_page_file(stream, path);
    } else {
        return false;
    }
    true
}

/// Serves the data path `head` asks for (see [`is_data_path`]) from `book`.
pub fn serve_data(stream: &mut TcpStream, head: &Head, book: &ReplayBook) {
    match head.path() {
        "/replay/hello.json" => json(stream, &book.hello),
        "/replay/index.json" => json(stream, &book.index_json()),
        "/replay/frames.json" => frames(stream, head, book),
        "/replay/sound.f32" => {
            let bytes: Vec<u8> = book.sound.iter().flat_map(|s| s.to_le_bytes()).collect();
            respond(stream, "200 OK", "application/octet-stream", "", &bytes);
        }
        _ => respond_text(stream, "404 Not Found", "not found"),
    }
}

impl Routes for ReplayRoutes {
    fn route(&self, mut stream: TcpStream, head: Head, _gate: &Arc<Gate>) {
        let path = head.path();
        let page = if path == "/index.html" { "/" } else { path };
        if serve_page(&mut stream, page, "/") {
            return;
        }
        match path {
            p if is_data_path(p) => serve_data(&mut stream, &head, &self.book),
            "/recording.mcap" => serve_download(&mut stream, Some(self.file.clone()), ""),
            "/favicon.ico" => respond(&mut stream, "204 No Content", "image/x-icon", "", b""),
            _ => respond_text(&mut stream, "404 Not Found", "not found"),
        }
    }
}

/// A running replay server.
pub struct ReplayServer {
    listener: Listener,
}

impl ReplayServer {
    /// Serves `book` (made from the recording at `file`) on `127.0.0.1:port` (0: any free
    /// port).
    pub fn start(book: ReplayBook, file: PathBuf, port: u16) -> std::io::Result<ReplayServer> {
        let routes = Arc::new(ReplayRoutes {
            book: Arc::new(book),
            file,
        });
        let listener = Listener::start(
            SocketAddr::from(([127, 0, 0, 1], port)),
            Limits::default(),
            routes,
            Arc::new(AtomicBool::new(false)),
        )?;
        Ok(ReplayServer { listener })
    }

    /// The page's URL.
    pub fn url(&self) -> String {
        format!("http://{}/", self.listener.addr())
    }

    /// The gate (limits and refusal counts).
    pub fn gate(&self) -> &Arc<Gate> {
        self.listener.gate()
    }

    /// Stops serving.
    pub fn stop(&mut self) {
        self.listener.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The page loads replay.js and the style sheet; every module replay.js imports, and every
    /// module those import, is one the replay server serves.
    #[test]
    fn the_replay_page_imports_only_served_modules() {
        assert!(HTML.contains(r#"<script type="module" src="/replay.js"></script>"#));
        assert!(HTML.contains(r#"href="/play.css""#));
        let mut todo = vec![JS];
        let mut seen = Vec::new();
        while let Some(body) = todo.pop() {
            for m in body
                .lines()
                .filter(|l| l.starts_with("import "))
                .filter_map(|l| l.split("from './").nth(1)?.split('\'').next())
            {
                let path = format!("/{m}");
                assert!(SHARED.contains(&path.as_str()), "{path} is not served");
                if !seen.contains(&path) {
                    let f = crate::server::PAGE_FILES.iter().find(|f| f.path == path);
                    todo.push(f.map(|f| f.body).unwrap_or_default());
                    seen.push(path);
                }
            }
        }
        seen.sort();
        assert_eq!(seen, ["/camera.js", "/draw.js", "/events.js", "/page.js"]);
    }
}
