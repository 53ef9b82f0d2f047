//! A recording's frames: PNG files and/or an animated GIF, every `every`-th tick.

use super::{MediaError, camera_for, draw_prims, style};
use crate::replay::Resimulation;
use crate::scene::optical::RecordedPicture;
use haptic_engine::scene::Scene;
use haptic_engine::sink::{Sink, SinkError, TickView};
use haptic_types::Primitive;
use haptic_types::value::ValueError;
use recording::channels::messages::DescriptionMsg;
use recording::{Recording, RecordingError};
use render::{Frame, GifWriter, Image, Palette, View};
use std::path::PathBuf;

/// What to draw of a recording.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FramesOptions {
    /// Draw every N-th tick (default: tick rate / 30, 30 frames per second of session; for the
    /// optical tweezers, the display tick nearest to that).
    pub every: Option<u64>,
    /// Camera (default: top for a flat world, oblique otherwise).
    pub view: Option<View>,
    /// Image width, px (in [`WIDTH_PX`](super::WIDTH_PX); height 3/4 of it).
    pub width: u32,
    /// Folder for `frame_NNNNN.png` files (created), if any.
    pub frames_dir: Option<PathBuf>,
    /// Animated GIF to write, if any (at most 50 frames/s: `every` ≥ rate / 50).
    pub gif: Option<PathBuf>,
    /// Recompute an optical-tweezers recording even when its recorded state could be drawn.
    pub resimulate: bool,
}

/// What [`recording_frames`] wrote.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FramesSummary {
    /// Pictures drawn.
    pub frames: u64,
    /// Ticks in the recording.
    pub ticks: u64,
    /// Whether the frames were drawn from the recorded state (optical tweezers) instead of
    /// recomputing the session.
    pub from_recorded_state: bool,
    /// GIF size, bytes (0 without a GIF).
    pub gif_bytes: u64,
    /// What was written, one line per file or folder.
    pub written: Vec<String>,
}

/// The frame renderer as a sink of the runner: draws every `every`-th tick into
/// `frames_dir/frame_NNNNN.png` and, when asked, an animated GIF.
struct FramesSink<'a> {
    opts: &'a FramesOptions,
    every: u64,
    rate: u64,
    kind: &'static str,
    path: Vec<[f64; 3]>,
    prims: Vec<Primitive>,
    frame: Option<Frame>,
    img: Option<Image>,
    gif: Option<GifWriter<std::io::BufWriter<std::fs::File>>>,
    frames: u64,
}

impl FramesSink<'_> {
    fn draw_tick(&mut self, n: u64, scene: &dyn Scene) -> Result<(), MediaError> {
        self.draw_tick_with(n, |prims| {
            scene.draw(prims);
            Ok(())
        })
    }

    /// Draws tick `n` from the primitives `fill` appends.
    fn draw_tick_with(
        &mut self,
        n: u64,
        fill: impl FnOnce(&mut Vec<Primitive>) -> Result<(), MediaError>,
    ) -> Result<(), MediaError> {
        let title = format!("{}  t = {:.3} s", self.kind, n as f64 / self.rate as f64);
        self.prims.clear();
        fill(&mut self.prims)?;
        if self.frame.is_none() {
            let cam = camera_for(&self.prims, &self.path, self.opts.view, self.opts.width)?;
            self.frame = Some(Frame::new(cam, style())?);
            self.img = Some(Image::new(cam.width_px(), cam.height_px())?);
        }
        let (Some(f), Some(im)) = (self.frame.as_mut(), self.img.as_mut()) else {
            return Ok(());
        };
        draw_prims(f, &self.prims, &title)?;
        f.draw_into(im)?;
        if let Some(dir) = &self.opts.frames_dir {
            im.save_png(dir.join(format!("frame_{:05}.png", self.frames)))?;
        }
        if let Some(path) = &self.opts.gif {
            if self.gif.is_none() {
                let file = std::fs::File::create(path).map_err(|source| MediaError::Io {
                    path: path.clone(),
                    source,
                })?;
                // palette from the first frame; the writer switches when new colours appear
                let pal = Palette::from_images(&[im], 255)?;
                let fps = self.rate as f64 / self.every as f64;
                self.gif = Some(GifWriter::new(
                    std::io::BufWriter::new(file),
                    im.width(),
                    im.height(),
                    fps,
                    pal,
                )?);
            }
            if let Some(g) = self.gif.as_mut() {
                g.add_frame(im)?;
            }
        }
        self.frames += 1;
        Ok(())
    }
}

impl Sink for FramesSink<'_> {
    fn name(&self) -> &'static str {
        "frames"
    }

    fn tick(&mut self, t: &TickView<'_>) -> Result<(), SinkError> {
        let n = t.result.tick;
        if n % self.every != 0 {
            return Ok(());
        }
        self.draw_tick(n, t.lp.scene()).map_err(SinkError::new)
    }
}

/// The recorded-state drawer of an optical-tweezers recording whose state fields this build
/// reads; `None` for other scenes (they are recomputed).
fn recorded_picture(sim: &Resimulation<'_>, d: &DescriptionMsg) -> Option<RecordedPicture> {
    if d.scene_kind != "optical_tweezers" {
        return None;
    }
    let pic = RecordedPicture::new(&sim.scene_file().world().ok()??);
    pic.reads(&d.state_fields).then_some(pic)
}

/// The drawing cadence: `opts.every`, or 30 frames per second of session (for a recorded-state
/// picture, the display tick nearest to it); checked against the GIF's 50 frames/s.
fn cadence(
    opts: &FramesOptions,
    rate: u64,
    display_every: u64,
    recorded: bool,
) -> Result<u64, MediaError> {
    let every = opts.every.unwrap_or(if recorded {
        display_every * ((rate / 30) as f64 / display_every as f64).round().max(1.0) as u64
    } else {
        (rate / 30).max(1)
    });
    let min_every = rate.div_ceil(50).max(1);
    if every == 0 || (opts.gif.is_some() && every < min_every) {
        // Only small counts are refused (0, or under `min_every`): exact as an f64.
        return Err(MediaError::Range(ValueError::out_of_range(
            "every",
            every as f64,
            if opts.gif.is_some() {
                format!("{min_every} or more ticks (a GIF plays at most 50 frames/s)")
            } else {
                "1 or more ticks".into()
            },
        )));
    }
    Ok(every)
}

/// Draws every `every`-th tick of `rec` into the folder and/or the GIF of `opts`: recomputed
/// from its inputs, or, for an optical-tweezers recording whose cadence is a multiple of the
/// display cadence (the default is) and unless `opts.resimulate`, from its recorded state.
pub fn recording_frames(
    rec: &Recording,
    opts: &FramesOptions,
) -> Result<FramesSummary, MediaError> {
    super::check_width(opts.width)?;
    let sim = Resimulation::prepare(rec)?;
    let config = sim.haptic_loop().config().clone();
    let rate = u64::from(config.rate_hz);
    let display_every = u64::from(config.display_every).max(1);
    let picture = recorded_picture(&sim, &rec.description);
    let every = cadence(opts, rate, display_every, picture.is_some())?;
    if let Some(dir) = &opts.frames_dir {
        std::fs::create_dir_all(dir).map_err(|source| MediaError::Io {
            path: dir.clone(),
            source,
        })?;
    }
    let mut sink = FramesSink {
        opts,
        every,
        rate,
        kind: sim.haptic_loop().scene().kind(),
        path: sim.cursor_path(),
        prims: Vec::new(),
        frame: None,
        img: None,
        gif: None,
        frames: 0,
    };
    let from_recorded_state = picture.is_some() && every % display_every == 0 && !opts.resimulate;
    let ticks = match picture {
        Some(pic) if from_recorded_state => {
            draw_recorded(rec, &pic, every, config.display_scale, &mut sink)?
        }
        _ => {
            let ticks = sim.ticks();
            sim.run(vec![&mut sink])?;
            ticks
        }
    };
    finish(sink, opts, ticks, from_recorded_state)
}

/// Closes the GIF and says what was written.
fn finish(
    mut sink: FramesSink<'_>,
    opts: &FramesOptions,
    ticks: u64,
    from_recorded_state: bool,
) -> Result<FramesSummary, MediaError> {
    let frames = sink.frames;
    let mut gif_bytes = 0;
    let mut written = Vec::new();
    if let Some(dir) = &opts.frames_dir {
        written.push(format!("{frames} PNG frames in {}", dir.display()));
    }
    if let (Some(g), Some(path)) = (sink.gif.take(), &opts.gif) {
        let mut w = g.finish()?;
        std::io::Write::flush(&mut w).map_err(|source| MediaError::Io {
            path: path.clone(),
            source,
        })?;
        drop(w);
        gif_bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        written.push(format!(
            "GIF animation {} ({frames} frames, {gif_bytes} bytes)",
            path.display()
        ));
    }
    Ok(FramesSummary {
        frames,
        ticks,
        from_recorded_state,
        gif_bytes,
        written,
    })
}

/// Draws every `every`-th tick of an optical-tweezers recording from its recorded state (no
/// physics): `/world/state`, the scene force of `/haptic/force` and the envelope polyline of
/// `/foxglove/scene` (written at display rate; `every` is a multiple of the display cadence).
/// Returns the number of ticks in the recording.
fn draw_recorded(
    rec: &Recording,
    pic: &RecordedPicture,
    every: u64,
    display_scale: f64,
    sink: &mut FramesSink<'_>,
) -> Result<u64, MediaError> {
    use recording::Channel;
    use recording::channels::messages::{ForceMsg, StateMsg};
    let bad = |m: &recording::reader::RecordedMessage, detail: String| {
        MediaError::Recording(RecordingError::BadMessage {
            topic: m.channel.topic().to_string(),
            log_time_ns: m.log_time_ns,
            detail,
        })
    };
    let n_fields = rec.description.state_fields.len();
    let mut state: Option<StateMsg> = None;
    let mut force: Option<ForceMsg> = None;
    let mut ticks = 0;
    for m in &rec.messages {
        match m.channel {
            Channel::State => {
                let s = StateMsg::decode(&m.data, n_fields).map_err(|e| bad(m, e.to_string()))?;
                ticks = s.tick + 1;
                state = Some(s);
                force = None;
            }
            Channel::Force => {
                force = Some(ForceMsg::decode(&m.data).map_err(|e| bad(m, e.to_string()))?);
            }
            Channel::FoxgloveScene => {
                let (Some(s), Some(f)) = (&state, &force) else {
                    continue;
                };
                if s.tick % every != 0 {
                    continue;
                }
                let envelope = recording::foxglove_out::polyline_points(&m.data, "polyline_0")
                    .map_err(|e| bad(m, e))?
                    .into_iter()
                    .map(|q| q.map(|c| c / display_scale))
                    .collect();
                sink.draw_tick_with(s.tick, |prims| {
                    pic.draw(&s.values, s.cursor_m, f.world_force_n, envelope, prims)
                        .map_err(MediaError::Picture)
                })?;
            }
            _ => {}
        }
    }
    Ok(ticks)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rate and display cadence of a scene file under `scenes/`.
    fn rates(name: &str) -> (u64, u64) {
        let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenes")
            .join(name);
        let text = std::fs::read_to_string(p).unwrap();
        let s = crate::scene::file::load_scene(&text, None).unwrap();
        (
            u64::from(s.config.rate_hz),
            u64::from(s.config.display_every),
        )
    }

    fn every(every: Option<u64>, gif: bool) -> FramesOptions {
        FramesOptions {
            every,
            gif: gif.then(|| "x.gif".into()),
            ..FramesOptions::default()
        }
    }

    /// docs/render.md: "the default cadence is the display tick nearest 30 frames/s (every 40
    /// ticks at 1 kHz with a 50 Hz display: 25 frames/s)"; recomputed, "tick rate / 30".
    #[test]
    fn the_default_cadence_is_the_display_tick_nearest_30_frames_per_second() {
        let (rate, display) = rates("optical_tweezers.toml");
        assert_eq!((rate, display), (1000, 20));
        let rec = cadence(&every(None, true), rate, display, true).unwrap();
        assert_eq!(rec, 40);
        assert_eq!(rate / rec, 25);
        // recomputed scenes: every 33 ticks at 1 kHz (30.3 frames/s)
        for scene in ["brickworld.toml", "nanoworld.toml", "wall.toml"] {
            let (rate, display) = rates(scene);
            assert_eq!((rate, display), (1000, 20), "{scene}");
            assert_eq!(
                cadence(&every(None, true), rate, display, false).unwrap(),
                33
            );
        }
        // at 10 kHz with a 50 Hz display: every 400 ticks, 25 frames/s again
        let (rate, display) = rates("optical_tweezers_10khz.toml");
        assert_eq!((rate, display), (10_000, 200));
        assert_eq!(
            cadence(&every(None, true), rate, display, true).unwrap(),
            400
        );
        assert_eq!(
            cadence(&every(None, true), rate, display, false).unwrap(),
            333
        );
        // a display cadence above rate / 30 is kept (never 0 frames)
        assert_eq!(cadence(&every(None, false), 1000, 100, true).unwrap(), 100);
        // an explicit --every is taken as given
        assert_eq!(cadence(&every(Some(30), true), 1000, 20, true).unwrap(), 30);
    }

    /// docs/render.md: a 60 s session (60 000 ticks at 1 kHz) gives 1819 frames recomputed
    /// (brick and nano worlds, every 33 ticks) and 1500 drawn from the recorded state
    /// (optical tweezers, every 40): ticks 0, N, 2N, … below 60 000.
    #[test]
    fn a_60_s_session_has_1819_recomputed_or_1500_recorded_state_frames() {
        let frames = |every: u64| (0..60_000u64).filter(|n| n % every == 0).count();
        let (rate, display) = rates("brickworld.toml");
        assert_eq!(
            frames(cadence(&every(None, true), rate, display, false).unwrap()),
            1819
        );
        let (rate, display) = rates("optical_tweezers.toml");
        assert_eq!(
            frames(cadence(&every(None, true), rate, display, true).unwrap()),
            1500
        );
    }

    /// docs/render.md: "`--every` must keep a GIF at most 50 frames/s: at 1 kHz, N ≥ 20".
    #[test]
    fn a_gif_cadence_under_20_ticks_at_1_khz_is_refused() {
        assert_eq!(
            cadence(&every(Some(20), true), 1000, 20, false).unwrap(),
            20
        );
        assert_eq!(
            cadence(&every(Some(19), true), 1000, 20, false)
                .unwrap_err()
                .to_string(),
            "every = 19 is out of range: allowed 20 or more ticks (a GIF plays at most 50 \
             frames/s)"
        );
        // without a GIF any positive cadence goes, 0 does not
        assert_eq!(cadence(&every(Some(1), false), 1000, 20, false).unwrap(), 1);
        assert_eq!(
            cadence(&every(Some(0), false), 1000, 20, false)
                .unwrap_err()
                .to_string(),
            "every = 0 is out of range: allowed 1 or more ticks"
        );
    }
}
