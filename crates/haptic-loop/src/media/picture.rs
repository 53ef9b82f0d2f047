//! One picture: a scene's initial state, or a recording's last tick framed on its bodies.

use super::{MediaError, camera_for, check_width, draw_prims, style, view_for};
use crate::replay::Resimulation;
use crate::scene::load_scene;
use crate::session::SceneSource;
use haptic_types::{Primitive, Rgba};
use recording::Recording;
use render::{Camera, Frame, View};
use std::path::Path;

/// Draws a scene file's initial state into the PNG `out`.
pub fn scene_picture(
    source: &SceneSource,
    out: &Path,
    view: Option<View>,
    width: u32,
) -> Result<(), MediaError> {
    check_width(width)?;
    let loaded = load_scene(&source.text, None).map_err(|e| source.locate(e))?;
    let mut prims = Vec::new();
    loaded.scene.draw(&mut prims);
    let cam = camera_for(&prims, &[], view, width)?;
    let mut frame = Frame::new(cam, style())?;
    let title = format!("{} (initial state)", loaded.scene.kind());
    draw_prims(&mut frame, &prims, &title)?;
    frame.finish()?.save_png(out)?;
    Ok(())
}

/// The last picture of a recording, ready to draw.
pub struct FinalPicture {
    /// The picture.
    pub frame: Frame,
    /// Ticks recomputed.
    pub ticks: u64,
    /// The box the camera frames (m): the end state's bodies, not its backdrops.
    pub action_m: ([f64; 3], [f64; 3]),
}

/// Share of the picture's shorter side left around the end state's bodies (for their labels).
const FINAL_MARGIN: f64 = 0.25;

/// The last picture of a recording: the recomputed end state framed on its bodies (not the
/// backdrops: `render::action_bounds`; the whole scene when the cursor is its only body), with
/// the cursor's path as a faint trail; with the ticks recomputed.
pub fn final_frame(
    rec: &Recording,
    view: Option<View>,
    width: u32,
) -> Result<FinalPicture, MediaError> {
    check_width(width)?;
    let sim = Resimulation::prepare(rec)?;
    let rate = sim.haptic_loop().config().rate_hz;
    let kind = sim.haptic_loop().scene().kind();
    let path = sim.cursor_path();
    let ticks = sim.ticks();
    let lp = sim.run(Vec::new())?;
    let mut prims = Vec::new();
    lp.scene().draw(&mut prims);
    // Framed on the end state's bodies (the cursor among them), with room for their labels;
    // a scene whose only body is the cursor (the wall) shows its backdrop whole.
    let bodies = prims
        .iter()
        .filter(|p| {
            !render::is_backdrop(p) && matches!(p, Primitive::Sphere { .. } | Primitive::Box { .. })
        })
        .count();
    let (lo, hi) = (if bodies >= 2 {
        render::action_bounds(&prims)
    } else {
        None
    })
    .or_else(|| render::bounds(&prims))
    .unwrap_or(([0.0; 3], [0.0; 3]));
    let cam = Camera::fit(
        view_for(lo, hi, view),
        lo,
        hi,
        width,
        width * 3 / 4,
        FINAL_MARGIN,
    )?;
    let mut frame = Frame::new(cam, style())?;
    // The trail: one point per 10 ms is finer than a pixel at any speed a hand moves.
    if path.len() > 1 {
        let step = (path.len() / 2000).max(1);
        prims.insert(
            0,
            Primitive::Polyline {
                points_m: path.iter().step_by(step).copied().collect(),
                closed: false,
                color: Rgba([0.55, 0.75, 1.0, 0.35]),
            },
        );
    }
    let t = ticks as f64 / f64::from(rate);
    let title = format!("{kind}  t = {t:.3} s (end of recording)");
    draw_prims(&mut frame, &prims, &title)?;
    Ok(FinalPicture {
        frame,
        ticks,
        action_m: (lo, hi),
    })
}
