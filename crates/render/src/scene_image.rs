//! A built scene to a finished image, as `render` and every frame of a series make it: the
//! frame driver over the scene's model and volume, then the colour legend of a model coloured
//! by a column; or, for a giant frame, streamed to a PNG in bands.

use std::path::Path;

use scene::Scene;
use spmd::Isa;

use crate::driver::{render_frame, FrameInputs, RenderStats};
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

/// One frame of a built scene to make: what is seen, how, how large, on which backend. What
/// [`render_scene`], [`render_scene_to_file`] and the MPI ranks' `cluster::Ranks` take.
#[derive(Clone, Copy)]
pub struct SceneFrame<'a> {
    /// The scene: its model and volume.
    pub scene: &'a Scene,
    /// The view.
    pub camera: &'a Camera,
    /// How it is rendered (its volume marched with `settings.march`).
    pub settings: &'a RenderSettings,
    /// Width and height (pixels).
    pub size: (u32, u32),
    /// Colour of the legend's text when a legend is drawn (`None`: no legend).
    pub legend_ink: Option<[u8; 3]>,
    /// The SIMD backend (supported by this CPU, see [`Isa::select`]).
    pub isa: Isa,
}

impl SceneFrame<'_> {
    /// `f` given the frame driver's inputs: the scene's model and volume seen by the camera.
    pub fn with_inputs<R>(&self, f: impl FnOnce(&FrameInputs) -> R) -> R {
        let vscene = self.scene.volume_scene(self.settings.march);
        f(&FrameInputs {
            model: self.scene.model.as_deref(),
            volume: vscene.as_ref(),
            camera: self.camera,
        })
    }
}

/// Renders `job` into a new frame and draws the legend when `job.legend_ink` is given.
/// `on_rows`, when given, is told the rows finished as bands of the frame complete (a
/// progress bar; the bands cost idle threads at each band's end).
pub fn render_scene(
    job: &SceneFrame,
    on_rows: Option<&mut dyn FnMut(u32, u32)>,
) -> Result<SceneImage, RenderError> {
    let (set, isa) = (job.settings, job.isa);
    let mut frame = Framebuffer::new(job.size.0, job.size.1, set.background_packed())?;
    let stats = job.with_inputs(|inp| match on_rows {
        Some(f) => render_frame_with_progress(inp, set, &mut frame, isa, f),
        None => render_frame(inp, set, &mut frame, isa),
    })?;
    let legend = draw_scene_legend(job.scene, &mut frame, job.legend_ink);
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

/// Renders `job` to the image file `path` as `bnsview render` does: whole, with the legend
/// ([`render_scene`]), saved in the format of its name; or, for a frame [`is_streamed`], band by
/// band into a PNG ([`render_png_streamed`]; call [`check_frame`] first). `on_rows` as in
/// [`render_scene`] (a streamed frame reports its bands always). Returns what rendering did
/// and the legend, as [`SceneImage`].
pub fn render_scene_to_file(
    job: &SceneFrame,
    on_rows: Option<&mut dyn FnMut(u32, u32)>,
    path: &Path,
) -> Result<(RenderStats, Option<(Legend, bool)>), RenderError> {
    if !is_streamed(job.size) {
        let image = render_scene(job, on_rows)?;
        image.frame.save(path)?;
        return Ok((image.stats, image.legend));
    }
    let mut none = |_, _| {};
    let on_rows = on_rows.unwrap_or(&mut none);
    let rows = band_rows(job.size.0);
    let stats = job.with_inputs(|inp| {
        render_png_streamed(inp, job.settings, job.size, rows, path, job.isa, on_rows)
    })?;
    Ok((stats, None))
}
