//! `nanohaptics play`: the teaching game in a browser (the `play` crate serves the page).

use crate::status;
use haptic_devices::source::DeviceSource;
use haptic_loop::session::SceneSource;
use std::path::PathBuf;

/// Arguments of `nanohaptics play`.
#[derive(clap::Args, Debug)]
pub struct PlayArgs {
    /// Scene file or built-in scene name (brickworld, nanoworld, wall, optical_tweezers).
    #[arg(default_value = "brickworld")]
    pub scene: PathBuf,
    /// Loopback port of the page and its WebSocket (0: any free port).
    #[arg(long, default_value_t = play::DEFAULT_PORT)]
    pub port: u16,
    /// A real device over the UDP bridge (udp:HOST:PORT, or udp:PORT on loopback) as the
    /// hand; the page is then the view and the sound.
    #[arg(long)]
    pub device: Option<String>,
    /// The session's recording (MCAP), also offered for download on the end screen.
    #[arg(long, default_value = "play.mcap")]
    pub out: PathBuf,
    /// Session length, s (0 < s ≤ 3600); without it the session ends when the player ends it
    /// on the page or presses Ctrl-C.
    #[arg(long)]
    pub seconds: Option<f64>,
    #[command(flatten)]
    pub(crate) rt: crate::rt_args::RtArgs,
}

/// `--device` of a page front end: a device in another process over the bridge (`None`: the
/// page is the hand); a device model is refused, saying whose hand the page is (`hand`).
pub(crate) fn bridged_device(
    device: Option<&str>,
    hand: &str,
) -> Result<Option<haptic_devices::bridge::BridgeConfig>, String> {
    match device.map(DeviceSource::parse).transpose() {
        Ok(None) => Ok(None),
        Ok(Some(DeviceSource::Udp(b))) => Ok(Some(b)),
        Ok(Some(DeviceSource::Model(m))) => Err(format!(
            "--device `{}`: {hand}; --device names a device in another process (udp:HOST:PORT \
             or udp:PORT)",
            m.name()
        )),
        Err(e) => Err(format!("--device: {e}")),
    }
}

/// Runs `nanohaptics play`: prints the page's address, runs the session, prints its figures.
/// After the session the end screen and the download stay up until Ctrl-C.
pub fn cmd(a: &PlayArgs) -> Result<u8, String> {
    let scene = SceneSource::resolve(&a.scene).map_err(|e| e.to_string())?;
    let mut c = play::PlayConfig::new(scene, a.out.clone());
    c.port = a.port;
    c.seconds = a.seconds;
    c.rt = a.rt.request()?;
    c.device = crate::play_cmd::bridged_device(a.device.as_deref(), "play's own hand is the page")?;
    let stop = crate::run_cmd::interrupt_flag()?;
    let s = play::run(&c, &stop, &mut |url| {
        println!("open {url} in a browser (Ctrl-C ends the session)");
    })
    .map_err(|e| e.to_string())?;
    println!("{}", s.line());
    Ok(status::SUCCESS)
}
