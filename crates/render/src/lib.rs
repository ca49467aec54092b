//! Rendering (paper §4.2, §4.5): one frame driver — 16×16 tiles scheduled by rayon, camera
//! rays of a pinhole or orthographic camera, one integrator per modality (headlight b&s,
//! volume, vol+b&s, direct light with shadows, ambient occlusion, path tracing) — writing a
//! whole RGBA8 frame, a progressive f32 accumulation, the tiles a caller owns or a band of
//! rows. All options are one [`RenderSettings`].
//!
//! Units: positions and radii in Ångström (Å); field of view in degrees.

#![warn(missing_docs)]

mod accum;
mod ao_at;
mod band_encoder;
mod camera_rays;
mod driver;
mod framebuffer;
mod integrator;
mod legend;
mod look;
mod progress;
mod rng;
mod scene_image;
mod settings;
mod streamed;

pub use accum::Accum;
pub use ao_at::ambient_occlusion_at;
pub use band_encoder::BandEncoder;
pub use driver::{
    accumulate, render_frame, render_rows, render_tiles, FrameInputs, RenderStats, TileSet, TILE,
};
pub use framebuffer::{Framebuffer, ImageFormat, RenderError, JPEG_QUALITY};
pub use integrator::{trace, Traced};
pub use legend::{draw_legend, draw_text, legend_label, Legend, LegendBox, MIN_LEGEND_FRAME};
pub use look::{Look, Mode};
pub use progress::{render_frame_with_progress, PROGRESS_BANDS};
pub use scene::{
    rgba, viridis, Camera, Coloring, Colormap, Model, ModelOptions, Projection, Style, View,
};
pub use scene_image::{
    check_frame, draw_scene_legend, render_scene, render_scene_to_file, SceneFrame, SceneImage,
};
pub use settings::{
    Material, Modality, RenderSettings, SecondaryTraversal, SettingsError, DARK_BACKGROUND,
    DIRECT_AMBIENT, HEADLIGHT_AMBIENT, MAX_AO_SAMPLES, MAX_DEPTH, MAX_SPP, WHITE_BACKGROUND,
};
pub use streamed::{
    band_buffer, band_rows, bands, is_streamed, render_png_streamed, PngStream, BAND_BYTES,
    STREAM_ABOVE_BYTES,
};
pub use volume::Light;
