//! The classroom's paths: the join page and `POST /join`, each student's page (`/play?s=TOKEN`,
//! the page's modules, `/ws?s=TOKEN`, `/recording.mcap?s=TOKEN`), and the teacher's
//! (`/teacher?code=…`, `/teacher/ws?code=…`, `/recordings.zip?code=…`, and a student's ended
//! session replayed: `/replay?s=TOKEN&code=…`, a lesson's finished step
//! `/replay?s=TOKEN&step=ID&code=…`, with its data under `/replay/`). Every request passed
//! the listener's gate and its `Host`/`Origin` check before it reaches these. Joining changes
//! the class (a session, a name taken), so it is a form `POST` from the join page itself
//! ([`webguard::form`]): a link or a page from another site cannot fill the class with names.

use super::{Class, JoinError, Phase, lesson, teacher};
use crate::http::{accept_upgrade, respond, respond_text};
use crate::replay::{ReplayBook, server as replay};
use crate::server::{PAGE_FILES, Routes, page_link, serve_download, serve_page_file};
use std::collections::HashMap;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::Mutex;
use webguard::Head;
use webguard::gate::Gate;

/// The classroom's files besides the play page's.
const JOIN_CSS: &str = include_str!("page/class.css");
const TEACHER_HTML: &str = include_str!("page/teacher.html");
const TEACHER_JS: &str = include_str!("page/teacher.js");

/// The classroom's routes.
pub(crate) struct ClassRoutes {
    pub(crate) class: Arc<Class>,
    /// The students' ended sessions made ready to replay, by token (made on the first ask).
    pub(crate) replays: Mutex<HashMap<String, Arc<ReplayBook>>>,
}

/// Escapes text for HTML.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// The join page, with `error` above the form when a join was refused.
fn join_page(class: &Class, error: Option<&str>, name: &str) -> String {
    let code = if class.join_code.is_some() {
        r#"<label>Join code <input name="code" inputmode="numeric" autocomplete="off" required maxlength="12"></label>"#
    } else {
        ""
    };
    let error = error
        .map(|e| format!(r#"<p class="error" role="alert">{}</p>"#, esc(e)))
        .unwrap_or_default();
    format!(
        r#"<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>nanohaptics classroom: join</title><link rel="stylesheet" href="/class.css"></head>
<body><main class="join"><h1>Join the class</h1>
<p>{what}: <b>{scene}</b>. Enter your name: you get your own world and your own recording.</p>
{error}<form method="post" action="/join">
<label>Your name <input name="name" value="{name}" required maxlength="32" autocomplete="off" autofocus></label>
{code}<button type="submit">Join</button></form></main></body></html>
"#,
        what = if class.lesson.is_some() {
            "Lesson"
        } else {
            "Scene"
        },
        scene = esc(&class.scene_name),
        name = esc(name),
    )
}

fn html(stream: &mut TcpStream, status: &str, body: &str) {
    respond(
        stream,
        status,
        "text/html; charset=utf-8",
        "",
        body.as_bytes(),
    );
}

impl ClassRoutes {
    fn teacher_ok(&self, head: &Head, gate: &Gate) -> bool {
        let ok = head.query("code").as_deref() == Some(self.class.teacher_code.as_str());
        if !ok {
            gate.refused.count("code");
        }
        ok
    }
}

impl ClassRoutes {
    /// `POST /join` with the form's `name` and `code`: the student's session, or the join page
    /// with the reason. A request that is not a form `POST` from this server's page is refused
    /// with its reason (and counted), and opens nothing.
    fn join(&self, stream: &mut TcpStream, head: &Head, gate: &Arc<Gate>) {
        let class = &self.class;
        let form = match webguard::form::read_own_form(stream, head) {
            Ok(f) => f,
            Err(e) => {
                gate.refused.count(e.kind());
                let allow = if matches!(e, webguard::form::FormError::Method { .. }) {
                    "Allow: POST\r\n"
                } else {
                    ""
                };
                respond(
                    stream,
                    e.status(),
                    "text/html; charset=utf-8",
                    allow,
                    join_page(class, Some(&e.to_string()), "").as_bytes(),
                );
                return webguard::serve::drain_body(stream, head, webguard::form::MAX_FORM_BYTES);
            }
        };
        let name = form.get("name").unwrap_or_default().to_string();
        match class.join(&name, form.get("code")) {
            Ok(s) => respond(
                stream,
                "303 See Other",
                "text/plain; charset=utf-8",
                &format!("Location: /play?s={}\r\n", s.token),
                b"joined\n",
            ),
            Err(e) => {
                gate.refused.count(match e {
                    JoinError::Code => "code",
                    _ => "join",
                });
                let status = match e {
                    JoinError::Code => "403 Forbidden",
                    JoinError::Full { .. } => "503 Service Unavailable",
                    JoinError::Taken { .. } => "409 Conflict",
                    _ => "400 Bad Request",
                };
                let shown: String = name.chars().take(32).collect();
                html(
                    stream,
                    status,
                    &join_page(class, Some(&e.to_string()), &shown),
                );
            }
        }
    }

    /// A student's page, link and recording, by their session's token (`?s=`).
    fn student_route(&self, mut stream: TcpStream, head: &Head, gate: &Arc<Gate>) {
        let Some(s) = head.query("s").and_then(|t| self.class.student(&t)) else {
            return respond_text(
                &mut stream,
                "404 Not Found",
                "no such session in this class: join again at /",
            );
        };
        match head.path() {
            "/play" => {
                serve_page_file(&mut stream, "/index.html");
            }
            "/ws" if head.is_upgrade() => {
                if accept_upgrade(&mut stream, head).is_ok() {
                    page_link(stream, &s.shared, gate);
                }
            }
            "/ws" => respond_text(
                &mut stream,
                "400 Bad Request",
                "a WebSocket upgrade is expected here",
            ),
            _ => {
                let file = s.shared.recording.lock().ok().and_then(|r| r.clone());
                serve_download(
                    &mut stream,
                    file,
                    "the recording is served once the session has ended",
                );
            }
        }
    }
}

impl ClassRoutes {
    /// The teacher's replay of a student's ended session (`?s=TOKEN&code=…`): the page, or
    /// its data. A session still running is not replayed yet (409).
    fn replay_route(&self, mut stream: TcpStream, head: &Head) {
        let Some(s) = head.query("s").and_then(|t| self.class.student(&t)) else {
            return respond_text(
                &mut stream,
                "404 Not Found",
                "no such session in this class",
            );
        };
        let (file, key) = if s.lesson.is_some() {
            // A lesson's student: one of their steps, once its world has closed.
            let Some(id) = head.query("step") else {
                return respond_text(
                    &mut stream,
                    "400 Bad Request",
                    &format!(
                        "{} is taking a lesson: name the step to replay (&step=ID)",
                        s.name
                    ),
                );
            };
            match lesson::step_recording(&s, &id) {
                Ok(p) => (p, format!("{}/{id}", s.token)),
                Err(e) => return respond_text(&mut stream, "409 Conflict", &e),
            }
        } else {
            (s.out.clone(), s.token.clone())
        };
        let ended = s.lesson.is_some() || s.status.lock().is_ok_and(|st| st.phase == Phase::Ended);
        if !ended {
            return respond_text(
                &mut stream,
                "409 Conflict",
                &format!(
                    "{}'s session is still running: it can be replayed once it has ended",
                    s.name
                ),
            );
        }
        if !replay::is_data_path(head.path()) {
            replay::serve_page(&mut stream, head.path(), "/replay");
            return;
        }
        let cached = self.replays.lock().ok().and_then(|m| m.get(&key).cloned());
        let book = match cached {
            Some(b) => b,
            None => match ReplayBook::from_file(&file) {
                Ok(b) => {
                    let b = Arc::new(b);
                    if let Ok(mut m) = self.replays.lock() {
                        m.insert(key, b.clone());
                    }
                    b
                }
                Err(e) => {
                    return respond_text(
                        &mut stream,
                        "500 Internal Server Error",
                        &format!("{}: {e}", file.display()),
                    );
                }
            },
        };
        replay::serve_data(&mut stream, head, &book);
    }
}

impl Routes for ClassRoutes {
    fn post_paths(&self) -> &'static [&'static str] {
        &["/join"]
    }

    fn route(&self, mut stream: TcpStream, head: Head, gate: &Arc<Gate>) {
        let class = &self.class;
        let path = head.path().to_string();
        match path.as_str() {
            "/" | "/index.html" => html(&mut stream, "200 OK", &join_page(class, None, "")),
            "/join" => self.join(&mut stream, &head, gate),
            "/play" | "/ws" | "/recording.mcap" => self.student_route(stream, &head, gate),
            "/class.css" => respond(
                &mut stream,
                "200 OK",
                "text/css; charset=utf-8",
                "",
                JOIN_CSS.as_bytes(),
            ),
            "/teacher" if self.teacher_ok(&head, gate) => html(&mut stream, "200 OK", TEACHER_HTML),
            "/teacher.js" => respond(
                &mut stream,
                "200 OK",
                "text/javascript; charset=utf-8",
                "",
                TEACHER_JS.as_bytes(),
            ),
            "/teacher/ws" if self.teacher_ok(&head, gate) => {
                if head.is_upgrade() && accept_upgrade(&mut stream, &head).is_ok() {
                    teacher::link(stream, class, gate);
                } else {
                    respond_text(
                        &mut stream,
                        "400 Bad Request",
                        "a WebSocket upgrade is expected here",
                    );
                }
            }
            "/recordings.zip" if self.teacher_ok(&head, gate) => {
                match teacher::zip_of_recordings(class) {
                    Ok(bytes) => respond(
                        &mut stream,
                        "200 OK",
                        "application/zip",
                        "Content-Disposition: attachment; filename=\"class-recordings.zip\"\r\n",
                        &bytes,
                    ),
                    Err(e) => respond_text(&mut stream, "500 Internal Server Error", &e),
                }
            }
            "/replay.js" => {
                replay::serve_page(&mut stream, "/replay.js", "/replay");
            }
            p if (p == "/replay" || replay::is_data_path(p)) && self.teacher_ok(&head, gate) => {
                self.replay_route(stream, &head)
            }
            p if p == "/replay" || replay::is_data_path(p) => respond_text(
                &mut stream,
                "403 Forbidden",
                "the teacher's code is wrong or missing: use the teacher address printed at start",
            ),
            "/teacher" | "/teacher/ws" | "/recordings.zip" => respond_text(
                &mut stream,
                "403 Forbidden",
                "the teacher's code is wrong or missing: use the teacher address printed at start",
            ),
            "/favicon.ico" => respond(&mut stream, "204 No Content", "image/x-icon", "", b""),
            p if p != "/index.html" && PAGE_FILES.iter().any(|f| f.path == p) => {
                serve_page_file(&mut stream, p);
            }
            _ => respond_text(&mut stream, "404 Not Found", "not found"),
        }
    }
}
