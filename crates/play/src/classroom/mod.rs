//! # The classroom: one server for a whole class
//!
//! `nanohaptics classroom [SCENE]` serves one address for a class. Each student opens it,
//! enters a name and gets their own world, their own page as the hand, their own sound and
//! their own recording (`DIR/NAME-START.mcap`), which replays bit for bit like any `play`
//! session. A teacher page (`/teacher`, behind a code printed at start) shows every student's
//! score, blueprint, time, force and connection, sets the class's switches for everyone or one
//! student, ends every session and downloads every recording as one zip.
//!
//! - **Pacing** ([`sched`]): a few worker threads (one per core, at most four) tick every
//!   session at the scene's rate against one schedule, not a thread per student.
//! - **Safety**: the same gate as `play` ([`webguard::gate`], [`crate::http`]): `Host` and
//!   `Origin` checked on every request and upgrade, limits on students, connections per
//!   address, message size and rate, names of bounded length and characters that never become
//!   a path ([`names`]), every refusal answered and counted.
//! - **Where it listens**: loopback by default (a student needs only a name); on a class
//!   network (`--listen 0.0.0.0` or an interface address) students also need the join code.
//!
//! - **A real device** ([`ClassConfig::device`]): a device bridged over UDP joins as a student,
//!   its session paced by the device on its own thread.
//! - **A lesson** ([`ClassConfig::lesson`], `classroom --lesson`; [`lesson`]): each student
//!   takes it on their page, each step's world ticked by the same workers. The teacher page
//!   follows where each student is, their time on the step and their answers as they come.
//!   The teacher opens the next step for everyone or holds the class before one. The class
//!   report ([`teaching::class_report`]) is in the recordings' zip, and it is written beside
//!   the recordings at the end.
//!
//! What it is not: no accounts, no TLS, no persistence across restarts (the recordings stay in
//! the folder).

mod device;
pub mod lesson;
mod live;
mod lobby;
pub mod names;
mod routes;
mod sched;
mod teacher;
mod threads;
pub mod zip;

use crate::PlayError;
use crate::input::PageDevice;
use crate::server::{Listener, Shared};
use crate::session::{Hand, PageSession, SessionSpec, SessionSummary};
use haptic_loop::session::{SceneSource, now_unix_ns};
use live::Live;
pub use live::Phase;
pub use sched::CycleStats;
use std::hash::{BuildHasher, Hasher};
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use threads::{
    Plan, class_limits, start_coach, start_device, start_finisher, start_lobby, start_workers,
};
use webguard::gate::RefusedCounts;

/// Ticks between two updates of what the teacher page shows of a student (50 ms at 1 kHz).
pub const STATUS_EVERY_TICKS: u64 = 50;
/// Most students a class may be started with.
pub const MAX_CLASS: usize = 200;

/// A class to serve.
#[derive(Clone, Debug)]
pub struct ClassConfig {
    /// The scene every student plays.
    pub scene: SceneSource,
    /// The address listened on (loopback by default; `0.0.0.0` or an interface address for a
    /// class network).
    pub listen: IpAddr,
    /// The port (0: any free port).
    pub port: u16,
    /// Students playing at once (1 to 200).
    pub max_students: usize,
    /// The folder of the recordings (created if missing).
    pub out_dir: PathBuf,
    /// Each student's session length, s (0 < s ≤ 3600; `None`: until the student or the
    /// teacher ends it).
    pub seconds: Option<f64>,
    /// The teacher's code (`None`: drawn at random, printed at start).
    pub teacher_code: Option<String>,
    /// The students' join code on a class network (`None`: drawn at random; never asked on
    /// loopback).
    pub join_code: Option<String>,
    /// Worker threads ticking the sessions (`None`: one per core, at most four).
    pub workers: Option<usize>,
    /// A real device over the UDP bridge that joins as a student (its session paced by the
    /// device, on its own thread), named [`ClassConfig::device_name`].
    pub device: Option<haptic_devices::bridge::BridgeConfig>,
    /// The name the bridged device plays under.
    pub device_name: String,
    /// A lesson every student takes (`None`: every student plays [`ClassConfig::scene`]).
    /// Each step runs its own scene, and their rates must agree (one schedule for the
    /// workers). A student's steps are recorded to `out_dir/NAME-START/STEP-ID.mcap`.
    pub lesson: Option<teaching::Lesson>,
    /// The tick workers' real-time scheduling (default `SCHED_FIFO` 50 and memory locked; the
    /// workers are not pinned, so each core can take one); `None`: ask for nothing (`--no-rt`).
    pub rt: Option<haptic_engine::realtime::RtRequest>,
}

impl ClassConfig {
    /// A class of up to 40 on loopback port 8080, recordings in `out_dir`.
    pub fn new(scene: SceneSource, out_dir: PathBuf) -> Self {
        ClassConfig {
            scene,
            listen: IpAddr::from([127, 0, 0, 1]),
            port: crate::DEFAULT_PORT,
            max_students: 40,
            out_dir,
            seconds: None,
            teacher_code: None,
            join_code: None,
            workers: None,
            device: None,
            device_name: "device".into(),
            lesson: None,
            rt: Some(haptic_engine::realtime::RtRequest::default()),
        }
    }
}

/// The addresses of a class, as printed at start.
#[derive(Clone, Debug, PartialEq)]
pub struct ClassAddresses {
    /// Where students join.
    pub student_url: String,
    /// The teacher page, with its code.
    pub teacher_url: String,
    /// The teacher's code.
    pub teacher_code: String,
    /// The students' join code (`None` on loopback).
    pub join_code: Option<String>,
}

/// What the teacher page shows of a student now.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Status {
    /// Waiting, playing or ended.
    pub phase: Phase,
    /// Ticks run.
    pub ticks: u64,
    /// Session time, s.
    pub time_s: f64,
    /// Missed deadlines.
    pub missed: u64,
    /// Force sent to the hand now, N.
    pub force_n: f64,
    /// The scene's state (name, value): score, slots filled, …
    pub state: Vec<(String, f64)>,
    /// The switches' values now (name, value).
    pub switches: Vec<(String, f64)>,
    /// The state's values as last read (reused, so a report allocates nothing).
    #[serde(skip)]
    values: Vec<f64>,
    /// The kind of scene the names are of (a lesson's steps change it).
    #[serde(skip)]
    kind: &'static str,
}

/// A student of the class.
pub struct Student {
    /// Their name as they typed it (checked).
    pub name: String,
    /// Their session's token (the page's `?s=`).
    pub token: String,
    /// Their recording (a lesson's: the folder of its steps' recordings).
    pub out: PathBuf,
    /// Their session's link to their pages.
    pub shared: Arc<Shared>,
    /// What the teacher sees.
    pub status: Mutex<Status>,
    /// Their way through the class's lesson, if it has one.
    pub(crate) lesson: Option<Mutex<lesson::StudentLesson>>,
}

impl Status {
    /// A student who joined and has not started.
    fn waiting() -> Self {
        Status {
            phase: Phase::Waiting,
            ticks: 0,
            time_s: 0.0,
            missed: 0,
            force_n: 0.0,
            state: Vec::new(),
            switches: Vec::new(),
            values: Vec::new(),
            kind: "",
        }
    }
}

impl Student {
    /// Updates what the teacher sees: where the session is (`p`) and `lp`'s state, force and
    /// switches after its last tick. On the tick thread (every [`STATUS_EVERY_TICKS`] ticks) it
    /// never waits: when the teacher page is reading the status this report is skipped (the next
    /// comes 50 ticks later); the last report, at the finish, waits. It allocates only when the
    /// scene changes (a lesson's next step), for the state's and switches' names.
    fn report(&self, p: &crate::session::Progress, lp: &haptic_engine::HapticLoop) {
        let mut st = if p.last {
            match self.status.lock() {
                Ok(st) => st,
                Err(_) => return,
            }
        } else {
            match self.status.try_lock() {
                Ok(st) => st,
                Err(_) => return,
            }
        };
        let (ticks, missed) = (p.ticks, p.missed);
        let scene = lp.scene();
        if st.kind != scene.kind() {
            st.kind = scene.kind();
            st.state.clear();
            st.switches = scene.switch_values();
        }
        let f = lp.last_result().device_force_n;
        st.ticks = ticks;
        st.time_s = ticks as f64 / f64::from(lp.config().rate_hz);
        st.missed = missed;
        st.force_n = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
        let mut values = std::mem::take(&mut st.values);
        values.clear();
        scene.state(&mut values);
        if st.state.len() != values.len() {
            st.state = scene.state_fields().into_iter().map(|n| (n, 0.0)).collect();
        }
        for ((_, v), x) in st.state.iter_mut().zip(&values) {
            *v = *x;
        }
        st.values = values;
        for (name, v) in st.switches.iter_mut() {
            if let Some(x) = scene.switch_value(name) {
                *v = x;
            }
        }
    }

    fn set_phase(&self, p: Phase) {
        if let Ok(mut s) = self.status.lock() {
            s.phase = p;
        }
    }

    /// Pages connected now.
    pub fn pages(&self) -> usize {
        self.shared.pages.lock().map(|p| p.len()).unwrap_or(0)
    }
}

/// What a student's session produced.
#[derive(Debug)]
pub struct StudentSummary {
    /// The student.
    pub name: String,
    /// The lesson's step the session was the world of (`None`: no lesson).
    pub step: Option<String>,
    /// Their session.
    pub session: SessionSummary,
}

impl StudentSummary {
    /// One line for a person.
    pub fn line(&self) -> String {
        let s = &self.session;
        format!(
            "{}{}: {}, {} ticks, {} missed deadlines, score {}, recording {}{}",
            self.name,
            self.step
                .as_deref()
                .map(|id| format!(", step {id}"))
                .unwrap_or_default(),
            s.end,
            s.stats.ticks,
            s.stats.missed,
            s.state("score").unwrap_or(0.0),
            s.recording.display(),
            s.error
                .as_deref()
                .map(|e| format!(" (error: {e})"))
                .unwrap_or_default()
        )
    }
}

/// What a class produced.
#[derive(Debug)]
pub struct ClassSummary {
    /// Where it was served.
    pub addresses: ClassAddresses,
    /// Every student's session, in the order they ended.
    pub students: Vec<StudentSummary>,
    /// What the server refused, by reason.
    pub refused: RefusedCounts,
    /// Worker threads that ticked the sessions.
    pub workers: usize,
    /// The real-time scheduling the workers got (the first worker's; they all ask alike).
    pub realtime: haptic_engine::realtime::RtStatus,
    /// Each worker's cycles: how late they began, their work, how many ran late.
    pub schedule: Vec<sched::CycleStats>,
    /// The files of the class report written at the end, with a lesson (none without).
    pub report: Vec<PathBuf>,
}

/// Why a student could not join.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum JoinError {
    /// The name.
    #[error(transparent)]
    Name(#[from] names::NameError),
    /// A wrong join code.
    #[error("the join code is wrong: ask your teacher for the class's code")]
    Code,
    /// The class is full.
    #[error("the class is full ({max} students playing): wait for a place or ask your teacher")]
    Full {
        /// The limit.
        max: usize,
    },
    /// A student of that name is playing.
    #[error("`{name}` is already playing in this class: choose another name")]
    Taken {
        /// The name.
        name: String,
    },
    /// The session could not be set up.
    #[error("cannot start your session: {0}")]
    Setup(String),
}

/// A random code of `n` characters from `alphabet` (the process's OS-seeded hasher keys).
fn random_code(n: usize, alphabet: &[u8]) -> String {
    let mut out = String::new();
    while out.len() < n {
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(now_unix_ns());
        let mut x = h.finish();
        for _ in 0..8 {
            if out.len() == n {
                break;
            }
            out.push(alphabet[(x % alphabet.len() as u64) as usize] as char);
            x /= alphabet.len() as u64;
        }
    }
    out
}

/// A worker's inbox and its count of sessions.
type WorkerLink = (Mutex<Sender<Box<Live>>>, Arc<AtomicUsize>);
/// A worker's thread; it returns the real-time scheduling it got.
type WorkerHandle = std::thread::JoinHandle<sched::WorkerReport>;

/// The class's state shared by the routes, the workers and the finisher.
pub(crate) struct Class {
    config: ClassConfig,
    scene_name: String,
    kind: &'static str,
    switches: &'static [haptic_types::SwitchSpec],
    rate_hz: u32,
    ticks: Option<u64>,
    teacher_code: String,
    join_code: Option<String>,
    students: Mutex<Vec<Arc<Student>>>,
    lesson: Option<lesson::ClassLesson>,
    workers: Vec<WorkerLink>,
    lobby: Mutex<Sender<Box<Live>>>,
    pub(crate) finished: Mutex<Vec<StudentSummary>>,
    ended: AtomicUsize,
    shutdown: Arc<AtomicBool>,
}

impl Class {
    /// Joins `name` (with `code` on a class network): their session is set up and handed to
    /// the least busy worker; it starts at their page's Start.
    pub(crate) fn join(&self, name: &str, code: Option<&str>) -> Result<Arc<Student>, JoinError> {
        if let Some(c) = &self.join_code
            && code != Some(c.as_str())
        {
            return Err(JoinError::Code);
        }
        let name = names::check_name(name)?;
        let mut students = self
            .students
            .lock()
            .map_err(|_| JoinError::Setup("the class is shutting down".into()))?;
        let playing: Vec<&Arc<Student>> = students
            .iter()
            .filter(|s| {
                s.status
                    .lock()
                    .map(|st| st.phase != Phase::Ended)
                    .unwrap_or(false)
            })
            .collect();
        if playing.iter().any(|s| s.name == name) {
            return Err(JoinError::Taken { name });
        }
        if playing.len() >= self.config.max_students {
            return Err(JoinError::Full {
                max: self.config.max_students,
            });
        }
        let taken: Vec<PathBuf> = students.iter().map(|s| s.out.clone()).collect();
        let start_ns = now_unix_ns();
        let out = names::recording_path(
            &self.config.out_dir,
            &name,
            start_ns / 1_000_000_000,
            &taken,
        );
        let shared = Arc::new(Shared::default());
        let token = random_code(24, b"0123456789abcdefghijklmnopqrstuvwxyz");
        if let Some(cl) = &self.lesson {
            // The lesson's coach opens each step's world when the student reaches it.
            let dir = out.with_extension("");
            let lesson = cl.student(shared.clone(), dir.clone(), &name, &token);
            let student = Arc::new(Student {
                name,
                token,
                out: dir,
                shared,
                status: Mutex::new(Status::waiting()),
                lesson: Some(Mutex::new(lesson)),
            });
            students.push(student.clone());
            return Ok(student);
        }
        let file = self
            .config
            .scene
            .parse()
            .map_err(|e| JoinError::Setup(e.to_string()))?;
        let hand = Hand::Page(PageDevice::new(
            file.device.model.specs().clone(),
            shared.input.clone(),
        ));
        let spec = SessionSpec {
            scene: &self.config.scene,
            scene_name: &self.scene_name,
            out: out.clone(),
            recording_url: format!("/recording.mcap?s={token}"),
            start_time_ns: start_ns,
            operator: format!("person (browser page, classroom student `{name}`)"),
            link: "page".into(),
            seconds: self.config.seconds,
            ticks: self.ticks,
        };
        let session = PageSession::open(&spec, hand, shared.clone())
            .map_err(|e| JoinError::Setup(e.to_string()))?;
        let student = Arc::new(Student {
            name,
            token,
            out,
            shared,
            status: Mutex::new(Status::waiting()),
            lesson: None,
        });
        self.dispatch(Box::new(Live::new(student.clone(), session)))?;
        students.push(student.clone());
        Ok(student)
    }

    /// Hands `live` to the lobby, which begins it at its page's Start and then hands it to a
    /// worker.
    pub(crate) fn dispatch(&self, live: Box<Live>) -> Result<(), JoinError> {
        self.lobby
            .lock()
            .map_err(|_| JoinError::Setup("the class is shutting down".into()))?
            .send(live)
            .map_err(|_| JoinError::Setup("the class is shutting down".into()))
    }

    /// Hands `live` to the least busy worker.
    pub(crate) fn to_worker(&self, live: Box<Live>) -> Result<(), JoinError> {
        let (tx, load) = self
            .workers
            .iter()
            .min_by_key(|(_, l)| l.load(Ordering::Relaxed))
            .ok_or_else(|| JoinError::Setup("the class has no worker".into()))?;
        load.fetch_add(1, Ordering::Relaxed);
        tx.lock()
            .map_err(|_| JoinError::Setup("the class is shutting down".into()))?
            .send(live)
            .map_err(|_| JoinError::Setup("the class is shutting down".into()))
    }

    /// The class of `config` playing `plan`, ticked by `workers`.
    fn new(
        config: &ClassConfig,
        plan: Plan,
        workers: Vec<WorkerLink>,
        lobby: Sender<Box<Live>>,
        shutdown: Arc<AtomicBool>,
    ) -> Class {
        let loopback = config.listen.is_loopback();
        Class {
            config: config.clone(),
            scene_name: plan.scene_name,
            kind: plan.kind,
            switches: plan.switches,
            rate_hz: plan.rate_hz,
            ticks: plan.ticks,
            teacher_code: config
                .teacher_code
                .clone()
                .unwrap_or_else(|| random_code(8, b"ABCDEFGHJKLMNPQRSTUVWXYZ23456789")),
            join_code: (!loopback).then(|| {
                config
                    .join_code
                    .clone()
                    .unwrap_or_else(|| random_code(6, b"0123456789"))
            }),
            students: Mutex::new(Vec::new()),
            lesson: config.lesson.clone().map(lesson::ClassLesson::new),
            workers,
            lobby: Mutex::new(lobby),
            finished: Mutex::new(Vec::new()),
            ended: AtomicUsize::new(0),
            shutdown,
        }
    }

    /// The addresses printed at start, for a listener bound to `addr`.
    fn addresses(&self, addr: SocketAddr) -> ClassAddresses {
        let shown = if self.config.listen.is_unspecified() {
            SocketAddr::new(IpAddr::from([127, 0, 0, 1]), addr.port())
        } else {
            addr
        };
        ClassAddresses {
            student_url: format!("http://{shown}/"),
            teacher_url: format!("http://{shown}/teacher?code={}", self.teacher_code),
            teacher_code: self.teacher_code.clone(),
            join_code: self.join_code.clone(),
        }
    }

    /// The student whose session token is `token`.
    pub(crate) fn student(&self, token: &str) -> Option<Arc<Student>> {
        self.students
            .lock()
            .ok()?
            .iter()
            .find(|s| s.token == token)
            .cloned()
    }

    /// Every student so far.
    pub(crate) fn students(&self) -> Vec<Arc<Student>> {
        self.students.lock().map(|s| s.clone()).unwrap_or_default()
    }
}

/// Waits for the stopped workers: the real time the first got (they all ask alike) and every
/// worker's cycles.
fn join_workers(
    handles: Vec<WorkerHandle>,
) -> (haptic_engine::realtime::RtStatus, Vec<sched::CycleStats>) {
    let mut realtime = haptic_engine::realtime::RtStatus::default();
    let mut schedule = Vec::new();
    for (i, h) in handles.into_iter().enumerate() {
        if let Ok(r) = h.join() {
            if i == 0 {
                realtime = r.realtime;
            }
            schedule.push(r.cycles);
        }
    }
    (realtime, schedule)
}

/// Runs a class: serves the join page, the students' pages and the teacher page (their
/// addresses are given to `on_ready` as soon as the port is bound), ticks every student's
/// session, and on `stop` ends every session cleanly (each recording complete) and returns
/// every student's summary.
pub fn run(
    config: &ClassConfig,
    stop: &AtomicBool,
    on_ready: &mut dyn FnMut(&ClassAddresses),
) -> Result<ClassSummary, PlayError> {
    let plan = Plan::check(config)?;
    let serve_err = |e: std::io::Error| PlayError::Serve {
        port: config.port,
        message: e.to_string(),
    };
    let worker_stop = Arc::new(AtomicBool::new(false));
    let (fin_tx, fin_rx) = std::sync::mpsc::channel::<Box<Live>>();
    let (workers, handles) =
        start_workers(config, &plan, &fin_tx, &worker_stop).map_err(serve_err)?;
    drop(fin_tx);
    let shutdown = Arc::new(AtomicBool::new(false));
    let (lobby_tx, lobby_rx) = std::sync::mpsc::channel::<Box<Live>>();
    let class = Arc::new(Class::new(
        config,
        plan,
        workers,
        lobby_tx,
        shutdown.clone(),
    ));
    let lobby_stop = Arc::new(AtomicBool::new(false));
    let lobby = start_lobby(&class, lobby_rx, &lobby_stop).map_err(serve_err)?;
    let finisher = start_finisher(class.clone(), fin_rx).map_err(serve_err)?;
    let mut listener = Listener::start(
        SocketAddr::new(config.listen, config.port),
        class_limits(config),
        Arc::new(routes::ClassRoutes {
            class: class.clone(),
            replays: Default::default(),
        }),
        shutdown,
    )
    .map_err(serve_err)?;
    let addresses = class.addresses(listener.addr());
    let device = start_device(config, &class, &worker_stop)?;
    let coach_stop = Arc::new(AtomicBool::new(false));
    let coach = start_coach(&class, &coach_stop).map_err(serve_err)?;
    on_ready(&addresses);
    while !stop.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(20));
    }
    // No step's world opens once the class stops.
    coach_stop.store(true, Ordering::Relaxed);
    if let Some(c) = coach {
        let _ = c.join();
    }
    // The sessions still waiting for their Start go to the workers to end.
    lobby_stop.store(true, Ordering::Relaxed);
    let _ = lobby.join();
    worker_stop.store(true, Ordering::Relaxed);
    let (realtime, schedule) = join_workers(handles);
    if let Some(d) = device {
        // A device that never said hello is not waited for (its own wait may be long): its
        // session never began and has nothing to write.
        let waiting = class
            .students()
            .iter()
            .find(|s| s.name == config.device_name.trim())
            .is_some_and(|s| s.status.lock().is_ok_and(|st| st.phase == Phase::Waiting));
        if !waiting {
            let _ = d.join();
        }
    }
    let _ = finisher.join();
    for s in class.students() {
        if let Some(m) = &s.lesson {
            lesson::end(&class, &mut lesson::locked(m), &s);
        }
        s.shared.shutdown.store(true, Ordering::Relaxed);
    }
    listener.stop();
    let report = match lesson::class_report(&class) {
        Some(r) => r.write(&config.out_dir).map_err(|e| {
            PlayError::Failed(format!(
                "the class report in {}: {e}",
                config.out_dir.display()
            ))
        })?,
        None => Vec::new(),
    };
    let students = class
        .finished
        .lock()
        .map(|mut f| std::mem::take(&mut *f))
        .unwrap_or_default();
    Ok(ClassSummary {
        addresses,
        students,
        refused: listener.gate().refused.snapshot(),
        workers: class.workers.len(),
        realtime,
        schedule,
        report,
    })
}
