//! A built scene to a finished image, as `render` and every frame of a series make it: the
//! frame driver over the scene's model and volume, then the colour legend of a model coloured
//! by a column; or, for a giant frame, streamed to a PNG in bands.

use std::path::Path;

use scene::Scene;
use spmd::Isa;

use crate::driver::{render_frame, with_scene_inputs, RenderStats};
use crate::framebuffer::{Framebuffer, ImageFormat, RenderError};
use crate::legend::{draw_legend, Legend};
use crate::progress::render_frame_with_progress;
use crate::settings::RenderSettings;
use crate::streamed::{band_buffer, band_rows, is_streamed, render_png_streamed};
use crate::Camera;

/// An image of a scene and how it was made.
pub struct SceneImage {
    /// The frame.
    pub frame: Framebuffer,
    /// What rendering it did.
    pub stats: RenderStats,
    /// The legend of the model's column colouring (`None`: coloured by element, or no model),
    /// and whether it was drawn (it is not on frames under [`crate::MIN_LEGEND_FRAME`]).
    pub legend: Option<(Legend, bool)>,
}

/// Renders `scene` seen by `camera` into a new frame of `size` pixels with `settings` (its
/// volume marched with `settings.march`), and draws the legend with text of colour
/// `legend_ink` when given. `on_rows`, when given, is told the rows finished as bands of the
/// frame complete (a progress bar; the bands cost idle threads at each band's end).
pub fn render_scene(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    size: (u32, u32),
    legend_ink: Option<[u8; 3]>,
    isa: Isa,
    on_rows: Option<&mut dyn FnMut(u32, u32)>,
) -> Result<SceneImage, RenderError> {
    let mut frame = Framebuffer::new(size.0, size.1, settings.background_packed())?;
    let stats = with_scene_inputs(scene, camera, settings.march, |inp| match on_rows {
        Some(f) => render_frame_with_progress(inp, settings, &mut frame, isa, f),
        None => render_frame(inp, settings, &mut frame, isa),
    })?;
    let legend = draw_scene_legend(scene, &mut frame, legend_ink);
    Ok(SceneImage {
        frame,
        stats,
        legend,
    })
}

/// The legend of `scene`'s model when it is coloured by a column, drawn into `frame` with text
/// of colour `legend_ink` when given: the legend and whether it was drawn (it is not on frames
/// under [`crate::MIN_LEGEND_FRAME`]).
pub fn draw_scene_legend(
    scene: &Scene,
    frame: &mut Framebuffer,
    legend_ink: Option<[u8; 3]>,
) -> Option<(Legend, bool)> {
    let color = scene.settings.model.as_ref().map(|ms| &ms.color);
    let range = scene.model.as_ref().and_then(|m| m.color_range);
    color.and_then(|c| Legend::of(c, range)).map(|l| {
        let drawn = legend_ink.is_some_and(|ink| draw_legend(frame, &l, ink).is_some());
        (l, drawn)
    })
}

/// Checks that a frame of `size` can be made before the scene is built: a streamed frame's
/// band, or the whole frame, is allocated and dropped; a streamed frame must go to a PNG
/// without a legend.
pub fn check_frame(size: (u32, u32), path: &Path, legend: bool) -> Result<(), RenderError> {
    if !is_streamed(size) {
        return Framebuffer::new(size.0, size.1, 0).map(drop);
    }
    let band = band_rows(size.0).min(size.1);
    let band_bytes = u64::from(size.0) * u64::from(band) * 4;
    let reason = match ImageFormat::from_path(path)? {
        ImageFormat::Jpeg => Some("it is written as PNG only: name the output .png".into()),
        ImageFormat::Png if legend => Some("it has no legend: leave out --legend".into()),
        ImageFormat::Png if size.0.max(size.1) > i32::MAX as u32 => Some(format!(
            "it cannot be larger than PNG's {} pixels a side",
            i32::MAX
        )),
        ImageFormat::Png => band_buffer(size.0, band).err().map(|_| {
            format!(
                "one band of {band} rows needs {:.1} GiB, more than can be allocated: make the \
                 frame narrower",
                band_bytes as f64 / f64::from(1 << 30)
            )
        }),
    };
    match reason {
        Some(reason) => Err(RenderError::Streamed { size, reason }),
        None => Ok(()),
    }
}

/// Renders `scene` to the image file `path` as `bnsview render` does: whole, with the legend
/// ([`render_scene`]), saved in the format of its name; or, for a frame [`is_streamed`], band by
/// band into a PNG ([`render_png_streamed`]; call [`check_frame`] first). `on_rows` as in
/// [`render_scene`] (a streamed frame reports its bands always). Returns what rendering did
/// and the legend, as [`SceneImage`].
#[allow(clippy::too_many_arguments)]
pub fn render_scene_to_file(
    scene: &Scene,
    camera: &Camera,
    settings: &RenderSettings,
    size: (u32, u32),
    legend_ink: Option<[u8; 3]>,
    isa: Isa,
    on_rows: Option<&mut dyn FnMut(u32, u32)>,
    path: &Path,
) -> Result<(RenderStats, Option<(Legend, bool)>), RenderError> {
    if !is_streamed(size) {
        let image = render_scene(scene, camera, settings, size, legend_ink, isa, on_rows)?;
        image.frame.save(path)?;
        return Ok((image.stats, image.legend));
    }
    let mut none = |_, _| {};
    let on_rows = on_rows.unwrap_or(&mut none);
    let rows = band_rows(size.0);
    let stats = with_scene_inputs(scene, camera, settings.march, |inp| {
        render_png_streamed(inp, settings, size, rows, path, isa, on_rows)
    })?;
    Ok((stats, None))
}
