//! Times `read_recording` alone (the file already in memory) on the recordings given as
//! arguments: `cargo run --release -p nanohaptics-recording --example read_timing --
//! recordings/brickworld.mcap [runs]`. Prints the fastest and the median of the runs (default
//! 20), in ms, with the file size and the ticks read (the same for every run: the read is
//! deterministic). A measurement helper, not a test: no time is asserted.

use std::time::Instant;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first() else {
        return Err("usage: read_timing <recording.mcap> [runs]".into());
    };
    let runs: usize = match args.get(1) {
        Some(n) => n
            .parse()
            .map_err(|_| format!("runs `{n}` is not a count"))?,
        None => 20,
    };
    let buf = std::fs::read(path).map_err(|e| format!("{path}: {e}"))?;
    let mut ms = Vec::with_capacity(runs);
    let mut ticks = 0;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let r = recording::read_recording(&buf, false).map_err(|e| e.to_string())?;
        ms.push(t0.elapsed().as_secs_f64() * 1e3);
        ticks = r.integrity.ticks;
    }
    ms.sort_by(f64::total_cmp);
    println!(
        "{path}: {} bytes, {ticks} ticks, read in {:.2} ms (fastest) / {:.2} ms (median of {})",
        buf.len(),
        ms[0],
        ms[ms.len() / 2],
        ms.len()
    );
    Ok(())
}
