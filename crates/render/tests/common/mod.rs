//! Helpers shared by the render tests.

use render::{render_frame, Camera, FrameInputs, Framebuffer, Model, RenderSettings, RenderStats};
use spmd::Isa;

/// `scene` alone rendered into a new `w × h` frame with `set` (through the one driver).
pub fn render_bs(
    scene: &Model,
    cam: &Camera,
    w: u32,
    h: u32,
    set: &RenderSettings,
    isa: Isa,
) -> (Framebuffer, RenderStats) {
    let mut fb = Framebuffer::new(w, h, set.background_packed()).unwrap();
    let stats = render_frame(&FrameInputs::geometry(scene, cam), set, &mut fb, isa).unwrap();
    (fb, stats)
}
