//! The one frame driver (paper §4.2): 16×16 tiles scheduled by rayon, camera rays from
//! [`crate::camera_rays`], one integrator kernel per tile ([`crate::integrator::TileJob`]),
//! results written into a whole frame, an accumulation buffer, the tiles a caller owns or a
//! band of rows.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use scene::{Camera, Model};
use spmd::Isa;
use volume::Medium;

use crate::accum::{tone, Accum};
use crate::camera_rays::ViewRays;
use crate::framebuffer::Framebuffer;
use crate::integrator::{TileJob, TileOut};
use crate::settings::{RenderSettings, SettingsError};

/// Tile edge in pixels (tiles are the rayon tasks).
pub const TILE: usize = 16;

/// What a frame shows: the ball-and-stick model and/or the volume (built with the settings'
/// `march` options), seen by a camera.
#[derive(Clone, Copy)]
pub struct FrameInputs<'a> {
    /// The opaque pass (b&s); `None` for the volume alone.
    pub model: Option<&'a Model>,
    /// The volume pass; `None` for geometry alone.
    pub volume: Option<&'a Medium<'a>>,
    /// The view.
    pub camera: &'a Camera,
}

impl<'a> FrameInputs<'a> {
    /// Ball-and-stick geometry alone, seen by `camera`.
    pub fn geometry(model: &'a Model, camera: &'a Camera) -> FrameInputs<'a> {
        FrameInputs {
            model: Some(model),
            volume: None,
            camera,
        }
    }
}

/// Which tiles (16×16, numbered `tx` across and `ty` down) a call renders.
#[derive(Clone, Copy)]
pub enum TileSet<'a> {
    /// Every tile.
    All,
    /// Tile `(tx + ty·tiles_across)` mod `ranks` == `rank` (round robin over processes).
    Interleaved {
        /// This process.
        rank: usize,
        /// Number of processes (≥ 1).
        ranks: usize,
    },
    /// The tiles for which the predicate of `(tx, ty)` is true.
    Where(&'a (dyn Fn(usize, usize) -> bool + Sync)),
}

impl TileSet<'_> {
    /// Whether tile `(tx, ty)` (in tiles from the top left) of a frame `across` tiles wide is
    /// in the set.
    pub fn owns(&self, tx: usize, ty: usize, across: usize) -> bool {
        match *self {
            TileSet::All => true,
            TileSet::Interleaved { rank, ranks } => (tx + ty * across) % ranks.max(1) == rank,
            TileSet::Where(f) => f(tx, ty),
        }
    }
}

/// What a render did.
#[derive(Clone, Copy, Debug)]
pub struct RenderStats {
    /// Backend used.
    pub isa: Isa,
    /// Wall time of the frame (tiles only, the buffers already allocated).
    pub time: Duration,
    /// Camera rays cast (pixels × samples).
    pub rays: u64,
}

impl RenderStats {
    /// Million rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64().max(1e-12) * 1e-6
    }
    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.time.as_secs_f64().max(1e-12)
    }

    /// One line for `-v`: the time, the frame (`size` pixels, `mode` as named on the command
    /// line, the settings), rays per second, frames per second, and per sample for the
    /// progressive modalities.
    pub fn describe(&self, set: &RenderSettings, size: (u32, u32), mode: &str) -> String {
        let (secs, spp, (w, h)) = (self.time.as_secs_f64(), set.frame_samples(), size);
        let per_sample = if set.is_linear() {
            format!(", {spp} spp, {:.3} s per spp", secs / spp.max(1) as f64)
        } else {
            String::new()
        };
        format!(
            "render:  {secs:.3} s  {w}x{h} {mode}{} ({:.1} Mrays/s, {:.2} fps{per_sample})",
            set.describe(),
            self.mrays_per_s(),
            self.fps(),
        )
    }
}

/// Renders the whole frame into `fb` (its size is the frame's): the headlight modes write
/// display pixels; the ray-traced modalities take [`RenderSettings::frame_samples`] samples
/// and tone map them. `isa` must be supported (see [`Isa::select`]).
pub fn render_frame(
    inp: &FrameInputs,
    set: &RenderSettings,
    fb: &mut Framebuffer,
    isa: Isa,
) -> Result<RenderStats, SettingsError> {
    render_tiles(inp, set, TileSet::All, fb, isa)
}

/// As [`render_frame`] for only the tiles in `tiles` (the others of `fb` are left as they
/// are): the union over ranks of `TileSet::Interleaved` is the whole frame, bit for bit.
pub fn render_tiles(
    inp: &FrameInputs,
    set: &RenderSettings,
    tiles: TileSet,
    fb: &mut Framebuffer,
    isa: Isa,
) -> Result<RenderStats, SettingsError> {
    let (w, h) = (fb.width as usize, fb.height as usize);
    render_rows_of(inp, set, tiles, w, h, 0..h, &mut fb.pixels, isa)
}

/// Rows `rows` of a `width × height` frame into `band` (`rows.len() × width` packed pixels,
/// row major), only the tiles of `tiles` (the other pixels are left as they are): bit for bit
/// those pixels of [`render_frame`]. A band of a giant frame, or a rank's share of it.
#[allow(clippy::too_many_arguments)]
pub fn render_rows(
    inp: &FrameInputs,
    set: &RenderSettings,
    tiles: TileSet,
    width: u32,
    height: u32,
    rows: Range<u32>,
    band: &mut [u32],
    isa: Isa,
) -> Result<RenderStats, SettingsError> {
    let (w, h) = (width as usize, height as usize);
    let rows = rows.start.min(height) as usize..rows.end.min(height) as usize;
    assert_eq!(band.len(), rows.len() * w, "band size");
    render_rows_of(inp, set, tiles, w, h, rows, band, isa)
}

/// Adds `spp` more samples per pixel into `acc` (progressive: sample numbers continue from
/// `acc.samples`, so the result does not depend on how samples are split between calls).
/// Direct and AO trace the pixel centre (one sample stands for all `spp`); path tracing
/// jitters within the pixel; the headlight modes add their display values.
pub fn accumulate(
    inp: &FrameInputs,
    set: &RenderSettings,
    acc: &mut Accum,
    spp: u32,
    isa: Isa,
) -> Result<RenderStats, SettingsError> {
    set.validate(inp.model.is_some(), inp.volume.is_some())?;
    let (w, h) = (acc.width as usize, acc.height as usize);
    let first = acc.samples;
    let st = drive(
        inp,
        set,
        TileSet::All,
        (w, h),
        0..h,
        &mut acc.rgb,
        3,
        (first, spp),
        isa,
        &|out, r, cols, dst: &mut [f32]| match out {
            TileOut::Rgb(v) => {
                for (d, s) in dst.iter_mut().zip(&v[3 * r * TILE..3 * (r * TILE + cols)]) {
                    *d += s;
                }
            }
            TileOut::Packed(p) => {
                for (d, px) in dst.chunks_mut(3).zip(&p[r * TILE..r * TILE + cols]) {
                    for (ch, v) in d.iter_mut().enumerate() {
                        *v += ((px >> (8 * ch)) & 255) as f32 / 255.0 * spp as f32;
                    }
                }
            }
        },
    );
    if w > 0 && h > 0 && spp > 0 {
        acc.samples += spp;
    }
    Ok(st)
}

/// Rows `rows` of the frame into `buf` (their pixels), only tiles of `tiles`.
#[allow(clippy::too_many_arguments)]
fn render_rows_of(
    inp: &FrameInputs,
    set: &RenderSettings,
    tiles: TileSet,
    w: usize,
    h: usize,
    rows: Range<usize>,
    buf: &mut [u32],
    isa: Isa,
) -> Result<RenderStats, SettingsError> {
    set.validate(inp.model.is_some(), inp.volume.is_some())?;
    let spp = set.frame_samples();
    let (linear, exposure) = (set.is_linear(), set.exposure);
    let k = 1.0 / spp.max(1) as f32;
    Ok(drive(
        inp,
        set,
        tiles,
        (w, h),
        rows,
        buf,
        1,
        (0, spp),
        isa,
        &|out, r, cols, dst: &mut [u32]| match out {
            TileOut::Packed(p) => dst.copy_from_slice(&p[r * TILE..r * TILE + cols]),
            TileOut::Rgb(v) => {
                for (d, c) in dst.iter_mut().zip(v[3 * r * TILE..].chunks(3)) {
                    *d = tone(c, k, linear, exposure);
                }
            }
        },
    ))
}

/// Writes one tile's result into a destination row: `(tile, tile row, columns, row)`.
type PutRow<'a, P> = dyn Fn(&TileOut, usize, usize, &mut [P]) + Sync + 'a;

/// The tile scheduler: the tiles of `tiles` that meet rows `rows` of a `w × h` frame, each a
/// rayon task dispatched once to `isa`, written into `buf` (those rows, `per_px` elements a
/// pixel) by `put(tile, tile row, columns, destination row)`. Samples `first..first + spp`.
#[allow(clippy::too_many_arguments)]
fn drive<P: Send>(
    inp: &FrameInputs,
    set: &RenderSettings,
    tiles: TileSet,
    (w, h): (usize, usize),
    rows: Range<usize>,
    buf: &mut [P],
    per_px: usize,
    (first_sample, spp): (u32, u32),
    isa: Isa,
    put: &PutRow<'_, P>,
) -> RenderStats {
    let start = Instant::now();
    let view = ViewRays::new(inp.camera, w, h);
    let across = w.div_ceil(TILE);
    if set.uses_wide() {
        if let Some(m) = inp.model {
            m.wide();
        }
    }
    let npx = AtomicU64::new(0);
    if w > 0 && h > 0 && spp > 0 && !rows.is_empty() {
        // Bands of rows within one tile row each.
        let mut bands = Vec::new();
        let mut rest = buf;
        let mut y = rows.start;
        while y < rows.end {
            let end = ((y / TILE + 1) * TILE).min(rows.end);
            let (band, tail) = rest.split_at_mut((end - y) * w * per_px);
            bands.push((y, end, band));
            rest = tail;
            y = end;
        }
        bands.into_par_iter().for_each(|(y0, y1, band)| {
            let ty = y0 / TILE;
            // Each tile is a rayon task rendering into its own buffer, then copied into the
            // band (rows of the frame are not contiguous per tile).
            let outs: Vec<(usize, TileOut)> = (0..across)
                .into_par_iter()
                .filter(|&tx| tiles.owns(tx, ty, across))
                .map(|tx| {
                    let job = TileJob {
                        model: inp.model,
                        volume: inp.volume,
                        view: &view,
                        set,
                        x0: tx * TILE,
                        y0: ty * TILE,
                        width: w,
                        first_sample,
                        spp,
                    };
                    (tx, job.dispatch(isa))
                })
                .collect();
            for (tx, out) in &outs {
                let x0 = tx * TILE;
                let cols = TILE.min(w - x0);
                npx.fetch_add(((y1 - y0) * cols) as u64, Relaxed);
                for y in y0..y1 {
                    let o = ((y - y0) * w + x0) * per_px;
                    put(out, y - ty * TILE, cols, &mut band[o..o + cols * per_px]);
                }
            }
        });
    }
    RenderStats {
        isa,
        time: start.elapsed(),
        rays: npx.into_inner() * spp as u64,
    }
}
