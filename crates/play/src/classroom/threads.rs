//! How a class starts: its plan checked before anyone joins, and its threads — the tick
//! workers, the finisher, the lesson's coach, the bridged device's student — with the
//! listener's limits.

use super::live::{self, Live};
use super::{
    Class, ClassConfig, MAX_CLASS, WorkerHandle, WorkerLink, device, lesson, lobby, names, sched,
};
use crate::PlayError;
use haptic_loop::session::{SessionError, ticks_for};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use webguard::gate::Limits;

/// The lesson's coach on a thread of its own, when the class has a lesson.
pub(super) fn start_coach(
    class: &Arc<Class>,
    stop: &Arc<AtomicBool>,
) -> std::io::Result<Option<std::thread::JoinHandle<()>>> {
    if class.lesson.is_none() {
        return Ok(None);
    }
    let (c, s) = (class.clone(), stop.clone());
    std::thread::Builder::new()
        .name("class-coach".into())
        .spawn(move || lesson::coach(&c, &s))
        .map(Some)
}

/// The lobby (`lobby.rs`) on a thread of its own: sessions wait there for their page's Start.
pub(super) fn start_lobby(
    class: &Arc<Class>,
    inbox: std::sync::mpsc::Receiver<Box<Live>>,
    stop: &Arc<AtomicBool>,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    let (c, s) = (class.clone(), stop.clone());
    std::thread::Builder::new()
        .name("class-lobby".into())
        .spawn(move || lobby::lobby(&c, inbox, &s))
}

/// What a class plays, checked before anyone joins.
pub(super) struct Plan {
    pub(super) scene_name: String,
    pub(super) kind: &'static str,
    pub(super) switches: &'static [haptic_types::SwitchSpec],
    pub(super) rate_hz: u32,
    pub(super) ticks: Option<u64>,
}

impl Plan {
    /// Checks the class's size, its scene (whole) and session length, and makes the
    /// recordings' folder.
    pub(super) fn check(config: &ClassConfig) -> Result<Plan, PlayError> {
        if !(1..=MAX_CLASS).contains(&config.max_students) {
            return Err(PlayError::Session(SessionError::Option(
                haptic_types::value::ValueError::out_of_range(
                    "--max-students",
                    config.max_students as f64,
                    "1 ≤ students ≤ 200",
                )
                .to_string(),
            )));
        }
        let file = config.scene.parse()?;
        let loaded = haptic_loop::scene::load_scene(&config.scene.text, Some(file.device.model))
            .map_err(|e| config.scene.locate(e))?;
        let (switches, kind) = (loaded.scene.switches(), loaded.scene.kind());
        let rate_hz = match &config.lesson {
            Some(l) => lesson_rate(l)?,
            None => file.loop_.rate_hz,
        };
        if config.lesson.is_some() && config.seconds.is_some() {
            return Err(PlayError::Session(SessionError::Option(
                "--seconds does not apply to a lesson: each step ends when its condition is met, \
                 and the lesson when the student finishes it or is ended"
                    .into(),
            )));
        }
        let ticks = config.seconds.map(|s| ticks_for(s, rate_hz)).transpose()?;
        std::fs::create_dir_all(&config.out_dir).map_err(|e| {
            PlayError::Session(SessionError::Option(format!(
                "cannot create the recordings' folder {}: {e}",
                config.out_dir.display()
            )))
        })?;
        Ok(Plan {
            scene_name: match &config.lesson {
                Some(l) => l.title.clone(),
                None => file.scene.name.clone(),
            },
            kind,
            switches,
            rate_hz,
            ticks,
        })
    }
}

/// The one tick rate of a lesson's steps (the workers keep one schedule), Hz; steps at
/// another rate than the first are refused, named.
fn lesson_rate(lesson: &teaching::Lesson) -> Result<u32, PlayError> {
    let Some(first) = lesson.steps.first() else {
        return Err(PlayError::Session(SessionError::Option(
            "the lesson has no step".into(),
        )));
    };
    match lesson.steps.iter().find(|s| s.rate_hz != first.rate_hz) {
        Some(s) => Err(PlayError::Session(SessionError::Option(format!(
            "lesson: step `{}` ticks at {} Hz and step `{}` at {} Hz: a class ticks every \
             session on one schedule, so every step must tick at the same rate",
            first.id, first.rate_hz, s.id, s.rate_hz
        )))),
        None => Ok(first.rate_hz),
    }
}

/// The tick workers (one per core, at most four, or as configured), each with its inbox and
/// its count of sessions; an ended session goes to `finished`.
pub(super) fn start_workers(
    config: &ClassConfig,
    plan: &Plan,
    finished: &Sender<Box<Live>>,
    stop: &Arc<AtomicBool>,
) -> std::io::Result<(Vec<WorkerLink>, Vec<WorkerHandle>)> {
    let n = config
        .workers
        .unwrap_or_else(|| {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        })
        .clamp(1, 4);
    let period_ns = 1_000_000_000 / u64::from(plan.rate_hz.max(1));
    let mut workers = Vec::new();
    let mut handles = Vec::new();
    for i in 0..n {
        let (tx, rx) = std::sync::mpsc::channel();
        let load = Arc::new(AtomicUsize::new(0));
        let (l, f, s) = (load.clone(), finished.clone(), stop.clone());
        let rt = config
            .rt
            .map(|r| haptic_engine::realtime::RtRequest { pin: false, ..r });
        handles.push(
            std::thread::Builder::new()
                .name(format!("class-tick-{i}"))
                .spawn(move || sched::worker(rx, f, period_ns, l, s, rt))?,
        );
        workers.push((Mutex::new(tx), load));
    }
    Ok((workers, handles))
}

/// The finisher: closes each ended session off the tick threads.
pub(super) fn start_finisher(
    class: Arc<Class>,
    ended: std::sync::mpsc::Receiver<Box<Live>>,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    std::thread::Builder::new()
        .name("class-finish".into())
        .spawn(move || {
            while let Ok(l) = ended.recv() {
                let s = match l.finish() {
                    live::Finished::Session(s) => {
                        class.ended.fetch_add(1, Ordering::Relaxed);
                        *s
                    }
                    // A lesson's step: its student's lesson counts once, when it ends.
                    live::Finished::Step(student, world) => {
                        lesson::close_step(&class, &student, *world)
                    }
                };
                if let Ok(mut f) = class.finished.lock() {
                    f.push(s);
                }
            }
        })
}

/// A connection per page file, a link per page: four per student from one address on
/// loopback (every student of a test or a one-machine class shares 127.0.0.1).
pub(super) fn class_limits(config: &ClassConfig) -> Limits {
    Limits {
        max_connections: 8 * config.max_students + 16,
        max_per_address: if config.listen.is_loopback() {
            8 * config.max_students + 16
        } else {
            16
        },
        ..Limits::default()
    }
}

/// The bridged device's student on a thread of its own, when the class has one.
pub(super) fn start_device(
    config: &ClassConfig,
    class: &Arc<Class>,
    stop: &Arc<AtomicBool>,
) -> Result<Option<std::thread::JoinHandle<Result<(), String>>>, PlayError> {
    let Some(b) = config.device.clone() else {
        return Ok(None);
    };
    let name = names::check_name(&config.device_name)
        .map_err(|e| PlayError::Session(SessionError::Option(format!("--device-name: {e}"))))?;
    let (c, s) = (class.clone(), stop.clone());
    std::thread::Builder::new()
        .name("class-device".into())
        .spawn(move || device::run_device_student(&c, b, &name, &s))
        .map(Some)
        .map_err(|e| PlayError::Serve {
            port: config.port,
            message: e.to_string(),
        })
}
