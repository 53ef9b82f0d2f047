//! `nanohaptics classroom`: one server for a whole class (the `play` crate's
//! [`play::classroom`]).

use crate::status;
use haptic_loop::session::SceneSource;
use std::net::{IpAddr, UdpSocket};
use std::path::PathBuf;

/// Arguments of `nanohaptics classroom`.
#[derive(clap::Args, Debug)]
pub struct ClassroomArgs {
    /// Scene file or built-in scene name (brickworld, nanoworld, wall, optical_tweezers).
    #[arg(default_value = "brickworld")]
    pub scene: PathBuf,
    /// Port of the class's pages (0: any free port).
    #[arg(long, default_value_t = play::DEFAULT_PORT)]
    pub port: u16,
    /// Address to listen on: 127.0.0.1 (this computer only, the default), 0.0.0.0 (every
    /// network of this computer) or one interface's address. Off loopback, students need the
    /// join code printed at start.
    #[arg(long, default_value = "127.0.0.1")]
    pub listen: IpAddr,
    /// Students playing at once (1 to 200).
    #[arg(long, default_value_t = 40)]
    pub max_students: usize,
    /// Folder of the recordings, one per student session (NAME-START.mcap).
    #[arg(long, default_value = "class")]
    pub out_dir: PathBuf,
    /// Each student's session length, s (0 < s ≤ 3600); without it a session ends when the
    /// student or the teacher ends it, or at Ctrl-C.
    #[arg(long)]
    pub seconds: Option<f64>,
    /// A real device over the UDP bridge (udp:HOST:PORT, or udp:PORT on loopback) that joins
    /// as a student, paced by the device; the class's pages may watch it.
    #[arg(long)]
    pub device: Option<String>,
    /// The name the bridged device plays under.
    #[arg(long, default_value = "device")]
    pub device_name: String,
    /// Take every student through a lesson (FILE, or without it the built-in module): each
    /// step runs its own scene (SCENE is then the bridged device's only), each student's
    /// steps recorded to OUT_DIR/NAME-START/STEP-ID.mcap; the teacher page follows every
    /// student and opens or holds steps; the class report is written to OUT_DIR at the end.
    #[arg(long, value_name = "FILE", num_args = 0..=1)]
    pub lesson: Option<Option<PathBuf>>,
    #[command(flatten)]
    pub(crate) rt: crate::rt_args::RtArgs,
}

/// This computer's address on its default route (no packet is sent: a UDP socket is only
/// pointed at a documentation address to learn which local address the system would use).
fn lan_address() -> Option<IpAddr> {
    let s = UdpSocket::bind("0.0.0.0:0").ok()?;
    s.connect("192.0.2.1:9").ok()?;
    s.local_addr()
        .ok()
        .map(|a| a.ip())
        .filter(|ip| !ip.is_unspecified())
}

/// Runs `nanohaptics classroom`: prints the students' and the teacher's addresses, serves the
/// class until Ctrl-C, then ends every session and prints each student's figures.
pub fn cmd(a: &ClassroomArgs) -> Result<u8, String> {
    let scene = SceneSource::resolve(&a.scene).map_err(|e| e.to_string())?;
    let mut c = play::classroom::ClassConfig::new(scene, a.out_dir.clone());
    c.port = a.port;
    c.listen = a.listen;
    c.max_students = a.max_students;
    c.seconds = a.seconds;
    c.device_name = a.device_name.clone();
    c.lesson = crate::play_cmd::lesson(a.lesson.as_ref())?;
    c.rt = a.rt.request()?;
    c.device = crate::play_cmd::bridged_device(
        a.device.as_deref(),
        "the students' hands are their pages",
    )?;
    let stop = crate::run_cmd::interrupt_flag()?;
    let listen = a.listen;
    let s = play::classroom::run(&c, &stop, &mut |addr| {
        println!(
            "classroom: up to {} students, recordings in {}",
            c.max_students,
            c.out_dir.display()
        );
        if let Some(l) = &c.lesson {
            println!(
                "  lesson         {} ({} steps; the teacher page opens the locked ones)",
                l.title,
                l.steps.len()
            );
        }
        if listen.is_loopback() {
            println!(
                "  students open  {}  (on this computer a name is enough)",
                addr.student_url
            );
        } else {
            let port = addr
                .student_url
                .rsplit(':')
                .next()
                .unwrap_or("")
                .trim_end_matches('/');
            let shown = if listen.is_unspecified() {
                lan_address().unwrap_or(listen)
            } else {
                listen
            };
            let host = match shown {
                IpAddr::V6(v6) => format!("[{v6}]"),
                v4 => v4.to_string(),
            };
            println!("  students open  http://{host}:{port}/  on the class network");
            if let Some(code) = &addr.join_code {
                println!("  join code      {code}  (write it on the board)");
            }
        }
        if let Some(b) = &c.device {
            println!(
                "  device         `{}` joins from udp:{} once it says hello",
                c.device_name, b.bind
            );
        }
        println!(
            "  teacher page   {}  (keep its code, {}, to yourself)",
            addr.teacher_url, addr.teacher_code
        );
        println!("Ctrl-C ends every session and prints the class's figures.");
    })
    .map_err(|e| e.to_string())?;
    print_summary(&s);
    Ok(status::SUCCESS)
}

/// The class's figures at its end: the workers, each student, the report, the refusals.
fn print_summary(s: &play::classroom::ClassSummary) {
    println!(
        "{} student sessions on {} tick workers; real time: {}",
        s.students.len(),
        s.workers,
        s.realtime.describe()
    );
    // The workers that ticked (none when nobody played).
    for (i, c) in s.schedule.iter().enumerate().filter(|(_, c)| c.cycles > 0) {
        println!("  tick worker {}: {}", i + 1, c.describe());
    }
    for st in &s.students {
        println!("  {}", st.line());
    }
    if let Some(md) = s
        .report
        .iter()
        .find(|p| p.extension().is_some_and(|e| e == "md"))
    {
        println!("class report: {}", md.display());
    }
    let r = s.refused;
    println!(
        "refused: {} in all ({} host, {} origin, {} join, {} code, {} connections, {} size, {} rate, {} head)",
        r.total(),
        r.host,
        r.origin,
        r.join,
        r.code,
        r.connections,
        r.size,
        r.rate,
        r.head
    );
}
