//! Plays a scene in the browser through the library ([`play::run`]; the program's
//! `nanohaptics play` is the same call with its flags):
//! `cargo run --release -p nanohaptics-play --example play -- brickworld [PORT] [SECONDS]`.

use haptic_loop::session::SceneSource;
use play::{PlayConfig, run};
use std::sync::atomic::AtomicBool;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map_or("brickworld", String::as_str);
    let scene = match SceneSource::resolve(scene.as_ref()) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let mut c = PlayConfig::new(scene, "play.mcap".into());
    if let Some(p) = args.get(1).and_then(|p| p.parse().ok()) {
        c.port = p;
    }
    c.seconds = args.get(2).and_then(|s| s.parse().ok());
    c.keep_serving_s = Some(600.0);
    let stop = AtomicBool::new(false);
    match run(&c, &stop, &mut |url| println!("open {url} in a browser")) {
        Ok(s) => println!("{}", s.line()),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
