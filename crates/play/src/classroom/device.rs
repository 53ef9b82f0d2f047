//! A real device bridged over UDP joins the class as a student: its session runs on its own
//! thread at the device's clock (the device paces it, as `play --device` does), the class's
//! pages may watch it at its own link, and the teacher sees, switches and ends it like any
//! other. One thread for the one device; the students' sessions stay on the workers.

use super::{Class, Phase, Status, Student, StudentSummary};
use crate::protocol::LatencyMs;
use crate::publish::{self, PlaySink, ToPublisher};
use crate::{announce, apply_page_switches, end_message, offer_end};
use haptic_devices::bridge::{BridgeConfig, UdpDevice};
use haptic_loop::HapticLoop;
use haptic_loop::pacing::Pacing;
use haptic_loop::runner::Runner;
use haptic_loop::session::{SessionError, now_unix_ns};
use haptic_loop::setup::{Setup, SetupOptions, session_device};
use haptic_types::HapticDevice;
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
    });
    if let Ok(mut s) = class.students.lock() {
        s.push(student.clone());
    }
    let summary = session(class, &student, bridge, start_ns, stop);
    let summary = match summary {
        Ok(s) => s,
        Err(e) => StudentSummary {
            name: name.to_string(),
            end: "stopped",
            stats: Default::default(),
            state: Vec::new(),
            recording: out,
            written: None,
            input_latency_ms: None,
            published: Default::default(),
            error: Some(e),
        },
    };
    student.set_phase(Phase::Ended);
    class.ended.fetch_add(1, Ordering::Relaxed);
    if let Ok(mut f) = class.finished.lock() {
        f.push(summary);
    }
    Ok(())
}

fn session(
    class: &Arc<Class>,
    student: &Arc<Student>,
    bridge: BridgeConfig,
    start_ns: u64,
    stop: &AtomicBool,
) -> Result<StudentSummary, String> {
    let file = class.config.scene.parse().map_err(|e| e.to_string())?;
    let source = haptic_devices::source::DeviceSource::Udp(bridge);
    let haptic_devices::source::DeviceSource::Udp(b) =
        session_device(&file, Some(&source), start_ns)
    else {
        return Err("the bridge's configuration was lost".into());
    };
    let link = format!("udp:{}", b.bind);
    let mut dev = UdpDevice::new(b);
    // Waits for the device's hello (its own wait limit applies).
    dev.open().map_err(|e| e.to_string())?;
    let specs = dev.specs().clone();
    let Setup {
        mut lp,
        header,
        mut sinks,
    } = Setup::new(&SetupOptions {
        operator: Some(format!(
            "person (bridged device, classroom student `{}`)",
            student.name
        )),
        keep_arrays: false,
        out: Some(student.out.clone()),
        start_time_ns: Some(start_ns),
        ..SetupOptions::new(&class.config.scene, specs.clone(), "realtime", &link)
    })
    .map_err(|e| e.to_string())?;
    announce(
        &student.shared,
        &class.scene_name,
        &lp,
        &specs,
        false,
        class.config.seconds,
    );
    student.set_phase(Phase::Playing);
    let fields = lp.scene().state_fields();
    let prox = haptic_loop::sound::proximity_on_distance_m(lp.scene().kind())
        .filter(|_| fields.iter().any(|f| f == "nearest_m"));
    let rate = lp.config().rate_hz;
    let (tx, rx) = std::sync::mpsc::channel::<ToPublisher>();
    let sh = student.shared.clone();
    let publisher = std::thread::Builder::new()
        .name("class-publish".into())
        .spawn(move || publish::run_publisher(rx, sh, rate, fields, prox))
        .map_err(|e| e.to_string())?;
    let mut play_sink = PlaySink::new(tx.clone(), student.shared.clone());
    let shared = student.shared.clone();
    let st = student.clone();
    let mut hook = move |tick: u64, lp: &mut HapticLoop| {
        if stop.load(Ordering::Relaxed) {
            shared.end_requested.store(true, Ordering::Relaxed);
        }
        apply_page_switches(&shared, &tx, tick, lp);
        if tick % super::STATUS_EVERY_TICKS == 0 {
            st.report(tick + 1, 0, lp);
        }
    };
    let result = {
        let mut list = sinks.list();
        list.push(&mut play_sink);
        let mut runner = Runner::new(list)
            .with_live(&mut hook)
            .stop_on(&student.shared.end_requested);
        runner.run(
            &mut lp,
            &mut dev,
            &header,
            class.ticks,
            Pacing::DeviceClock,
            &mut |_, _| {},
        )
    };
    drop(hook);
    let latencies = std::mem::take(&mut play_sink.input_latency_ms);
    drop(play_sink);
    let closed = dev.close();
    let published = publisher.join().unwrap_or_default();
    let (stats, end) = result.map_err(|e| SessionError::from(e).to_string())?;
    closed.map_err(|e| e.to_string())?;
    student.report(stats.ticks, stats.missed, &lp);
    let written = sinks.written();
    let input_latency_ms = LatencyMs::of(&latencies);
    let url = format!("/recording.mcap?s={}", student.token);
    let end_msg = end_message(
        &url,
        &student.out,
        end,
        &stats,
        rate,
        &sinks.totals,
        input_latency_ms,
        written.as_ref(),
    );
    offer_end(&student.shared, &student.out, &end_msg);
    Ok(StudentSummary {
        name: student.name.clone(),
        end: end.name(),
        stats,
        state: sinks.totals.state(),
        recording: student.out.clone(),
        written,
        input_latency_ms,
        published,
        error: None,
    })
}
