//! Animated GIF output: a global palette by median cut, fast per-pixel lookup, and frames
//! cropped to what changed since the previous frame.
//!
//! Each pixel is looked up through its 15-bit colour (5 bits per channel) in a table built
//! once per palette, so indexing a frame costs one table read per pixel. After the first
//! frame, each frame is stored as the smallest rectangle holding every pixel whose palette
//! index changed, with unchanged pixels inside it transparent (disposal: keep), which is what
//! keeps a long session's GIF small and fast to encode. A frame whose colours the palette does
//! not represent (more than [`BAD_PIXEL_SHARE`] of its pixels off by more than
//! [`BAD_PIXEL_ERROR`]) switches the writer to a palette made from that frame.

use std::io::Write;

use crate::error::{RenderError, finite, out_of_range};
use crate::image::Image;

const BINS: usize = 1 << 15;

fn key(r: u8, g: u8, b: u8) -> usize {
    (usize::from(r >> 3) << 10) | (usize::from(g >> 3) << 5) | usize::from(b >> 3)
}

/// A global GIF palette (at most 255 colours; one more index is kept for transparency) with
/// its 15-bit lookup table.
#[derive(Clone, Debug, PartialEq)]
pub struct Palette {
    colors: Vec<[u8; 3]>,
    lut: Vec<u8>,
    /// Per 15-bit cell: the largest channel error of any colour in the cell against the
    /// palette colour it maps to, 8-bit units.
    cell_err: Vec<u8>,
}

#[derive(Clone, Copy, Default)]
struct Bin {
    n: u64,
    sum: [u64; 3],
}

impl Palette {
    /// A palette of at most `max_colors` (1..=255) colours that represents the pixels of
    /// `images` well: median cut over their 15-bit colour histogram, each colour the mean of
    /// the pixels it stands for. Alpha is ignored (frames are drawn on an opaque background).
    /// Deterministic: same images, same palette.
    pub fn from_images(images: &[&Image], max_colors: usize) -> Result<Palette, RenderError> {
        if !(1..=255).contains(&max_colors) {
            return Err(out_of_range(
                "palette.max_colors",
                max_colors as f64,
                "1..=255",
            ));
        }
        let mut hist = vec![Bin::default(); BINS];
        let mut any = false;
        for img in images {
            for px in img.data().chunks_exact(4) {
                let b = &mut hist[key(px[0], px[1], px[2])];
                b.n += 1;
                b.sum[0] += u64::from(px[0]);
                b.sum[1] += u64::from(px[1]);
                b.sum[2] += u64::from(px[2]);
                any = true;
            }
        }
        if !any {
            return Err(RenderError::EmptyPalette);
        }
        let used: Vec<usize> = (0..BINS).filter(|&k| hist[k].n > 0).collect();
        let mean = |k: usize| -> [f64; 3] {
            let b = &hist[k];
            b.sum.map(|s| s as f64 / b.n as f64)
        };
        // boxes of bins; split the one with the largest (pixel count × channel range)
        let mut boxes: Vec<Vec<usize>> = vec![used];
        while boxes.len() < max_colors {
            let mut best: Option<(f64, usize, usize)> = None;
            for (bi, bx) in boxes.iter().enumerate() {
                if bx.len() < 2 {
                    continue;
                }
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                let mut n = 0u64;
                for &k in bx {
                    let m = mean(k);
                    for c in 0..3 {
                        lo[c] = lo[c].min(m[c]);
                        hi[c] = hi[c].max(m[c]);
                    }
                    n += hist[k].n;
                }
                let (ch, range) = (0..3)
                    .map(|c| (c, hi[c] - lo[c]))
                    .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
                let score = range * (n as f64).sqrt();
                if range > 0.0 && best.is_none_or(|(s, _, _)| score > s) {
                    best = Some((score, bi, ch));
                }
            }
            let Some((_, bi, ch)) = best else { break };
            let mut bx = std::mem::take(&mut boxes[bi]);
            bx.sort_by(|&a, &b| mean(a)[ch].total_cmp(&mean(b)[ch]).then(a.cmp(&b)));
            let total: u64 = bx.iter().map(|&k| hist[k].n).sum();
            let mut acc = 0u64;
            let mut cut = 1;
            for (i, &k) in bx.iter().enumerate() {
                acc += hist[k].n;
                if 2 * acc >= total {
                    cut = (i + 1).clamp(1, bx.len() - 1);
                    break;
                }
            }
            let upper = bx.split_off(cut);
            boxes[bi] = bx;
            boxes.push(upper);
        }
        let colors: Vec<[u8; 3]> = boxes
            .iter()
            .map(|bx| {
                let mut s = [0u64; 3];
                let mut n = 0u64;
                for &k in bx {
                    for (acc, v) in s.iter_mut().zip(hist[k].sum) {
                        *acc += v;
                    }
                    n += hist[k].n;
                }
                s.map(|v| ((v as f64 / n as f64).round()) as u8)
            })
            .collect();
        Ok(Palette::with_colors(colors, &hist))
    }

    fn with_colors(colors: Vec<[u8; 3]>, hist: &[Bin]) -> Palette {
        let lut: Vec<u8> = (0..BINS)
            .map(|k| {
                // representative of the bin: its mean if seen, else its centre
                let rep = if hist[k].n > 0 {
                    hist[k].sum.map(|s| s as f64 / hist[k].n as f64)
                } else {
                    [
                        (((k >> 10) & 31) * 8 + 4) as f64,
                        (((k >> 5) & 31) * 8 + 4) as f64,
                        ((k & 31) * 8 + 4) as f64,
                    ]
                };
                let mut best = (f64::INFINITY, 0u8);
                for (i, c) in colors.iter().enumerate() {
                    let d: f64 = (0..3).map(|j| (f64::from(c[j]) - rep[j]).powi(2)).sum();
                    if d < best.0 {
                        best = (d, i as u8);
                    }
                }
                best.1
            })
            .collect();
        let cell_err = (0..BINS)
            .map(|k| {
                let c = colors[usize::from(lut[k])];
                let lo = [((k >> 10) & 31) * 8, ((k >> 5) & 31) * 8, (k & 31) * 8];
                (0..3)
                    .map(|j| {
                        let v = usize::from(c[j]);
                        v.abs_diff(lo[j]).max(v.abs_diff(lo[j] + 7))
                    })
                    .max()
                    .unwrap_or(0) as u8
            })
            .collect();
        Palette {
            colors,
            lut,
            cell_err,
        }
    }

    /// The colours, 8-bit RGB.
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.colors
    }

    /// Palette index for an 8-bit RGB colour.
    pub fn index_of(&self, rgb: [u8; 3]) -> u8 {
        self.lut[key(rgb[0], rgb[1], rgb[2])]
    }
}

/// Frame delays (centiseconds, GIF's unit) for `n` frames at `fps`: frame i lasts
/// `round(100 (i+1) / fps) − round(100 i / fps)`, so the total is within 5 ms of `n / fps`
/// seconds and never drifts (30 fps gives 3, 4, 3, 3, 4, 3, …).
pub fn frame_delays_cs(n: u64, fps: f64) -> impl Iterator<Item = u16> {
    (0..n).map(move |i| delay_cs(i, fps))
}

fn delay_cs(i: u64, fps: f64) -> u16 {
    let t = |k: u64| (100.0 * k as f64 / fps).round();
    (t(i + 1) - t(i)) as u16
}

/// Writes an animated GIF (looping forever) one [`Image`] at a time.
pub struct GifWriter<W: Write> {
    enc: gif::Encoder<W>,
    width: u32,
    height: u32,
    fps: f64,
    palette: Palette,
    prev: Vec<u8>,
    cur: Vec<u8>,
    sub: Vec<u8>,
    frames: u64,
    bytes_hint: u64,
    /// The palette in force when it is not the global one (flat RGB, transparent entry last).
    local: Option<Vec<u8>>,
    switches: u64,
}

/// A pixel counts as badly represented when some colour of its 15-bit cell (5 bits per
/// channel) is farther than this from the cell's palette colour in some channel (8-bit units;
/// a bound on the pixel's own error that costs one table read).
pub const BAD_PIXEL_ERROR: u8 = 40;
/// When more than this share of a frame's pixels are badly represented (a colour appeared that
/// the palette's sample frames did not have), the writer switches to a palette made from that
/// frame, carried as a local palette from then on.
pub const BAD_PIXEL_SHARE: f64 = 0.0005;

impl<W: Write> GifWriter<W> {
    /// A GIF of `width` × `height` px (1..=65535) at `fps` frames per second (in (0, 50]:
    /// GIF delays are whole centiseconds and viewers slow down delays under 2 cs), with the
    /// given palette, written to `w`.
    pub fn new(
        w: W,
        width: u32,
        height: u32,
        fps: f64,
        palette: Palette,
    ) -> Result<GifWriter<W>, RenderError> {
        finite(|| "gif.fps".into(), fps)?;
        if !(fps > 0.0 && fps <= 50.0) {
            return Err(out_of_range("gif.fps", fps, "(0, 50] frames/s"));
        }
        let (Ok(w16), Ok(h16)) = (u16::try_from(width), u16::try_from(height)) else {
            return Err(RenderError::ImageSize {
                width_px: width,
                height_px: height,
                max: 65535,
            });
        };
        if w16 == 0 || h16 == 0 {
            return Err(RenderError::ImageSize {
                width_px: width,
                height_px: height,
                max: 65535,
            });
        }
        let mut flat: Vec<u8> = palette.colors.iter().flatten().copied().collect();
        flat.extend_from_slice(&[0, 0, 0]); // the transparent index
        let mut enc =
            gif::Encoder::new(w, w16, h16, &flat).map_err(|e| RenderError::Gif(e.to_string()))?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| RenderError::Gif(e.to_string()))?;
        let n = (width as usize) * (height as usize);
        Ok(GifWriter {
            enc,
            width,
            height,
            fps,
            palette,
            prev: vec![0; n],
            cur: vec![0; n],
            sub: Vec::new(),
            frames: 0,
            bytes_hint: 0,
            local: None,
            switches: 0,
        })
    }

    /// Frames written so far.
    pub fn frame_count(&self) -> u64 {
        self.frames
    }

    /// Pixels stored in the frames so far (after cropping to what changed).
    pub fn pixels_stored(&self) -> u64 {
        self.bytes_hint
    }

    /// How many times a frame with colours the palette did not represent made the writer
    /// switch to a palette built from that frame (see [`BAD_PIXEL_SHARE`]).
    pub fn palette_switches(&self) -> u64 {
        self.switches
    }

    /// Palette indices of `img` into `self.cur`; returns how many pixels are badly represented.
    fn index(&mut self, img: &Image) -> usize {
        let mut bad = 0;
        for (dst, px) in self.cur.iter_mut().zip(img.data().chunks_exact(4)) {
            let k = key(px[0], px[1], px[2]);
            *dst = self.palette.lut[k];
            bad += usize::from(self.palette.cell_err[k] > BAD_PIXEL_ERROR);
        }
        bad
    }

    /// Appends one image (it must have the GIF's size).
    pub fn add_frame(&mut self, img: &Image) -> Result<(), RenderError> {
        if img.width() != self.width || img.height() != self.height {
            return Err(RenderError::FrameSize {
                width: self.width,
                height: self.height,
                got_width: img.width(),
                got_height: img.height(),
            });
        }
        let w = self.width as usize;
        let h = self.height as usize;
        let bad = self.index(img);
        let mut full = self.frames == 0;
        if bad as f64 > BAD_PIXEL_SHARE * (w * h) as f64 {
            self.palette = Palette::from_images(&[img], 255)?;
            let mut flat: Vec<u8> = self.palette.colors.iter().flatten().copied().collect();
            flat.extend_from_slice(&[0, 0, 0]);
            self.local = Some(flat);
            self.switches += 1;
            self.index(img);
            full = true;
        }
        let transparent = self.palette.colors.len() as u8;
        let delay = delay_cs(self.frames, self.fps);
        let palette = self.local.clone();
        let frame = if full {
            self.bytes_hint += (w * h) as u64;
            gif::Frame {
                delay,
                dispose: gif::DisposalMethod::Keep,
                width: self.width as u16,
                height: self.height as u16,
                buffer: std::borrow::Cow::Borrowed(&self.cur),
                palette,
                ..gif::Frame::default()
            }
        } else {
            // bounding rectangle of the changed pixels
            let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0usize, 0usize);
            for y in 0..h {
                let row = y * w..(y + 1) * w;
                let (a, b) = (&self.cur[row.clone()], &self.prev[row]);
                if a == b {
                    continue;
                }
                let first = a.iter().zip(b).position(|(p, q)| p != q).unwrap_or(0);
                let last = w
                    - 1
                    - a.iter()
                        .rev()
                        .zip(b.iter().rev())
                        .position(|(p, q)| p != q)
                        .unwrap_or(0);
                x0 = x0.min(first);
                x1 = x1.max(last);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
            self.sub.clear();
            if x0 > x1 {
                // nothing changed: one transparent pixel keeps the frame's time
                (x0, y0, x1, y1) = (0, 0, 0, 0);
                self.sub.push(transparent);
            } else {
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = y * w + x;
                        let c = self.cur[i];
                        self.sub
                            .push(if c == self.prev[i] { transparent } else { c });
                    }
                }
            }
            self.bytes_hint += self.sub.len() as u64;
            gif::Frame {
                delay,
                dispose: gif::DisposalMethod::Keep,
                transparent: Some(transparent),
                left: x0 as u16,
                top: y0 as u16,
                width: (x1 - x0 + 1) as u16,
                height: (y1 - y0 + 1) as u16,
                buffer: std::borrow::Cow::Borrowed(&self.sub),
                palette,
                ..gif::Frame::default()
            }
        };
        self.enc
            .write_frame(&frame)
            .map_err(|e| RenderError::Gif(e.to_string()))?;
        std::mem::swap(&mut self.prev, &mut self.cur);
        self.frames += 1;
        Ok(())
    }

    /// Ends the GIF and returns the writer.
    pub fn finish(self) -> Result<W, RenderError> {
        self.enc
            .into_inner()
            .map_err(|e| RenderError::Gif(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delays_at_30_fps_sum_exactly() {
        let d: Vec<u16> = frame_delays_cs(1800, 30.0).collect();
        assert_eq!(d.iter().map(|&x| u64::from(x)).sum::<u64>(), 6000);
        assert_eq!(&d[..6], &[3, 4, 3, 3, 4, 3]);
        assert!(d.iter().all(|&x| x == 3 || x == 4));
    }
}
