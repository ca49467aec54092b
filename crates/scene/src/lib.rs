//! Scene assembly (paper §4.1): from atoms and typed settings to what the renderer traces —
//! the ball-and-stick [`Model`] (geometry, BVH, per-slot colours, bounding sphere) — and the
//! [`Camera`] with the paper's far/close views (Table 3).
//!
//! Units: positions and radii in Ångström (Å); field of view in degrees.

mod camera;
mod colormap;
mod model;

pub use camera::{Camera, Projection, View};
pub use colormap::{viridis, Colormap};
pub use model::{Coloring, Model, ModelOptions, Style};

/// Packs an RGBA8 colour as the framebuffer stores it (`r | g << 8 | b << 16 | a << 24`).
pub const fn rgba(r: u8, g: u8, b: u8, a: u8) -> u32 {
    r as u32 | (g as u32) << 8 | (b as u32) << 16 | (a as u32) << 24
}
