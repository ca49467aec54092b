//! A built scene to a finished image, as `render` and every frame of a series make it: the
//! frame driver over the scene's model and volume, then the colour legend of a model coloured
//! by a column.

use scene::Scene;
use spmd::Isa;

use crate::driver::{render_frame, FrameInputs, RenderStats};
use crate::framebuffer::{Framebuffer, RenderError};
use crate::legend::{draw_legend, Legend};
use crate::progress::render_frame_with_progress;
use crate::settings::RenderSettings;
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
    let vscene = scene.volume_scene(settings.march);
    let inputs = FrameInputs {
        model: scene.model.as_ref(),
        volume: vscene.as_ref(),
        camera,
    };
    let mut frame = Framebuffer::new(size.0, size.1, settings.background_packed())?;
    let stats = match on_rows {
        Some(f) => render_frame_with_progress(&inputs, settings, &mut frame, isa, f)?,
        None => render_frame(&inputs, settings, &mut frame, isa)?,
    };
    let color = scene.settings.model.as_ref().map(|ms| &ms.color);
    let range = scene.model.as_ref().and_then(|m| m.color_range);
    let legend = color.and_then(|c| Legend::of(c, range)).map(|l| {
        let drawn = legend_ink.is_some_and(|ink| draw_legend(&mut frame, &l, ink).is_some());
        (l, drawn)
    });
    Ok(SceneImage {
        frame,
        stats,
        legend,
    })
}
