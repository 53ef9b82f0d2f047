//! The teacher's link: every student's status four times a second (`class`), and the
//! teacher's commands — a switch for the class or one student, end one session or all — each
//! answered (`done` or `error`). And the zip of every finished recording.

use super::{Class, Phase};
use crate::wslink::{self, Incoming, LinkConfig};
use std::net::TcpStream;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use tungstenite::Message;
use webguard::gate::Gate;

/// How often the teacher page is sent the class, ms.
pub const CLASS_EVERY_MS: u64 = 250;

/// A teacher's command.
#[derive(Debug, PartialEq, serde::Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TeacherMsg {
    /// Set switch `name` to `value` for `student` (`None`: every student playing or waiting).
    Switch {
        /// The switch's name.
        name: String,
        /// Its value.
        value: f64,
        /// One student's name, or everyone.
        #[serde(default)]
        student: Option<String>,
    },
    /// End one student's session.
    End {
        /// The student's name.
        student: String,
    },
    /// End every session.
    EndAll,
}

/// What the teacher page is sent.
#[derive(Debug, serde::Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum TeacherReply {
    /// A command done.
    Done {
        /// What was done, in words.
        message: String,
    },
    /// A command refused.
    Error {
        /// The field at fault.
        field: String,
        /// Why.
        message: String,
    },
}

/// The `class` message: the scene, its switches, the codes' use and every student's status.
pub(crate) fn class_json(class: &Class, gate: &Gate) -> String {
    let students: Vec<serde_json::Value> = class
        .students()
        .iter()
        .map(|s| {
            let st = s.status.lock().map(|st| st.clone()).ok();
            serde_json::json!({
                "name": s.name,
                "token": s.token,
                "pages": s.pages(),
                "recording": s.out.file_name().map(|n| n.to_string_lossy().to_string()),
                "status": st,
            })
        })
        .collect();
    let switches: Vec<serde_json::Value> = class
        .switches
        .iter()
        .map(|s| {
            serde_json::json!({
                "name": s.name, "min": s.min, "max": s.max, "boolean": s.boolean, "doc": s.doc
            })
        })
        .collect();
    serde_json::json!({
        "type": "class",
        "scene": class.scene_name,
        "rate_hz": class.rate_hz,
        "max_students": class.config.max_students,
        "join_code": class.join_code,
        "switches": switches,
        "students": students,
        "ended": class.ended.load(Ordering::Relaxed),
        "refused": gate.refused.snapshot(),
    })
    .to_string()
}

/// Carries out one teacher command; the answer in words.
pub(crate) fn command(class: &Class, text: &str) -> TeacherReply {
    let msg: TeacherMsg = match serde_json::from_str(text) {
        Ok(m) => m,
        Err(e) => {
            return TeacherReply::Error {
                field: "type".into(),
                message: format!(
                    "not a teacher command ({e}): allowed switch {{name, value, student?}}, end \
                     {{student}}, end_all"
                ),
            };
        }
    };
    let active = |name: Option<&str>| {
        class
            .students()
            .into_iter()
            .filter(|s| {
                s.status
                    .lock()
                    .map(|st| st.phase != Phase::Ended)
                    .unwrap_or(false)
            })
            .filter(|s| name.is_none_or(|n| s.name == n))
            .collect::<Vec<_>>()
    };
    match msg {
        TeacherMsg::Switch {
            name,
            value,
            student,
        } => {
            let spec = match haptic_types::switch::check(class.kind, class.switches, &name, value) {
                Ok(s) => s,
                Err(e) => {
                    let field = match e {
                        haptic_types::SwitchError::Unknown { .. } => "switch.name",
                        _ => "switch.value",
                    };
                    return TeacherReply::Error {
                        field: field.into(),
                        message: e.to_string(),
                    };
                }
            };
            let targets = active(student.as_deref());
            if targets.is_empty() {
                return TeacherReply::Error {
                    field: "switch.student".into(),
                    message: match student {
                        Some(n) => format!("no student `{n}` is playing or waiting"),
                        None => "no student is playing or waiting".into(),
                    },
                };
            }
            for s in &targets {
                if let Ok(mut q) = s.shared.switches.lock() {
                    q.push((0, spec.name.to_string(), value));
                }
            }
            TeacherReply::Done {
                message: format!(
                    "{} = {} for {}",
                    spec.name,
                    world_form::fmt_num(value),
                    match student {
                        Some(n) => n,
                        None => format!("{} students", targets.len()),
                    }
                ),
            }
        }
        TeacherMsg::End { student } => match active(Some(&student)).first() {
            Some(s) => {
                s.shared.end_requested.store(true, Ordering::Relaxed);
                TeacherReply::Done {
                    message: format!("ended {student}'s session"),
                }
            }
            None => TeacherReply::Error {
                field: "end.student".into(),
                message: format!("no student `{student}` is playing or waiting"),
            },
        },
        TeacherMsg::EndAll => {
            let all = active(None);
            for s in &all {
                s.shared.end_requested.store(true, Ordering::Relaxed);
            }
            TeacherReply::Done {
                message: format!("ended {} sessions", all.len()),
            }
        }
    }
}

/// The teacher page's WebSocket: the class every [`CLASS_EVERY_MS`], commands as they come
/// (bounded in size and rate by the gate's limits).
pub(crate) fn link(stream: TcpStream, class: &Class, gate: &Gate) {
    let mut peer = TeacherPeer {
        class,
        gate,
        replies: Vec::new(),
        last: None,
    };
    let link = LinkConfig {
        read_wait: Duration::from_millis(20),
        max_write_buffer_bytes: None,
    };
    wslink::run(stream, gate, link, &mut peer, None);
}

/// The teacher page's end of its link: commands in, their replies and the class's status
/// every [`CLASS_EVERY_MS`] out.
struct TeacherPeer<'a> {
    class: &'a Class,
    gate: &'a Gate,
    replies: Vec<Message>,
    last: Option<Instant>,
}

impl wslink::Peer for TeacherPeer<'_> {
    fn stopped(&self) -> bool {
        self.class.shutdown.load(Ordering::Relaxed)
    }

    fn receive(&mut self, msg: Incoming<'_>) {
        if let Incoming::Text(t) = msg {
            let r = command(self.class, t);
            if let Ok(t) = serde_json::to_string(&r) {
                self.replies.push(Message::text(t));
            }
        }
    }

    fn next_out(&mut self) -> Option<Message> {
        if !self.replies.is_empty() {
            return Some(self.replies.remove(0));
        }
        if self
            .last
            .is_none_or(|t| t.elapsed() >= Duration::from_millis(CLASS_EVERY_MS))
        {
            self.last = Some(Instant::now());
            return Some(Message::text(class_json(self.class, self.gate)));
        }
        None
    }
}

/// A zip of every finished recording (the sessions still running are not in it).
pub(crate) fn zip_of_recordings(class: &Class) -> Result<Vec<u8>, String> {
    let mut files = Vec::new();
    for s in class.students() {
        let ended = s
            .status
            .lock()
            .map(|st| st.phase == Phase::Ended)
            .unwrap_or(false);
        let Some(name) = s.out.file_name().map(|n| n.to_string_lossy().to_string()) else {
            continue;
        };
        if ended {
            let bytes = std::fs::read(&s.out)
                .map_err(|e| format!("cannot read {}: {e}", s.out.display()))?;
            files.push((name, bytes));
        }
    }
    super::zip::zip_stored(&files).map_err(|e| e.to_string())
}
