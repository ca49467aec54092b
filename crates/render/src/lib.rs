//! Ball-and-stick rendering (paper §4.2, §4.5 "b&s"): scene assembly (styles, colouring), a
//! pinhole or orthographic camera with the paper's `far`/`close` views (Table 3), 16×16 tiles
//! scheduled by rayon, pixel blocks of `LANES` primary rays traced as one packet through the
//! BVH, headlight diffuse shading, an RGBA8 framebuffer and PNG output.
//!
//! Units: positions and radii in Ångström (Å); field of view in degrees.

mod framebuffer;
mod tile;
mod trace;

pub use framebuffer::{Framebuffer, RenderError};
pub use scene::{
    rgba, viridis, Camera, Coloring, Colormap, Model, ModelOptions, Projection, Style, View,
};
pub use tile::{render_bs, render_bs_into, render_frame_into, RenderOptions, RenderStats, TILE};
pub use trace::{
    ambient_occlusion_at, occluded, render_modal, render_modal_into, trace, Accum, Material,
    Modality, SecondaryTraversal, TraceOptions, Traced,
};
pub use volume::Light;
