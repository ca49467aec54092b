//! A frame rendered in bands of tile rows with a report after each band, so a front end can
//! show how far a long render is (a progress bar): the same bytes as [`render_frame`].

use spmd::Isa;

use crate::driver::{render_rows, FrameInputs, RenderStats, TileSet, TILE};
use crate::{Framebuffer, RenderSettings, SettingsError};

#[cfg(doc)]
use crate::render_frame;

/// Bands a frame is split into (fewer for short frames: a band is at least one tile row).
pub const PROGRESS_BANDS: u32 = 32;

/// [`render_frame`] band by band (about [`PROGRESS_BANDS`] bands of whole tile rows), calling
/// `on_rows(done, height)` after each with the rows finished so far. Same pixels as
/// [`render_frame`]; the stats sum the bands'.
pub fn render_frame_with_progress(
    inp: &FrameInputs,
    set: &RenderSettings,
    fb: &mut Framebuffer,
    isa: Isa,
    on_rows: &mut dyn FnMut(u32, u32),
) -> Result<RenderStats, SettingsError> {
    let (w, h) = (fb.width, fb.height);
    let tile = TILE as u32;
    let band = h.div_ceil(PROGRESS_BANDS).div_ceil(tile).max(1) * tile;
    let mut stats = RenderStats {
        isa,
        time: Default::default(),
        rays: 0,
    };
    let mut start = 0;
    while start < h {
        let end = (start + band).min(h);
        let pixels = &mut fb.pixels[(start * w) as usize..(end * w) as usize];
        let s = render_rows(inp, set, TileSet::All, w, h, start..end, pixels, isa)?;
        stats.time += s.time;
        stats.rays += s.rays;
        on_rows(end, h);
        start = end;
    }
    Ok(stats)
}
