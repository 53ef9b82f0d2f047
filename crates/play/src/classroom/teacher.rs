//! The teacher's link: every student's status four times a second (`class`; in a lesson,
//! where each student is, their time on the step and their answers), and the teacher's
//! commands — a switch for the class or one student, end one session or all; in a lesson, open
//! the next locked step, open a step or hold the class before one — each answered (`done` or
//! `error`). And the zip of every finished recording (with a lesson, the class report too).

use super::{Class, Phase, lesson};
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
    EndAll {},
    /// Open the lesson's first step locked for the class, for everyone.
    OpenNext {},
    /// Open step `step` (its id) for everyone: students waiting at it go on.
    OpenStep {
        /// The step's id.
        step: String,
    },
    /// Hold the class before step `step` (its id): it is locked for everyone who has not
    /// entered it.
    HoldStep {
        /// The step's id.
        step: String,
    },
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
                "lesson": s.lesson.as_ref().map(|m| lesson::locked(m).view()),
                "steps_run": lesson::steps_run(s),
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
        "lesson": class.lesson.as_ref().map(|cl| {
            let locks = cl.locks();
            serde_json::json!({
                "title": cl.lesson.title,
                "steps": cl.lesson.steps.iter().zip(locks).map(|(s, locked)| serde_json::json!({
                    "id": s.id, "title": s.title, "locked": locked,
                })).collect::<Vec<_>>(),
            })
        }),
        "ended": class.ended.load(Ordering::Relaxed),
        "refused": gate.refused.snapshot(),
    })
    .to_string()
}

/// The students playing or waiting (named `name`, or all).
fn active(class: &Class, name: Option<&str>) -> Vec<std::sync::Arc<super::Student>> {
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
        .collect()
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
                     {{student}}, end_all, open_next, open_step {{step}}, hold_step {{step}}"
                ),
            };
        }
    };
    let active = |name: Option<&str>| active(class, name);
    match msg {
        TeacherMsg::OpenNext {} | TeacherMsg::OpenStep { .. } | TeacherMsg::HoldStep { .. } => {
            lesson_command(class, msg)
        }
        TeacherMsg::Switch { .. } if class.lesson.is_some() => TeacherReply::Error {
            field: "switch.name".into(),
            message: "in a lesson each step sets its own switches: open or hold steps instead"
                .into(),
        },
        TeacherMsg::Switch {
            name,
            value,
            student,
        } => switch_command(class, &name, value, student),
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
        TeacherMsg::EndAll {} => {
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

/// A switch for the class (`student`: `None`) or one student.
fn switch_command(class: &Class, name: &str, value: f64, student: Option<String>) -> TeacherReply {
    let spec = match haptic_types::switch::check(class.kind, class.switches, name, value) {
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
    let targets = active(class, student.as_deref());
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

/// A lesson's command: open the next locked step, open one, or hold the class before one.
fn lesson_command(class: &Class, msg: TeacherMsg) -> TeacherReply {
    let Some(cl) = &class.lesson else {
        return TeacherReply::Error {
            field: "type".into(),
            message: "the class has no lesson (start it with `classroom --lesson`)".into(),
        };
    };
    let (step, open) = match msg {
        TeacherMsg::OpenNext {} => match cl.next_locked() {
            Some(s) => (Ok(s), true),
            None => {
                return TeacherReply::Error {
                    field: "open_next".into(),
                    message: "every step of the lesson is open".into(),
                };
            }
        },
        TeacherMsg::OpenStep { step } => (cl.step_index(&step), true),
        TeacherMsg::HoldStep { step } => (cl.step_index(&step), false),
        _ => {
            return TeacherReply::Error {
                field: "type".into(),
                message: "not a lesson command".into(),
            };
        }
    };
    let s = match step {
        Ok(s) => s,
        Err(message) => {
            return TeacherReply::Error {
                field: "step".into(),
                message,
            };
        }
    };
    let n = cl.set_open(class, s, open);
    let id = &cl.lesson.steps[s].id;
    TeacherReply::Done {
        message: if open {
            format!(
                "step {} ({id}) is open for everyone: {n} students told",
                s + 1
            )
        } else {
            format!(
                "the class is held before step {} ({id}): {n} students told",
                s + 1
            )
        },
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

/// A zip of every finished recording (the sessions still running are not in it); with a
/// lesson, every step's recording whose world has closed (`NAME-START/STEP-ID.mcap`) and the
/// class report as it stands (written to the recordings' folder first).
pub(crate) fn zip_of_recordings(class: &Class) -> Result<Vec<u8>, String> {
    let mut files = Vec::new();
    if let Some(report) = lesson::class_report(class) {
        let dir = &class.config.out_dir;
        for p in report.write(dir).map_err(|e| e.to_string())? {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().to_string())
                .unwrap_or_default();
            let bytes =
                std::fs::read(&p).map_err(|e| format!("cannot read {}: {e}", p.display()))?;
            files.push((name, bytes));
        }
    }
    for s in class.students() {
        if s.lesson.is_some() {
            let folder = s.out.file_name().map(|n| n.to_string_lossy().to_string());
            for id in lesson::steps_run(&s) {
                let p = lesson::step_recording(&s, &id)?;
                let bytes =
                    std::fs::read(&p).map_err(|e| format!("cannot read {}: {e}", p.display()))?;
                files.push((
                    format!("{}/{id}.mcap", folder.as_deref().unwrap_or("")),
                    bytes,
                ));
            }
            continue;
        }
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

#[cfg(test)]
mod tests {
    use super::TeacherMsg;

    /// docs/play.md's table of the teacher's commands: each row parses as a command with the
    /// fields it names, and the table lists every command there is.
    #[test]
    fn the_documented_commands_are_the_teacher_link_s() {
        let doc = include_str!("../../../../docs/play.md");
        let at = doc.find("| command | fields | does |").expect("the table");
        let rows: Vec<&str> = doc[at..]
            .lines()
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .collect();
        let mut kinds = Vec::new();
        for row in &rows {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let kind = cells[1].trim_matches('`');
            let mut msg = serde_json::json!({ "type": kind });
            for f in ["name", "student", "step"] {
                if cells[2].contains(&format!("`{f}`")) {
                    msg[f] = "x".into();
                }
            }
            if cells[2].contains("`value`") {
                msg["value"] = 0.5.into();
            }
            let parsed: Result<TeacherMsg, _> = serde_json::from_value(msg.clone());
            assert!(parsed.is_ok(), "{msg}: {parsed:?}");
            kinds.push(kind.to_string());
        }
        assert_eq!(
            kinds,
            [
                "switch",
                "end",
                "end_all",
                "open_next",
                "open_step",
                "hold_step"
            ]
        );
        // Unknown commands and fields are refused.
        assert!(serde_json::from_str::<TeacherMsg>(r#"{"type":"skip"}"#).is_err());
        for extra in [
            r#"{"type":"open_next","step":"a"}"#,
            r#"{"type":"end_all","student":"a"}"#,
        ] {
            assert!(
                serde_json::from_str::<TeacherMsg>(extra).is_err(),
                "{extra}"
            );
        }
    }
}
