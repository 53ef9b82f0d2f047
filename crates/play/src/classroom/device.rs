//! A real device bridged over UDP joins the class as a student: its session runs on its own
//! thread at the device's clock (the device paces it, as `play --device` does), the class's
//! pages may watch it at its own link, and the teacher sees, switches and ends it like any
//! other. One thread for the one device; the students' sessions stay on the workers.

use super::{Class, Phase, Status, Student, StudentSummary};
use crate::session::{Hand, PageSession, SessionSpec, SessionSummary};
use haptic_devices::bridge::BridgeConfig;
use haptic_devices::source::DeviceSource;
use haptic_engine::pacing::Pacing;
use haptic_loop::session::now_unix_ns;
use haptic_loop::setup::session_device;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// Registers the device's student `name` (its page link exists at once, waiting for the
/// device's hello) and runs its session until the device says goodbye, the teacher ends it or
/// the class stops; its summary joins the class's.
pub(crate) fn run_device_student(
    class: &Arc<Class>,
    bridge: BridgeConfig,
    name: &str,
    stop: &AtomicBool,
) -> Result<(), String> {
    let start_ns = now_unix_ns();
    let out = {
        let students = class.students.lock().map_err(|_| "the class stopped")?;
        let taken: Vec<_> = students.iter().map(|s| s.out.clone()).collect();
        super::names::recording_path(
            &class.config.out_dir,
            name,
            start_ns / 1_000_000_000,
            &taken,
        )
    };
    let shared = Arc::new(crate::server::Shared::default());
    let student = Arc::new(Student {
        name: name.to_string(),
        token: super::random_code(24, b"0123456789abcdefghijklmnopqrstuvwxyz"),
        out: out.clone(),
        shared: shared.clone(),
        status: Mutex::new(Status::waiting()),
        lesson: None,
    });
    if let Ok(mut s) = class.students.lock() {
        s.push(student.clone());
    }
    let session =
        session(class, &student, bridge, start_ns, stop).unwrap_or_else(|e| SessionSummary {
            end: "stopped",
            recording: out,
            error: Some(e),
            ..SessionSummary::default()
        });
    student.set_phase(Phase::Ended);
    class.ended.fetch_add(1, Ordering::Relaxed);
    if let Ok(mut f) = class.finished.lock() {
        f.push(StudentSummary {
            name: name.to_string(),
            step: None,
            session,
        });
    }
    Ok(())
}

fn session(
    class: &Arc<Class>,
    student: &Arc<Student>,
    bridge: BridgeConfig,
    start_ns: u64,
    stop: &AtomicBool,
) -> Result<SessionSummary, String> {
    let file = class.config.scene.parse().map_err(|e| e.to_string())?;
    let device = session_device(&file, Some(&DeviceSource::Udp(bridge)), start_ns);
    let link = match &device {
        DeviceSource::Udp(b) => format!("udp:{}", b.bind),
        DeviceSource::Model(_) => return Err("the bridge's configuration was lost".into()),
    };
    // Waits for the device's hello (its own wait limit applies).
    let hand = Hand::open(device, &student.shared).map_err(|e| e.to_string())?;
    let spec = SessionSpec {
        scene: &class.config.scene,
        scene_name: &class.scene_name,
        out: student.out.clone(),
        recording_url: format!("/recording.mcap?s={}", student.token),
        start_time_ns: start_ns,
        operator: format!(
            "person (bridged device, classroom student `{}`)",
            student.name
        ),
        link,
        seconds: class.config.seconds,
        ticks: class.ticks,
    };
    let st = student.clone();
    let mut session = PageSession::open(&spec, hand, student.shared.clone())
        .map_err(|e| e.to_string())?
        .with_reporter(
            super::STATUS_EVERY_TICKS,
            Box::new(move |p, lp| st.report(p, lp)),
        );
    student.set_phase(Phase::Playing);
    session.run(Pacing::DeviceClock, class.config.rt.as_ref(), stop);
    Ok(session.finish())
}
