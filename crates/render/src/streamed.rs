//! Giant frames in bounded memory (the paper's 512-megapixel frame buffer, Figure 1): the
//! frame rendered in bands of whole tile rows, each band encoded straight into a streaming
//! PNG writer, in order, then overwritten by the next. Only one band is ever in memory.

use std::fs::File;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};

pub use scene::{band_rows, is_streamed, BAND_BYTES, STREAM_ABOVE_BYTES};
use spmd::Isa;

use crate::band_encoder::BandEncoder;
use crate::driver::{render_rows, FrameInputs, RenderStats, TileSet, TILE};
use crate::framebuffer::RenderError;
use crate::settings::RenderSettings;

// Bands are whole rows of tiles.
const _: () = assert!(TILE as u32 == scene::BAND_ROW_MULTIPLE);

/// The bands of `rows_per_band` rows (the last shorter) that cover `height` rows, in order.
pub fn bands(height: u32, rows_per_band: u32) -> impl Iterator<Item = Range<u32>> {
    let step = rows_per_band.max(1);
    (0..height.div_ceil(step)).map(move |b| b * step..((b + 1) * step).min(height))
}

/// An 8-bit RGBA PNG written row by row as the rows are made. It is written under a temporary
/// name beside its path (`.NAME.partial`) and renamed by [`PngStream::finish`] once every row
/// is in; dropped unfinished (an error, a panic) it removes the temporary file, so a failure
/// never leaves a half-written image under the final name.
pub struct PngStream {
    path: PathBuf,
    part: PathBuf,
    writer: Option<png::StreamWriter<'static, File>>,
    size: (u32, u32),
    rows: u32,
}

impl PngStream {
    /// Starts the PNG of a `size` frame (pixels) to be renamed to `path` when finished.
    pub fn create(path: &Path, size: (u32, u32)) -> Result<PngStream, RenderError> {
        let part = partial_name(path);
        let file = File::create(&part).map_err(|e| png_error(path, e.into()))?;
        let mut stream = PngStream {
            path: path.to_path_buf(),
            part,
            writer: None,
            size,
            rows: 0,
        };
        let mut enc = png::Encoder::new(file, size.0, size.1);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        // The stream writer buffers 1 MiB and writes each full buffer as one IDAT chunk.
        let writer = enc.write_header().map_err(|e| stream.encoding(e))?;
        let writer = writer
            .into_stream_writer_with_size(1 << 20)
            .map_err(|e| stream.encoding(e))?;
        stream.writer = Some(writer);
        Ok(stream)
    }

    /// Appends whole rows of packed pixels (a multiple of the width, in order).
    pub fn write_rows(&mut self, pixels: &[u32]) -> Result<(), RenderError> {
        let w = self.size.0 as usize;
        let rows = pixels.len() / w.max(1);
        assert!(
            pixels.len() == rows * w && self.rows as usize + rows <= self.size.1 as usize,
            "whole rows within the frame"
        );
        let writer = self.writer.as_mut().expect("the writer lives until finish");
        let result = writer.write_all(&rgba_bytes(pixels));
        result.map_err(|e| png_error(&self.path, e.into()))?;
        self.rows += rows as u32;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows(&self) -> u32 {
        self.rows
    }

    /// The file's final name.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Ends the PNG (every row must be in) and renames it to its path.
    pub fn finish(mut self) -> Result<(), RenderError> {
        assert_eq!(self.rows, self.size.1, "every row written");
        let writer = self.writer.take().expect("the writer lives until finish");
        writer.finish().map_err(|e| self.encoding(e))?;
        std::fs::rename(&self.part, &self.path).map_err(|e| png_error(&self.path, e.into()))
    }

    fn encoding(&self, e: png::EncodingError) -> RenderError {
        png_error(&self.path, std::io::Error::other(e).into())
    }
}

impl Drop for PngStream {
    fn drop(&mut self) {
        // Unfinished (finish takes the writer): close the file and take it away.
        if let Some(w) = self.writer.take() {
            drop(w);
            std::fs::remove_file(&self.part).ok();
        }
    }
}

/// Renders the `size` frame in bands of `rows_per_band` rows (see [`scene::band_rows`]), each
/// encoded into a [`PngStream`] to `path` by a [`BandEncoder`] while the next band renders;
/// `on_rows` is told the rows rendered. Pixels are bit for bit those of [`crate::render_frame`].
pub fn render_png_streamed(
    inp: &FrameInputs,
    set: &RenderSettings,
    (w, h): (u32, u32),
    rows_per_band: u32,
    path: &Path,
    isa: Isa,
    on_rows: &mut dyn FnMut(u32, u32),
) -> Result<RenderStats, RenderError> {
    let mut band = band_buffer(w, rows_per_band.min(h))?;
    let spare = band_buffer(w, rows_per_band.min(h))?;
    let mut png = BandEncoder::spawn(PngStream::create(path, (w, h))?, spare)?;
    let mut stats = RenderStats {
        isa,
        time: Default::default(),
        rays: 0,
    };
    for rows in bands(h, rows_per_band) {
        let n = (rows.end - rows.start) as usize * w as usize;
        let s = render_rows(
            inp,
            set,
            TileSet::All,
            w,
            h,
            rows.clone(),
            &mut band[..n],
            isa,
        )?;
        (stats.time, stats.rays) = (stats.time + s.time, stats.rays + s.rays);
        band = png.write(band, n)?;
        on_rows(rows.end, h);
    }
    png.finish()?;
    Ok(stats)
}

/// A zeroed buffer of `rows` rows of `width` packed pixels, or [`RenderError::TooLarge`].
pub fn band_buffer(width: u32, rows: u32) -> Result<Vec<u32>, RenderError> {
    let len = usize::try_from(u64::from(width) * u64::from(rows))
        .map_err(|_| RenderError::TooLarge(width, rows))?;
    let mut band = Vec::new();
    band.try_reserve_exact(len)
        .map_err(|_| RenderError::TooLarge(width, rows))?;
    band.resize(len, 0u32);
    Ok(band)
}

/// The temporary name `path` is written under: `.NAME.partial` in the same directory (so
/// the rename stays on one file system).
fn partial_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or("frame.png".into(), |n| n.to_string_lossy().into_owned());
    path.with_file_name(format!(".{name}.partial"))
}

fn png_error(path: &Path, source: image::ImageError) -> RenderError {
    RenderError::Png {
        path: path.display().to_string(),
        source,
    }
}

/// Packed pixels as R, G, B, A bytes (no copy on little-endian machines).
pub(crate) fn rgba_bytes(p: &[u32]) -> std::borrow::Cow<'_, [u8]> {
    if cfg!(target_endian = "little") {
        std::borrow::Cow::Borrowed(bytemuck::cast_slice(p))
    } else {
        std::borrow::Cow::Owned(p.iter().flat_map(|p| p.to_le_bytes()).collect())
    }
}
